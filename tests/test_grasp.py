"""The grasp model: geometry, plans, execution, schedules and validation."""

import numpy as np
import pytest
from scipy.signal import find_peaks

import minvar
from minvar import GraspTask, GripVia, PointMassPlant, plan_grasp, simulate_grasp
from minvar.analysis import expected_distance
from minvar.grasp_stats import (
    bootstrap_peak,
    grasp_moments,
    max_grip_aperture,
    path_sd,
    peak,
    peak_deviation,
    summarize_grasp,
)
from minvar.moments import state_moments

pytestmark = pytest.mark.usefixtures("engine")  # plans and simulations once per solver engine


@pytest.fixture(scope="module")
def plan(engine):
    return plan_grasp(GraspTask())  # by `engine` (MINVAR_KERNEL)


@pytest.fixture(scope="module")
def result(plan):
    return simulate_grasp(plan.task, 400, seed=7, plan=plan)


def test_default_geometry_is_the_thesis_setup():
    t = GraspTask()
    assert t.wrist_start == (0.0, -0.26)
    assert t.wrist_target == (0.0, -0.06)  # 6 cm short of the object centre (line 724)
    assert t.transport_distance == pytest.approx(0.20)  # "distance to be moved" (line 953)
    assert t.finger_target == (0.02, 0.0) and t.thumb_target == (-0.02, 0.0)
    assert t.shoulder == pytest.approx((0.15, -0.51))
    # the closed tips start below the line of the digit targets (Fig. 4.4(a), line 814)
    assert 0 < t.tip_start < t.wrist_offset
    assert t.steps == 100
    (via,) = t.via_schedule  # 1 cm outside the 4 cm disk, level, at 70 %
    assert (via.half_aperture, via.height, via.fraction) == pytest.approx((0.03, 0.0, 0.7))


def test_plan_is_consistent_with_the_kinematics(plan):
    t = plan.task
    arm, finger, thumb = plan.arm, plan.finger, plan.thumb
    np.testing.assert_allclose(arm.chain.forward(arm.q_start), t.wrist_start, atol=1e-12)
    np.testing.assert_allclose(arm.chain.forward(arm.q_goal), t.wrist_target, atol=1e-12)
    for cp, sign in ((finger, 1), (thumb, -1)):
        np.testing.assert_allclose(cp.chain.forward(cp.q_start), (0, t.tip_start), atol=1e-12)
        np.testing.assert_allclose(cp.chain.forward(cp.q_goal), (sign * 0.02, 0.06), atol=1e-12)
        np.testing.assert_allclose(cp.chain.forward(cp.q_via), [(sign * 0.03, 0.06)], atol=1e-12)
        # each digit's middle joint bends out on its own side, at start and goal
        for q in (cp.q_start, cp.q_goal, *cp.q_via):
            assert sign * cp.chain.elbow(q)[0] > 0.05
        # the joint-space task is what was planned
        np.testing.assert_allclose(cp.task.start, cp.q_start)
        np.testing.assert_allclose(cp.problem.X1[:2], cp.q_start)
    # the thumb mirrors the finger: q_thumb = (pi - q1, -q2), without a 2 pi jump
    for a, b in ((finger.q_start, thumb.q_start), (finger.q_goal, thumb.q_goal)):
        np.testing.assert_allclose(b, (np.pi - a[0], -a[1]), atol=1e-12)
    # the right arm's elbow is outward (+x), bent, on the same branch throughout
    assert arm.elbow == 1 and arm.q_start[1] > 1.5 and arm.q_goal[1] > 1.0
    assert arm.chain.elbow(arm.q_start)[0] > 0.25
    # forward models (A, B) and inverse models (L, K) of the right sizes
    for cp in plan.chains.values():
        T, n = cp.problem.horizon, cp.problem.n_states
        assert cp.solution.L.shape == (T, 2, n) and cp.solution.K.shape == (T, n, 6)
        assert cp.solution.converged


def test_noise_free_plan_reaches_the_targets(plan):
    t, nom = plan.task, plan.nominal()
    assert nom.trials == 1
    assert np.linalg.norm(nom.wrist[0, -1] - t.wrist_target) < 1e-4
    assert np.linalg.norm(nom.finger[0, -1] - t.finger_target) < 2e-4
    assert np.linalg.norm(nom.thumb[0, -1] - t.thumb_target) < 2e-4
    assert nom.wrist_speed[0, -1] < 1e-3 and nom.finger_speed[0, -1] < 1e-3
    # it starts where it should: wrist at (0, -d), tips touching
    np.testing.assert_allclose(nom.wrist[0, 0], t.wrist_start, atol=1e-12)
    assert nom.aperture[0, 0] < 1e-12
    # the digit passes its via-point (hand frame) at 70 % of the movement
    k = round(0.7 * t.steps)
    tip = plan.finger.chain.forward(plan.finger.nominal_q[k])
    assert np.linalg.norm(tip - plan.finger_via[0]) < 5e-4
    # the exact mean of the execution is the noise-free plan
    mean, _ = state_moments(plan.finger.execution, plan.finger.solution.K,
                            plan.finger.solution.L)
    np.testing.assert_allclose(mean, plan.finger.solution.mean_states, atol=1e-12)


def test_execution_noise_is_one_percent_per_joint(plan):
    cp = plan.arm
    np.testing.assert_allclose(cp.execution.C, [np.diag([0.01, 0]), np.diag([0, 0.01])])
    assert not np.any(cp.execution.D0)  # no sensory noise at execution by default
    np.testing.assert_allclose(cp.problem.C[0], 0.4 * np.eye(2))  # planning: sigma_u
    noisy = plan_grasp(GraspTask(execution_sigma_s=0.4)).arm.execution
    np.testing.assert_allclose(noisy.D0, cp.problem.D0)


def test_simulation_shapes_and_identities(result):
    r = result
    assert r.time.shape == (101,) and r.time[-1] == pytest.approx(1.0)
    for name in ("wrist", "finger", "thumb", "wrist_velocity", "q_arm", "q_thumb"):
        assert getattr(r, name).shape == (400, 101, 2)
    np.testing.assert_allclose(r.aperture, np.linalg.norm(r.finger - r.thumb, axis=-1))
    np.testing.assert_allclose(r.wrist, r.plan.arm.chain.forward(r.q_arm))
    # digit bases follow the simulated wrist
    np.testing.assert_allclose(r.finger - r.wrist, r.plan.finger.chain.forward(r.q_finger))
    assert np.all(r.aperture[:, 0] < 1e-12)  # the digits start touching
    # velocities by the Jacobian agree with finite differences of the paths
    fd = np.gradient(r.finger[0], r.time, axis=0)
    # central differences err by O(dt^2) times the jerk, which grows with the speed
    np.testing.assert_allclose(r.finger_velocity[0, 1:-1], fd[1:-1],
                               atol=0.025 * np.abs(fd).max())


def test_monte_carlo_variability_matches_exact_moments(plan, result):
    mom = grasp_moments(plan)
    w_mc, w_ex = peak(path_sd(result.wrist), result.relative_time), peak(mom.wrist_sd,
                                                                         mom.relative_time)
    a_mc, a_ex = peak(result.aperture_sd, result.relative_time), peak(mom.aperture_sd,
                                                                      mom.relative_time)
    # an SD from 400 repetitions has about 3.5 % sampling error
    assert w_mc[0] == pytest.approx(w_ex[0], rel=0.12)
    assert a_mc[0] == pytest.approx(a_ex[0], rel=0.12)
    assert abs(w_mc[1] - w_ex[1]) <= 0.05 and abs(a_mc[1] - a_ex[1]) <= 0.05
    np.testing.assert_allclose(result.finger_end.std(0, ddof=1), mom.finger_end_sd, rtol=0.15)
    np.testing.assert_allclose(result.aperture.mean(0), mom.aperture_mean, atol=2e-6)
    # 1 % CV: tens of micrometres
    assert 2e-5 < w_ex[0] < 2e-4


def test_seed_reproducibility():
    t = GraspTask(duration=0.5)
    a, b = simulate_grasp(t, 30, seed=3), simulate_grasp(t, 30, seed=3)
    c = simulate_grasp(t, 30, seed=4)
    np.testing.assert_array_equal(a.finger, b.finger)
    np.testing.assert_array_equal(a.wrist, b.wrist)
    assert not np.array_equal(a.finger, c.finger)
    g = simulate_grasp(t, 30, seed=np.random.default_rng(3))  # a Generator works too
    assert g.finger.shape == a.finger.shape


def test_reach_only_keeps_the_grip_closed():
    t = GraspTask(reach_only=True)
    r = simulate_grasp(t, 50, seed=0)
    assert t.via_schedule == ()
    assert r.aperture.max() < 1e-9  # closed start = goal: no command, no noise
    assert np.linalg.norm(r.wrist[:, -1].mean(0) - t.wrist_target) < 1e-4
    assert plan_grasp(t).finger.q_via.shape == (0, 2)


def test_delayed_opening_schedule_keeps_the_grip_small_early():
    normal = plan_grasp(GraspTask()).nominal()
    delayed = GraspTask(grip_via=(GripVia(0.0, 0.0, 0.5), GripVia(0.03, 0.0, 0.85)))
    d = simulate_grasp(delayed, 50, seed=0)
    half = d.relative_time <= 0.5
    assert d.aperture[:, half].max() < 0.3 * normal.aperture[0, half].max()
    assert d.aperture[:, half].max() < 0.015
    assert d.mga_time.mean() > 0.75 > normal.mga_time[0]
    assert d.mga.mean() > 0.05  # it still opens wide, late


def test_open_close_open_schedule_has_two_maxima():
    oco = GraspTask(grip_via=(GripVia(0.03, 0, 0.45), GripVia(0.005, 0, 0.65),
                              GripVia(0.03, 0, 0.85)))
    r = simulate_grasp(oco, 50, seed=0)
    a = r.aperture.mean(0)
    peaks, _ = find_peaks(a, prominence=0.01)
    assert len(peaks) == 2
    t1, t2 = r.relative_time[peaks]
    assert 0.3 < t1 < 0.55 and 0.75 < t2 < 0.95
    assert a[(r.relative_time > t1) & (r.relative_time < t2)].min() < 0.025
    # a normal grasp has one
    assert len(find_peaks(plan_grasp(GraspTask()).nominal().aperture[0], prominence=0.01)[0]) == 1


def test_other_time_step():
    t = GraspTask(plant=PointMassPlant(dt=1 / 30))
    nom = plan_grasp(t).nominal()
    assert t.steps == 30 and nom.time.shape == (31,)
    assert np.linalg.norm(nom.wrist[0, -1] - t.wrist_target) < 1e-3
    assert np.linalg.norm(nom.finger[0, -1] - t.finger_target) < 2e-3


def test_to_pandas_is_tidy(result):
    df = result.to_pandas()
    assert len(df) == 400 * 101
    row = df[(df.trial == 3) & (df.step == 50)].iloc[0]
    assert row.time == pytest.approx(0.5)
    assert row.finger_x == result.finger[3, 50, 0] and row.aperture == result.aperture[3, 50]
    assert row.thumb_q2 == result.q_thumb[3, 50, 1]


def test_summary(result, plan):
    s = summarize_grasp(result, grasp_moments(plan))
    assert s.trials == 400
    assert s.mga_mean == pytest.approx(result.mga.mean())
    assert 0.055 < s.mga_mean < 0.07 and 0.55 < s.mga_time_mean < 0.8
    assert s.finger_sd_x == pytest.approx(result.finger_end[:, 0].std(ddof=1))
    assert s.finger_sd == pytest.approx(np.hypot(s.finger_sd_x, s.finger_sd_y))
    assert s.wrist_sd_peak_exact == pytest.approx(s.wrist_sd_peak, rel=0.12)
    assert np.isnan(summarize_grasp(result).wrist_sd_peak_exact)


def test_statistics_functions_known_answers():
    rt = np.linspace(0, 1, 5)
    ap = np.array([[0, 1, 3, 2, 1], [0, 4, 1, 1, 1.0]])
    mga, when = max_grip_aperture(ap, rt)
    np.testing.assert_array_equal(mga, [3, 4])
    np.testing.assert_array_equal(when, [0.5, 0.25])
    assert peak(np.array([1, 5, 2.0]), np.array([0, 0.5, 1])) == (5.0, 0.5)
    paths = np.zeros((2, 3, 2))
    paths[0, 1] = (3, 4)  # mean path at step 1 is (1.5, 2); deviations 2.5 each
    dev, t = peak_deviation(paths, np.array([0, 0.5, 1]))
    np.testing.assert_allclose(dev, [2.5, 2.5])
    np.testing.assert_allclose(t, [0.5, 0.5])
    np.testing.assert_allclose(path_sd(paths), [0, np.sqrt(4.5 + 8), 0])


def test_expected_distance_known_answers():
    # no scatter: the offset itself; no offset, isotropic: the Rayleigh mean s sqrt(pi/2)
    assert expected_distance((3e-3, 4e-3), np.zeros((2, 2))) == pytest.approx(5e-3)
    s = 2e-5
    assert expected_distance((0, 0), s**2 * np.eye(2)) == pytest.approx(
        s * np.sqrt(np.pi / 2), rel=3e-3)
    # far from the target the scatter adds |offset| + tr(cov)/(2 |offset|) to first order
    off, cov = np.array([1e-3, 0.0]), np.diag([0.0, (1e-4) ** 2])
    assert expected_distance(off, cov) == pytest.approx(1e-3 + 1e-8 / 2e-3, rel=1e-4)


def test_exact_summary_matches_the_repetitions(plan, result):
    s = summarize_grasp(result, grasp_moments(plan))
    # 400 repetitions: the mean distance and the MGA agree with their exact values
    assert s.finger_distance_mean == pytest.approx(s.finger_distance_exact, rel=0.05)
    assert s.mga_mean == pytest.approx(s.mga_exact, rel=1e-3)
    assert abs(s.mga_time_mean - s.mga_time_exact) <= 0.011


def test_bootstrap_peak_resamples_the_repetitions(result):
    draws = bootstrap_peak(result.aperture, result.relative_time, 300,
                           np.random.default_rng(1))
    assert draws.shape == (300, 2)
    sd, when = peak(result.aperture_sd, result.relative_time)
    lo, hi = np.percentile(draws[:, 0], [2.5, 97.5])
    assert lo < sd < hi and hi - lo < 0.3 * sd  # an SD from 400 repetitions: +-7 %
    assert abs(np.median(draws[:, 1]) - when) <= 0.02
    # one repetition repeated: every resample is it, so the SD is 0 throughout
    same = np.repeat(result.aperture[:1], 5, axis=0)
    np.testing.assert_allclose(bootstrap_peak(same, result.relative_time, 3,
                                              np.random.default_rng(0))[:, 0], 0, atol=1e-12)


def test_moments_with_another_transport_are_exact(plan):
    near = GraspTask(distance=0.20)
    moved = grasp_moments(plan).with_transport(grasp_moments(plan_grasp(near)))
    direct = grasp_moments(plan_grasp(near))
    for name in ("wrist_mean", "finger_mean", "thumb_mean", "aperture_sd"):
        np.testing.assert_allclose(getattr(moved, name), getattr(direct, name), atol=1e-12)
    np.testing.assert_allclose(moved.finger_cov, direct.finger_cov, rtol=1e-9, atol=1e-20)
    with pytest.raises(ValueError, match="steps"):
        moved.with_transport(grasp_moments(plan_grasp(GraspTask(duration=0.5))))


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(distance=0.5), "distance"),  # wrist target beyond the arm's reach
        (dict(distance=0.0), "distance"),
        (dict(object_size=0.4), "object_size"),  # wider than the gripper spans
        (dict(object_size=-0.01), "object_size"),
        (dict(viapoint_offset=0.2), "viapoint_offset"),
        (dict(viapoint_time=1.0), "viapoint_time"),
        (dict(viapoint_time=0.0), "viapoint_time"),
        (dict(viapoint_time=0.999), "viapoint_time"),  # rounds onto the last step
        (dict(duration=0.0), "duration"),
        (dict(duration=-1.0), "duration"),
        (dict(duration=0.01), "duration"),  # shorter than 2 steps
        (dict(duration=float("nan")), "duration"),
        (dict(execution_cv=-0.1), "execution_cv"),
        (dict(shoulder_offset=(0.7, 0.0)), "shoulder_offset"),
        (dict(grip_via=(GripVia(0.03, 0, 0.8), GripVia(0.03, 0, 0.5))), "grip_via"),
        (dict(grip_via=("x",)), "grip_via"),
        (dict(grip_via=(GripVia(0.25, 0, 0.5),)), "grip_via"),
        (dict(tip_start=0.3), "tip_start"),
    ],
)
def test_bad_task_raises_naming_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        GraspTask(**kwargs)


def test_bad_call_arguments():
    with pytest.raises(ValueError, match="fraction"):
        GripVia(0.02, 0.0, 1.2)
    with pytest.raises(ValueError, match="half_aperture"):
        GripVia(-0.01, 0.0, 0.5)
    for trials in (0, -3, 2.5, True):
        with pytest.raises(ValueError, match="trials"):
            simulate_grasp(GraspTask(), trials)
    with pytest.raises(ValueError, match="plan"):
        simulate_grasp(GraspTask(), 5, plan=plan_grasp(GraspTask(object_size=0.06)))
    with pytest.raises(ValueError, match="task"):
        plan_grasp("not a task")


def test_public_names_exported():
    for name in ("GraspTask", "GripVia", "plan_grasp", "simulate_grasp", "GraspResult",
                 "GraspPlan", "ChainPlan", "grasp_moments", "summarize_grasp"):
        assert name in minvar.__all__ and hasattr(minvar, name)

"""Reaching behaviour the thesis (ch. 3) and docs/model.md report."""

import numpy as np
import pytest
from scipy.stats import spearmanr

from minvar import (
    PointMassPlant,
    ReachTask,
    ViaPoint,
    reach_problem,
    simulate_reach,
    solve,
    state_moments,
)
from minvar.analysis import (
    closest_approach,
    count_speed_peaks,
    path_deviation,
    peak_to_mean_speed,
    speed_accuracy,
)
from minvar.plant import POSITION, VELOCITY

pytestmark = pytest.mark.usefixtures("engine")  # every test plans: once per solver engine

THESIS_REACH = ReachTask((0.2, 0.2), (0.4, 0.5), 0.5)
S_TASK = ReachTask(
    (-0.2, 0.5), (-0.4, 0.2), 1.0,
    (ViaPoint((-0.4, 0.4), fraction=0.25), ViaPoint((-0.2, 0.3), fraction=0.75)),
)


def test_default_reach_ends_on_target_and_at_rest():
    sol = solve(reach_problem(THESIS_REACH))
    end = sol.mean_states[-1]
    assert np.linalg.norm(end[POSITION] - THESIS_REACH.goal) < 0.002
    assert np.linalg.norm(end[VELOCITY]) < 0.01


@pytest.mark.parametrize(
    "start, goal, duration",
    [((0.2, 0.2), (0.4, 0.5), 0.5), ((0.0, 0.3), (0.3, 0.3), 0.8), ((0.1, 0.5), (-0.1, 0.2), 1.2)],
)
def test_point_to_point_speed_profile_has_one_peak(start, goal, duration):
    r = simulate_reach(ReachTask(start, goal, duration), 100, seed=1)
    assert count_speed_peaks(r.mean_speed) == 1
    assert 1.7 < peak_to_mean_speed(r.mean_speed, r.time) < 2.2  # humans: ~1.875


def test_mean_path_is_straight_single_paths_are_curved():
    r = simulate_reach(THESIS_REACH, 200, seed=2)
    mean_dev = np.abs(path_deviation(r.mean_position, THESIS_REACH.start, THESIS_REACH.goal)).max()
    single = np.abs(path_deviation(r.position, THESIS_REACH.start, THESIS_REACH.goal)).max(axis=1)
    assert mean_dev < 0.002
    assert np.median(single) > 3 * mean_dev


def test_endpoint_sd_falls_as_duration_grows_exactly():
    sds = []
    for d in (0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2):
        p = reach_problem(ReachTask(THESIS_REACH.start, THESIS_REACH.goal, d))
        s = solve(p)
        _, cov = state_moments(p, s.K, s.L)
        sds.append(np.sqrt(np.trace(cov[-1][:2, :2])))
    assert np.all(np.diff(sds) < 0)
    assert sds[0] > 1.8 * sds[-1]


@pytest.mark.parametrize("dt, sd_mm, end_mm", [(0.01, 7.3, 1.45), (0.0111, 8.2, 1.7),
                                                (0.008, 5.8, 1.2), (0.005, 3.6, 0.7)])
def test_variability_depends_on_the_step_as_documented(dt, sd_mm, end_mm):
    # docs/model.md: the noises enter per step, unscaled by sqrt(dt), so the
    # end-point SD follows the step while the mean path hardly moves
    p = reach_problem(THESIS_REACH, PointMassPlant(dt=dt))
    s = solve(p)
    mean, cov = state_moments(p, s.K, s.L)
    end_mm_measured = np.linalg.norm(mean[-1, :2] - THESIS_REACH.goal) * 1000
    assert np.sqrt(np.trace(cov[-1][:2, :2])) * 1000 == pytest.approx(sd_mm, abs=0.05)
    assert end_mm_measured == pytest.approx(end_mm, abs=0.05)



@pytest.mark.parametrize("trials", [1, 0, 2.5])
def test_speed_accuracy_needs_two_whole_repetitions(trials):
    # one gave NaN SDs (and numpy's warnings), as the command line refuses it
    with pytest.raises(ValueError, match="speed_accuracy: trials: .*>= 2"):
        speed_accuracy(THESIS_REACH, durations=(0.5,), trials=trials)

@pytest.mark.slow
def test_speed_accuracy_sweep_monte_carlo():
    sweep = speed_accuracy(THESIS_REACH, trials=200, seed=0)
    s = sweep.summary
    assert len(sweep.trials) == 8 * 200
    assert spearmanr(s["duration"], s["sd_total"]).statistic < -0.9
    assert spearmanr(s["duration"], s["distance_mean"]).statistic < -0.8
    assert s["sd_total"].iloc[0] > 1.5 * s["sd_total"].iloc[-1]


def test_s_movement_passes_via_points_and_reaches_goal():
    # thesis line 652: the 's' passes its via-points. Judged as numbers.md judges it: the
    # expected path's miss against 2 SD of the repetitions' scatter where each is due
    r = simulate_reach(S_TASK, 200, seed=3)
    expected = solve(reach_problem(S_TASK)).mean_states[:, POSITION]
    for v in S_TASK.via_points:
        k = int(round(v.fraction * (r.time.size - 1)))
        scatter = np.sqrt(r.position[:, k].var(axis=0, ddof=1).sum())
        assert closest_approach(expected, v.position) < 2 * scatter
    # the number, and why it is not 0: the via-point cost is soft, so the path cuts the
    # corners by about 5 mm (4.8 and 4.4 mm; a 5 mm limit was our own rule, not a claim)
    miss = [closest_approach(expected, v.position) * 1000 for v in S_TASK.via_points]
    assert miss == pytest.approx([4.8, 4.4], abs=0.1)
    # its end against 2 SD of the repetitions' end points, as numbers.md judges it (a 1 cm
    # limit was our own number); the number: 3.4 mm
    end = np.linalg.norm(expected[-1] - np.asarray(S_TASK.goal))
    assert end < 2 * np.sqrt(r.position[:, -1].var(axis=0, ddof=1).sum())
    assert end * 1000 == pytest.approx(3.4, abs=0.1)
    assert count_speed_peaks(r.mean_speed) == 3  # three strokes of the 's'


def test_monte_carlo_endpoint_sd_matches_exact():
    p = reach_problem(THESIS_REACH)
    s = solve(p)
    _, cov = state_moments(p, s.K, s.L)
    r = simulate_reach(THESIS_REACH, 2000, seed=4, solution=s)
    np.testing.assert_allclose(r.endpoint.std(0, ddof=1), np.sqrt(np.diag(cov[-1])[:2]), rtol=0.08)


def test_result_object():
    r = simulate_reach(THESIS_REACH, 3, seed=0)
    t, pos = r
    assert t.shape == (51,) and pos.shape == (3, 51, 2)
    df = r.to_pandas()
    assert len(df) == 3 * 51
    assert {"trial", "step", "time", "x", "y", "speed"} <= set(df.columns)
    assert df.loc[df.trial == 2, "x"].to_numpy() == pytest.approx(pos[2, :, 0])

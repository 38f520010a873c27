"""Appendix A: curvature, via-point extraction, MSD, replay and generalisation."""

import numpy as np
import pytest

from minvar import ReachTask, ViaPoint, simulate_reach
from minvar.analysis import closest_approach
from minvar.kinematics import TwoLinkChain
from minvar.similarity import joint_msd, msd, path_distance
from minvar.viapoints import (
    CRITERIA,
    ViaPointMovement,
    compare_criteria,
    criterion_signal,
    expected_path,
    extract_via_points,
    letter_a,
    local_extrema,
    replay,
    spatiotemporal_curvature,
    viapoint_timing,
)

CURVED = ReachTask((-0.15, 0.30), (0.15, 0.30), 1.0, (ViaPoint((0.0, 0.40), fraction=0.5),))


# --- spatio-temporal curvature (eq. A.1) -------------------------------------------------

def test_curvature_of_straight_constant_speed_line_is_zero():
    t = np.linspace(0, 1, 101)
    p = np.stack([0.1 + 0.3 * t, 0.2 - 0.4 * t], axis=1)
    np.testing.assert_allclose(spatiotemporal_curvature(p, t), 0, atol=1e-12)


@pytest.mark.parametrize("R, w", [(0.1, 2 * np.pi), (0.05, 10.0), (0.3, 1.0)])
def test_curvature_of_circle_at_constant_angular_speed(R, w):
    # x = R cos wt, y = R sin wt:  |a| = R w^2, v x a = R^2 w^3, |v| = R w
    # => kappa = sqrt(R^2 w^4 + R^4 w^6) / (1 + R^2 w^2)^(3/2) = R w^2 / (1 + R^2 w^2)
    t = np.linspace(0, 2, 4001)
    p = R * np.stack([np.cos(w * t), np.sin(w * t)], axis=1)
    kappa = spatiotemporal_curvature(p, t)
    np.testing.assert_allclose(kappa, R * w**2 / (1 + R**2 * w**2), rtol=1e-4)


def test_curvature_of_accelerating_line_is_its_acceleration_over_speed_term():
    # x = t^2 along a line: v = 2t, a = 2, v x a = 0 => kappa = 2 / (1 + 4 t^2)^(3/2)
    t = np.linspace(0, 1, 201)
    p = np.stack([t**2, np.zeros_like(t)], axis=1)
    np.testing.assert_allclose(spatiotemporal_curvature(p, t), 2 / (1 + 4 * t**2) ** 1.5,
                               rtol=1e-9)


@pytest.mark.usefixtures("engine")  # plans: once per solver engine
def test_curvature_unit_is_the_length_unit_of_eq_a1():
    # the same circle in centimetres: R -> 100 R in the formula
    R, w = 0.1, 2 * np.pi
    t = np.linspace(0, 2, 4001)
    p = R * np.stack([np.cos(w * t), np.sin(w * t)], axis=1)
    kappa = spatiotemporal_curvature(p, t, unit=0.01)
    Rc = 100 * R
    np.testing.assert_allclose(kappa, Rc * w**2 / (1 + Rc**2 * w**2), rtol=1e-4)
    # speed and acceleration extrema do not depend on it; curvature's do
    r = simulate_reach(CURVED, 1, seed=0)
    for c in ("speed", "acceleration"):
        np.testing.assert_array_equal(extract_via_points(r.position[0], r.time, c),
                                      extract_via_points(r.position[0], r.time, c, unit=0.01))
    metres = extract_via_points(r.position[0], r.time, "curvature")
    cm = extract_via_points(r.position[0], r.time, "curvature", unit=0.01)
    assert not np.array_equal(metres, cm)
    with pytest.raises(ValueError, match="unit"):
        spatiotemporal_curvature(p, t, unit=0.0)


# --- extraction -------------------------------------------------------------------------

def test_local_extrema_of_a_synthetic_profile():
    t = np.linspace(0, 1, 1201)
    x = np.sin(2 * np.pi * 3 * t) + 0.01 * np.sin(2 * np.pi * 60 * t)
    found = t[local_extrema(x, prominence=0.05)]
    np.testing.assert_allclose(found, np.arange(1, 12, 2) / 12, atol=0.005)
    assert len(local_extrema(x, prominence=0.0)) > 6  # ripples near the peaks, when asked for
    assert local_extrema(np.ones(10)).size == 0


def test_extract_finds_speed_extrema_of_a_known_movement():
    # x = t - sin(4 pi t) / (4 pi): speed 1 - cos(4 pi t): max at 0.25, 0.75; min at 0.5
    t = np.arange(101) * 0.01
    p = np.stack([t - np.sin(4 * np.pi * t) / (4 * np.pi), np.zeros_like(t)], axis=1)
    np.testing.assert_array_equal(extract_via_points(p, t, "speed"), [25, 50, 75])
    # the acceleration magnitude |4 pi sin 4 pi t| has maxima at 1/8, 3/8, ... and a zero at 1/2
    acc = extract_via_points(p, t, "acceleration")
    np.testing.assert_allclose(t[acc], [0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875], atol=0.011)
    with pytest.raises(ValueError, match="criterion"):
        criterion_signal(p, t, "jerk")


# --- similarity (eq. A.2) -----------------------------------------------------------------

def test_msd_zero_for_identical_and_grows_with_shift():
    t = np.linspace(0, 1, 101)
    q = np.stack([np.sin(np.pi * t), t**2], axis=1)
    assert msd(q, q) == 0.0
    d = [msd(q[k:], q[: len(q) - k]) for k in range(6)]
    assert d[0] == 0 and np.all(np.diff(d) > 0)
    # sum over samples and joints, over the common length only
    a, b = np.zeros((4, 2)), np.ones((3, 2))
    assert msd(a, b) == 6.0 and msd(a, b, mean=True) == 2.0
    with pytest.raises(ValueError, match="coordinates"):
        msd(np.zeros((3, 2)), np.zeros((3, 3)))


@pytest.mark.usefixtures("engine")  # plans: once per solver engine
def test_joint_msd_compensates_for_arm_length():
    t, p = expected_path(CURVED)
    _, other = expected_path(ReachTask(CURVED.start, CURVED.goal, 1.0))
    small = joint_msd(p, other, chain=TwoLinkChain(0.3, 0.3))
    assert small > 0 and joint_msd(p, p) == 0
    # The same movements made by an arm twice as long, twice as large: same angles.
    big = joint_msd(2 * p, 2 * other, chain=TwoLinkChain(0.6, 0.6))
    assert big == pytest.approx(small, rel=1e-9)
    assert msd(2 * p, 2 * other) == pytest.approx(4 * msd(p, other))  # Cartesian MSD is not


def test_path_distance_ignores_timing():
    s = np.linspace(0, 1, 50)
    line = np.stack([s, np.zeros_like(s)], axis=1)
    slow = np.stack([s**2, np.zeros_like(s)], axis=1)  # same segment, other timing
    assert path_distance(line, slow) < 1e-12
    assert path_distance(line, line + [0, 0.01]) == pytest.approx(0.01)


# --- representation and generalisation (eqs. A.3-A.5) -----------------------------------------

def test_representation_round_trips_a_task():
    m = ViaPointMovement.from_task(CURVED)
    assert m.via_fractions == (0.5,) and m.n_points == 3
    task = m.to_task()
    assert task.via_points[0].time_s(task.duration) == pytest.approx(0.5)
    assert ViaPointMovement.from_task(task) == m
    df = m.to_pandas()
    assert list(df["kind"]) == ["start", "via", "goal"] and df["time"].iloc[-1] == 1.0


def test_retime_keeps_relative_via_point_times():
    m = letter_a(duration=2.0)
    fast = m.retime(0.8)
    assert fast.via_fractions == m.via_fractions
    np.testing.assert_allclose(fast.via_times, m.via_times / 2.0 * 0.8)  # eq. A.3
    assert fast.points().tolist() == m.points().tolist()


def test_transform_maps_points_by_eqs_a4_a5():
    m = ViaPointMovement((0.1, 0.3), (0.2, 0.5), 1.0, ((0.3, 0.4), (0.25, 0.45)), (0.3, 0.6))
    new = m.transform(start=(-0.1, 0.35), scale=0.5)
    s_old, s_new = np.array([0.1, 0.3]), np.array([-0.1, 0.35])
    np.testing.assert_allclose(new.start, s_new)
    np.testing.assert_allclose(new.goal, 0.5 * (np.array([0.2, 0.5]) - s_old) + s_new)
    np.testing.assert_allclose(new.via_positions, 0.5 * (np.array(m.via_positions) - s_old) + s_new)
    assert new.via_fractions == m.via_fractions and new.duration == m.duration


@pytest.mark.usefixtures("engine")  # plans: once per solver engine
def test_replayed_generalised_path_is_the_transformed_path():
    m = letter_a(duration=1.5)
    _, p = replay(m)
    s0 = np.array(m.start)
    moved = m.transform(start=(0.1, 0.3))
    _, p_moved = replay(moved)
    np.testing.assert_allclose(p_moved, p - s0 + (0.1, 0.3), atol=1e-9)  # exactly translated
    half = m.transform(scale=0.5)
    _, p_half = replay(half)
    # Signal-dependent noise scales with the movement, sensory noise does not:
    # the plan is nearly, not exactly, scale-free. Within 2 % of the letter's height.
    assert np.abs(p_half - (0.5 * (p - s0) + s0)).max() < 0.02 * 0.5 * 0.10


def test_movement_validation_names_the_argument():
    with pytest.raises(ValueError, match="via_fractions"):
        ViaPointMovement((0, 0.3), (0.1, 0.3), 1.0, ((0, 0.4),), (1.2,))
    with pytest.raises(ValueError, match="via_positions but"):
        ViaPointMovement((0, 0.3), (0.1, 0.3), 1.0, ((0, 0.4),), ())
    with pytest.raises(ValueError, match="scale"):
        letter_a().transform(scale=0)
    with pytest.raises(ValueError, match="indices"):
        ViaPointMovement.from_samples(np.zeros((5, 2)), np.arange(5.0), [0, 2])


# --- the letter 'a' ----------------------------------------------------------------------

@pytest.mark.usefixtures("engine")  # plans: once per solver engine
def test_letter_a_reverses_with_near_zero_speed_near_70_percent():
    m = letter_a(duration=1.5)
    t, p = replay(m)
    speed = np.linalg.norm(np.gradient(p, t, axis=0), axis=1)
    window = (t > 0.55 * m.duration) & (t < 0.85 * m.duration)
    i = np.flatnonzero(window)[np.argmin(speed[window])]
    assert 0.65 < t[i] / m.duration < 0.75
    assert speed[i] < 0.1 * speed.max()
    # and the bowl closes: the path passes near every via-point
    for v in m.via_positions:
        assert closest_approach(p, v) < 0.01


# --- criteria and timing -----------------------------------------------------------------------

@pytest.mark.usefixtures("engine")  # plans: once per solver engine
def test_compare_criteria_replays_and_scores():
    r = simulate_reach(CURVED, 2, seed=7)
    trajs = [(r.time, r.position[k]) for k in range(2)]
    c = compare_criteria(trajs)
    t = c.table
    assert len(t) == 2 * len(CRITERIA)
    assert (t["n_points"] == t["n_via"] + 2).all()
    np.testing.assert_allclose(t["score"], t["msd_per_sample"] * t["n_points"])
    assert c.best in CRITERIA and c.summary["wins"].sum() == 2
    # via-points help: every criterion's replay beats the replay from start and goal alone
    p = r.position[0]
    _, bare = replay(ViaPointMovement(p[0], p[-1], r.time[-1]))
    worst = t.loc[t["trajectory"] == 0, "msd"].max()
    assert worst < joint_msd(p, bare)
    with pytest.raises(ValueError, match="plant.dt"):
        compare_criteria([(r.time * 2, r.position[0])])


@pytest.mark.usefixtures("engine")  # plans: once per solver engine
def test_viapoint_timing_is_zero_at_reference_and_grows():
    df = viapoint_timing(CURVED, [-0.2, -0.1, 0.0, 0.1, 0.2])
    assert df.loc[2, "msd"] == 0 and df.loc[2, "path_distance"] == 0
    assert df.loc[0, "msd"] > df.loc[1, "msd"] > 0
    assert df.loc[4, "msd"] > df.loc[3, "msd"] > 0
    with pytest.raises(ValueError, match="via-point"):
        viapoint_timing(ReachTask((0, 0.3), (0.1, 0.3), 0.5), [0.1])

"""Chapter 2 baselines against closed forms and optimality conditions."""

import numpy as np
import pytest
from scipy.integrate import trapezoid

from minvar import ViaPoint
from minvar.analysis import path_deviation, peak_to_mean_speed
from minvar.baselines import (
    minimum_angle_jerk,
    minimum_derivative,
    minimum_derivative_profile,
    minimum_jerk,
    peak_to_mean_ratio,
)
from minvar.kinematics import TwoLinkChain


def test_minimum_jerk_matches_flash_hogan_closed_form():
    start, goal, T = np.array([0.1, 0.2]), np.array([0.3, 0.45]), 0.8
    m = minimum_jerk(start, goal, T, dt=0.001)
    tau = m.time / T
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    ds = (30 * tau**2 - 60 * tau**3 + 30 * tau**4) / T
    np.testing.assert_allclose(m.position, start + np.outer(s, goal - start), atol=1e-12)
    np.testing.assert_allclose(m.velocity, np.outer(ds, goal - start), atol=1e-10)
    # boundary conditions: at rest, zero acceleration, at both ends
    for k in (0, -1):
        np.testing.assert_allclose(m.velocity[k], 0, atol=1e-12)
        np.testing.assert_allclose(m.acceleration[k], 0, atol=1e-9)


def test_minimum_jerk_speed_is_a_symmetric_bell_with_ratio_exactly_1_875():
    m = minimum_jerk((0, 0), (0.2, 0), 1.0, dt=0.001)
    np.testing.assert_allclose(m.speed, m.speed[::-1], atol=1e-12)
    assert np.argmax(m.speed) == len(m.time) // 2
    assert peak_to_mean_ratio(3) == pytest.approx(1.875, abs=1e-15)
    assert peak_to_mean_speed(m.speed, m.time) == pytest.approx(1.875, abs=1e-5)
    # straight path
    assert np.abs(path_deviation(m.position, (0, 0), (0.2, 0))).max() < 1e-15


def test_minimum_jerk_via_point_passes_exactly_and_is_optimal():
    start, goal, T = (0.0, 0.3), (0.2, 0.3), 1.0
    via = ViaPoint((0.05, 0.42), fraction=0.3)
    m = minimum_jerk(start, goal, T, via_points=[via], dt=0.001)
    assert m.position[300] == pytest.approx(via.position, abs=1e-12)
    np.testing.assert_allclose(m.velocity[[0, -1]], 0, atol=1e-10)
    # Optimality (Euler-Lagrange, weak form): the jerk is orthogonal to the jerk
    # of every admissible variation (zero, with its first two derivatives, at
    # the ends; zero at the via-point time).
    t = m.time
    jerk = np.gradient(m.acceleration, t, axis=0, edge_order=2)
    rng = np.random.default_rng(0)
    P = np.polynomial.Polynomial
    for _ in range(3):
        eta = P([0, 0, 0, 1]) * P([1, -1]) ** 3 * P([-0.3, 1]) * P(rng.normal(size=3))
        eta_jerk = eta.deriv(3)(t)[:, None] * np.array([[1.0, -0.5]])
        inner = trapezoid(np.sum(jerk * eta_jerk, axis=1), t)
        scale = np.sqrt(trapezoid(np.sum(jerk**2, 1), t) * trapezoid(np.sum(eta_jerk**2, 1), t))
        assert abs(inner) < 1e-3 * scale


def test_minimum_derivative_spline_equals_incomplete_beta_closed_form():
    tau = np.linspace(0, 1, 201)
    for n in range(1, 7):
        m = minimum_derivative(n, (0, 0), (1.0, 0), 1.0, dt=0.005)
        pos, vel = minimum_derivative_profile(n, tau)
        np.testing.assert_allclose(m.position[:, 0], pos, atol=1e-9)
        np.testing.assert_allclose(m.velocity[:, 0], vel, atol=1e-7)
        assert peak_to_mean_speed(m.speed, m.time) == pytest.approx(
            peak_to_mean_ratio(n), rel=1e-3
        )


def test_peak_to_mean_ratio_increases_with_order():
    r = [peak_to_mean_ratio(n) for n in range(1, 8)]
    assert r[0] == pytest.approx(1.0) and r[1] == pytest.approx(1.5)
    assert np.all(np.diff(r) > 0)
    # the human 1.875 is closest to jerk (thesis Fig. 2.6(c))
    assert int(np.argmin(np.abs(np.array(r) - 1.875))) + 1 == 3


def test_minimum_angle_jerk_joint_paths_straight_hand_paths_curved():
    chain = TwoLinkChain()
    start, goal = (-0.15, 0.35), (0.15, 0.35)
    m = minimum_angle_jerk(start, goal, 1.0, chain=chain, dt=0.002)
    q = m.joints.position
    np.testing.assert_allclose(m.hand.position[0], start, atol=1e-12)
    np.testing.assert_allclose(m.hand.position[-1], goal, atol=1e-12)
    # straight in joint space: every sample on the segment from q[0] to q[-1]
    d = (q[-1] - q[0]) / np.linalg.norm(q[-1] - q[0])
    rel = q - q[0]
    assert np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]).max() < 1e-12
    # curved in hand space: the hand bows by centimetres
    assert np.abs(path_deviation(m.hand.position, start, goal)).max() > 0.01
    # hand velocity and acceleration are consistent with the hand path
    t = m.time
    v = np.gradient(m.hand.position, t, axis=0)
    np.testing.assert_allclose(v[1:-1], m.hand.velocity[1:-1], atol=2e-4)
    a = np.gradient(m.hand.velocity, t, axis=0)
    np.testing.assert_allclose(a[2:-2], m.hand.acceleration[2:-2], atol=2e-3)
    df = m.to_pandas()
    assert len(df) == len(t) and {"x", "y", "shoulder", "elbow", "speed"} <= set(df.columns)


def test_minimum_angle_jerk_via_point_reached_in_hand_space():
    via = ViaPoint((0.0, 0.45), seconds=0.4)
    m = minimum_angle_jerk((-0.15, 0.35), (0.15, 0.35), 1.0, via_points=[via], dt=0.01)
    np.testing.assert_allclose(m.hand.position[40], via.position, atol=1e-12)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: minimum_derivative(0, (0, 0), (1, 0), 1.0), "order"),
        (lambda: minimum_jerk((0, 0), (1, 0), -1.0), "duration"),
        (lambda: minimum_jerk((0, 0), (1, 0), 1.0, dt=0.9), "dt"),
        (lambda: minimum_jerk((0, 0), (1,), 1.0), "goal"),
        (
            lambda: minimum_jerk(
                (0, 0), (1, 0), 1.0,
                via_points=[ViaPoint((0, 1), fraction=0.6), ViaPoint((1, 1), fraction=0.3)],
            ),
            "increase",
        ),
        (lambda: minimum_angle_jerk((0, 0.3), (0, 0.9), 1.0), "out of reach"),
        (lambda: minimum_derivative_profile(3, [1.5]), "tau"),
    ],
)
def test_bad_input_names_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()

"""Chapter 2 comparison models: minimum jerk, minimum n-th derivative, minimum angle jerk.

Method. The thesis made its minimum jerk figures "using the optimal control
scheme of chapter 3" and defers the details to an appendix that our copy does
not contain. We use the exact solutions instead:

- minimising the integral of the squared n-th derivative of position, with the
  position given at the start, the goal and any via-points (at given times)
  and derivatives 1 .. n-1 zero at both ends, gives a spline of degree
  2n - 1 with its knots at the via-point times, continuous up to derivative
  2n - 2 (the Euler-Lagrange equation x^(2n) = 0 on each segment, with the
  natural conditions at the free interior derivatives). For jerk (n = 3) this
  is the piecewise quintic of Flash & Hogan (1985); with no via-point it is
  the familiar ``x0 + (x1 - x0)(10 tau^3 - 15 tau^4 + 6 tau^5)``. We build it
  with :func:`scipy.interpolate.make_interp_spline`, which places the knots of
  an odd-degree spline at the data sites.
- without via-points the point-to-point solution is the regularised incomplete
  beta function ``I_tau(n, n)``, so the velocity is a scaled beta density and
  the peak/mean velocity ratio has the closed form ``B(n, n)^-1 / 4^(n-1)``:
  1.5, 1.875, 2.1875, 2.4609, 2.7070 for n = 2 .. 6 (Fig. 2.6(c)).
- minimum angle jerk (Fig. 2.7, 2.8) is the same minimum jerk spline in the
  joint space of a two-link arm: start, via-points and goal are mapped to
  joint angles by inverse kinematics (one elbow branch, angles kept
  continuous), the joint trajectory is the quintic spline (straight in joint
  space when there are no via-points) and the hand follows by forward
  kinematics (a curved path).

All trajectories are noiseless: these models have no disturbance, which is
the thesis's point against them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.interpolate import make_interp_spline
from scipy.special import beta as beta_function
from scipy.special import betainc

from .kinematics import TwoLinkChain
from .limits import check_steps
from .task import ViaPoint
from .validation import Point, checked

__all__ = [
    "SmoothTrajectory",
    "ArmTrajectory",
    "minimum_derivative",
    "minimum_jerk",
    "minimum_angle_jerk",
    "minimum_derivative_profile",
    "peak_to_mean_ratio",
]

#: Derivative orders with a name, for labels.
_ORDER_NAMES = {1: "velocity", 2: "acceleration", 3: "jerk", 4: "snap", 5: "crackle", 6: "pop"}


@dataclass(frozen=True, eq=False)
class SmoothTrajectory:
    """A noiseless planned trajectory in a 2-D space (hand: m; joints: rad).

    Attributes
    ----------
    time : (S,) array
        Sample times, s, from 0 to the movement duration.
    position : (S, 2) array
        Positions (m, or rad in joint space).
    velocity : (S, 2) array
        First time derivative (m/s or rad/s).
    acceleration : (S, 2) array
        Second time derivative (m/s^2 or rad/s^2).
    label : str
        What produced it (e.g. ``"minimum jerk"``), for legends.
    """

    time: np.ndarray = field(repr=False)
    position: np.ndarray = field(repr=False)
    velocity: np.ndarray = field(repr=False)
    acceleration: np.ndarray = field(repr=False)
    label: str = ""

    @property
    def speed(self) -> np.ndarray:
        """(S,) tangential speed, m/s (or rad/s)."""
        return np.hypot(self.velocity[:, 0], self.velocity[:, 1])

    def to_pandas(self) -> pd.DataFrame:
        """One row per sample: time (s), x, y, vx, vy, speed, ax, ay."""
        return pd.DataFrame(
            {
                "time": self.time,
                "x": self.position[:, 0],
                "y": self.position[:, 1],
                "vx": self.velocity[:, 0],
                "vy": self.velocity[:, 1],
                "speed": self.speed,
                "ax": self.acceleration[:, 0],
                "ay": self.acceleration[:, 1],
            }
        )


@dataclass(frozen=True, eq=False)
class ArmTrajectory:
    """A minimum angle jerk movement of a two-link arm.

    Attributes
    ----------
    chain : TwoLinkChain
        The arm.
    joints : SmoothTrajectory
        Joint angles (rad), velocities and accelerations; ``position[:, 0]`` is
        the shoulder angle, ``position[:, 1]`` the elbow angle.
    hand : SmoothTrajectory
        Hand (tip) position, velocity and acceleration by forward kinematics, m.
    """

    chain: TwoLinkChain
    joints: SmoothTrajectory = field(repr=False)
    hand: SmoothTrajectory = field(repr=False)

    @property
    def time(self) -> np.ndarray:
        """(S,) sample times, s."""
        return self.joints.time

    def to_pandas(self) -> pd.DataFrame:
        """One row per sample: time, hand x, y, speed (m, m/s), shoulder, elbow (rad) and
        their velocities (rad/s)."""
        return pd.DataFrame(
            {
                "time": self.time,
                "x": self.hand.position[:, 0],
                "y": self.hand.position[:, 1],
                "speed": self.hand.speed,
                "shoulder": self.joints.position[:, 0],
                "elbow": self.joints.position[:, 1],
                "shoulder_velocity": self.joints.velocity[:, 0],
                "elbow_velocity": self.joints.velocity[:, 1],
            }
        )


def _check_order(order) -> int:
    if isinstance(order, bool) or not isinstance(order, int | np.integer) or order < 1:
        raise ValueError(f"order: expected an integer derivative order >= 1, got {order!r}")
    return int(order)


def _sample_times(owner: str, duration: float, dt: float) -> np.ndarray:
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"{owner}: duration must be a positive time in s, got {duration}")
    if not (np.isfinite(dt) and 0 < dt <= duration / 2):
        raise ValueError(
            f"{owner}: dt must be positive and at most half the duration ({duration} s), got {dt}"
        )
    steps = check_steps(duration, dt, f"{owner}: duration")  # before sampling it
    return np.linspace(0.0, duration, steps + 1)


def _knots(owner: str, start, goal, duration: float, via_points: Sequence[ViaPoint]):
    """Knot times (s) and positions (K, 2) of start, via-points and goal."""
    times = [0.0]
    points = [checked(start, Point, (owner, "start"))]
    for i, v in enumerate(via_points):
        if not isinstance(v, ViaPoint):
            raise ValueError(f"{owner}: via_points[{i}] must be a ViaPoint, got {v!r}")
        times.append(v.time_s(duration))
        points.append(v.position)
    times.append(float(duration))
    points.append(checked(goal, Point, (owner, "goal")))
    times = np.asarray(times)
    if np.any(np.diff(times) <= 0):
        raise ValueError(
            f"{owner}: via-point times must increase strictly inside (0, {duration}) s, "
            f"got {times[1:-1].tolist()}"
        )
    return times, np.asarray(points, dtype=float)


def _rest_to_rest_spline(times: np.ndarray, points: np.ndarray, order: int):
    """Spline of degree 2 order - 1 through ``points`` with derivatives 1..order-1 zero at
    both ends: the minimiser of the integrated squared ``order``-th derivative."""
    k = 2 * order - 1
    ends = [(d, np.zeros(points.shape[1])) for d in range(1, order)]
    return make_interp_spline(times, points, k=k, bc_type=(ends, ends) if ends else None)


def minimum_derivative(
    order: int,
    start,
    goal,
    duration: float,
    *,
    via_points: Sequence[ViaPoint] = (),
    dt: float = 0.01,
) -> SmoothTrajectory:
    """The movement that minimises the integrated squared ``order``-th derivative of position.

    Parameters
    ----------
    order : int
        Derivative minimised: 2 acceleration, 3 jerk (Flash & Hogan), 4 snap, ...
    start, goal : (2,) array_like
        Start and goal positions (m; any unit works, the result is in the same).
    duration : float
        Movement time, s.
    via_points : sequence of ViaPoint
        Positions the movement passes through exactly, at the given times.
    dt : float
        Sample interval of the returned trajectory, s.

    Returns
    -------
    SmoothTrajectory
        Starts and ends at rest (derivatives 1 .. order-1 zero at both ends).
    """
    order = _check_order(order)
    time = _sample_times("minimum_derivative", duration, dt)
    knot_t, knot_p = _knots("minimum_derivative", start, goal, duration, via_points)
    spline = _rest_to_rest_spline(knot_t, knot_p, order)
    name = _ORDER_NAMES.get(order, f"derivative {order}")
    return SmoothTrajectory(
        time=time,
        position=spline(time),
        velocity=spline(time, 1),
        acceleration=spline(time, 2),
        label=f"minimum {name}",
    )


def minimum_jerk(
    start, goal, duration: float, *, via_points: Sequence[ViaPoint] = (), dt: float = 0.01
) -> SmoothTrajectory:
    """Minimum (Cartesian) jerk movement (Flash & Hogan 1985; thesis eq. 2.11, Fig. 2.5).

    Parameters
    ----------
    start, goal : (2,) array_like
        Start and goal hand positions, m.
    duration : float
        Movement time, s.
    via_points : sequence of ViaPoint
        Positions passed through exactly at the given times (piecewise quintic).
    dt : float
        Sample interval, s.

    Returns
    -------
    SmoothTrajectory
        A straight path with the bell-shaped speed profile
        ``30 tau^2 (1 - tau)^2 |goal - start| / duration`` when there are no via-points.
    """
    return minimum_derivative(3, start, goal, duration, via_points=via_points, dt=dt)


def minimum_derivative_profile(order: int, tau) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form normalised point-to-point profile of the minimum ``order``-th derivative.

    Parameters
    ----------
    order : int
        Derivative minimised (>= 1).
    tau : array_like
        Normalised time t / duration, in [0, 1].

    Returns
    -------
    position, velocity : arrays shaped like ``tau``
        Fraction of the distance covered, ``I_tau(order, order)`` (regularised
        incomplete beta), and its derivative with respect to ``tau``.
    """
    order = _check_order(order)
    tau = np.asarray(tau, dtype=float)
    if np.any((tau < 0) | (tau > 1)):
        raise ValueError("minimum_derivative_profile: tau must lie in [0, 1]")
    velocity = tau ** (order - 1) * (1 - tau) ** (order - 1) / beta_function(order, order)
    return betainc(order, order, tau), velocity


def peak_to_mean_ratio(order: int) -> float:
    """Peak/mean velocity ratio of the minimum ``order``-th derivative reach (Fig. 2.6(c)).

    Parameters
    ----------
    order : int
        Derivative minimised (>= 1).

    Returns
    -------
    float
        ``1 / (4^(order-1) B(order, order))``: exactly 1.875 for jerk (order 3).
    """
    order = _check_order(order)
    return float(0.25 ** (order - 1) / beta_function(order, order))


def _tip_acceleration(chain: TwoLinkChain, q, dq, ddq) -> np.ndarray:
    """Hand acceleration J(q) ddq + dJ/dt dq of a two-link chain, m/s^2."""
    q1, q12 = q[:, 0], q[:, 0] + q[:, 1]
    w1, w12 = dq[:, 0], dq[:, 0] + dq[:, 1]
    a1, a12 = ddq[:, 0], ddq[:, 0] + ddq[:, 1]
    ax = (-chain.l1 * (np.cos(q1) * w1**2 + np.sin(q1) * a1)
          - chain.l2 * (np.cos(q12) * w12**2 + np.sin(q12) * a12))
    ay = (chain.l1 * (-np.sin(q1) * w1**2 + np.cos(q1) * a1)
          + chain.l2 * (-np.sin(q12) * w12**2 + np.cos(q12) * a12))
    return np.stack([ax, ay], axis=-1)


def minimum_angle_jerk(
    start,
    goal,
    duration: float,
    *,
    chain: TwoLinkChain | None = None,
    elbow: int = 1,
    via_points: Sequence[ViaPoint] = (),
    dt: float = 0.01,
) -> ArmTrajectory:
    """Minimum angle jerk movement of a two-link arm (thesis eq. 2.12, Figs. 2.7-2.8).

    Parameters
    ----------
    start, goal : (2,) array_like
        Start and goal hand positions, m, in the chain's frame.
    duration : float
        Movement time, s.
    chain : TwoLinkChain, optional
        The arm (default: two 0.30 m links, shoulder at the origin).
    elbow : {1, -1}
        Elbow branch of the inverse kinematics, the same for every point (the
        sign of the elbow angle).
    via_points : sequence of ViaPoint
        Hand positions passed through exactly at the given times.
    dt : float
        Sample interval, s.

    Returns
    -------
    ArmTrajectory
        Joint paths straight (no via-points), hand path curved.

    Raises
    ------
    ValueError
        If a point is out of the arm's reach.
    """
    chain = TwoLinkChain() if chain is None else chain
    time = _sample_times("minimum_angle_jerk", duration, dt)
    knot_t, knot_p = _knots("minimum_angle_jerk", start, goal, duration, via_points)
    q_knots = chain.inverse(knot_p, elbow)
    q_knots[:, 0] = np.unwrap(q_knots[:, 0])  # no 2 pi jump between knots
    spline = _rest_to_rest_spline(knot_t, q_knots, 3)
    q, dq, ddq = spline(time), spline(time, 1), spline(time, 2)
    joints = SmoothTrajectory(time, q, dq, ddq, label="minimum angle jerk (joints)")
    hand = SmoothTrajectory(
        time=time,
        position=chain.forward(q),
        velocity=np.einsum("sij,sj->si", chain.jacobian(q), dq),
        acceleration=_tip_acceleration(chain, q, dq, ddq),
        label="minimum angle jerk",
    )
    return ArmTrajectory(chain=chain, joints=joints, hand=hand)

"""The reach-to-grasp task of thesis chapter 4: geometry, via-points, timing.

Geometry (frames: docs/coordinates.md; model: docs/model.md). World frame:
origin at the object centre, +y from the wrist's start toward the object,
metres. The object is a disk of diameter ``object_size``.

* **Arm**: a 2-link planar chain (links 0.30 m). Its shoulder sits at
  ``shoulder_offset`` from the wrist's start position ``(0, -distance)`` —
  by default 0.15 m to the right of and 0.25 m behind it, a right arm whose
  elbow bends outward (to +x of the shoulder-wrist line), 122 deg at the
  start. The wrist target is ``wrist_offset`` (6 cm) short of the object
  centre along the approach: ``(0, -wrist_offset)`` (thesis line 724). The
  wrist therefore travels ``distance - wrist_offset``
  (:attr:`GraspTask.transport_distance`): 20 cm by default, the thesis's
  "distance to be moved" (line 953; "20cm in front of the hand", line 770).
* **Gripper**: two 2-link digits (links 0.10 m), the finger and the thumb,
  both based at the wrist. The hand frame is the world frame translated (not
  rotated) to the wrist. At the start the digit tips touch (line 730) at
  ``(0, tip_start)`` in the hand frame, on the approach axis: by default
  2 cm ahead of the wrist, 4 cm below the line of the digit targets (which
  lies ``wrist_offset`` ahead of the wrist once it is on its target). The
  thesis gives no value; its Fig. 4.4(a) (line 814) has the digits reach "a
  point level with the target position" during the movement, so they start
  below it (docs/model.md tabulates how the chapter's verdicts depend on
  this choice). The finger's middle joint bends outward to +x, the thumb's
  to -x (the elbow branches are fixed for each chain, so the joint angles
  stay continuous).
* **Targets**: the digit tips end on the object surface on the line through
  its centre perpendicular to the approach, the finger at ``(+size/2, 0)``
  and the thumb at ``(-size/2, 0)`` (world frame; hand frame
  ``(+-size/2, wrist_offset)``). A digit via-point lies ``viapoint_offset``
  outside the surface along that line, ``viapoint_height`` above it, at
  ``viapoint_time`` of the movement; :class:`GripVia` schedules replace it.
"""

from __future__ import annotations

from dataclasses import field
from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from .errors import ParameterError
from .kinematics import TwoLinkChain
from .limits import check_steps
from .plant import FORMS, PointMassPlant
from .validation import Extent, Length, NonNegative, Point, Positive, Span, Tuple, declared

__all__ = ["CHAINS", "DEFAULT_SHOULDER", "GraspTask", "GripVia", "shoulder_for"]

#: Names of the three chains, in the order they are planned and simulated.
CHAINS = ("arm", "finger", "thumb")


def _bad(name: str, problem: str) -> ParameterError:
    """A relation between :class:`GraspTask`'s fields broken, named by ``name``."""
    return ParameterError(problem, location=("GraspTask", name))


_Links = Annotated[tuple[Span, Span], Tuple]


@declared
class GripVia:
    """A via-point of the grip channel, shared by both digits (mirrored).

    Parameters
    ----------
    half_aperture : float
        Lateral distance of each tip from the approach axis, m (>= 0): the
        finger passes ``+half_aperture``, the thumb ``-half_aperture``; the
        aperture there is twice this.
    height : float
        Height relative to the line through the digit targets, m (positive:
        further along the approach, beyond the object's centre line).
    fraction : float
        Time as a fraction of the movement, strictly between 0 and 1.
    """

    half_aperture: Extent
    height: Length
    fraction: Annotated[float, Field(gt=0, lt=1)]


#: The shoulder relative to the wrist's start for reaches up to about 0.33 m
#: (:class:`GraspTask`'s default, the thesis's posture).
DEFAULT_SHOULDER = (0.15, -0.25)
#: Farthest the wrist's goal may lie from the shoulder, as a share of the arm's length.
MAX_REACH_SHARE = 0.9


def shoulder_for(distance: float, wrist_offset: float = 0.06,
                 arm_links: tuple[float, float] = (0.30, 0.30)) -> tuple[float, float]:
    """Where the shoulder sits, relative to the wrist's start, for a reach of ``distance`` m.

    A person reaching farther starts with the hand nearer the body: the
    thesis's posture (:data:`DEFAULT_SHOULDER`) up to where the wrist's
    goal would lie beyond :data:`MAX_REACH_SHARE` of the arm's length; for
    longer reaches the start moves toward the shoulder, so the goal stays at
    that share (an object 0.5 m away is reached, not refused).

    Parameters
    ----------
    distance : float
        Wrist start to object centre, m.
    wrist_offset : float
        How far short of the object centre the wrist stops, m.
    arm_links : (float, float)
        Upper arm and forearm lengths, m.
    """
    side, back = DEFAULT_SHOULDER[0], -DEFAULT_SHOULDER[1]
    reach = MAX_REACH_SHARE * sum(arm_links)
    longest = float(np.sqrt(max(reach**2 - side**2, 0.0)))  # shoulder to goal, along the approach
    back = min(back, longest - (distance - wrist_offset))
    if back < -side:
        # the hand would start well ahead of the shoulder: no arm makes this
        # reach; the thesis's posture lets GraspTask say so, naming the distance
        return DEFAULT_SHOULDER
    return (side, -back)


@declared
class GraspTask:
    """One reach-to-grasp movement (thesis 4.1.1; geometry in the module docstring).

    All lengths in m, times in s unless stated. Every length and coordinate
    lies within :data:`minvar.limits.MAX_POSITION_M`, and the movement has at
    most :data:`minvar.limits.MAX_STEPS` steps (docs/model.md, Limits).

    Parameters
    ----------
    object_size : float
        Diameter of the disk to grasp (>= 0; thesis 0-8 cm).
    distance : float
        Distance from the wrist's start to the object centre (> 0). The wrist
        travels ``distance - wrist_offset`` (:attr:`transport_distance`); the
        default 0.26 m makes that the thesis's 20 cm (line 953: "the distance
        to be moved", swept over 8-24 cm).
    duration : float
        Movement time (> 0; thesis 0.6-1.2 s). Must span at least 2 plant steps.
    viapoint_offset : float
        Distance of the default digit via-point outside the object surface,
        along the grip axis (>= 0).
    viapoint_height : float
        Height of the default via-point relative to the line through the
        digit targets (positive: further along the approach).
    viapoint_time : float
        Time of the default via-point, a fraction of the movement in (0, 1).
    grip_via : tuple of GripVia, optional
        Explicit grip via-points replacing the default one (in increasing
        time; ``()`` for none). Used to derive abnormal grasps, e.g. delayed
        opening or open-close-open.
    reach_only : bool
        Transport only: the digits' goal is their closed start posture and
        they have no via-points.
    plant : PointMassPlant
        Plant of every chain, in joint coordinates; its ``dt`` sets the step
        and its noise (``sigma_u``, ``sigma_s``) the planning noise model.
    execution_cv : float
        Coefficient of variation of the signal-dependent noise on each joint
        command at execution (>= 0; thesis: 1 %).
    execution_sigma_s : float
        Scale of the sensory noise at execution, multiplying
        ``plant.sensory_sd`` (>= 0; default 0: none, see the module docstring).
    wrist_offset : float
        Wrist target distance short of the object centre along the approach
        (> 0; thesis 6 cm).
    tip_start : float
        Where the touching digit tips start, ahead of the wrist along the
        approach axis (hand frame). Default 0.02: below the line of the digit
        targets (``wrist_offset`` ahead of the wrist at the goal), as thesis
        Fig. 4.4(a) implies (line 814); the thesis gives no value.
    shoulder_offset : (2,) tuple
        Shoulder position relative to the wrist's start position (world axes).
    arm_links : (2,) tuple
        Upper-arm and forearm lengths (thesis 0.30 m each).
    digit_links : (2,) tuple
        Lengths of the two links of each digit (thesis 0.10 m each).
    r : float
        Effort weight of every chain's cost (``R = r dt / T I``); the reach
        default, not the thesis's printed 0.002 (see :mod:`minvar.task`).
    w_v, w_f : float
        Final velocity and force weights of every chain's goal cost (the
        reach defaults).
    form : {"project", "thesis"}
        Every chain's model: the project's Euler filter and ``R = r dt / T I``
        (default), or the thesis's printed exponential filter and
        ``R = r / T I`` (:class:`minvar.task.ReachTask`).
    """

    object_size: Extent = 0.04
    distance: Span = 0.26
    duration: Positive = 1.0
    viapoint_offset: Extent = 0.01
    viapoint_height: Length = 0.0
    viapoint_time: Annotated[float, Field(gt=0, lt=1)] = 0.7
    grip_via: Annotated[tuple[GripVia, ...], Tuple] | None = None
    reach_only: bool = False
    plant: PointMassPlant = field(default_factory=PointMassPlant)
    execution_cv: NonNegative = 0.01
    execution_sigma_s: NonNegative = 0.0
    wrist_offset: Span = 0.06
    tip_start: Length = 0.02
    shoulder_offset: Point = DEFAULT_SHOULDER
    arm_links: _Links = (0.30, 0.30)
    digit_links: _Links = (0.10, 0.10)
    r: NonNegative = 2e-4
    w_v: NonNegative = 0.2
    w_f: NonNegative = 0.01
    form: Literal[FORMS] = "project"

    def __post_init__(self):
        if self.grip_via is not None:
            fr = [v.fraction for v in self.grip_via]
            if any(b <= a for a, b in zip(fr, fr[1:])):
                raise _bad("grip_via", f"fractions must increase, got {fr}")
        self._check_timing()
        self._check_reach()

    def _check_timing(self) -> None:
        dt = self.plant.dt
        T = check_steps(self.duration, dt, ("GraspTask", "duration"))  # before steps are counted
        if T < 2:
            raise _bad("duration", f"{self.duration} s is shorter than 2 steps of {dt} s")
        used = self.via_schedule
        name = "viapoint_time" if self.grip_via is None else "grip_via"
        steps = [int(round(v.fraction * self.duration / dt)) for v in used]
        for v, n in zip(used, steps):
            if not 0 < n < T:
                raise _bad(
                    name, f"via-point at {v.fraction:g} of {self.duration} s falls "
                    f"on step {n}, outside the movement's steps 1..{T - 1}"
                )
        if len(set(steps)) != len(steps):
            raise _bad("grip_via", f"two via-points fall on the same step {steps}")

    def _check_reach(self) -> None:
        lo, hi = abs(self.arm_links[0] - self.arm_links[1]), sum(self.arm_links)
        d_start = float(np.hypot(*self.shoulder_offset))
        if not lo <= d_start <= hi:
            raise _bad(
                "shoulder_offset", f"the wrist's start is {d_start:.3f} m from the "
                f"shoulder, outside the arm's reach [{lo:.3f}, {hi:.3f}] m"
            )
        d_goal = float(np.linalg.norm(np.subtract(self.wrist_target, self.shoulder)))
        if not lo <= d_goal <= hi:
            raise _bad(
                "distance", f"an object {self.distance} m away puts the wrist target "
                f"{d_goal:.3f} m from the shoulder, outside the arm's reach "
                f"[{lo:.3f}, {hi:.3f}] m"
            )
        lo, hi = abs(self.digit_links[0] - self.digit_links[1]), sum(self.digit_links)

        def check(point, name, what):
            d = float(np.hypot(*point))
            if not lo <= d <= hi:
                raise _bad(
                    name, f"{what} {d:.3f} m from the wrist, outside the "
                    f"digits' reach [{lo:.3f}, {hi:.3f}] m"
                )

        check((0.0, self.tip_start), "tip_start", "the closed digit tips lie")
        if self.reach_only:
            return
        check(self.finger_goal_hand, "object_size",
              f"an object of {self.object_size} m puts the digit targets")
        name = "grip_via" if self.grip_via is not None else "viapoint_offset"
        for v in self.via_schedule:
            check((v.half_aperture, self.wrist_offset + v.height), name, "a digit via-point lies")

    # --- geometry (world frame unless stated) ---------------------------------
    @property
    def wrist_start(self) -> tuple[float, float]:
        """Wrist position at the start, m."""
        return (0.0, -self.distance)

    @property
    def transport_distance(self) -> float:
        """How far the wrist travels, start to target: ``distance - wrist_offset``, m."""
        return self.distance - self.wrist_offset

    @property
    def wrist_target(self) -> tuple[float, float]:
        """Wrist target, ``wrist_offset`` short of the object centre, m."""
        return (0.0, -self.wrist_offset)

    @property
    def shoulder(self) -> tuple[float, float]:
        """Shoulder (arm base) position, m."""
        return (self.shoulder_offset[0], self.shoulder_offset[1] - self.distance)

    @property
    def finger_target(self) -> tuple[float, float]:
        """Finger-tip target on the object surface, m."""
        return (0.0, 0.0) if self.reach_only else (self.object_size / 2, 0.0)

    @property
    def thumb_target(self) -> tuple[float, float]:
        """Thumb-tip target on the object surface, m."""
        return (0.0, 0.0) if self.reach_only else (-self.object_size / 2, 0.0)

    @property
    def finger_goal_hand(self) -> tuple[float, float]:
        """Finger-tip goal in the hand frame (relative to the wrist target), m."""
        if self.reach_only:
            return (0.0, self.tip_start)
        return (self.object_size / 2, self.wrist_offset)

    @property
    def via_schedule(self) -> tuple[GripVia, ...]:
        """The grip via-points in use: ``grip_via``, or the default one; none if reach_only."""
        if self.reach_only:
            return ()
        if self.grip_via is not None:
            return self.grip_via
        return (
            GripVia(
                self.object_size / 2 + self.viapoint_offset,
                self.viapoint_height,
                self.viapoint_time,
            ),
        )

    @property
    def steps(self) -> int:
        """Number of control steps T (``duration / plant.dt``, rounded)."""
        return int(round(self.duration / self.plant.dt))

    @property
    def time(self) -> np.ndarray:
        """(T+1,) time of each state, s."""
        return np.arange(self.steps + 1) * self.plant.dt

    def chains(self) -> dict[str, TwoLinkChain]:
        """The arm (world frame) and the two digits (hand frame) as :class:`TwoLinkChain`."""
        return {
            "arm": TwoLinkChain(*self.arm_links, base=self.shoulder),
            "finger": TwoLinkChain(*self.digit_links, base=(0.0, 0.0)),
            "thumb": TwoLinkChain(*self.digit_links, base=(0.0, 0.0)),
        }

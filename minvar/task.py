"""Reaching tasks with via-points, and their LQG cost (thesis eqs. 3.20-3.25).

For P positional targets (via-points in the order given, then the goal) the
task error is scaled by ``1/(P+2)``; each via-point costs only position, at its
own step; the goal adds ``(w_v v)^2 + (w_f f)^2`` at the final step. Effort is
``R = r dt / T I``, T the number of steps: the effort term as a time integral.
``form="thesis"`` takes the thesis's printed model instead: ``R = r / T I``
(eq. 3.22, line 558) on the printed exponential muscle filter
(:mod:`minvar.plant`). The target coordinates live in ``Q`` against a pair
of constant 1s appended to the state per target (thesis 3.2.3).

The default weights, ``r = 2e-4``, ``w_v = 0.2``, ``w_f = 0.01``, are not the
thesis's printed ``r = 0.002``, ``w_v = 0.1``: run through Todorov's own code
on the thesis's problems, those leave the hand 1-2 cm short of the goal and of
the via-points, still moving at 0.2 m/s. With these defaults the 0.5 s reach
ends within 2 mm of the goal at under 0.01 m/s, the 's' passes within 5 mm of
its via-points and the peak/mean speed ratio is 2.0 (humans: about 1.9). See
docs/model.md for the model, its parameters and this choice.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np

from .errors import ParameterError
from .limits import check_problem, check_steps
from .plant import FORCE, FORMS, N_BASE, POSITION, VELOCITY, PointMassPlant
from .problem import LQGProblem
from .validation import NonNegative, Point, Positive, Tuple, declared

__all__ = ["ViaPoint", "ReachTask", "reach_problem"]


@declared
class ViaPoint:
    """A position the movement should pass through at a given time.

    Give the time either as ``fraction`` of the movement (0 < fraction < 1) or
    in ``seconds`` from the start; exactly one of the two.

    Parameters
    ----------
    position : (2,) array_like
        Via-point position (m, or rad in joint space), each coordinate within
        :data:`minvar.limits.MAX_POSITION_M`.
    fraction : float, optional
        Time as a fraction of the movement duration.
    seconds : float, optional
        Time in seconds from the start of the movement.
    """

    position: Point
    fraction: float | None = None
    seconds: float | None = None

    def __post_init__(self):
        if (self.fraction is None) == (self.seconds is None):
            raise ParameterError("give the time as exactly one of fraction= or seconds=",
                                 location=("ViaPoint", "fraction"))

    def time_s(self, duration: float) -> float:
        """The via-point time in seconds for a movement of ``duration`` s."""
        return self.seconds if self.seconds is not None else self.fraction * duration

    def step(self, duration: float, dt: float) -> int:
        """The step index at which the via-point is costed.

        Raises
        ------
        ValueError
            If the time does not fall strictly inside the movement.
        """
        steps = int(round(duration / dt))
        n = int(round(self.time_s(duration) / dt))
        if not 0 < n < steps:
            if self.fraction is not None:
                when = f"fraction={self.fraction}"
            else:
                when = f"seconds={self.seconds}"
            raise ValueError(
                f"ViaPoint at {self.position}: time {when} falls outside the movement "
                f"(must be strictly between 0 and {duration} s, i.e. steps 1..{steps - 1})"
            )
        return n


@declared
class ReachTask:
    """A point-to-point movement, optionally through via-points.

    Parameters
    ----------
    start, goal : (2,) array_like
        Start and goal positions (m; rad for joint-space tasks), each
        coordinate within :data:`minvar.limits.MAX_POSITION_M`.
    duration : float
        Movement time, s. Must span at least 2 plant steps and at most
        :data:`minvar.limits.MAX_STEPS`.
    via_points : sequence of ViaPoint
        Intermediate positional targets.
    r : float
        Effort weight; ``R = r dt / T I`` (default 2e-4, not the thesis's
        printed 0.002, which leaves the hand short of the goal: see the module
        docstring and docs/model.md).
    w_v, w_f : float
        Weights of the final velocity and force in the goal cost (default
        ``w_v`` 0.2, not the thesis's 0.1, for the same reason).
    form : {"project", "thesis"}
        ``"project"`` (default): the Euler muscle filter and ``R = r dt / T I``.
        ``"thesis"``: the thesis's printed model, the exponential filter with
        the command entering f~ at unit gain (lines 520-524) and
        ``R = r / T I`` (lines 382, 558). docs/thesis.md says why the default
        is the project's.
    """

    start: Point
    goal: Point
    duration: Positive
    via_points: Annotated[tuple[ViaPoint, ...], Tuple] = ()
    r: NonNegative = 2e-4
    w_v: NonNegative = 0.2
    w_f: NonNegative = 0.01
    form: Literal[FORMS] = "project"

    def steps(self, dt: float) -> int:
        """Number of control steps T for time step ``dt``.

        Raises
        ------
        ValueError
            If the movement is shorter than 2 steps, or longer than
            :data:`minvar.limits.MAX_STEPS`.
        """
        T = check_steps(self.duration, dt, ("ReachTask", "duration"))
        if T < 2:
            raise ParameterError(f"{self.duration} s is shorter than 2 steps of {dt} s",
                                 location=("ReachTask", "duration"))
        return T

    @property
    def targets(self) -> list[tuple[float, float]]:
        """Positional targets in state order: via-points as given, then the goal."""
        return [v.position for v in self.via_points] + [self.goal]


def reach_problem(task: ReachTask, plant: PointMassPlant | None = None) -> LQGProblem:
    """Build the :class:`~minvar.problem.LQGProblem` of a reaching task.

    Parameters
    ----------
    task : ReachTask
        Start, goal, duration, via-points and cost weights.
    plant : PointMassPlant, optional
        The plant (default: :class:`~minvar.plant.PointMassPlant`'s parameters,
        the thesis's; docs/model.md).

    Returns
    -------
    LQGProblem
        ``T = task.steps(plant.dt)`` steps; ``n = 8 + 2 P`` states.
    """
    # as plan_grasp's: not an AttributeError from the first field read
    if not isinstance(task, ReachTask):
        raise ValueError(f"reach_problem: task: expected a ReachTask, got {type(task).__name__}")
    if plant is not None and not isinstance(plant, PointMassPlant):
        raise ValueError(f"reach_problem: plant: expected a PointMassPlant, got "
                         f"{type(plant).__name__}")
    plant = PointMassPlant() if plant is None else plant
    T = task.steps(plant.dt)
    targets = task.targets
    P = len(targets)
    n = plant.n_states(P)
    check_problem(T, n, "ReachTask")  # before Q, (T+1) x n x n, is allocated
    A, B = plant.dynamics(P, task.form)
    H, D0 = plant.observation(P)
    # Divide by (P + 2) rather than multiply by its reciprocal: the same
    # rounding as Todorov's code, so the reference inputs match bit for bit.
    weight = P + 2.0
    Q = np.zeros((T + 1, n, n))
    steps = [v.step(task.duration, plant.dt) for v in task.via_points] + [T]
    for k, (target, step) in enumerate(zip(targets, steps)):
        for axis in range(2):
            p, one, g = POSITION.start + axis, N_BASE + 2 * k + axis, target[axis]
            Q[step, p, p] += 1.0 / weight
            Q[step, p, one] -= g / weight
            Q[step, one, p] -= g / weight
            Q[step, one, one] += g * g / weight
    for axis in range(2):
        v, f = VELOCITY.start + axis, FORCE.start + axis
        Q[T, v, v] += task.w_v * task.w_v / weight
        Q[T, f, f] += task.w_f * task.w_f / weight
    X1 = np.zeros(n)
    X1[POSITION] = task.start
    X1[N_BASE:] = 1.0
    return LQGProblem(
        A=A,
        B=B,
        C=list(plant.control_noise()),
        C0=np.zeros((n, 1)),
        H=H,
        D=[np.zeros((H.shape[0], n))],
        D0=D0,
        E0=np.zeros((n, 1)),
        Q=Q,
        R=task.r * (1.0 if task.form == "thesis" else plant.dt) / T * np.eye(2),
        X1=X1,
        S1=np.zeros((n, n)),
    )

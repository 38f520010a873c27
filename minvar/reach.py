"""Reaching movements: plan a task, execute noisy repetitions, hold the result."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .execution import simulate
from .lqg import LQGSolution, solve
from .plant import FORCE, POSITION, VELOCITY, PointMassPlant
from .task import ReachTask, reach_problem

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

# pandas is imported when a table is asked for: `import minvar` stays light
# (pandas takes about half a second to import).

__all__ = ["ReachResult", "simulate_reach"]


@dataclass(frozen=True, eq=False)
class ReachResult:
    """Noisy repetitions of one reaching movement.

    Unpacks as ``time, position = result``.

    Attributes
    ----------
    task : ReachTask
        The movement that was planned.
    time : (T+1,) array
        Time of each state, s.
    position, velocity, force : (trials, T+1, 2) arrays
        Hand position (m), velocity (m/s) and muscle force (N).
    control : (trials, T, 2) array
        Motor commands before control-dependent noise.
    solution : LQGSolution
        The gains that produced the movement.
    """

    task: ReachTask
    time: np.ndarray
    position: np.ndarray = field(repr=False)
    velocity: np.ndarray = field(repr=False)
    force: np.ndarray = field(repr=False)
    control: np.ndarray = field(repr=False)
    solution: LQGSolution = field(repr=False)

    def __iter__(self):
        return iter((self.time, self.position))

    @property
    def trials(self) -> int:
        """Number of repetitions."""
        return self.position.shape[0]

    @property
    def speed(self) -> np.ndarray:
        """(trials, T+1) tangential speed, m/s."""
        return np.hypot(self.velocity[..., 0], self.velocity[..., 1])

    @property
    def mean_position(self) -> np.ndarray:
        """(T+1, 2) mean hand path over repetitions, m."""
        return self.position.mean(axis=0)

    @property
    def mean_speed(self) -> np.ndarray:
        """(T+1,) mean speed profile over repetitions, m/s."""
        return self.speed.mean(axis=0)

    @property
    def endpoint(self) -> np.ndarray:
        """(trials, 2) final hand positions, m."""
        return self.position[:, -1]

    def to_pandas(self) -> pd.DataFrame:
        """One tidy row per repetition and time step.

        Columns: trial, step, time (s), x, y (m), vx, vy, speed (m/s), fx, fy (N).
        """
        import pandas as pd

        trials, steps = self.position.shape[:2]
        return pd.DataFrame(
            {
                "trial": np.repeat(np.arange(trials), steps),
                "step": np.tile(np.arange(steps), trials),
                "time": np.tile(self.time, trials),
                "x": self.position[..., 0].ravel(),
                "y": self.position[..., 1].ravel(),
                "vx": self.velocity[..., 0].ravel(),
                "vy": self.velocity[..., 1].ravel(),
                "speed": self.speed.ravel(),
                "fx": self.force[..., 0].ravel(),
                "fy": self.force[..., 1].ravel(),
            }
        )


def simulate_reach(
    task: ReachTask,
    trials: int = 100,
    *,
    seed: int | np.random.Generator | None = 0,
    plant: PointMassPlant | None = None,
    solution: LQGSolution | None = None,
) -> ReachResult:
    """Plan ``task`` with the minimum variance model and execute ``trials`` repetitions.

    Parameters
    ----------
    task : ReachTask
        Start, goal, duration, via-points, cost weights.
    trials : int
        Number of noisy repetitions.
    seed : int or numpy.random.Generator, optional
        Randomness of the execution noise.
    plant : PointMassPlant, optional
        Plant and noise parameters (default: :class:`~minvar.plant.PointMassPlant`'s,
        docs/model.md).
    solution : LQGSolution, optional
        Gains already solved for this task and plant (skips planning).

    Returns
    -------
    ReachResult
    """
    if not isinstance(task, ReachTask):  # as simulate_grasp's
        raise ValueError(f"simulate_reach: task: expected a ReachTask, got {type(task).__name__}")
    plant = PointMassPlant() if plant is None else plant
    problem = reach_problem(task, plant)
    if solution is None:
        solution = solve(problem)
    traj = simulate(problem, solution, trials, seed=seed)
    X = traj.states
    return ReachResult(
        task=task,
        time=np.arange(problem.horizon + 1) * plant.dt,
        position=X[..., POSITION],
        velocity=X[..., VELOCITY],
        force=X[..., FORCE],
        control=traj.controls,
        solution=solution,
    )

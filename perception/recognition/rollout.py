"""The models' own movements, executed from their stored gains.

A model's inverse model (``L``) drives its forward model (``A, B``) from its
planned start: with no noise this is the movement the model expects (the
"normal trajectories predicted by the reach-to-grasp model" of thesis Figs.
5.5-5.7); with signal-dependent noise on the commands — the execution noise
of :mod:`minvar` (``C1 = cv I``, ``C2 = cv [[0, 1], [-1, 0]]``) — it is one of
the model's own noisy demonstrations, from which the verdict is calibrated
(:mod:`perception.recognition.verdict`). The controller sees the true state
(no sensory noise), as in the chapter 4 executions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from perception.recognition.leaves import Leaves, forward_kinematics
from perception.recognition.models import MotorModel

__all__ = ["Rollout", "rollout"]

_ROTATE = np.array([[0.0, 1.0], [-1.0, 0.0]])


@dataclass(frozen=True, eq=False)
class Rollout:
    """Executions of every model: positions in the model frame.

    Attributes
    ----------
    time : (S+1,) array
        Model time of each step, s (0 at the command onset).
    wrist, finger, thumb : (M, trials, S+1, 2) arrays
        Wrist and digit tip positions, m.
    """

    time: np.ndarray
    wrist: np.ndarray
    finger: np.ndarray
    thumb: np.ndarray

    @property
    def aperture(self) -> np.ndarray:
        """(M, trials, S+1) grip aperture, m."""
        return np.linalg.norm(self.finger - self.thumb, axis=-1)


def rollout(models: Sequence[MotorModel], steps: int, *, trials: int = 1, cv: float = 0.0,
            rng: np.random.Generator | None = None) -> Rollout:
    """Execute every model for ``steps`` model steps from its planned start.

    Parameters
    ----------
    models : sequence of MotorModel
        Models sharing one time step.
    steps : int
        Model steps to run; past its plan's horizon a model holds its goal.
    trials : int
        Repetitions of each model.
    cv : float
        Coefficient of variation of the signal-dependent command noise (0: the
        noise-free, nominal movement).
    rng : numpy.random.Generator, optional
        Source of the noise (required when ``cv > 0``).
    """
    if cv > 0 and rng is None:
        raise ValueError("rollout: a noisy execution (cv > 0) needs rng")
    models = list(models)
    leaves = Leaves(models, steps)
    x = np.repeat(leaves.x0[:, None], trials, axis=1)  # (L, trials, n)
    q = np.empty((steps + 1, leaves.count, trials, 2))
    q[0] = x[..., :2]
    for s in range(steps):
        u = leaves.command(x, s)
        if cv > 0:
            e1, e2 = rng.standard_normal((2, *u.shape[:-1], 1))
            u = u + cv * (e1 * u + e2 * (u @ _ROTATE.T))
        x = leaves.advance(x, u)
        q[s + 1] = x[..., :2]
    M = len(models)
    flat = q.reshape(steps + 1, leaves.count * trials, 2)
    tip, _ = forward_kinematics(flat, np.repeat(leaves.l1, trials), np.repeat(leaves.l2, trials))
    tip = tip.reshape(steps + 1, M, 3, trials, 2) + leaves.base.reshape(1, M, 3, 1, 2)
    tip = np.moveaxis(tip, 0, -2)  # (M, 3, trials, S+1, 2)
    wrist = tip[:, 0]
    return Rollout(time=np.arange(steps + 1) * models[0].dt, wrist=wrist,
                   finger=wrist + tip[:, 1], thumb=wrist + tip[:, 2])

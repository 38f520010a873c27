"""Every chain of every model stacked into arrays, for batched stepping.

The engine (:mod:`perception.recognition.engine`) and the models' own
executions (:mod:`perception.recognition.rollout`) both advance all leaves of
all models at once: the stacked forward models ``(A, B)``, control gains
``L``, Kalman gains ``K`` (position columns) and prediction covariances ``P``,
padded to one state size, and the forward kinematics of the stacked chains.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Sequence

import numpy as np

from minvar.kinematics import TwoLinkChain
from perception.recognition.models import MotorModel

__all__ = ["Leaves", "forward_kinematics"]

#: Stacked gains kept for the last few model sets (:meth:`Leaves.of`).
CACHED_SETS = 8
_CACHE: OrderedDict[tuple[int, ...], tuple[tuple[MotorModel, ...], Leaves]] = OrderedDict()


class Leaves:
    """All chains of all models stacked (padded to one state size) for batched stepping.

    Parameters
    ----------
    models : sequence of MotorModel
        The models; their chains are stacked in order (arm, finger, thumb each).
    steps : int
        Model steps to provide gains for; beyond a plan's horizon a model
        keeps its last gains (it holds the goal).
    """

    def __init__(self, models: Sequence[MotorModel], steps: int):
        chains = [c for m in models for c in m.chains]
        self.count = len(chains)
        n = max(c.A.shape[0] for c in chains)
        m_u = chains[0].B.shape[1]
        L_ = len(chains)
        self.A = np.zeros((L_, n, n))
        self.B = np.zeros((L_, n, m_u))
        self.Kp = np.zeros((steps, L_, n, 2))
        self.Lg = np.zeros((steps, L_, m_u, n))
        self.P = np.zeros((steps, L_, 2, 2))
        self.x0 = np.zeros((L_, n))
        for i, c in enumerate(chains):
            k = c.A.shape[0]
            self.A[i] = np.eye(n)  # padded constant states stay put
            self.A[i, :k, :k] = c.A
            self.B[i, :k] = c.B
            t = np.minimum(np.arange(steps), c.horizon - 1)
            self.Kp[:, i, :k] = c.K[t][:, :, :2]
            self.Lg[:, i, :, :k] = c.L[t]
            self.P[:, i] = c.P[np.minimum(np.arange(steps), c.horizon)]
            self.x0[i, :k] = c.x0
        # the closed loop x' = (A - B L_s) x as one product a step, transposed for states
        # held as rows; past the longest plan's horizon every gain is its last
        last = min(steps, max(c.horizon for c in chains))
        self._closed = np.ascontiguousarray(
            (self.A[None] - self.B[None] @ self.Lg[:last]).transpose(0, 1, 3, 2))
        self.l1 = np.array([c.l1 for c in chains])
        self.l2 = np.array([c.l2 for c in chains])
        self.base = np.array([c.base for c in chains])
        self.chains = chains

    @classmethod
    def of(cls, models: Sequence[MotorModel], steps: int) -> Leaves:
        """The models' leaves for at least ``steps`` steps, stacked once per set of models.

        A stream judged frame by frame scores the same models again at every
        frame (:class:`perception.online.OnlineRecognizer`): their gains are
        stacked once. Keyed on the models themselves (a model is never changed
        after it is planned; a calibrated or re-planned one is a new object),
        so more steps than asked for change nothing: past a plan's horizon its
        gains are the last ones.
        """
        key = tuple(id(m) for m in models)
        hit = _CACHE.get(key)
        same = hit is not None and all(a is b for a, b in zip(hit[0], models))
        if same and len(hit[1].P) >= steps:
            _CACHE.move_to_end(key)
            return hit[1]
        # a stream's movement grows a few steps a frame: stacked again, then for twice as
        # many, not for every few steps more
        leaves = cls(models, max(steps, 2 * len(hit[1].P)) if same else steps)
        _CACHE[key] = (tuple(models), leaves)
        while len(_CACHE) > CACHED_SETS:
            _CACHE.popitem(last=False)
        return leaves

    def command(self, state: np.ndarray, s: int) -> np.ndarray:
        """The motor command ``-L x`` of every leaf at step ``s`` for (L, ..., n) states."""
        return -np.einsum("lmn,l...n->l...m", self.Lg[s], state)

    def advance(self, state: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The forward models: ``A x + B u`` for (L, ..., n) states and (L, ..., m) commands."""
        return (np.einsum("lij,l...j->l...i", self.A, state)
                + np.einsum("lim,l...m->l...i", self.B, u))

    def step(self, state: np.ndarray, s: int) -> np.ndarray:
        """Every leaf one model step on: the command ``-L x`` through ``(A, B)``.

        ``state`` is (L, n) or (L, k, n) for k states per leaf. The same as
        ``advance(state, command(state, s))`` to rounding, ten times faster: a
        stream scores its prefix again at every frame.
        """
        closed = self._closed[min(s, len(self._closed) - 1)]
        if state.ndim == 2:
            return (state[:, None] @ closed)[:, 0]
        return state @ closed


def forward_kinematics(q: np.ndarray, l1: np.ndarray, l2: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Tip positions and Jacobians of stacked leaves.

    Parameters
    ----------
    q : (N, L, 2) array
        Joint angles of every leaf, rad.
    l1, l2 : (L,) arrays
        Link lengths of every leaf, m.

    Returns
    -------
    tip : (N, L, 2) array
        Tip positions relative to each chain's base, m.
    J : (N, L, 2, 2) array
        Jacobians, m/rad.
    """
    tip = np.empty(q.shape)
    J = np.empty(q.shape + (2,))
    for chain, cols in _geometries(l1, l2):
        tip[:, cols] = chain.forward(q[:, cols])
        J[:, cols] = chain.jacobian(q[:, cols])
    return tip, J


def _geometries(l1: np.ndarray, l2: np.ndarray) -> list[tuple[TwoLinkChain, np.ndarray]]:
    """One chain per distinct geometry (a few at most) and the leaves that have it; found
    once per set of link lengths (a stream's frames all score the same leaves)."""
    key = (np.asarray(l1, dtype=float).tobytes(), np.asarray(l2, dtype=float).tobytes())
    hit = _GEOMETRIES.get(key)
    if hit is None:
        geometry = np.stack([l1, l2], axis=1)
        hit = [(TwoLinkChain(*g), np.flatnonzero((geometry == g).all(axis=1)))
               for g in np.unique(geometry, axis=0)]
        _GEOMETRIES[key] = hit
        while len(_GEOMETRIES) > 8:
            _GEOMETRIES.pop(next(iter(_GEOMETRIES)))
    return hit


#: :func:`_geometries` per set of link lengths (bytes of ``l1`` and ``l2``).
_GEOMETRIES: dict[tuple[bytes, bytes], list] = {}

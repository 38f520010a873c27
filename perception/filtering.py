"""The causal alpha-beta filter the observation smooths marker positions with.

A constant-velocity tracker with fixed gains: each frame's position is
predicted from the last estimate and velocity, then corrected by ``alpha``
(position) and ``beta`` (velocity) times the residual. It lags a frame or
so but never looks ahead: :func:`alpha_beta` of a clip is :class:`AlphaBeta`
run over its frames one at a time, and a series that begins with one
filtered before resumes from it (the online recogniser observes the rows so
far after every row). docs/recognition.md says why the positions are
filtered at all: with raw tracks half a pixel of noise randomises the sign
of the small per-frame changes the thesis's confidence rule counts.
"""

from __future__ import annotations

import copy

import numpy as np

from perception.resume import Kept, extended

__all__ = ["AlphaBeta", "alpha_beta"]

#: Filtered series kept per thread to resume from (:func:`alpha_beta`): each with its
#: output and the filter's state after it.
RESUMABLE = 4
_KEPT = Kept(RESUMABLE)


def alpha_beta(z: np.ndarray, dt: np.ndarray | float, alpha: float, beta: float) -> np.ndarray:
    """Causal alpha-beta filter of positions, coasting through gaps.

    Parameters
    ----------
    z : (N, ..., 2) array
        Positions; NaN where missing.
    dt : float or (N,) array
        Frame period(s), s (``dt[i]`` is the time from frame i-1 to i).
    alpha, beta : float
        Position and velocity gains.

    Returns
    -------
    (N, ..., 2) array
        Filtered positions, read-only; NaN where the input is missing (a gap is not
        filled; the filter restarts from the first measurement after it).
    """
    z = np.asarray(z, dtype=float)
    dt = np.broadcast_to(np.asarray(dt, dtype=float), (z.shape[0],))
    # the online recogniser observes the rows so far after every row: each call is the
    # last one's series and a row more; the filter is causal, so the rows it filtered
    # are filtered alike (the same operations on the same numbers), and the new rows'
    # output is appended to theirs (resume.extended: no copy of the rows before, and a
    # read-only series the next passes know begins with this one's)
    kept = _KEPT.longest((alpha, beta), (z, dt))
    if kept is None:
        start, step = 0, AlphaBeta(z.shape[1:], alpha, beta)
        done = np.empty((0, *z.shape[1:]))
    else:
        start, done = len(kept[0][0]), kept[1][0]
        step = copy.copy(kept[1][1])  # its state is replaced at every frame, never changed
    new = np.empty((z.shape[0] - start, *z.shape[1:]))
    for i in range(start, z.shape[0]):
        new[i - start] = step(z[i], dt[i])
    out = extended(done, new)
    _KEPT.keep((alpha, beta), (z, dt), (out, copy.copy(step)), kept)
    return out


class AlphaBeta:
    """:func:`alpha_beta` one frame at a time (an online stream's filter).

    Parameters
    ----------
    shape : tuple of int
        Shape of one frame's positions, ``(..., 2)``.
    alpha, beta : float
        Position and velocity gains.
    """

    def __init__(self, shape: tuple[int, ...], alpha: float, beta: float):
        self.alpha, self.beta = alpha, beta
        self.x = np.full(shape, np.nan)
        self.v = np.zeros(shape)
        self.missing_before = np.ones(shape[:-1] + (1,), dtype=bool)
        self.second = np.zeros(shape[:-1] + (1,), dtype=bool)  # first measurement after a (re)start

    def __call__(self, zi: np.ndarray, dt: float) -> np.ndarray:
        """The filtered positions of the next frame ``zi`` (NaN where missing), ``dt`` s later.

        Each frame replaces the state's arrays rather than writing into them: a
        copy of the filter (:func:`copy.copy`) resumes on its own.
        """
        x, v, alpha, beta = self.x, self.v, self.alpha, self.beta
        have = np.isfinite(zi).all(axis=-1, keepdims=True)
        pred = x + v * dt
        resid = zi - pred
        x_new = np.where(have, pred + alpha * resid, pred)
        v_new = np.where(have, v + beta / max(dt, 1e-9) * resid, v)
        # After a gap, start again from the measurement (coasting on an old
        # velocity lands far from the marker), and take the velocity from the
        # first two measurements back (two-point initiation).
        fresh = have & self.missing_before
        two = have & self.second & ~fresh
        v_new = np.where(two, (zi - x) / max(dt, 1e-9), np.where(fresh, 0.0, v_new))
        x_new = np.where(fresh | two, zi, x_new)
        self.second = fresh | (self.second & ~have)
        self.missing_before = ~have
        self.x, self.v = x_new, v_new
        return np.where(have, x_new, np.nan)

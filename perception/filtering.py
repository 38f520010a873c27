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
import threading

import numpy as np

from perception.resume import begins_with

__all__ = ["AlphaBeta", "alpha_beta"]

#: Filtered series kept per thread to resume from (:func:`alpha_beta`).
RESUMABLE = 4
_KEPT = threading.local()


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
        Filtered positions; NaN where the input is missing (a gap is not filled;
        the filter restarts from the first measurement after it).
    """
    z = np.asarray(z, dtype=float)
    dt = np.broadcast_to(np.asarray(dt, dtype=float), (z.shape[0],))
    out = np.full_like(z, np.nan)
    start, step = _resume(z, dt, alpha, beta, out)
    for i in range(start, z.shape[0]):
        out[i] = step(z[i], dt[i])
    _keep(z, dt, alpha, beta, out, step)
    return out


def _resume(z, dt, alpha, beta, out) -> tuple[int, AlphaBeta]:
    """Where to start filtering ``z``: after the longest series filtered before (in this
    thread, with these gains) that ``z`` and ``dt`` begin with, its output copied into
    ``out``; else at 0.

    The online recogniser observes the rows so far after every row: each call
    is the last one's series and one row more. The filter is causal, so the
    rows it has filtered are filtered alike (the same operations on the same
    numbers) and only the new ones cost anything.
    """
    best = None
    for kept in getattr(_KEPT, "series", ()):
        kz, kdt, ka, kb, kout, kstep = kept
        n = len(kz)
        if (ka == alpha and kb == beta and (best is None or n > len(best[0]))
                and begins_with((z, dt), (kz, kdt))):
            best = kept
    if best is None:
        return 0, AlphaBeta(z.shape[1:], alpha, beta)
    n = len(best[0])
    out[:n] = best[4]
    return n, copy.copy(best[5])  # its state is replaced at every frame, never changed


def _keep(z, dt, alpha, beta, out, step) -> None:
    """Keep a filtered series and the filter's state after it (:func:`_resume`)."""
    series = [k for k in getattr(_KEPT, "series", ()) if len(k[0]) != len(z)
              or not np.array_equal(k[0], z, equal_nan=True)]
    _KEPT.series = [(z.copy(), dt.copy(), alpha, beta, out.copy(), copy.copy(step)),
                    *series][:RESUMABLE]


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

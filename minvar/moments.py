"""Exact moments of an LQG system under arbitrary gains, by moment propagation.

The one Python home of the model's moment recursions: :class:`Moments` steps
the second moments of the estimate ``xhat`` and its error ``e = x - xhat``
through the full noise model of :mod:`minvar.lqg` (control- and
state-dependent noise included) and :func:`mean_states` the mean. Under any
gains they are the independent check on the cost :func:`minvar.lqg.solve`
reports, the exact distribution the Monte Carlo of
:func:`minvar.execution.simulate` samples, and the models' predictive
uncertainty that recognition scores with; with the filter's optimal gain they
are the moments of the solver's own forward pass. ``minvar/_lqg_kernel.c`` is
their compiled twin and must match them to rounding (tests/test_speed_solver.py).
"""

from __future__ import annotations

import functools

import numpy as np

from . import _kernel
from .problem import LQGProblem

__all__ = ["Moments", "estimation_error_covariance", "expected_cost", "mean_states",
           "state_moments"]


def mean_states(problem: LQGProblem, L: np.ndarray) -> np.ndarray:
    """Mean states ``E[x[t+1]] = (A - B L[t]) E[x[t]]`` from ``X1``, (T+1, n).

    The noise is zero-mean and enters linearly, so this is also the
    noise-free trajectory, and ``E[xhat] = E[x]`` (``E[e] = 0``). The compiled
    twin is ``lqg_mean_states``.

    Parameters
    ----------
    problem : LQGProblem
        The problem (``A``, ``B``, ``X1``).
    L : (T, m, n) array
        Control gains.

    Returns
    -------
    (T+1, n) array
        ``E[x[t]]`` for t = 0..T.
    """
    p = problem
    X = np.empty((p.horizon + 1, p.n_states))
    X[0] = p.X1
    closed = p.A[None] - p.B[None] @ L  # (T, n, n)
    for t in range(p.horizon):
        X[t + 1] = closed[t] @ X[t]
    return X


class Moments:
    """Second moments of the estimate and its error, a step at a time, under any gains.

    The state of the recursion is ``(Mhh, Mhe, Mee)``: ``E[xhat xhat']``,
    ``E[xhat e']`` and ``E[e e']`` with ``e = x - xhat`` (so ``E[x x'] = Mhh +
    Mhe + Mhe' + Mee``), from ``(X1 X1', 0, S1)``. With ``Y = A - B L``,
    ``Z = K H``, ``akh = A - K H`` and ``W = K (D0 D0' + sum_j D_j E[x x'] D_j') K'``::

        Mhh' = Y Mhh Y' + Y Mhe Z' + Z Mhe' Y' + Z Mee Z' + W + E0 E0'
        Mhe' = (Y Mhe + Z Mee) akh' - W - E0 E0'
        Mee' = akh Mee akh' + sum_i B C_i L Mhh L' C_i' B' + W + E0 E0' + C0 C0'

    The solver's forward pass (Todorov's ``kalman_lqg.m``) steps the same
    moments with the filter gain that is optimal for them, ``K M = A Mee H'``
    with ``M = H Mee H' + D0 D0' + sum_j D_j E[x x'] D_j'``; then ``Z Mee Z' +
    W = K (A Mee H')'`` and the ``W`` terms of ``Mhe'`` and ``Mee'`` cancel,
    which :meth:`step` uses when given that product. Compiled twins:
    ``lqg_error_cov`` (any gains) and ``lqg_forward`` (optimal ``K``).

    Parameters
    ----------
    problem : LQGProblem
        The problem whose noise model is propagated.
    """

    def __init__(self, problem: LQGProblem):
        p = self.p = problem
        self.At = np.ascontiguousarray(p.A.T)
        self.Ht = np.ascontiguousarray(p.H.T)
        self.BC = np.einsum("ij,cjk->cik", p.B, p.C)  # (c, n, m): thesis C_i
        self.DD0 = p.D0 @ p.D0.T
        self.CC0 = p.C0 @ p.C0.T
        self.EE0 = p.E0 @ p.E0.T
        self.Dt = np.ascontiguousarray(np.transpose(p.D, (0, 2, 1)))
        self.has_C = bool(np.any(p.C))
        self.has_D = bool(np.any(p.D))
        self.has_E0 = bool(np.any(self.EE0))
        self.has_C0 = bool(np.any(self.CC0))

    def start(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(Mhh, Mhe, Mee)`` at t = 0: ``xhat[0] = X1``, ``x[0] ~ N(X1, S1)``."""
        p = self.p
        return np.outer(p.X1, p.X1), np.zeros((p.n_states, p.n_states)), p.S1.copy()

    @functools.cached_property
    def noise_fwd(self) -> np.ndarray:
        """sum_i X_i M X_i' as one product on vec(M), X_i = B C_i (row-major:
        vec(X M Y) = (X kron Y') vec(M))."""
        n, m = self.p.n_states, self.p.n_controls
        return sum((np.kron(BCi, BCi) for BCi in self.BC), np.zeros((n * n, m * m)))

    def add_sensor_noise(self, out: np.ndarray, Mhh, Mhe, Mee) -> np.ndarray:
        """``out += D0 D0' + sum_j D_j E[x x'] D_j'`` (the observation noise's covariance)."""
        out += self.DD0
        if self.has_D:
            Mxx = Mee + Mhh + Mhe + Mhe.T
            out += (self.p.D @ Mxx @ self.Dt).sum(axis=0)
        return out

    def step(self, Mhh, Mhe, Mee, K, L, *, KMK=None, akh=None):
        """The moments at t + 1 from those at t under gains ``K`` (n, k) and ``L`` (m, n).

        ``KMK``: ``K M K'`` when ``K`` is the filter gain optimal for these
        moments (the forward pass; see the class), which skips the terms that
        cancel. ``akh``: an (n, n) array to receive ``A - K H``. Returns
        ``(Mhh, Mhe, Mee)``; ``Mhe`` is the input itself when it stays zero
        (optimal ``K``, no internal noise).
        """
        p = self.p
        A, B, H = p.A, p.B, p.H
        n = p.n_states
        if akh is None:
            akh = np.empty((n, n))
        np.subtract(A, K.dot(H), out=akh)
        optimal = KMK is not None
        if optimal:
            newE = akh.dot(Mee).dot(self.At)
        else:
            W = K.dot(self.add_sensor_noise(np.zeros((p.n_outputs,) * 2), Mhh, Mhe, Mee)).dot(K.T)
            ZMee = K.dot(H.dot(Mee))
            newE = akh.dot(Mee).dot(akh.T) + W
        if self.has_C:
            LML = L.dot(Mhh).dot(L.T)
            newE += self.noise_fwd.dot(LML.ravel()).reshape(n, n)
        if self.has_C0 or self.has_E0:
            newE += self.EE0 + self.CC0
        # akh Mee A' is symmetric only in exact arithmetic: with little sensory noise its
        # rounding grows from step to step until the iteration diverges
        newE = 0.5 * (newE + newE.T)
        abl = A - B.dot(L)
        if optimal:
            newX = KMK + abl.dot(Mhh).dot(abl.T)
        else:
            newX = ZMee.dot(H.T).dot(K.T) + W + abl.dot(Mhh).dot(abl.T)
        newXE = Mhe  # stays exactly zero with the optimal K and no internal noise
        if self.has_E0 or not optimal:
            cross = abl.dot(Mhe).dot(self.Ht).dot(K.T)
            newX += self.EE0 + cross + cross.T
            newXE = abl.dot(Mhe).dot(akh.T) - self.EE0
            if not optimal:
                newXE += ZMee.dot(akh.T) - W
        return newX, newXE, newE


def _propagate(problem: LQGProblem, K: np.ndarray, L: np.ndarray):
    """Yield ``(t, E[x], Mhh, Mhe, Mee)`` (see :class:`Moments`) for t = 0..T under ``K``, ``L``."""
    p = problem
    T, n, m, k = p.horizon, p.n_states, p.n_controls, p.n_outputs
    K = np.asarray(K, dtype=float)
    L = np.asarray(L, dtype=float)
    if K.shape != (T, n, k):
        raise ValueError(f"K must have shape {(T, n, k)}, got {K.shape}")
    if L.shape != (T, m, n):
        raise ValueError(f"L must have shape {(T, m, n)}, got {L.shape}")
    moments = Moments(p)
    means = mean_states(p, L)
    M = moments.start()
    for t in range(T):
        yield t, means[t], *M
        M = moments.step(*M, K[t], L[t])
    yield T, means[T], *M


def state_moments(
    problem: LQGProblem, K: np.ndarray, L: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Exact mean and covariance of the true state under gains ``K``, ``L``.

    The distribution the Monte Carlo of :func:`minvar.execution.simulate`
    samples from, without sampling error (e.g. the exact end-point SD).

    Parameters
    ----------
    problem : LQGProblem
        The problem (its noise model is the one propagated).
    K : (T, n, k) array
        Filter gains.
    L : (T, m, n) array
        Control gains.

    Returns
    -------
    mean : (T+1, n) array
        ``E[x[t]]``.
    cov : (T+1, n, n) array
        ``Cov[x[t]]``.
    """
    means, covs = [], []
    for _, mean, Mhh, Mhe, Mee in _propagate(problem, K, L):
        means.append(mean)
        covs.append(Mhh + Mhe + Mhe.T + Mee - np.outer(mean, mean))
    return np.array(means), np.array(covs)


def estimation_error_covariance(problem: LQGProblem, K: np.ndarray, L: np.ndarray, *,
                                engine: str = "auto") -> np.ndarray:
    """Exact covariance of the filter's error ``x[t] - xhat[t]`` under gains ``K``, ``L``.

    ``xhat[t]`` uses observations up to ``t - 1``, so this is the spread of the
    true state about the one-step prediction: the model's own predictive
    uncertainty, used to score observed movements by likelihood.

    Parameters
    ----------
    problem : LQGProblem
        The problem (its noise model is the one propagated).
    K : (T, n, k) array
        Filter gains.
    L : (T, m, n) array
        Control gains.
    engine : {"auto", "c", "numpy"}, optional
        The compiled recursion or the numpy one (:class:`Moments`, as
        :func:`state_moments` and :func:`expected_cost`); as in
        :func:`minvar.lqg.solve`.

    Returns
    -------
    (T+1, n, n) array
        ``Cov[x[t] - xhat[t]]`` for t = 0..T.
    """
    p = problem
    T, n, m, k = p.horizon, p.n_states, p.n_controls, p.n_outputs
    K = np.asarray(K, dtype=float)
    L = np.asarray(L, dtype=float)
    compiled = _kernel.use_compiled(_kernel.check_engine(engine, "estimation_error_covariance"))
    if compiled and K.shape == (T, n, k) and L.shape == (T, m, n):
        return _kernel.error_covariance(p, K, L)  # the same recursion, compiled
    return np.array([Mee for *_, Mee in _propagate(problem, K, L)])


def expected_cost(problem: LQGProblem, K: np.ndarray, L: np.ndarray) -> float:
    """Exact expected cost of arbitrary gains ``K``, ``L`` by moment propagation.

    Propagates the second moment of the joint vector ``z = [x; xhat]`` through
    the full noise model, so it needs no optimality of either gain. It is the
    independent check on the cost that :func:`solve` reports, and the way to
    score a perturbed or hand-made controller.

    Parameters
    ----------
    problem : LQGProblem
        The problem.
    K : (T, n, k) array
        Filter gains.
    L : (T, m, n) array
        Control gains.

    Returns
    -------
    float
        ``E[sum_t x'Q[t]x + u'Ru]`` including the final state cost.
    """
    p = problem
    cost = 0.0
    for t, _, Mhh, Mhe, Mee in _propagate(p, K, L):
        cost += np.trace(p.Q[t] @ (Mhh + Mhe + Mhe.T + Mee))
        if t < p.horizon:
            Lt = np.asarray(L[t], dtype=float)
            cost += np.trace(Lt.T @ p.R @ Lt @ Mhh)  # u = -L xhat
    return float(cost)

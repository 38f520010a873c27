"""Exact moments of an LQG system under arbitrary gains, by moment propagation.

The second moment of the joint vector ``z = [x; xhat]`` is propagated through
the full noise model of :mod:`minvar.lqg` (control- and state-dependent noise
included), so nothing here needs the gains to be optimal: it is the
independent check on the cost :func:`minvar.lqg.solve` reports, the exact
distribution the Monte Carlo of :func:`minvar.execution.simulate` samples,
and the models' predictive uncertainty that recognition scores with.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import _kernel

if TYPE_CHECKING:
    from .lqg import LQGProblem

__all__ = ["estimation_error_covariance", "expected_cost", "state_moments"]


def _joint_moments(problem: LQGProblem, K: np.ndarray, L: np.ndarray):
    """Yield ``(t, mean z, second moment of z)`` of ``z = [x; xhat]`` for t = 0..T."""
    p = problem
    T, n, m, k = p.horizon, p.n_states, p.n_controls, p.n_outputs
    K = np.asarray(K, dtype=float)
    L = np.asarray(L, dtype=float)
    if K.shape != (T, n, k):
        raise ValueError(f"K must have shape {(T, n, k)}, got {K.shape}")
    if L.shape != (T, m, n):
        raise ValueError(f"L must have shape {(T, m, n)}, got {L.shape}")
    A, B, H = p.A, p.B, p.H
    X1 = p.X1
    mean = np.concatenate([X1, X1])
    S = np.outer(mean, mean)
    S[:n, :n] += p.S1
    CC0, DD0, EE0 = p.C0 @ p.C0.T, p.D0 @ p.D0.T, p.E0 @ p.E0.T
    G = np.zeros((2 * n, 2 * n))
    for t in range(T):
        yield t, mean, S
        Kt, Lt = K[t], L[t]
        F = np.block([[A, -B @ Lt], [Kt @ H, A - B @ Lt - Kt @ H]])
        S_next = F @ S @ F.T
        for Ci in p.C:  # control-dependent noise acts through xhat
            G[:] = 0
            G[:n, n:] = -B @ Ci @ Lt
            S_next += G @ S @ G.T
        for Dj in p.D:  # state-dependent sensory noise enters the estimate
            G[:] = 0
            G[n:, :n] = Kt @ Dj
            S_next += G @ S @ G.T
        S_next[:n, :n] += CC0
        S_next[n:, n:] += Kt @ DD0 @ Kt.T + EE0
        mean, S = F @ mean, S_next
    yield T, mean, S


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
    n = problem.n_states
    means, covs = [], []
    for _, mean, S in _joint_moments(problem, K, L):
        mx = mean[:n]
        means.append(mx)
        covs.append(S[:n, :n] - np.outer(mx, mx))
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
        The compiled recursion or the numpy one (:func:`_joint_moments`, as
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
    out = []
    for _, _, S in _joint_moments(problem, K, L):
        out.append(S[:n, :n] - S[:n, n:] - S[n:, :n] + S[n:, n:])
    return np.array(out)


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
    n, T = p.n_states, p.horizon
    cost = 0.0
    for t, _, S in _joint_moments(p, K, L):
        cost += np.trace(p.Q[t] @ S[:n, :n])
        if t < T:
            Lt = np.asarray(L[t], dtype=float)
            cost += np.trace(Lt.T @ p.R @ Lt @ S[n:, n:])
    return float(cost)

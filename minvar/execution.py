"""Monte Carlo execution of an LQG controller: many noisy repetitions at once.

Every repetition runs the plant, the noisy sensors, the Kalman filter and the
control law of :mod:`minvar.lqg`; the loop is over time, all repetitions are
advanced together as ``(trials, n)`` arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .limits import check_simulation
from .lqg import LQGSolution
from .problem import LQGProblem

__all__ = ["Trajectories", "simulate", "as_generator"]


def as_generator(seed: int | np.random.Generator | None) -> np.random.Generator:
    """A ``numpy.random.Generator`` from a seed, or the generator itself."""
    if isinstance(seed, np.random.Generator):
        return seed
    return np.random.default_rng(seed)


@dataclass(frozen=True, eq=False)
class Trajectories:
    """Noisy repetitions of one LQG movement.

    Attributes
    ----------
    states : (trials, T+1, n) array
        True states x[0] .. x[T].
    estimates : (trials, T+1, n) array
        Kalman filter estimates xhat[0] .. xhat[T].
    controls : (trials, T, m) array
        Commands u[0] .. u[T-1] (before control-dependent noise).
    cost : (trials,) array
        Realised cost ``sum_t x'Q[t]x + u'Ru`` of each repetition.
    """

    states: np.ndarray = field(repr=False)
    estimates: np.ndarray = field(repr=False)
    controls: np.ndarray = field(repr=False)
    cost: np.ndarray = field(repr=False)

    @property
    def trials(self) -> int:
        """Number of repetitions."""
        return self.states.shape[0]


def simulate(
    problem: LQGProblem,
    solution: LQGSolution,
    trials: int = 100,
    *,
    seed: int | np.random.Generator | None = 0,
    execution: LQGProblem | None = None,
) -> Trajectories:
    """Run ``trials`` noisy repetitions of a solved problem in one vectorised pass.

    Parameters
    ----------
    problem : LQGProblem
        The planned problem (dynamics, cost, initial state).
    solution : LQGSolution
        Its gains, from :func:`minvar.lqg.solve`.
    trials : int
        Number of repetitions (>= 1; their arrays within
        :data:`minvar.limits.MEMORY_BUDGET`, see
        :func:`minvar.limits.simulation_bytes`).
    seed : int or numpy.random.Generator, optional
        Randomness; the same seed gives the same trajectories.
    execution : LQGProblem, optional
        Problem whose noise model (``C, C0, D, D0, E0, S1``) is used to execute
        the plan, when it differs from the planning model (e.g. the grasp
        chapter's 1 % coefficient of variation; ``problem.with_noise(...)``). Its
        plant, cost and start (``A, B, H, Q, R, X1``) must be the planned ones.
        Defaults to ``problem``.

    Returns
    -------
    Trajectories
        States, estimates, commands and realised cost of every repetition.

    Raises
    ------
    ValueError
        If ``trials`` is not a whole number of at least 1 or its arrays would exceed
        the memory budget (checked before any allocation), the solution is for another
        problem, or ``execution`` differs from ``problem`` in more than its noise.
    """
    if isinstance(trials, bool) or int(trials) != trials or trials < 1:
        raise ValueError(f"simulate: trials must be a whole number >= 1, got {trials!r}")
    trials = int(trials)
    p = problem
    e = p if execution is None else execution
    if e is not p:
        # only the noise is executed from it: a plant or cost of its own would be ignored
        for name in ("A", "B", "H", "Q", "R", "X1"):
            mine, planned = getattr(e, name), getattr(p, name)
            if mine is not planned and not np.array_equal(mine, planned):
                raise ValueError(
                    f"simulate: execution.{name} differs from the planned problem's; only "
                    "the execution's noise model (C, C0, D, D0, E0, S1) is used"
                )
    rng = as_generator(seed)
    T, n, m = p.horizon, p.n_states, p.n_controls
    check_simulation(trials, T, n, "simulate: trials", n_controls=m)
    K, L = solution.K, solution.L
    if K.shape[0] != T or L.shape != (T, m, n):
        raise ValueError(
            f"simulate: solution gains are for a different problem (L {L.shape}, "
            f"expected {(T, m, n)})"
        )

    # Row-vector form: x_next = x @ A' + ...; the estimator update folded into
    # one matrix per step, xhat_next = xhat (A - B L - K H)' + y K'.
    At, Bt, Ht = p.A.T, p.B.T, p.H.T
    neg_Lt = -np.transpose(L, (0, 2, 1))
    Ft = np.transpose(p.A[None] - p.B[None] @ L - K @ p.H[None], (0, 2, 1))
    Kt = np.transpose(K, (0, 2, 1))
    C_cat = np.concatenate(list(e.C), axis=0).T if len(e.C) and np.any(e.C) else None  # (m, c*m)
    D_cat = np.concatenate(list(e.D), axis=0).T if len(e.D) and np.any(e.D) else None  # (n, d*k)
    k = p.n_outputs
    C0t = e.C0.T if np.any(e.C0) else None
    D0t = e.D0.T if np.any(e.D0) else None
    E0t = e.E0.T if np.any(e.E0) else None

    X = np.empty((trials, T + 1, n))
    Xh = np.empty((trials, T + 1, n))
    U = np.empty((trials, T, m))
    x0 = np.broadcast_to(p.X1, (trials, n)).copy()
    if np.any(e.S1):
        w, V = np.linalg.eigh(0.5 * (e.S1 + e.S1.T))
        x0 += rng.standard_normal((trials, n)) @ (V * np.sqrt(np.clip(w, 0, None))).T
    X[:, 0] = x = x0
    Xh[:, 0] = xh = np.broadcast_to(p.X1, (trials, n)).copy()
    for t in range(T):
        u = xh @ neg_Lt[t]
        U[:, t] = u
        u_noisy = u
        if C_cat is not None:
            eps = rng.standard_normal((trials, len(e.C), 1))
            u_noisy = u + (eps * (u @ C_cat).reshape(trials, -1, m)).sum(axis=1)
        y = x @ Ht
        if D0t is not None:
            y = y + rng.standard_normal((trials, D0t.shape[0])) @ D0t
        if D_cat is not None:
            eta = rng.standard_normal((trials, len(e.D), 1))
            y = y + (eta * (x @ D_cat).reshape(trials, -1, k)).sum(axis=1)
        x_next = x @ At + u_noisy @ Bt
        if C0t is not None:
            x_next += rng.standard_normal((trials, C0t.shape[0])) @ C0t
        xh = xh @ Ft[t] + y @ Kt[t]
        if E0t is not None:
            xh += rng.standard_normal((trials, E0t.shape[0])) @ E0t
        x = x_next
        X[:, t + 1] = x
        Xh[:, t + 1] = xh
    cost = np.einsum("stn,tnk,stk->s", X, p.Q, X, optimize=True) + np.einsum(
        "stm,mk,stk->s", U, p.R, U, optimize=True
    )
    return Trajectories(states=X, estimates=Xh, controls=U, cost=cost)

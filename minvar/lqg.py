"""Todorov's (2005) LQG with signal-dependent noise.

The model (Todorov 2005, Neural Computation 17:1084; thesis eqs. 3.8-3.17)::

    x[t+1]    = A x[t] + B (u[t] + sum_i eps_i C_i u[t]) + C0 xi[t]
    y[t]      = H x[t] + sum_j eta_j D_j x[t] + D0 w[t]
    xhat[t+1] = A xhat[t] + B u[t] + K[t] (y[t] - H xhat[t]) + E0 v[t]
    u[t]      = -L[t] xhat[t]
    cost      = E[ sum_{t<T} (x' Q[t] x + u' R u) + x[T]' Q[T] x[T] ]

with ``eps_i, eta_j`` scalar and ``xi, w, v`` vector standard normal noise, and
``x[0] ~ N(X1, S1)``, ``xhat[0] = X1``. ``C_i`` are m x m (the thesis's C is
``B C_i``). The filter ``K`` and controller ``L`` are found by alternating a
forward pass (``K`` optimal for the current ``L``; the first pass uses
``L = 0``) and a backward pass (``L`` optimal for the current ``K``) until the
expected cost stops changing.

This is a line-by-line port of Todorov's ``kalman_lqg.m``; it reproduces that
code's ``K``, ``L``, expected trajectory and cost per iteration (see
``tests/test_lqg.py`` and ``tests/data/todorov_reach.json``). The problem itself,
:class:`~minvar.problem.LQGProblem`, is in :mod:`minvar.problem`; the exact
moments of any gains (``expected_cost``, ``state_moments``,
``estimation_error_covariance``) are in :mod:`minvar.moments` and imported
from there only.
"""

from __future__ import annotations

import functools
import logging
from dataclasses import dataclass, field

import numpy as np

from . import _kernel
from ._kernel import KernelUnavailableError
from .moments import Moments
from .moments import mean_states as _mean_states
from .problem import LQGProblem

log = logging.getLogger(__name__)

#: Largest relative bounce of a cost at its rounding floor that still counts as converged.
_FLOOR_RTOL = 1e-6

__all__ = ["LQGSolution", "solve", "KernelUnavailableError", "kernel_engine"]


@dataclass(frozen=True, eq=False)
class LQGSolution:
    """Filter and controller gains of an :class:`LQGProblem`.

    Attributes
    ----------
    K : (T, n, k) array
        Filter gains.
    L : (T, m, n) array
        Control gains, ``u[t] = -L[t] xhat[t]``.
    cost : float
        Expected cost of the returned ``K`` and ``L``.
    cost_history : (iterations,) array
        Expected cost after each iteration.
    iterations : int
        Forward/backward iterations run.
    converged : bool
        Whether the cost change fell below the tolerance before ``max_iter``.
    mean_states : (T+1, n) array
        Expected state trajectory with no noise (``xhat = x``).
    """

    K: np.ndarray
    L: np.ndarray
    cost: float
    cost_history: np.ndarray
    iterations: int
    converged: bool
    mean_states: np.ndarray = field(repr=False)


def _is_positive_definite(M: np.ndarray) -> bool:
    """True if ``M`` is safely invertible as a symmetric positive definite matrix."""
    if M.size == 0:
        return False
    w = np.linalg.eigvalsh(0.5 * (M + M.T))
    return bool(w[0] > 1e-12 * max(w[-1], np.finfo(float).tiny))


class _Solver:
    """Gain recursions for one problem; precomputes the constant terms once.

    Linear systems are solved by Cholesky when the matrix is bounded below by a
    positive definite constant (``D0 D0'`` for the filter, ``R`` for the
    controller) and with the pseudo-inverse, as in Todorov's code, when it may
    be singular. The forward pass's moments are stepped by
    :class:`minvar.moments.Moments`, the recursion the exact moments of any
    gains use too.
    """

    def __init__(self, p: LQGProblem, compiled: bool = True):
        self.p = p
        self.moments = mom = Moments(p)
        self.At, self.Ht, self.BC, self.Dt = mom.At, mom.Ht, mom.BC, mom.Dt
        self.Bt = np.ascontiguousarray(p.B.T)
        self.DD0, self.CC0, self.EE0 = mom.DD0, mom.CC0, mom.EE0
        self.has_C, self.has_D, self.has_E0, self.has_C0 = (mom.has_C, mom.has_D, mom.has_E0,
                                                            mom.has_C0)
        # additive noise terms of the cost (zero for the thesis problems)
        self.has_noise_cost = self.has_C0 or self.has_E0 or bool(np.any(self.DD0))
        self.filter_pd = _is_positive_definite(self.DD0)
        self.control_pd = _is_positive_definite(p.R)
        # The compiled passes cover the Cholesky case (every planning problem
        # of this project); the pseudo-inverse case runs in numpy.
        self.fast = None
        if compiled and self.filter_pd and self.control_pd:
            flags = ((_kernel.HAS_C if self.has_C else 0) | (_kernel.HAS_D if self.has_D else 0)
                     | (_kernel.TRACK_XE if self.has_E0 else 0)
                     | (_kernel.ADD_NOISE if self.has_C0 or self.has_E0 else 0)
                     | (_kernel.NOISE_COST if self.has_noise_cost else 0))
            self.fast = _kernel.Arrays(p, self.BC, self.DD0, self.CC0, self.EE0, flags)

    def step(self, L: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """One iteration: ``K`` optimal for ``L``, then the new ``L`` and its expected cost."""
        if self.fast is not None:
            K = _kernel.forward(self.fast, L)
            if K is not None:
                out = _kernel.backward(self.fast, K)
                if out is not None:
                    return K, *out
        K, AKH = self.forward(L)
        L, cost = self.backward(K, AKH)
        return K, L, cost

    @functools.cached_property
    def noise_bwd(self) -> np.ndarray:
        """sum_i C_i' M C_i as one product on vec(M); the numpy passes only."""
        m = self.p.n_controls
        return sum((np.kron(Ci.T, Ci.T) for Ci in self.p.C), np.zeros((m * m, m * m)))

    @staticmethod
    def _solve(M: np.ndarray, Y: np.ndarray, pd: bool) -> np.ndarray:
        """``M^-1 Y`` for symmetric ``M``: Cholesky when ``M`` is positive definite,
        else the pseudo-inverse, as Todorov's code does for every step."""
        if pd:
            from scipy.linalg.lapack import dposv  # the numpy passes only: start-up time

            _, X, info = dposv(M, Y)
            if info == 0:
                return X
        return np.linalg.pinv(M).dot(Y)

    # The two passes are the hot path of every planning call (hundreds of steps
    # times a few iterations, on matrices of ~14 x 14): they use ndarray.dot and
    # LAPACK directly because numpy's per-call overhead, not arithmetic, is the
    # cost at this size.
    def forward(self, L: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Filter gains ``K`` optimal for control gains ``L``; also ``A - K H`` per step."""
        p, mom = self.p, self.moments
        A, H, Ht = p.A, p.H, self.Ht
        T, n, k = p.horizon, p.n_states, p.n_outputs
        K = np.empty((T, n, k))
        AKH = np.empty((T, n, n))
        SiX, SiXE, SiE = mom.start()  # E[xhat xhat'], E[xhat e'], E[e e'], e = x - xhat
        for t in range(T):
            SiEHt = SiE.dot(Ht)
            M = mom.add_sensor_noise(H.dot(SiEHt), SiX, SiXE, SiE)  # the filter's system
            ASH = A.dot(SiEHt)  # A SiE H'
            Kt = self._solve(M, ASH.T, self.filter_pd).T  # A SiE H' M^-1
            K[t] = Kt
            SiX, SiXE, SiE = mom.step(SiX, SiXE, SiE, Kt, L[t], KMK=Kt.dot(ASH.T), akh=AKH[t])
        return K, AKH

    def backward(self, K: np.ndarray, AKH: np.ndarray) -> tuple[np.ndarray, float]:
        """Control gains ``L`` optimal for filter gains ``K``, and the expected cost."""
        p = self.p
        A, B, At, Bt = p.A, p.B, self.At, self.Bt
        T, n, m = p.horizon, p.n_states, p.n_controls
        L = np.empty((T, m, n))
        Sx = p.Q[T].copy()
        Se = np.zeros((n, n))
        cost = 0.0
        for t in range(T - 1, -1, -1):
            Kt = K[t]
            if self.has_noise_cost:
                cost += np.trace(Sx.dot(self.CC0)) + np.trace(
                    Se.dot(Kt.dot(self.DD0).dot(Kt.T) + self.EE0 + self.CC0)
                )
            SxB = Sx.dot(B)
            BSxB = Bt.dot(SxB)
            temp = p.R + BSxB
            if self.has_C:
                BSxeB = BSxB + Bt.dot(Se).dot(B)
                temp += self.noise_bwd.dot(BSxeB.ravel()).reshape(m, m)
            AtSx = At.dot(Sx)
            AtSxB = AtSx.dot(B)
            Lt = self._solve(temp, AtSxB.T, self.control_pd)  # B' Sx A = (A' Sx B)'
            L[t] = Lt
            akh = AKH[t]
            ASBL = AtSxB.dot(Lt)
            newSe = ASBL + akh.T.dot(Se).dot(akh)
            SxNew = p.Q[t] + AtSx.dot(A) - ASBL
            if self.has_D:
                KSeK = Kt.T.dot(Se).dot(Kt)
                SxNew += (self.Dt @ KSeK @ p.D).sum(axis=0)
            Sx, Se = SxNew, newSe
        X1 = p.X1
        cost += float(X1.dot(Sx).dot(X1)) + float(np.trace((Se + Sx).dot(p.S1)))
        return L, cost

    def mean_states(self, L: np.ndarray) -> np.ndarray:
        """Noise-free trajectory under ``u = -L x`` from ``X1``."""
        p = self.p
        if self.fast is not None:
            return _kernel.mean_states(p, L)
        return _mean_states(p, L)


def solve(
    problem: LQGProblem,
    *,
    atol: float = 1e-15,
    tol: float = 0.0,
    max_iter: int = 500,
    initial_L: np.ndarray | None = None,
    engine: str = "auto",
) -> LQGSolution:
    """Find the filter ``K`` and controller ``L`` that are optimal for each other.

    The stopping rule is that of Todorov's ``kalman_lqg.m``, so ``K``, ``L``
    and the mean states match his code's output to rounding on any problem.

    Parameters
    ----------
    problem : LQGProblem
        The problem to solve.
    atol : float, optional
        Stop when the expected cost changes by less than ``atol`` between
        iterations (Todorov's absolute test, with his 1e-15). As in his code,
        iteration also stops when the cost rose more than 3 times in the last
        10 iterations (after 20): it is then bouncing on its rounding floor,
        and counts as converged if those changes are below 1e-6 of the cost.
    tol : float, optional
        Also stop when the change is below ``tol`` times the cost (a relative
        test; 0, off, by default as in Todorov's code).
    max_iter : int, optional
        Maximum number of forward/backward iterations; ``max_iter=2`` runs
        exactly two (Todorov's ``Niter=2``).
    initial_L : (T, m, n) array, optional
        Control gains for the first forward pass (default zeros, as the thesis
        and Todorov's code; thesis line 481: any start converges to the same
        answer).
    engine : {"auto", "c", "numpy"}, optional
        Which implementation runs the forward and backward passes. ``"c"``:
        the compiled kernel (``minvar/_lqg_kernel.c``, built by ``pip install``);
        ``"numpy"``: the numpy passes, the same results to rounding (gains to
        about 1e-12 relative), five to ten times slower. ``"auto"`` (default):
        what the environment variable ``MINVAR_KERNEL`` says (``c`` or
        ``numpy``) if it is set, else the compiled kernel where it is built,
        falling back to numpy with one warning per process (logger
        ``minvar``) where it is not (:func:`kernel_engine` says which runs).
        Problems whose filter or control system may be singular (``D0 D0'``
        or ``R`` not positive definite) run the numpy passes' pseudo-inverse
        whatever the engine.

    Returns
    -------
    LQGSolution
        Gains, expected cost, cost per iteration and the noise-free mean states.
        A problem that does not converge in ``max_iter`` iterations has
        ``converged=False`` and is reported once per process in the log.

    Raises
    ------
    ValueError
        If ``tol``, ``atol``, ``max_iter``, ``initial_L`` or ``engine`` are out of
        range, or the recursions break down: non-finite moments or gains (e.g.
        dynamics so unstable that the moments overflow), or a singular
        observation noise whose filter system cannot be solved. The message
        names the cause.
    KernelUnavailableError
        If ``engine="c"`` (or ``"auto"`` with ``MINVAR_KERNEL=c``) and the
        compiled kernel is not built or cannot be loaded (an ``ImportError``).
    """
    if not isinstance(problem, LQGProblem):
        raise ValueError(f"solve: expected an LQGProblem, got {type(problem).__name__}")
    if not (tol >= 0 and atol >= 0):
        raise ValueError(f"solve: tol and atol must be >= 0, got tol={tol}, atol={atol}")
    if int(max_iter) < 1:
        raise ValueError(f"solve: max_iter must be >= 1, got {max_iter}")
    compiled = _kernel.use_compiled(_kernel.check_engine(engine, "solve"))
    solver = _Solver(problem, compiled)
    T, m, n = problem.horizon, problem.n_controls, problem.n_states
    L = np.zeros((T, m, n)) if initial_L is None else np.array(initial_L, dtype=float)
    if L.shape != (T, m, n) or not np.all(np.isfinite(L)):
        raise ValueError(f"solve: initial_L must be finite, of shape {(T, m, n)}, got {L.shape}")
    history: list[float] = []
    converged = False
    K = None
    for it in range(int(max_iter)):
        with np.errstate(all="ignore"):  # overflow is reported below, by its cause
            try:
                K, L, cost = solver.step(L)
            except np.linalg.LinAlgError as exc:
                raise ValueError(_breakdown(solver, it, f"a linear solve failed ({exc})")) from None
        if not (np.isfinite(cost) and np.isfinite(K).all() and np.isfinite(L).all()):
            raise ValueError(_breakdown(solver, it, _first_bad(K, L)))
        history.append(cost)
        if len(history) > 1:
            change = abs(history[-2] - history[-1])
            if change < atol or change < tol * abs(history[-1]):
                converged = True
                break
        if len(history) > 20:
            # kalman_lqg.m's third test: a cost that rises more than 3 times in
            # 10 iterations is bouncing on its rounding floor (large target
            # coordinates make it a small difference of large terms)
            recent = np.diff(history[-11:])
            if np.sum(recent > 0) > 3:
                converged = bool(np.abs(recent).max() <= _FLOOR_RTOL * abs(history[-1]))
                break
    if not converged:
        _report_unconverged(problem, history)
    for arr in (K, L):
        arr.setflags(write=False)
    return LQGSolution(
        K=K,
        L=L,
        cost=history[-1],
        cost_history=np.array(history),
        iterations=len(history),
        converged=converged,
        mean_states=solver.mean_states(L),
    )


def kernel_engine(engine: str = "auto") -> str:
    """Which passes a :func:`solve` with ``engine`` runs: ``"c"`` or ``"numpy"``.

    ``python -c "import minvar; print(minvar.kernel_engine())"`` tells whether
    this install solves with the compiled kernel. It warns and raises nothing
    about a missing kernel (``"c"``, asked for or by ``MINVAR_KERNEL``, is then
    a solve's :class:`KernelUnavailableError`), and problems that need the
    pseudo-inverse run the numpy passes whatever it says.

    Parameters
    ----------
    engine : {"auto", "c", "numpy"}, optional
        The ``engine`` argument of :func:`solve`.

    Returns
    -------
    str
        ``"c"`` or ``"numpy"``.
    """
    return _kernel.resolve(engine, "kernel_engine")


def _first_bad(K: np.ndarray, L: np.ndarray) -> str:
    """Which gains went non-finite first, and at which step."""
    for name, G in (("filter gains K", K), ("control gains L", L)):
        bad = ~np.isfinite(G).reshape(len(G), -1).all(axis=1)
        if bad.any():
            return f"the {name} are not finite from step {int(np.argmax(bad))}"
    return "the expected cost is not finite"


def _breakdown(solver: _Solver, iteration: int, what: str) -> str:
    """The message of a solve that broke down: what happened and the likely cause."""
    p = solver.p
    causes = []
    growth = float(np.abs(np.linalg.eigvals(p.A)).max())
    if p.horizon * np.log10(max(growth, 1e-300)) > 100:
        causes.append(f"the dynamics A grow by {growth:.3g} per step, so the moments "
                      f"overflow within {p.horizon} steps")
    if not solver.filter_pd:
        causes.append("the observation noise D0 D0' is singular (some sensor has no "
                      "noise), so the filter's system H S H' + D0 D0' can be singular")
    cause = "; ".join(causes) or "the problem's moments overflow or cancel"
    return f"solve: iteration {iteration + 1}: {what}: {cause}"


#: Problems whose failure to converge has been reported in this process.
_REPORTED: set[tuple] = set()


def _report_unconverged(problem: LQGProblem, history: list[float]) -> None:
    """Log a plan that did not converge: once per problem and process, at warning level."""
    key = (problem.n_states, problem.horizon, round(history[-1], 12))
    last = abs(history[-2] - history[-1]) if len(history) > 1 else float("nan")
    msg = ("solve: the expected cost did not converge in %d iterations (last change %.3g, "
           "cost %.6g): the gains are those of the last iteration")
    if key in _REPORTED:
        log.debug(msg, len(history), last, history[-1])
        return
    _REPORTED.add(key)
    log.warning(msg, len(history), last, history[-1])

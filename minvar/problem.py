"""The finite-horizon LQG problem with signal-dependent noise, checked where it enters.

:class:`LQGProblem` holds the matrices of Todorov's (2005) model (the
equations are in :mod:`minvar.lqg`, which solves it); the recursions of
:mod:`minvar.moments` and the solver both read it, so it lives here, apart
from either.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

__all__ = ["LQGProblem"]


def _as_matrix(name: str, value, shape: tuple[int | None, ...]) -> np.ndarray:
    """Convert ``value`` to a finite float array of ``shape`` (None = any size)."""
    arr = np.array(value, dtype=float)
    if arr.ndim != len(shape) or any(s is not None and s != a for s, a in zip(shape, arr.shape)):
        want = "(" + ", ".join("*" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"LQGProblem.{name}: expected shape {want}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"LQGProblem.{name}: contains non-finite values (NaN or inf)")
    arr.setflags(write=False)
    return arr


def _as_stack(name: str, value, shape: tuple[int, int], what: str) -> np.ndarray:
    """A sequence of matrices of one ``shape`` as a read-only (count, *shape) array."""
    mats = [np.asarray(v, dtype=float) for v in value] if value is not None else []
    for i, m in enumerate(mats):
        if m.shape != shape:
            raise ValueError(
                f"LQGProblem.{name}[{i}]: expected shape {shape} ({what}), got {m.shape}"
            )
    arr = np.stack(mats) if mats else np.zeros((0, *shape))
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"LQGProblem.{name}: contains non-finite values (NaN or inf)")
    arr.setflags(write=False)
    return arr


def _check_psd(name: str, M: np.ndarray) -> None:
    """Raise unless ``M`` (or each of a stack) is symmetric positive semi-definite."""
    if M.ndim == 3:  # a cost per step is mostly zeros: check the others
        M = M[M.any(axis=(1, 2))]
    if not M.any():
        return
    scale = float(np.abs(M).max())
    if np.abs(M - np.swapaxes(M, -1, -2)).max() > 1e-10 * scale:
        raise ValueError(f"LQGProblem.{name}: expected a symmetric matrix")
    d = np.diagonal(M, axis1=-2, axis2=-1)
    if M.ndim == 2 and np.count_nonzero(M) == np.count_nonzero(d):  # diagonal
        lowest = float(d.min())
    else:
        lowest = np.linalg.eigvalsh(0.5 * (M + np.swapaxes(M, -1, -2))).min()
    if lowest < -1e-10 * scale:
        raise ValueError(f"LQGProblem.{name}: expected a positive semi-definite matrix "
                         f"(an eigenvalue is {lowest:.3g})")


@dataclass(frozen=True, eq=False)
class LQGProblem:
    """A finite-horizon LQG problem with signal-dependent noise.

    Shapes use n states, m controls, k observations, T steps.

    Parameters
    ----------
    A : (n, n) array
        State dynamics.
    B : (n, m) array
        Control input.
    C : sequence of (m, m) arrays
        Control-dependent noise: ``B C_i u`` scaled by a standard normal scalar.
    C0 : (n, p) array
        Additive process noise.
    H : (k, n) array
        Observation matrix.
    D : sequence of (k, n) arrays
        State-dependent observation noise: ``D_j x`` scaled by a standard normal scalar.
    D0 : (k, q) array
        Additive observation noise.
    E0 : (n, e) array
        Internal (estimation) noise added to the estimate.
    Q : (T+1, n, n) array
        State cost for x[0] .. x[T].
    R : (m, m) array
        Control cost per step.
    X1 : (n,) array
        Mean initial state (also the initial estimate).
    S1 : (n, n) array
        Covariance of the initial state.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    C0: np.ndarray
    H: np.ndarray
    D: np.ndarray
    D0: np.ndarray
    E0: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    X1: np.ndarray
    S1: np.ndarray

    def __post_init__(self):
        A = _as_matrix("A", self.A, (None, None))
        n = A.shape[0]
        if A.shape != (n, n):
            raise ValueError(f"LQGProblem.A: expected a square (n, n) matrix, got {A.shape}")
        B = np.array(self.B, dtype=float)
        if B.ndim != 2 or B.shape[0] != n:
            raise ValueError(
                f"LQGProblem.B: expected shape ({n}, m) to match A {A.shape}, got {B.shape}"
            )
        m = B.shape[1]
        B = _as_matrix("B", B, (n, m))
        H = np.array(self.H, dtype=float)
        if H.ndim != 2 or H.shape[1] != n:
            raise ValueError(
                f"LQGProblem.H: expected shape (k, {n}) to match A {A.shape}, got {H.shape}"
            )
        k = H.shape[0]
        H = _as_matrix("H", H, (k, n))
        Q = np.array(self.Q, dtype=float)
        if Q.ndim != 3 or Q.shape[1:] != (n, n) or Q.shape[0] < 2:
            raise ValueError(
                f"LQGProblem.Q: expected shape (T+1, {n}, {n}) with T >= 1, got {Q.shape}"
            )
        values = {
            "A": A,
            "B": B,
            "C": _as_stack("C", self.C, (m, m), "m x m"),
            "C0": _as_matrix("C0", self.C0, (n, None)),
            "H": H,
            "D": _as_stack("D", self.D, (k, n), "k x n"),
            "D0": _as_matrix("D0", self.D0, (k, None)),
            "E0": _as_matrix("E0", self.E0, (n, None)),
            "Q": _as_matrix("Q", Q, Q.shape),
            "R": _as_matrix("R", self.R, (m, m)),
            "X1": _as_matrix("X1", np.ravel(self.X1), (n,)),
            "S1": _as_matrix("S1", self.S1, (n, n)),
        }
        for key in ("Q", "R", "S1"):
            _check_psd(key, values[key])
        for key, val in values.items():
            object.__setattr__(self, key, val)

    def with_noise(self, *, C=None, D0=None) -> LQGProblem:
        """This problem with other control-dependent (``C``) or sensory (``D0``) noise.

        The same as ``dataclasses.replace(problem, C=..., D0=...)``, checking
        only the new matrices (a grasp's execution model, planned once per chain).
        """
        new = copy.copy(self)
        m, k = self.n_controls, self.n_outputs
        if C is not None:
            object.__setattr__(new, "C", _as_stack("C", C, (m, m), "m x m"))
        if D0 is not None:
            object.__setattr__(new, "D0", _as_matrix("D0", D0, (k, None)))
        return new

    @property
    def n_states(self) -> int:
        """Number of states n."""
        return self.A.shape[0]

    @property
    def n_controls(self) -> int:
        """Number of controls m."""
        return self.B.shape[1]

    @property
    def n_outputs(self) -> int:
        """Number of observations k."""
        return self.H.shape[0]

    @property
    def horizon(self) -> int:
        """Number of control steps T (states x[0] .. x[T])."""
        return self.Q.shape[0] - 1

"""The compiled passes of :mod:`minvar.lqg` (``minvar/_lqg_kernel.c``), loaded with ctypes.

The library is built by ``pip install`` (``setup.py``; a C compiler is all it
needs) and is optional: without it, or with ``MINVAR_KERNEL=numpy`` in the
environment, the solver runs its numpy passes, which give the same results to
rounding, five to ten times slower.
"""

from __future__ import annotations

import ctypes
import importlib.util
import logging
import os

import numpy as np

log = logging.getLogger(__name__)

__all__ = ["available", "backward", "error_covariance", "forward", "mean_states"]

#: Flags of the C passes (minvar/_lqg_kernel.c).
HAS_C, HAS_D, TRACK_XE, ADD_NOISE, NOISE_COST = 1, 2, 4, 8, 16

_int = ctypes.c_int
_ptr = ctypes.c_void_p


def _load():
    if os.environ.get("MINVAR_KERNEL", "").lower() == "numpy":
        return None
    spec = importlib.util.find_spec("minvar._lqg_kernel")
    if spec is None or not spec.origin:
        log.info("minvar: compiled LQG kernel not built; using the numpy passes")
        return None
    try:
        lib = ctypes.CDLL(spec.origin)
    except OSError as exc:  # pragma: no cover - a broken build
        log.info("minvar: cannot load the compiled LQG kernel (%s); using numpy", exc)
        return None
    if not hasattr(lib, "lqg_mean_states"):  # pragma: no cover - built from older source
        log.info("minvar: the compiled LQG kernel is out of date (reinstall); using numpy")
        return None
    lib.lqg_forward.argtypes = [_int] * 6 + [_ptr] * 11 + [_int, _ptr]
    lib.lqg_forward.restype = _int
    lib.lqg_backward.argtypes = [_int] * 6 + [_ptr] * 13 + [_int, _ptr, _ptr]
    lib.lqg_backward.restype = _int
    lib.lqg_error_cov.argtypes = [_int] * 6 + [_ptr] * 13
    lib.lqg_error_cov.restype = _int
    lib.lqg_mean_states.argtypes = [_int] * 3 + [_ptr] * 5
    lib.lqg_mean_states.restype = None
    return lib


_LIB = _load()


def available() -> bool:
    """Whether the compiled passes are in use."""
    return _LIB is not None


def _p(a: np.ndarray | None):
    return None if a is None else a.ctypes.data


def _c(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


class Arrays:
    """A problem's matrices as contiguous arrays and their addresses, prepared once per solve."""

    def __init__(self, p, BC: np.ndarray, DD0, CC0, EE0, flags: int):
        T, n, m, k = p.horizon, p.n_states, p.n_controls, p.n_outputs
        keep = [_c(a) for a in (p.A, p.B, p.H, BC, p.C, p.D, DD0, CC0, EE0, p.Q, p.R, p.X1,
                                p.S1)]
        self._keep = keep  # the addresses below point into these
        A, B, H, BC, C, D, DD0, CC0, EE0, Q, R, X1, S1 = (a.ctypes.data for a in keep)
        dims = (T, n, m, k, len(p.C), len(p.D))
        self.shapes = {"K": (T, n, k), "L": (T, m, n)}
        self.fwd = (*dims, A, B, H, BC, D, DD0, CC0, EE0, S1, X1)
        self.bwd = (*dims, A, B, H, C, D, DD0, CC0, EE0, Q, R, X1, S1)
        self.flags = flags


def forward(a: Arrays, L: np.ndarray) -> np.ndarray | None:
    """Filter gains ``K`` for control gains ``L``, or None if Cholesky failed."""
    K = np.empty(a.shapes["K"])
    L = _c(L)
    status = _LIB.lqg_forward(*a.fwd, L.ctypes.data, a.flags, K.ctypes.data)
    if status < 0:
        raise MemoryError("minvar: the LQG kernel ran out of memory")
    return K if status == 0 else None


def backward(a: Arrays, K: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Control gains ``L`` and the expected cost for filter gains ``K``, or None."""
    L = np.empty(a.shapes["L"])
    cost = ctypes.c_double()
    K = _c(K)
    status = _LIB.lqg_backward(*a.bwd, K.ctypes.data, a.flags, L.ctypes.data,
                               ctypes.byref(cost))
    if status < 0:
        raise MemoryError("minvar: the LQG kernel ran out of memory")
    return (L, cost.value) if status == 0 else None


def error_covariance(p, K: np.ndarray, L: np.ndarray) -> np.ndarray:
    """Exact ``Cov[x - xhat]`` for t = 0..T under gains ``K``, ``L`` (see lqg.py)."""
    T, n = p.horizon, p.n_states
    BC = np.einsum("ij,cjk->cik", p.B, p.C) if len(p.C) else np.zeros((0, n, p.n_controls))
    D = _c(p.D) if np.any(p.D) else None
    P = np.empty((T + 1, n, n))
    args = [_c(x) for x in (p.A, p.B, p.H, BC)]
    rest = [_c(x) for x in (p.D0 @ p.D0.T, p.C0 @ p.C0.T, p.E0 @ p.E0.T, p.S1, p.X1, K, L)]
    status = _LIB.lqg_error_cov(T, n, p.n_controls, p.n_outputs, len(p.C) if np.any(p.C) else 0,
                                0 if D is None else len(D), *map(_p, args), _p(D),
                                *map(_p, rest), _p(P))
    if status < 0:
        raise MemoryError("minvar: the LQG kernel ran out of memory")
    return P


def mean_states(p, L: np.ndarray) -> np.ndarray:
    """Noise-free states ``x[t+1] = (A - B L[t]) x[t]`` from ``X1``, (T+1, n)."""
    T, n, m = p.horizon, p.n_states, p.n_controls
    X = np.empty((T + 1, n))
    args = [_c(x) for x in (p.A, p.B, L, p.X1)]
    _LIB.lqg_mean_states(T, n, m, *map(_p, args), _p(X))
    return X

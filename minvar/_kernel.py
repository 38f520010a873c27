"""The compiled passes of :mod:`minvar.lqg` (``minvar/_lqg_kernel.c``), loaded with ctypes.

The library is built by ``pip install`` (``setup.py``; a C compiler is all it
needs) and is optional: the solver's ``engine`` argument picks the compiled
passes (``"c"``), its numpy passes (``"numpy"``), which give the same results to
rounding, five to ten times slower, or the compiled passes where they are built
(``"auto"``, the default; ``MINVAR_KERNEL=numpy`` or ``=c`` in the environment
sets what ``"auto"`` means). An ``"auto"`` solve that falls back to numpy because
the library is missing says so once per process, as a warning.
"""

from __future__ import annotations

import ctypes
import importlib.util
import logging
import os
import threading

import numpy as np

__all__ = ["ENGINES", "KernelUnavailableError", "available", "backward", "check_engine",
           "error_covariance", "forward", "loaded", "mean_states", "use_compiled"]

#: The values of the solver's ``engine`` argument.
ENGINES = ("auto", "c", "numpy")

#: Values of ``MINVAR_KERNEL`` and the engine each makes ``"auto"`` mean.
_ENV_ENGINES = {"": "auto", "auto": "auto", "c": "c", "compiled": "c", "numpy": "numpy"}


class KernelUnavailableError(ImportError):
    """``engine="c"`` was asked for but the compiled kernel is not built or cannot be loaded."""

#: Flags of the C passes (minvar/_lqg_kernel.c).
HAS_C, HAS_D, TRACK_XE, ADD_NOISE, NOISE_COST = 1, 2, 4, 8, 16

_int = ctypes.c_int
_ptr = ctypes.c_void_p


#: Why the library is not loaded (None when it is).
_WHY: str | None = None


def _load():
    """The library, or None with the reason in ``_WHY`` (said when a solve needs it)."""
    global _WHY
    spec = importlib.util.find_spec("minvar._lqg_kernel")
    if spec is None or not spec.origin:
        _WHY = "it was not built: no C compiler when minvar was installed"
        return None
    try:
        lib = ctypes.CDLL(spec.origin)
    except OSError as exc:  # pragma: no cover - a broken build
        _WHY = f"it cannot be loaded ({exc})"
        return None
    if not hasattr(lib, "lqg_mean_states"):  # pragma: no cover - built from older source
        _WHY = "it is out of date (reinstall minvar)"
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


def loaded() -> bool:
    """Whether the compiled library is built and loaded (``engine="c"`` can run)."""
    return _LIB is not None


def available() -> bool:
    """Whether the default engine (``"auto"``) uses the compiled passes.

    True when the library is loaded and ``MINVAR_KERNEL`` does not ask for numpy.
    """
    return _LIB is not None and os.environ.get("MINVAR_KERNEL", "").strip().lower() != "numpy"


def check_engine(engine, where: str) -> str:
    """``engine`` if it is one of :data:`ENGINES`, else a ValueError naming it (at ``where``)."""
    if not isinstance(engine, str) or engine not in ENGINES:
        raise ValueError(f"{where}: engine must be one of {', '.join(map(repr, ENGINES))}, "
                         f"got {engine!r}")
    return engine


#: Whether an "auto" fallback to numpy has been announced in this process.
_WARNED = False
_WARN_LOCK = threading.Lock()


def use_compiled(engine: str) -> bool:
    """Whether a solve with ``engine`` (checked by :func:`check_engine`) runs the compiled passes.

    ``"auto"`` takes its meaning from ``MINVAR_KERNEL`` when that is set, and
    otherwise uses the compiled passes where they are loaded, announcing the
    numpy fallback once per process (a warning on the ``minvar`` logger).
    ``"c"`` without the library raises :class:`KernelUnavailableError`.
    """
    global _WARNED
    if engine == "auto":
        env = os.environ.get("MINVAR_KERNEL", "")
        engine = _ENV_ENGINES.get(env.strip().lower())
        if engine is None:
            raise ValueError(f"MINVAR_KERNEL must be one of 'auto', 'c' (or 'compiled') or "
                             f"'numpy', got {env!r}")
    if engine == "numpy":
        return False
    if _LIB is not None:
        return True
    why = _WHY or "it is not loaded"
    if engine == "c":
        raise KernelUnavailableError(
            f"minvar: engine='c' needs the compiled LQG kernel (minvar/_lqg_kernel.c), but "
            f"{why}; reinstall minvar with a C compiler, or use engine='auto' or 'numpy'")
    with _WARN_LOCK:
        warn, _WARNED = not _WARNED, True
    if warn:
        logging.getLogger("minvar").warning(
            "minvar: the compiled LQG kernel is not available (%s); solving with the numpy "
            "passes, the same results five to ten times slower (engine='numpy' or "
            "MINVAR_KERNEL=numpy chooses them without this warning)", why)
    return False


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

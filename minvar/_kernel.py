"""The compiled passes of :mod:`minvar.lqg`: the extension module ``minvar._lqg_kernel``.

The module (``minvar/_lqg_kernel.c``) is built by ``pip install`` (``setup.py``;
a C compiler is all it needs) and is optional: the solver's ``engine`` argument
picks the compiled passes (``"c"``), its numpy passes (``"numpy"``), which give
the same results to rounding, five to ten times slower, or the compiled passes
where they are built (``"auto"``, the default; ``MINVAR_KERNEL=numpy`` or ``=c``
in the environment sets what ``"auto"`` means). An ``"auto"`` solve that falls
back to numpy because the module is missing says so once per process, as a
warning. :func:`resolve` says which engine a solve runs.
"""

from __future__ import annotations

import logging
import os
import threading

import numpy as np

__all__ = ["ENGINES", "KernelUnavailableError", "available", "backward", "check_engine",
           "error_covariance", "forward", "loaded", "mean_states", "resolve",
           "use_compiled"]

#: The values of the solver's ``engine`` argument.
ENGINES = ("auto", "c", "numpy")

#: Values of ``MINVAR_KERNEL`` and the engine each makes ``"auto"`` mean.
_ENV_ENGINES = {"": "auto", "auto": "auto", "c": "c", "compiled": "c", "numpy": "numpy"}


class KernelUnavailableError(ImportError):
    """``engine="c"`` was asked for but the compiled kernel is not built or cannot be loaded."""

#: Flags of the C passes (minvar/_lqg_kernel.c).
HAS_C, HAS_D, TRACK_XE, ADD_NOISE, NOISE_COST = 1, 2, 4, 8, 16


def _load():
    """The extension module and None, or None and why it is not there (said when needed)."""
    try:
        from . import _lqg_kernel
    except ModuleNotFoundError as exc:
        if exc.name != f"{__package__}._lqg_kernel":  # pragma: no cover - a bug, not a build
            raise
        return None, "it was not built: no C compiler when minvar was installed"
    except ImportError as exc:  # pragma: no cover - a broken build
        return None, f"it cannot be loaded ({exc})"
    if not hasattr(_lqg_kernel, "error_cov"):  # pragma: no cover - built from older source
        return None, "it is out of date (reinstall minvar)"
    return _lqg_kernel, None


#: The extension module, or None with the reason in ``_WHY``.
_KERNEL, _WHY = _load()


def loaded() -> bool:
    """Whether the compiled kernel is built and loaded (``engine="c"`` can run)."""
    return _KERNEL is not None


def available() -> bool:
    """Whether the default engine (``"auto"``) uses the compiled passes.

    True when the kernel is loaded and ``MINVAR_KERNEL`` does not ask for numpy.
    """
    return _KERNEL is not None and os.environ.get("MINVAR_KERNEL", "").strip().lower() != "numpy"


def check_engine(engine, where: str) -> str:
    """``engine`` if it is one of :data:`ENGINES`, else a ValueError naming it (at ``where``)."""
    if not isinstance(engine, str) or engine not in ENGINES:
        raise ValueError(f"{where}: engine must be one of {', '.join(map(repr, ENGINES))}, "
                         f"got {engine!r}")
    return engine


def _requested(engine: str) -> str:
    """``engine``, with ``"auto"`` replaced by what ``MINVAR_KERNEL`` asks for (if anything)."""
    if engine != "auto":
        return engine
    env = os.environ.get("MINVAR_KERNEL", "")
    requested = _ENV_ENGINES.get(env.strip().lower())
    if requested is None:
        raise ValueError(f"MINVAR_KERNEL must be one of 'auto', 'c' (or 'compiled') or "
                         f"'numpy', got {env!r}")
    return requested


def resolve(engine: str, where: str) -> str:
    """The engine a solve with ``engine`` runs, ``"c"`` or ``"numpy"``, silently.

    ``"c"`` (asked for, or by ``MINVAR_KERNEL``) stays ``"c"`` without the
    kernel: such a solve raises :class:`KernelUnavailableError`. A bad
    ``engine`` is a ValueError naming ``where``.
    """
    requested = _requested(check_engine(engine, where))
    return "c" if requested == "c" or (requested == "auto" and _KERNEL is not None) else "numpy"


#: Whether an "auto" fallback to numpy has been announced in this process.
_WARNED = False
_WARN_LOCK = threading.Lock()


def use_compiled(engine: str) -> bool:
    """Whether a solve with ``engine`` (checked by :func:`check_engine`) runs the compiled passes.

    ``"auto"`` takes its meaning from ``MINVAR_KERNEL`` when that is set, and
    otherwise uses the compiled passes where they are loaded, announcing the
    numpy fallback once per process (a warning on the ``minvar`` logger).
    ``"c"`` without the kernel raises :class:`KernelUnavailableError`.
    """
    global _WARNED
    engine = _requested(engine)
    if engine == "numpy":
        return False
    if _KERNEL is not None:
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


def _c(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


class Arrays:
    """A problem's matrices as contiguous float64 arrays, prepared once per solve."""

    def __init__(self, p, BC: np.ndarray, DD0, CC0, EE0, flags: int):
        T, n, m, k = p.horizon, p.n_states, p.n_controls, p.n_outputs
        self.dims = (T, n, m, k, len(p.C), len(p.D))
        A, B, H, BC, C, D, DD0, CC0, EE0, Q, R, X1, S1 = (
            _c(a) for a in (p.A, p.B, p.H, BC, p.C, p.D, DD0, CC0, EE0, p.Q, p.R, p.X1, p.S1))
        self.shapes = {"K": (T, n, k), "L": (T, m, n)}
        self.fwd = (A, B, H, BC, D, DD0, CC0, EE0, S1, X1)
        self.bwd = (A, B, H, C, D, DD0, CC0, EE0, Q, R, X1, S1)
        self.flags = flags


def forward(a: Arrays, L: np.ndarray) -> np.ndarray | None:
    """Filter gains ``K`` for control gains ``L``, or None if Cholesky failed."""
    K = np.empty(a.shapes["K"])
    ok = _KERNEL.forward(a.dims, a.flags, *a.fwd, _c(L), K)
    return K if ok else None


def backward(a: Arrays, K: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Control gains ``L`` and the expected cost for filter gains ``K``, or None."""
    L = np.empty(a.shapes["L"])
    cost = _KERNEL.backward(a.dims, a.flags, *a.bwd, _c(K), L)
    return None if cost is None else (L, cost)


def error_covariance(p, K: np.ndarray, L: np.ndarray) -> np.ndarray:
    """Exact ``Cov[x - xhat]`` for t = 0..T under gains ``K``, ``L`` (see moments.py)."""
    T, n, m = p.horizon, p.n_states, p.n_controls
    C = p.C if np.any(p.C) else p.C[:0]  # noise terms that are all zeros are skipped
    D = p.D if np.any(p.D) else p.D[:0]
    BC = np.einsum("ij,cjk->cik", p.B, C) if len(C) else np.zeros((0, n, m))
    P = np.empty((T + 1, n, n))
    _KERNEL.error_cov((T, n, m, p.n_outputs, len(C), len(D)),
                      *(_c(x) for x in (p.A, p.B, p.H, BC, D, p.D0 @ p.D0.T, p.C0 @ p.C0.T,
                                        p.E0 @ p.E0.T, p.S1, p.X1, K, L)), P)
    return P


def mean_states(p, L: np.ndarray) -> np.ndarray:
    """Noise-free states ``x[t+1] = (A - B L[t]) x[t]`` from ``X1``, (T+1, n)."""
    T, n, m = p.horizon, p.n_states, p.n_controls
    X = np.empty((T + 1, n))
    _KERNEL.mean_states((T, n, m, p.n_outputs, 0, 0), *(_c(x) for x in (p.A, p.B, L, p.X1)), X)
    return X

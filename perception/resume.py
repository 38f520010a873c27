"""A longer series that begins with one computed before: what the online path resumes from.

The online recogniser recognises the rows received so far after every row,
so each call's series is the last call's and a row more. The passes that
keep their last result per thread (the scene, the onset and end scans, the
spike test, the causal filter, the scores) resume only from a series the new
one begins with bit for bit: :func:`begins_with` is that one test, and
:class:`Kept` the one store each of them keeps its results in.

Comparing the rows costs a pass over every row at every row. A series that
is the rows of a :class:`Grown` (rows appended, never changed: the online
recogniser's rows, and what is made from them row by row with
:func:`extended` and :func:`rowwise`) needs none: a kept one of the same
:class:`Grown` is the new one's first rows by construction, so :class:`Kept`
keeps it as it is (no copy) and proves it by its identity and length. Any
other series is compared by its bytes. :class:`Ordered` keeps a series'
values in order for its median and percentiles (``np.median``'s and
``np.percentile``'s values, bit for bit).
"""

from __future__ import annotations

import bisect
import math
import threading
import weakref
from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["Grown", "Kept", "Ordered", "begins_with", "extended", "percentile_at", "rowwise"]


def begins_with(arrays: Sequence[np.ndarray], kept: Sequence[np.ndarray]) -> bool:
    """Whether each of ``arrays`` begins with its counterpart in ``kept``, bitwise.

    Each kept array must be no longer than its counterpart, of the same
    dtype and shape past the first axis, and its first rows' bytes (a NaN
    equal to a NaN of the same bits; 0.0 not equal to -0.0).

    Parameters
    ----------
    arrays : sequence of array
        The new series (time, positions, ...), first axis the rows.
    kept : sequence of array
        The series kept, in the same order.
    """
    return _begins(arrays, kept, [np.asarray(k).tobytes() for k in kept])


class Grown:
    """Rows appended and never changed: a series whose first rows are a proof of their
    own bytes.

    :meth:`rows` hands out read-only views of the rows so far (of a read-only
    buffer: they cannot be made writeable), on memory that only :meth:`append`
    writes, and only past them (it grows by doubling into new memory, the old
    left as it was). Two views of one :class:`Grown` therefore agree on the
    rows both hold: :class:`Kept` resumes from one without comparing them.
    One thread appends to a :class:`Grown` (a stream's passes keep theirs per
    thread).

    Parameters
    ----------
    rows : (N, ...) array
        The first rows (copied).
    extendable : bool
        Whether :func:`extended` may append to it in place (a series made row by row
        from others); False for one its owner alone appends to (the online
        recogniser's rows: another's append would put a row out of step with them).
    """

    def __init__(self, rows: np.ndarray, *, extendable: bool = True):
        rows = np.asarray(rows)
        self.n = 0
        self.extendable = extendable
        self._write, self._read = self._memory(max(64, 2 * len(rows)), rows.shape[1:],
                                               rows.dtype)
        self.append(rows)

    @staticmethod
    def _memory(size: int, shape: tuple, dtype) -> tuple[np.ndarray, np.ndarray]:
        """Two arrays on new memory: one to write rows with, and one on a read-only view
        of it that :meth:`rows` slices (their views cannot be made writeable)."""
        dtype = np.dtype(dtype)
        mem = bytearray(size * int(np.prod(shape, dtype=int)) * dtype.itemsize)
        return (np.frombuffer(mem, dtype).reshape(size, *shape),
                np.frombuffer(memoryview(mem).toreadonly(), dtype).reshape(size, *shape))

    def append(self, rows: np.ndarray) -> None:
        """Write ``rows`` (k, ...) after the rows so far (cast to this series' dtype)."""
        k, n, buf = len(rows), self.n, self._write
        if n + k > len(buf):
            write, read = self._memory(max(2 * len(buf), n + k), buf.shape[1:], buf.dtype)
            write[:n] = buf[:n]  # copied before any view of the new memory is handed out
            self._write, self._read = write, read
            buf = write
        buf[n:n + k] = rows
        self.n = n + k

    def empty(self, k: int) -> np.ndarray:
        """A new writeable (k, ...) array of this series' dtype and row shape."""
        return np.empty((k, *self._write.shape[1:]), self._write.dtype)

    def rows(self) -> np.ndarray:
        """The rows so far, a read-only view (plain ``ndarray``)."""
        view = self._read[:self.n]
        key = id(view)
        # known by its identity while it lives (a view of it, a slice, is another array:
        # compared by its bytes); forgotten with it, so that no other array takes its id
        _HANDED[key] = (weakref.ref(view, lambda ref: _forget(key, ref)), self)
        return view


#: The views :meth:`Grown.rows` handed out, by ``id``: (a weak reference, the Grown).
_HANDED: dict[int, tuple[weakref.ref, Grown]] = {}


def _forget(key: int, ref: weakref.ref) -> None:
    if _HANDED.get(key, (None,))[0] is ref:
        del _HANDED[key]


def grown_of(a) -> Grown | None:
    """The :class:`Grown` whose rows ``a`` is, as :meth:`Grown.rows` handed them out;
    None for any other array (a slice of them included)."""
    entry = _HANDED.get(id(a))
    return entry[1] if entry is not None and entry[0]() is a else None


def extended(first: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``np.concatenate([first, rows])``, bit for bit, as the rows of a :class:`Grown`:
    appended in place where ``first`` is every row of one (a stream's series, a row
    more), else a new one.

    Parameters
    ----------
    first : (N, ...) array
        The series so far.
    rows : (k, ...) array
        The rows after it, of ``first``'s dtype and row shape.
    """
    g = grown_of(first)
    rows = np.asarray(rows)
    if (g is None or not g.extendable or len(first) != g.n or rows.dtype != first.dtype
            or rows.shape[1:] != first.shape[1:]):
        g = Grown(np.concatenate([first, rows]))
    else:
        g.append(rows)
    return g.rows()


def rowwise(kept: Kept, key, source: np.ndarray, fn: Callable[[np.ndarray], np.ndarray]
            ) -> np.ndarray:
    """``fn(source)`` for a ``fn`` that maps each row alone, by element-wise operations
    that give a row the same bits in any array (``t - t0``, a column's copy): the result
    kept in ``kept`` under ``key`` for rows ``source`` begins with, extended with ``fn``
    of the rows after them, as the rows of a :class:`Grown` (read-only).

    Parameters
    ----------
    kept : Kept
        Where the results are kept.
    key : object
        What ``fn`` is (its parameters).
    source : (N, ...) array
        The rows.
    fn : callable
        Rows to their results, row for row.
    """
    found = kept.longest(key, (source,))
    if found is not None and len(found[0][0]) == len(source):
        return found[1]
    out = (extended(found[1], fn(source[len(found[0][0]):])) if found is not None
           else Grown(fn(source)).rows())
    kept.keep(key, (source,), out, found)
    return out


class Ordered:
    """The finite values of a series, kept in order as rows are added or replaced: its
    median and percentiles found again without partitioning every row (``np.median``'s
    and ``np.percentile``'s values, bit for bit: the same one or two values, combined by
    the same float operations).

    An :class:`Ordered` changed into another (:meth:`replaced`) hands its list on; the
    old one, asked again, orders its series afresh from the values it is given.

    Parameters
    ----------
    values : (N,) array
        The series so far (non-finite values are left out).
    """

    def __init__(self, values: np.ndarray):
        values = np.asarray(values, dtype=float)
        self._shared = [sorted(values[np.isfinite(values)].tolist()), 0]  # list, version
        self._version = 0

    def replaced(self, old: np.ndarray, new: np.ndarray,
                 whole: Callable[[], np.ndarray]) -> Ordered:
        """The series with the values ``old`` (among its own) taken out and ``new`` put in;
        ``whole()``: every value of the series then, ordered afresh where this one was
        changed already (by another series that began with it; called only then: making
        it is a pass over every row)."""
        if self._shared[1] != self._version:
            return Ordered(whole())
        values = self._shared[0]
        for v in np.asarray(old, dtype=float).tolist():
            if math.isfinite(v):
                del values[bisect.bisect_left(values, v)]
        for v in np.asarray(new, dtype=float).tolist():
            if math.isfinite(v):
                bisect.insort(values, v)
        self._shared[1] += 1
        out = object.__new__(Ordered)
        out._shared, out._version = self._shared, self._shared[1]
        return out

    def extended(self, new: np.ndarray, whole: Callable[[], np.ndarray]) -> Ordered:
        """:meth:`replaced` with nothing taken out: ``new`` values after the series."""
        return self.replaced((), new, whole)

    def _values(self) -> list:
        """The values in order; refused for an :class:`Ordered` that handed its list on (it
        would give the other series' values)."""
        if self._shared[1] != self._version:
            raise RuntimeError("an Ordered read after it was replaced (read the one "
                               "replaced() returned)")
        return self._shared[0]

    @property
    def n(self) -> int:
        """How many finite values."""
        return len(self._values())

    def median(self) -> float:
        """``float(np.median(values))`` of the finite values (NaN with none)."""
        v = self._values()
        n = len(v)
        if not n:
            return math.nan
        return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2

    def percentile(self, q: float) -> float:
        """``float(np.percentile(values, q))`` of the finite values (linear interpolation;
        NaN with none)."""
        v = self._values()
        return percentile_at(v.__getitem__, len(v), q)


def percentile_at(value: Callable[[int], float], n: int, q: float) -> float:
    """``float(np.percentile(x, q))`` (linear interpolation) of ``n`` values, ``value(k)``
    the k-th smallest: numpy's steps, bit for bit (NaN for none).

    Parameters
    ----------
    value : callable
        Rank (0-based) to value.
    n : int
        How many values.
    q : float
        The percentile, 0-100.
    """
    if not n:
        return math.nan
    # the virtual index (n - 1) q, the values either side of it (the last one from n - 1
    # on), and their lerp, taken from the far end where the weight is 0.5 or more
    virtual = (n - 1) * (q / 100)
    i = math.floor(virtual)
    if virtual >= n - 1:
        a = b = value(n - 1)
    else:
        a, b = value(i), value(i + 1)
    t = virtual - i
    diff = b - a
    return b - diff * (1 - t) if t >= 0.5 else a + diff * t


class Kept:
    """A pass's results kept in this thread, each with the key it was made under and
    the series it was made from, newest first, ``size`` at most.

    The series are kept as their bytes (a copy: the caller's arrays may change
    after), which the next call's series are compared with as they are: one
    copy of the new rows a test, not two. They are handed back as read-only
    arrays on those bytes. A series that is the first rows of a :class:`Grown`
    is kept as it is (its rows never change) and a new series of the same
    :class:`Grown`, as long or longer, begins with it: nothing is copied or
    compared.

    Parameters
    ----------
    size : int
        Most results kept.
    """

    def __init__(self, size: int):
        self.size = size
        self.local = threading.local()  # its ``entries``: (key, series, value, bytes)

    def longest(self, key, arrays: Sequence[np.ndarray], *, shorter: bool = False,
                first: Callable[[tuple], bool] | None = None) -> tuple[tuple, object] | None:
        """The ``(series, value)`` kept under ``key`` that ``arrays`` begin with, the
        longest; None if there is none.

        Parameters
        ----------
        key : object
            Compared with ``==``.
        arrays : sequence of array
            The new series.
        shorter : bool
            Only series shorter than ``arrays`` (something new to compute).
        first : callable, optional
            A cheap test of a kept series tried before :func:`begins_with`.
        """
        best = None
        for k, series, value, blobs in getattr(self.local, "entries", ()):
            n = len(series[0])
            if (k == key and (best is None or n > len(best[0][0]))
                    and (not shorter or n < len(arrays[0]))
                    and (first is None or first(series))
                    and _begins(arrays, series, blobs, self.size > 1)):
                best = (series, value)
        return best

    def keep(self, key, series: tuple, value, superseded: tuple | None = None) -> None:
        """Keep ``value`` made under ``key`` from ``series`` (copied here), in place of the
        ``superseded`` ``(series, value)`` it resumed."""
        # a Grown's rows as they are (None: no bytes), any other series' bytes copied
        blobs = tuple(None if grown_of(a) is not None else np.asarray(a).tobytes()
                      for a in series)
        views = tuple(a if b is None else
                      np.frombuffer(b, dtype=np.asarray(a).dtype).reshape(np.shape(a))
                      for a, b in zip(series, blobs))
        rest = [e for e in getattr(self.local, "entries", ())
                if superseded is None or e[1] is not superseded[0]]
        self.local.entries = [(key, views, value, blobs), *rest][:self.size]


def _begins(arrays: Sequence[np.ndarray], kept: Sequence[np.ndarray],
            blobs: Sequence[bytes], several: bool = False) -> bool:
    """:func:`begins_with`, the kept series' bytes at hand (None: a :class:`Grown`'s
    rows, kept as they are)."""
    for a, k in zip(arrays, kept, strict=True):  # shapes first: nothing compared
        if len(k) > len(a) or a.shape[1:] != k.shape[1:] or a.dtype != k.dtype:
            return False
    # a kept Grown's rows begin a longer series of the same Grown: proven, not compared
    todo = [(a, k, b) for a, k, b in zip(arrays, kept, blobs)
            if b is not None or grown_of(a) is not grown_of(k)]
    # where several series are kept (several markers' paths), each one's last row first:
    # another series differs there, told apart before the whole is copied
    if several and any(len(k) and k[-1:].tobytes() != a[len(k) - 1:len(k)].tobytes()
                       for a, k, _ in todo):
        return False
    # bit for bit: the bytes compared whole (memcmp), a few microseconds for a 60 s
    # stream's rows where np.array_equal(equal_nan=True) took tens, at every resumed
    # pass of every row; a NaN is its own bits, and -0.0 is not 0.0 (a pass may tell
    # them apart: resuming over one would not be the fresh pass)
    return all((k.tobytes() if b is None else b) == a[:len(k)].tobytes() for a, k, b in todo)

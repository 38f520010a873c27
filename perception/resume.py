"""A longer series that begins with one computed before: what the online path resumes from.

The online recogniser recognises the rows received so far after every row,
so each call's series is the last call's and a row more. The passes that
keep their last result per thread (the scene, the onset and end scans, the
spike test, the causal filter, the scores) resume only from a series the new
one begins with bit for bit: :func:`begins_with` is that one test, and
:class:`Kept` the one store each of them keeps its results in.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["Kept", "begins_with"]


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


class Kept:
    """A pass's results kept in this thread, each with the key it was made under and
    the series it was made from, newest first, ``size`` at most.

    The series are kept as their bytes (a copy: the caller's arrays may change
    after), which the next call's series are compared with as they are: one
    copy of the new rows a test, not two. They are handed back as read-only
    arrays on those bytes.

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
        blobs = tuple(np.asarray(a).tobytes() for a in series)
        views = tuple(np.frombuffer(b, dtype=np.asarray(a).dtype).reshape(np.shape(a))
                      for a, b in zip(series, blobs))
        rest = [e for e in getattr(self.local, "entries", ())
                if superseded is None or e[1] is not superseded[0]]
        self.local.entries = [(key, views, value, blobs), *rest][:self.size]


def _begins(arrays: Sequence[np.ndarray], kept: Sequence[np.ndarray],
            blobs: Sequence[bytes], several: bool = False) -> bool:
    """:func:`begins_with`, the kept series' bytes at hand."""
    for a, k in zip(arrays, kept, strict=True):  # shapes first: nothing compared
        if len(k) > len(a) or a.shape[1:] != k.shape[1:] or a.dtype != k.dtype:
            return False
    # where several series are kept (several markers' paths), each one's last row first:
    # another series differs there, told apart before the whole is copied
    if several and any(len(k) and k[-1:].tobytes() != a[len(k) - 1:len(k)].tobytes()
                       for a, k in zip(arrays, kept)):
        return False
    # bit for bit: the bytes compared whole (memcmp), a few microseconds for a 60 s
    # stream's rows where np.array_equal(equal_nan=True) took tens, at every resumed
    # pass of every row; a NaN is its own bits, and -0.0 is not 0.0 (a pass may tell
    # them apart: resuming over one would not be the fresh pass)
    return all(b == a[:len(k)].tobytes() for a, k, b in zip(arrays, kept, blobs))

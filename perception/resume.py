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
    shape past the first axis, and equal to its first rows, NaN equal to
    NaN.

    Parameters
    ----------
    arrays : sequence of array
        The new series (time, positions, ...), first axis the rows.
    kept : sequence of array
        The series kept, in the same order.
    """
    for a, k in zip(arrays, kept, strict=True):  # shapes first: nothing compared
        if len(k) > len(a) or a.shape[1:] != k.shape[1:]:
            return False
    return all(np.array_equal(k, a[:len(k)], equal_nan=True) for a, k in zip(arrays, kept))


class Kept:
    """A pass's results kept in this thread, each with the key it was made under and
    the series it was made from, newest first, ``size`` at most.

    Parameters
    ----------
    size : int
        Most results kept.
    """

    def __init__(self, size: int):
        self.size = size
        self.local = threading.local()  # its ``entries``: (key, series, value)

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
        for k, series, value in getattr(self.local, "entries", ()):
            n = len(series[0])
            if (k == key and (best is None or n > len(best[0][0]))
                    and (not shorter or n < len(arrays[0]))
                    and (first is None or first(series)) and begins_with(arrays, series)):
                best = (series, value)
        return best

    def keep(self, key, series: tuple, value, superseded: tuple | None = None) -> None:
        """Keep ``value`` made under ``key`` from ``series`` (copies of what may change),
        in place of the ``superseded`` ``(series, value)`` it resumed."""
        rest = [e for e in getattr(self.local, "entries", ())
                if superseded is None or e[1] is not superseded[0]]
        self.local.entries = [(key, series, value), *rest][:self.size]

"""A longer series that begins with one computed before: what the online path resumes from.

The online recogniser recognises the rows received so far after every row,
so each call's series is the last call's and a row more. The passes that
keep their last result per thread (the scene, the onset and end scans, the
spike test, the causal filter, the scores) resume only from a series the new
one begins with bit for bit: :func:`begins_with` is that one test.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["begins_with"]


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

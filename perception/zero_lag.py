"""The field's zero-lag low-pass and the derivative the landmarks read, bit for bit.

Labs filter motion capture with a Butterworth low-pass run forwards and
backwards (:func:`scipy.signal.filtfilt`) before they take its speed
(:func:`numpy.gradient`). A stream's landmarks take them after every row,
so here they are the same operations on the same numbers with what does not
change done once: the filter's design and its step response's steady state
per order and cutoff (:func:`design`), and the derivative of the rows asked
for alone (:func:`gradient_rows`). Tested against the library functions
bitwise (tests/test_landmarks_stream.py).
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["design", "filtfilt", "gradient_rows", "padlen"]


@functools.lru_cache(maxsize=64)
def design(order: int, wn: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Butterworth low-pass's coefficients and its step response's steady state
    (:func:`scipy.signal.lfilter_zi`): designed once per order and cutoff, not once per
    movement (a 2,000-trial table's 4,000 designs took 1.6 s; the steady state took
    30 us at each of a stream's rows, twice)."""
    from scipy.signal import butter, lfilter_zi  # noqa: PLC0415 (only when filtering)

    b, a = butter(order, wn)
    return b, a, lfilter_zi(b, a)


def padlen(b: np.ndarray, a: np.ndarray) -> int:
    """Rows :func:`scipy.signal.filtfilt` pads each end with by default (odd padding).

    Parameters
    ----------
    b, a : arrays
        The filter's numerator and denominator (:func:`design`).
    """
    return 3 * max(len(a), len(b))


def filtfilt(b: np.ndarray, a: np.ndarray, zi: np.ndarray, x: np.ndarray) -> np.ndarray:
    """:func:`scipy.signal.filtfilt` of ``x`` (N, K) along its rows, its default padding
    (odd, ``3 x max(len(a), len(b))`` rows), with ``zi`` its ``lfilter_zi(b, a)``: the same
    operations on the same numbers, without designing the steady state again at every call.
    """
    from scipy.signal import lfilter  # noqa: PLC0415 (only when filtering)

    edge = padlen(b, a)
    ext = np.concatenate((2 * x[0:1] - x[edge:0:-1], x,
                          2 * x[-1:] - x[-2:-(edge + 2):-1]), axis=0)
    zi = zi.reshape(-1, 1)
    y, _ = lfilter(b, a, ext, axis=0, zi=zi * ext[0:1])
    y, _ = lfilter(b, a, y[::-1], axis=0, zi=zi * y[-1:])
    return y[::-1][edge:-edge]


def gradient_rows(f: np.ndarray, x: np.ndarray, lo: int, hi: int) -> np.ndarray:
    """``np.gradient(f, x)[lo:hi]`` for (N,) ``f`` and ``x`` (N >= 2), bit for bit: its
    formulas (uniform steps where every step is the first, else the second-order
    non-uniform one; one-sided at the ends) on those rows alone, not every row of a
    stream's clip."""
    dx = np.diff(x)
    out = np.empty(hi - lo)
    a, b = max(lo, 1), min(hi, len(f) - 1)  # the interior rows asked for
    if b > a:
        if (dx == dx[0]).all():
            out[a - lo:b - lo] = (f[a + 1:b + 1] - f[a - 1:b - 1]) / (2. * dx[0])
        else:
            dx1, dx2 = dx[a - 1:b - 1], dx[a:b]
            ca = -(dx2) / (dx1 * (dx1 + dx2))
            cb = (dx2 - dx1) / (dx1 * dx2)
            cc = dx1 / (dx2 * (dx1 + dx2))
            out[a - lo:b - lo] = ca * f[a - 1:b - 1] + cb * f[a:b] + cc * f[a + 1:b + 1]
    if lo == 0 < hi:
        out[0] = (f[1] - f[0]) / dx[0]
    if lo < len(f) == hi:
        out[-1] = (f[-1] - f[-2]) / dx[-1]
    return out

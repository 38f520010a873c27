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
from typing import NamedTuple

import numpy as np

__all__ = ["Pass", "design", "filtfilt", "filtfilt_resumed", "gradient_rows", "padlen"]


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


def gradient_rows(f: np.ndarray, x: np.ndarray, lo: int, hi: int,
                  uniform: bool | None = None) -> np.ndarray:
    """``np.gradient(f, x, axis=0)[lo:hi]`` for (N,) or (N, K) ``f`` and (N,) ``x``
    (N >= 2), bit for bit: its formulas (uniform steps where every step is the first,
    else the second-order non-uniform one; one-sided at the ends) on those rows alone,
    and the steps they read, not every row of a stream's clip.

    Parameters
    ----------
    f : (N,) or (N, K) array
        Values.
    x : (N,) array
        Their coordinates.
    lo, hi : int
        The rows asked for.
    uniform : bool, optional
        Whether every step of ``x`` is its first (numpy's choice of formula), where the
        caller knows; default: found here.
    """
    n = len(f)
    if uniform is None:
        steps = np.diff(x)
        uniform = bool((steps == steps[0]).all())
    first = max(lo - 1, 0)  # the steps the rows read: x[first:last + 1]
    dx = np.diff(x[first:min(hi + 1, n)])
    if f.ndim == 2:  # coefficients per row, as numpy reshapes them along the axis
        dx = dx[:, None]
    out = np.empty((hi - lo, *f.shape[1:]))
    a, b = max(lo, 1), min(hi, n - 1)  # the interior rows asked for
    if b > a:
        if uniform:
            out[a - lo:b - lo] = (f[a + 1:b + 1] - f[a - 1:b - 1]) / (2. * (x[1] - x[0]))
        else:
            dx1, dx2 = dx[a - 1 - first:b - 1 - first], dx[a - first:b - first]
            ca = -(dx2) / (dx1 * (dx1 + dx2))
            cb = (dx2 - dx1) / (dx1 * dx2)
            cc = dx1 / (dx2 * (dx1 + dx2))
            out[a - lo:b - lo] = ca * f[a - 1:b - 1] + cb * f[a:b] + cc * f[a + 1:b + 1]
    if lo == 0 < hi:
        out[0] = (f[1] - f[0]) / (x[1] - x[0])
    if lo < n == hi:
        out[-1] = (f[-1] - f[-2]) / (x[-1] - x[-2])
    return out


#: Rows between the backward pass's states a resumed pass compares with the last pass's.
STRIDE = 32
#: How far before a run's end those states are kept, rows: a backward pass started a
#: row later meets the last one's, bit for bit, within 40-160 rows of the end at cutoffs
#: of 0.7-0.1 of Nyquist, 300 at 0.95 (the cap: 10 Hz at 15 frames/s); a run whose pass
#: has not met it by then is filtered whole.
DEPTH = 16 * STRIDE


class Pass(NamedTuple):
    """What :func:`filtfilt_resumed` needs to filter a run that begins with ``x``.

    Attributes
    ----------
    n : int
        Rows of the run filtered.
    forward : (P + N, K) array
        The forward pass's output over the start's padding and the run.
    state : array
        The forward filter's state after them (before the end's padding).
    back : dict
        The backward pass's state at rows ``m x STRIDE`` within ``DEPTH`` of the end,
        after filtering the rows from there to the end (and the end's padding).
    y : (N, K) array
        The filtered run.
    """

    n: int
    forward: np.ndarray
    state: np.ndarray
    back: dict
    y: np.ndarray


def filtfilt_resumed(b: np.ndarray, a: np.ndarray, zi: np.ndarray, x: np.ndarray,
                     last: Pass | None = None) -> Pass:
    """:func:`filtfilt` of ``x`` (N, K), bit for bit, resumed from ``last`` (a :class:`Pass`
    of a run ``x`` begins with: the caller has checked its rows), and what resumes it.

    The forward pass is causal: it goes on from the last one's state over the new rows.
    The backward pass starts at the new end and goes back a stretch of ``STRIDE`` rows at
    a time; where its state equals the last pass's at the same row, bit for bit, every
    row before is filtered as the last pass filtered it (the same operations on the same
    numbers from the same state), and its output is taken. :func:`scipy.signal.lfilter`
    goes on from a state bit for bit as in one call (tests/test_landmarks_stream.py).

    Parameters
    ----------
    b, a, zi : arrays
        The filter (:func:`design`).
    x : (N, K) array
        The run, N > :func:`padlen`.
    last : Pass, optional
        The pass of a run that ``x`` begins with.
    """
    from scipy.signal import lfilter  # noqa: PLC0415 (only when filtering)

    edge, n = padlen(b, a), len(x)
    end = 2 * x[-1:] - x[-2:-(edge + 2):-1]
    if last is None:
        start = 2 * x[0:1] - x[edge:0:-1]
        head = np.concatenate((start, x), axis=0)
        forward, state = lfilter(b, a, head, axis=0, zi=zi.reshape(-1, 1) * head[0:1])
        back_last, y_last = {}, None
    else:
        m = last.n
        new, state = lfilter(b, a, x[m:], axis=0, zi=last.state)
        forward = np.concatenate((last.forward, new), axis=0)
        back_last, y_last = last.back, last.y
    tail, _ = lfilter(b, a, end, axis=0, zi=state)
    # backwards: the end's padding, then the run's rows from its end, a stretch at a time
    fx = forward[edge:]
    z = zi.reshape(-1, 1) * tail[-1:]
    _, z = lfilter(b, a, tail[::-1], axis=0, zi=z)
    y = np.empty_like(x)
    back = {}
    hi = n
    while hi > 0:
        lo = (hi - 1) // STRIDE * STRIDE if hi > n - DEPTH else 0
        part, z = lfilter(b, a, fx[lo:hi][::-1], axis=0, zi=z)
        y[lo:hi] = part[::-1]
        hi = lo
        if lo and lo > n - DEPTH:
            back[lo] = z
            same = back_last.get(lo)
            if same is not None and same.tobytes() == z.tobytes():
                y[:lo] = y_last[:lo]  # from here back, the last pass's rows
                back.update((r, s) for r, s in back_last.items() if r < lo and r > n - DEPTH)
                break
    return Pass(n, forward, state, back, y)

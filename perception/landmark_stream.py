"""What the landmarks of a stream's rows so far resume from the last row's, bit for bit.

The online recogniser measures the landmarks of the rows received so far
after every row (:func:`perception.landmarks.observed_landmarks`). Three of
their passes read every row: the median time step, the zero-lag low-pass of
the run of seen samples still open (its backward pass starts from the last
row, so any value may change with a row more), and the speed with its 10th
percentile, the noise floor. Each is resumed here from the last series this
thread measured that the new one begins with, its result the fresh pass's bit
for bit (tests/test_landmarks_stream.py):

* the time step's median from the steps kept in order
  (:class:`~perception.resume.Ordered`), the new steps put in place;
* the open run's low-pass by :func:`perception.zero_lag.filtfilt_resumed`:
  the forward pass goes on from its state, the backward pass runs back from
  the new end until its state is the last pass's at the same row;
* the speed of the rows whose low-passed positions changed (and a row
  either side, which the derivative reads), and the floor from the speeds
  of the rows before them, kept in order, and the new ones.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

from perception import zero_lag
from perception.resume import Kept, Ordered, percentile_at
from perception.rowwise import row_norm

__all__ = ["filtfilt_run", "median_step", "speed_and_floor"]

#: Time series whose steps were ordered in this thread (:func:`median_step`).
_STEPS = Kept(2)
#: Open runs low-passed in this thread, with the passes that resume them.
_OPEN = Kept(4)
#: Low-passed paths whose speed was taken in this thread, with their speeds in order.
_SPEEDS = Kept(2)


def median_step(time: np.ndarray) -> float:
    """``float(np.median(np.diff(time)))``, NaN with fewer than two samples.

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    """
    time = np.asarray(time, dtype=float)
    if len(time) < 2:
        return math.nan
    kept = _STEPS.longest(None, (time,))
    m = 0 if kept is None else len(kept[0][0])
    if not np.isfinite(time[m:]).all():  # NaN steps: numpy's median is NaN
        return float(np.median(np.diff(time)))
    if kept is None:
        order = Ordered(np.diff(time))
    elif m == len(time):
        return kept[1].median()
    else:
        order = kept[1].extended(np.diff(time[m - 1:]), lambda: np.diff(time))
    _STEPS.keep(None, (time,), order, kept)
    return order.median()


def filtfilt_run(b: np.ndarray, a: np.ndarray, zi: np.ndarray, x: np.ndarray,
                 key) -> np.ndarray:
    """:func:`perception.zero_lag.filtfilt` of a run ``x`` (N, K) that lasts to the end of
    its series, resumed from the run it begins with filtered last in this thread under
    ``key`` (the filter's order and cutoff).

    Parameters
    ----------
    b, a, zi : arrays
        The filter (:func:`perception.zero_lag.design`).
    x : (N, K) array
        The run (kept as its bytes: the caller may write its output over it).
    key : object
        The filter's identity.
    """
    kept = _OPEN.longest(key, (x,))
    if kept is not None and len(kept[0][0]) == len(x):
        return kept[1].y
    done = zero_lag.filtfilt_resumed(b, a, zi, x, None if kept is None else kept[1])
    done.y.flags.writeable = False  # kept, and read by the next pass: never written to
    _OPEN.keep(key, (x,), done, kept)
    return done.y


def speed_and_floor(time: np.ndarray, p: np.ndarray, q: float) -> tuple[np.ndarray, float]:
    """``row_norm(np.gradient(p, time, axis=0))`` and the ``q``-th percentile of its finite
    values (0 with none), bit for bit; resumed from the path measured last in this
    thread on times ``time`` begins with: only the rows from the first whose position
    changed (less one: the derivative reads a row either side) are measured again, and
    the percentile is read from the rows before them, kept in order, and those rows.

    Parameters
    ----------
    time : (N,) array
        Sample times, s, N >= 3.
    p : (N, D) array
        Low-passed positions, m (NaN where lost; kept as they are: not changed after).
    q : float
        The percentile, 0-100.
    """
    time = np.asarray(time, dtype=float)
    kept = _SPEEDS.longest(None, (time,))
    r0 = 0
    if kept is not None:  # np.gradient's choice of formula: every step the first one's
        p0, speed0, settled0, uniform0 = kept[1]
        m = len(p0)
        uniform = uniform0 and bool((np.diff(time[m - 1:]) == time[1] - time[0]).all())
        if uniform == uniform0 and p.shape[1:] == p0.shape[1:]:
            # the first row whose bits differ from the kept path's (NaN alike: its bits)
            same = p[:m].view(np.int64) == p0.view(np.int64)
            if same.ndim == 2:  # a column at a time (rowwise: a row's reduction is slow)
                same = np.logical_and.reduce(same.T)
            changed = np.flatnonzero(~same)
            r0 = max(0, (int(changed[0]) if len(changed) else m) - 1)
    else:
        steps = np.diff(time)
        uniform = bool((steps == steps[0]).all())
    new = row_norm(zero_lag.gradient_rows(p, time, r0, len(time), uniform))
    speed = np.concatenate([speed0[:r0], new]) if r0 else new
    # the rows before r0 stand: their speeds in order, the ones that stood since the
    # last row put in (a new array: a kept one is never changed)
    if r0 and len(settled0[0]) <= r0:
        done, order = settled0
        more = speed[len(done):r0]
        more = np.sort(more[np.isfinite(more)])
        settled = (speed[:r0], np.insert(order, np.searchsorted(order, more), more))
    else:
        head = speed[:r0]
        settled = (head, np.sort(head[np.isfinite(head)]))
    speed.flags.writeable = False  # kept, and the next pass's first rows
    _SPEEDS.keep(None, (time,), (p, speed, settled, uniform), kept)
    tail = np.sort(new[np.isfinite(new)])
    return speed, _percentile(settled[1], tail, q)


def _percentile(a: np.ndarray, b: np.ndarray, q: float) -> float:
    """The ``q``-th percentile of the values of two sorted arrays together (0 for none),
    ``np.percentile``'s (:func:`~perception.resume.percentile_at`): the k-th smallest
    read from where ``b``'s values fall among ``a``'s, not a sort of both."""
    # b[j] is at pos[j] of the values in order (after a's equal ones); the rank k is b's
    # value where a pos is k, else a's value after the b's before it
    pos = np.searchsorted(a, b, side="right") + np.arange(len(b))
    pos_list = pos.tolist()

    def value(k: int) -> float:
        j = bisect.bisect_left(pos_list, k)
        return float(b[j]) if j < len(b) and pos_list[j] == k else float(a[k - j])

    floor = percentile_at(value, len(a) + len(b), q)
    return 0.0 if math.isnan(floor) else floor

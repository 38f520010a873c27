"""Movements of a recording's transport point, and which of them are reaches to grasp.

:func:`find_movements` bounds every movement by the field's rule around its
own speed peak and parts movements that run into each other (or turn into
the object's transport or a lift); :func:`classify_movements` tells from
the transport which are reaches; :func:`find_reaches` is the two. The rules
are docs/reaches.md's; :mod:`perception.reaches` applies them to a trial.
"""

from __future__ import annotations

import bisect
import dataclasses
import math

import numpy as np

from perception.landmarks import LandmarkParams, movement_bounds
from perception.reach_data import (
    _STILL_RANGE,
    _STILL_WINDOW,
    Movement,
    ReachParams,
)

__all__ = ["classify_movements", "find_movements", "find_reaches", "movements_of"]


def _field_bound(lp: LandmarkParams) -> str:
    return (f"{lp.speed:g} m/s" if lp.speed is not None
            else f"{lp.threshold * 100:g} % of peak speed")


def _still_speed(time: np.ndarray, path: np.ndarray, speed: np.ndarray) -> float:
    """The speed of the hand while it is still (its low-passed position within
    :data:`_STILL_RANGE` over :data:`_STILL_WINDOW`), m/s: the recording's noise floor.

    Measured on still stretches only, so that a session of back-to-back
    movements (the hand seldom at rest) does not take its slowest motion for
    noise. 0 where the hand is never still.
    """
    from scipy.ndimage import maximum_filter1d, minimum_filter1d  # noqa: PLC0415

    dt = float(np.median(np.diff(time)))
    n = max(3, int(round(_STILL_WINDOW / dt)) | 1)
    ok = np.isfinite(path).all(axis=1) & np.isfinite(speed)
    if ok.sum() < n:
        return 0.0
    p = np.where(ok[:, None], path, np.nanmean(path[ok], axis=0))
    spread = np.linalg.norm(maximum_filter1d(p, n, axis=0) - minimum_filter1d(p, n, axis=0),
                            axis=1)
    # a window touching a lost sample is not known to be still
    whole = minimum_filter1d(ok.astype(np.int8), n).astype(bool)
    still = whole & (spread < _STILL_RANGE)
    # the 10th percentile, as the landmarks' own floor (LandmarkParams.noise_factor) takes it
    return float(np.percentile(speed[still], 10)) if still.sum() >= n else 0.0


class _Seen:
    """A path and the rows where it is seen: the nearest seen row in O(log N)."""

    def __init__(self, path: np.ndarray):
        self.path = path
        self.ok = np.flatnonzero(np.isfinite(path).all(axis=1))

    def row(self, row: int | None, forward: bool) -> int | None:
        """``row``, or the nearest seen row in that direction (the first or last seen
        for None; None if there is none)."""
        ok = self.ok
        if not len(ok):
            return None
        if row is None:
            return int(ok[0] if forward else ok[-1])
        k = np.searchsorted(ok, row, side="left" if forward else "right")
        if forward:
            return int(ok[k]) if k < len(ok) else None
        return int(ok[k - 1]) if k > 0 else None

    def at(self, row: int | None, forward: bool) -> np.ndarray:
        return self.path[self.row(row, forward)]

    def displacement(self, a: int | None, b: int | None) -> np.ndarray | None:
        """From the first seen row at or after ``a`` to the last at or before ``b``."""
        ra, rb = self.row(a, True), self.row(b, False)
        if ra is None or rb is None or rb <= ra:
            return None
        return self.path[rb] - self.path[ra]


def _bounds(time: np.ndarray, speed: np.ndarray, peak: int,
            params: LandmarkParams) -> tuple[int | None, int | None]:
    """:func:`movement_bounds` looked for near the peak first, in a window that doubles
    until both bounds are in it (a session of a million rows has thousands of movements)."""
    n = len(time)
    half = 256
    while True:
        lo, hi = max(0, peak - half), min(n, peak + half + 1)
        onset, end = movement_bounds(time[lo:hi], speed[lo:hi], peak - lo, params)
        if (onset is not None or lo == 0) and (end is not None or hi == n):
            return (None if onset is None else onset + lo), (None if end is None else end + lo)
        half *= 4


def find_movements(time: np.ndarray, transport: np.ndarray, params: ReachParams | None = None,
                   aperture: np.ndarray | None = None, *,
                   speed: np.ndarray | None = None) -> list[Movement]:
    """Every movement of the transport point, in time order (not yet told apart).

    Each local peak of the (low-passed) speed of at least ``min_speed`` is
    bounded by the field's rule around its own peak, from the fastest down
    (peaks inside a movement already found are part of it); where that
    bound runs into a movement already found, the two part at the speed
    minimum between them. Then a movement that turns by ``turn`` or more at
    a speed minimum, with ``min_travel`` on each side, is cut there if the
    grip is closing from its widest there (or it barely changes: a
    whole-hand grasp) or the turn is a reversal (135 degrees or more); and
    movements that travel less than ``min_travel`` are left out.

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    transport : (N, 3) array
        The transport point, m (NaN where lost).
    params : ReachParams, optional
    aperture : (N,) array, optional
        Thumb-index distance, m (NaN where lost); without it a turn alone parts
        two movements.
    speed : (N,) array, optional
        ``params.landmarks.speed_of(time, transport)``, where the caller has it
        (:func:`classify_movements` reads it too).
    """
    from scipy.signal import find_peaks  # noqa: PLC0415 (as the landmarks take it)

    params = ReachParams() if params is None else params
    lp = params.landmarks
    time = np.asarray(time, dtype=float)
    transport = np.asarray(transport, dtype=float)
    n = len(time)
    if n < 3:
        return []
    speed = lp.speed_of(time, transport) if speed is None else speed
    if not np.isfinite(speed).any():
        return []
    # a lost stretch is neither a stop nor a peak: the speed across it is interpolated
    seen = np.flatnonzero(np.isfinite(speed))
    s = np.interp(np.arange(n), seen, speed[seen])
    floor = _still_speed(time, lp.lowpass(time, transport), speed)
    field_rule = _field_bound(lp)
    peaks = find_peaks(np.r_[0.0, s, 0.0], height=params.min_speed)[0] - 1
    # the movements found so far, as sorted first and last rows (bisect: no O(N) per peak)
    firsts: list[int] = []
    lasts: list[int] = []
    spans: list[list] = []
    for p in sorted(peaks.tolist(), key=lambda i: -s[i]):
        k = bisect.bisect_right(firsts, p)
        if k and lasts[k - 1] >= p:
            continue  # inside a movement already found
        bound = lp.speed if lp.speed is not None else max(lp.threshold * s[p],
                                                          lp.noise_factor * floor)
        onset, end = _bounds(time, speed, p, dataclasses.replace(lp, speed=float(bound)))
        on_rule = end_rule = field_rule
        if lp.speed is None and bound > lp.threshold * s[p] * (1 + 1e-9):
            on_rule = end_rule = (f"twice the still hand's speed ({bound / s[p]:.0%} of peak; "
                                  f"{field_rule} is below its noise)")
        if k and (onset is None or onset <= lasts[k - 1]):
            v = lasts[k - 1] + 1 + int(np.argmin(s[lasts[k - 1] + 1:p + 1]))
            onset, on_rule = v, _valley_rule(s, v, p)
        if k < len(firsts) and (end is None or end >= firsts[k]):
            v = p + int(np.argmin(s[p:firsts[k]]))
            end, end_rule = v, _valley_rule(s, v, p)
        firsts.insert(k, 0 if onset is None else onset)
        lasts.insert(k, n - 1 if end is None else end)
        spans.insert(k, [onset, p, end, on_rule, end_rule])
    seen = _Seen(transport)
    out = []
    for onset, p, end, on_rule, end_rule in spans:
        for m in _split(s, seen, aperture, Movement(onset, p, end, on_rule, end_rule), params):
            d = seen.displacement(m.onset, m.end)
            if d is not None and np.linalg.norm(d) >= params.min_travel:
                out.append(m)
    return out


def _valley_rule(s: np.ndarray, row: int, peak: int) -> str:
    return f"the speed minimum between two movements ({s[row] / s[peak]:.0%} of peak)"


def _split(s: np.ndarray, path: _Seen, aperture: np.ndarray | None, m: Movement,
           params: ReachParams) -> list[Movement]:
    """``m`` cut at each speed minimum where its path turns (see :func:`find_movements`)."""
    from scipy.signal import find_peaks  # noqa: PLC0415

    lo = 0 if m.onset is None else m.onset
    hi = len(s) - 1 if m.end is None else m.end
    dips = lo + find_peaks(-s[lo:hi + 1], prominence=0.05 * s[m.peak])[0]
    parts = [m]
    for v in sorted(dips, key=lambda r: s[r]):
        k = next(i for i, q in enumerate(parts)
                 if (q.onset is None or q.onset < v) and (q.end is None or v < q.end))
        q = parts[k]
        left, right = path.displacement(q.onset, v), path.displacement(v, q.end)
        if left is None or right is None:
            continue
        a, b = np.linalg.norm(left), np.linalg.norm(right)
        if min(a, b) < params.min_travel:
            continue
        angle = math.degrees(math.acos(float(np.clip(left @ right / (a * b), -1, 1))))
        q_lo = 0 if q.onset is None else q.onset
        q_hi = len(s) - 1 if q.end is None else q.end
        if angle < params.turn or (angle < 135
                                   and not _closed(aperture, q_lo, v, q_hi, params)):
            continue
        q_hi = len(s) - 1 if q.end is None else q.end
        p1 = q_lo + int(np.argmax(s[q_lo:v + 1]))
        p2 = v + int(np.argmax(s[v:q_hi + 1]))
        parts[k:k + 1] = [Movement(q.onset, p1, v, q.onset_bound, _valley_rule(s, v, p1)),
                          Movement(v, p2, q.end, _valley_rule(s, v, p2), q.end_bound)]
    return parts


def _closed(aperture: np.ndarray | None, lo: int, row: int, hi: int,
            params: ReachParams) -> bool:
    """Whether a grasp may be at ``row`` of the movement ``lo``-``hi``: the grip has opened
    by ``min_opening`` and its widest (of the whole movement) is behind it, the grip
    closing (by a tenth of its opening, 2 mm at least); or the grip says nothing (it
    changes by less than ``min_opening`` in the whole movement, or is unseen there). A grip
    still to open wider is still to grasp; one that only closes is letting go."""
    if aperture is None:
        return True
    g = aperture[lo:hi + 1]
    seen = np.flatnonzero(np.isfinite(g))
    k = row - lo
    if len(seen) < 3 or not np.isfinite(g[k]):
        return True
    if float(np.ptp(g[seen])) < params.min_opening:
        return True
    rest = float(np.median(g[seen[:3]]))
    j = int(seen[np.argmax(g[seen])])
    opening = float(g[j]) - rest
    return (opening >= params.min_opening and j < k
            and g[k] <= g[j] - max(0.1 * opening, 0.002))


def _opens(aperture: np.ndarray | None, m: Movement, params: ReachParams) -> bool:
    """Whether the grip opens by ``min_opening`` during movement ``m``."""
    if aperture is None or m.onset is None:
        return False
    g = aperture[m.onset:(len(aperture) if m.end is None else m.end + 1)]
    seen = g[np.isfinite(g)]
    return len(seen) >= 3 and float(seen.max() - seen[0]) >= params.min_opening


def _object_first_motion(obj: _Seen, ospeed: np.ndarray, hand_speed: np.ndarray,
                         m: Movement, params: ReachParams):
    """The row where the object starts to move during movement ``m`` after its peak, and
    where it stood before (None, None if it is not seen)."""
    path = obj.path
    on = obj.row(m.onset, True)
    if on is None:
        return None, None
    start = path[on]
    if m.onset is not None:
        before = path[max(0, m.onset - 5):m.onset + 1]
        before = before[np.isfinite(before).all(axis=1)]
        if len(before):
            start = np.median(before, axis=0)
    hi = len(path) - 1 if m.end is None else m.end
    away = np.linalg.norm(path[m.peak:hi + 1] - start, axis=1)
    moved = np.flatnonzero(away >= params.object_moved)
    if not len(moved):
        return None, start
    r = m.peak + int(moved[0])
    # back to where it began to move: the last row before, slower than the hand's bound
    lp = params.landmarks
    bound = lp.threshold * hand_speed[m.peak] if lp.speed is None else lp.speed
    slow = m.peak + np.flatnonzero(ospeed[m.peak:r + 1] < bound)
    return (int(slow[-1]) if len(slow) else m.peak), start


def classify_movements(time: np.ndarray, transport: np.ndarray, movements: list[Movement],
                       params: ReachParams | None = None,
                       object_path: np.ndarray | None = None,
                       aperture: np.ndarray | None = None, *,
                       speed: np.ndarray | None = None) -> list[Movement]:
    """Each movement told apart: a reach to grasp, what follows one, or another movement.

    Reach-ness is read from the transport, never from the grip. With an
    object (``object_path``, or ``params.object_position``), a reach ends
    ``params.approach`` of its starting distance nearer the object, and it ends
    where the object first moves if that comes before the hand stops (the
    rest of the movement is the object's transport). Without one, a reach
    goes away from where the hand rested; the movements after it are not
    reaches (a transport, a lift, the return) until one ends back within
    ``params.returned`` of the reach's length from where it began, unless one
    takes the hand on, at least ``min_travel`` farther from its rest, with
    a grip that opens by ``min_opening``: that one is the reach, and the
    movement before it was a preliminary one.

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    transport : (N, 3) array
        The transport point, m.
    movements : list of Movement
        From :func:`find_movements`.
    params : ReachParams, optional
    object_path : (N, 3) array, optional
        The object's centre, m.
    aperture : (N,) array, optional
        Thumb-index distance, m (NaN where lost).
    speed : (N,) array, optional
        As :func:`find_movements`'.

    Returns
    -------
    list of Movement
        The same movements, with ``kind`` and ``reason`` set (a reach's end
        moved to the object's first motion where that comes first).
    """
    params = ReachParams() if params is None else params
    time = np.asarray(time, dtype=float)
    if params.object_position is not None:
        object_path = np.broadcast_to(np.asarray(params.object_position, dtype=float),
                                      transport.shape)
    if object_path is not None and not np.isfinite(object_path).all(axis=1).any():
        object_path = None
    lp = params.landmarks
    speed = np.nan_to_num(lp.speed_of(time, transport) if speed is None else speed, nan=0.0)
    hand = _Seen(transport)
    if object_path is not None:
        obj = _Seen(object_path)
        ospeed = np.nan_to_num(lp.speed_of(time, object_path), nan=0.0)
    out = []
    home = None
    reached = False  # a reach is found (what follows it is not one unless it approaches)
    holding = None  # (index, start, end) of the last reach while the hand has not come back
    movements = list(movements)
    for i, m in enumerate(movements):
        if i and out[-1].end is not None and m.onset is not None and m.onset < out[-1].end:
            m = dataclasses.replace(m, onset=out[-1].end, onset_bound=out[-1].end_bound)
        a = hand.row(m.onset, True)
        start, stop = transport[a], hand.at(m.end, False)
        if object_path is not None:
            # a hand that does not stop at the object flows into its transport: look for
            # the object's first motion up to the next movement's peak too
            nxt = movements[i + 1] if i + 1 < len(movements) else None
            flows = nxt is not None and m.end is not None and nxt.onset == m.end
            moves, at = _object_first_motion(
                obj, ospeed, speed, dataclasses.replace(m, end=nxt.peak) if flows else m,
                params)
            if at is None:
                out.append(dataclasses.replace(m, kind="other",
                                               reason="the object is not seen"))
                continue
            if moves is not None and moves > a and (m.end is None or moves < m.end or flows):
                m = dataclasses.replace(m, end=moves, end_bound="the object's first motion")
                stop = hand.at(moves, False)
            d0, d1 = np.linalg.norm(start - at), np.linalg.norm(stop - at)
            if d0 - d1 >= params.approach * d0:
                reached = True
                out.append(dataclasses.replace(m, kind="reach"))
            elif reached:
                out.append(dataclasses.replace(m, kind="after", reason=(
                    "carries the object" if moves is not None and moves <= a + 1
                    else "moves away from the object" if d1 > d0
                    else "does not come near the object")))
            else:
                out.append(dataclasses.replace(m, kind="other", reason=(
                    "moves away from the object" if d1 > d0 else
                    f"does not come near the object (from {d0 * 1000:.0f} to "
                    f"{d1 * 1000:.0f} mm of it)")))
            continue
        home = start if home is None else home
        if holding is not None:
            k, begin, there = holding
            back = np.linalg.norm(stop - begin) <= params.returned * np.linalg.norm(there - begin)
            on = (np.linalg.norm(stop - home) >= np.linalg.norm(there - home)
                  + params.min_travel and _opens(aperture, m, params))
            if back:
                holding, home = None, stop
            elif on:  # the "reach" before was a preliminary movement: this is the reach
                out[k] = dataclasses.replace(out[k], kind="other", reason=(
                    "a preliminary movement (the hand went on to reach from there)"))
                holding = (len(out), begin, stop)  # its return goes back to the same rest
                out.append(dataclasses.replace(m, kind="reach"))
                continue
            out.append(dataclasses.replace(m, kind="after", reason=(
                "a return" if back else "holds the object (a transport, a lift)")))
            continue
        away = np.linalg.norm(stop - home) - np.linalg.norm(start - home)
        if away >= 0.5 * np.linalg.norm(stop - start):
            holding = (len(out), start, stop)
            out.append(dataclasses.replace(m, kind="reach"))
        else:
            out.append(dataclasses.replace(m, kind="other",
                                           reason="moves back toward where the hand rested"))
    return out


def movements_of(time: np.ndarray, transport: np.ndarray, params: ReachParams,
                 aperture: np.ndarray | None = None,
                 object_path: np.ndarray | None = None) -> list[Movement]:
    """:func:`find_movements` then :func:`classify_movements`, the transport's speed
    computed once for both (its low-pass filter was a tenth of reading a trial).

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    transport : (N, 3) array
        The transport point, m (NaN where lost).
    params : ReachParams
    aperture : (N,) array, optional
        Thumb-index distance, m (NaN where lost).
    object_path : (N, 3) array, optional
        The object's centre, m.
    """
    time = np.asarray(time, dtype=float)
    transport = np.asarray(transport, dtype=float)
    speed = params.landmarks.speed_of(time, transport) if len(time) >= 3 else None
    return classify_movements(time, transport,
                              find_movements(time, transport, params, aperture, speed=speed),
                              params, object_path, aperture, speed=speed)


def find_reaches(time: np.ndarray, transport: np.ndarray, aperture: np.ndarray | None = None,
                 params: ReachParams | None = None,
                 object_path: np.ndarray | None = None) -> list[tuple[int, int]]:
    """(onset, end) rows of every complete reach to grasp in a recording.

    :func:`find_movements` then :func:`classify_movements`; a reach the
    recording starts or ends in is left out (:func:`trial_reaches` says so).

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    transport : (N, 3) array
        The transport point, m (NaN where lost).
    aperture : (N,) array, optional
        Thumb-index distance, m: where the transport alone cannot tell a reach
        (see :func:`classify_movements`).
    params : ReachParams, optional
    object_path : (N, 3) array, optional
        The object's centre: a reach ends nearer it than it starts.
    """
    params = ReachParams() if params is None else params
    moves = movements_of(time, transport, params, aperture, object_path)
    return [(m.onset, m.end) for m in moves
            if m.kind == "reach" and m.onset is not None and m.end is not None]



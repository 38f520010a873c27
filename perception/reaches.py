"""Reaches in a 3D recording, each brought into the movement's own plane as tracks.

A motion-capture trial holds more than the reach: rest, the reach to the
object, the grasp, often the object's transport, a lift or a drink, the
return, and in a long session many of each. :func:`trial_reaches` finds
every reach to grasp in one and says of every trial that gives none, and of
every reach it cannot score, why (:class:`Unscored`). docs/reaches.md
describes the rules; in short:

* **movements** (:func:`find_movements`): every local peak of the transport
  point's speed (the wrist markers' mean where a wrist is mapped, else the
  grip midpoint) of at least :attr:`ReachParams.min_speed`, bounded by the
  field's rule around its own peak (:func:`perception.landmarks.movement_bounds`,
  5 % of that peak: no movement's bound depends on a faster one elsewhere).
  Where two movements follow each other without the speed falling to the
  bound, they part at the speed minimum between them; a movement whose path
  turns by :attr:`ReachParams.turn` or more at a speed minimum, with
  :attr:`ReachParams.min_travel` on each side (a reach then the object's
  transport or a lift; a withdrawal then the next reach), is two. Each
  bound says which rule set it (:attr:`Reach.bound`).
* **reaches** (:func:`classify_movements`): from the transport alone, not
  from the grip (a whole-hand grasp barely opens it, a late or slight
  opening is still a grasp). With object markers, a movement that ends
  :data:`APPROACH` of its distance nearer the object is a reach, and it ends
  where the object first moves if that comes before the hand stops.
  Without them, a movement away from where the hand rested is a reach;
  what follows it (transport, lift, drink, release) is not, until the hand
  has come back toward where the reach began.

:func:`reach_tracks` turns one reach into the tracks the recognition reads:

* **the plane**: the transport path from onset to end is fitted by its two
  principal directions (SVD); the model's +y is the start-to-end direction
  within the plane and +x the one across it. How far the path leaves the
  plane (RMS and largest, m) goes into the report.
* **the grip**: the aperture is the 3D thumb-index distance; the digits are
  placed across the approach at that aperture, the finger on the model's +x
  side (a projection would hide a grip that lies out of the plane, as it
  does when a lab's participants grasp along the line of sight).
* **the wrist**: a point :data:`WRIST_BEHIND` behind the grip midpoint
  along the approach, the models' own hand (a lab's wrist or hand markers
  carry the transport landmarks, in 3D, not the models' tracks).
* **the object**: the mean of its markers, a given position, or else where
  the grip midpoint comes to rest at the reach's end (where the hand closes
  on it); its size as given, or else the aperture there less the aperture
  at rest (what the recognition's grip aperture reads at contact).
* **rest**: a reach with less than :data:`MIN_REST` of stillness before its
  onset (a trial that starts late in its rest, or in motion) is given that
  much rest by holding its first clean sample, with a note; a reach that
  ends where the hand goes on (the object's first motion, the speed minimum
  before a transport or a lift) ends there, its last sample held as long.

Positions are written as "pixels" of one millimetre (:data:`PX_PER_M`),
y down, so every later stage reads them as it reads a clip's.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
from dataclasses import dataclass, field
from typing import Annotated, NamedTuple

import numpy as np
from pydantic import AfterValidator, BeforeValidator, Field

from perception.cleaning import CleaningParams, clean_path
from perception.errors import InputError
from perception.io.tracks import Status, Tracks
from perception.landmarks import LandmarkParams, movement_bounds
from perception.validation import NonNegative, Positive, Tuple, declared

__all__ = ["APPROACH", "MIN_REST", "MIN_SAMPLES", "PX_PER_M", "RETURNED", "WRIST_BEHIND",
           "MarkerMap", "Movement", "PlaneFit", "Reach", "ReachParams", "ReachTracks",
           "Unscored", "classify_movements", "find_movements", "find_reaches", "fit_plane",
           "reach_tracks", "recording_reaches", "trial_reaches"]

#: The scale of the tracks a reach becomes: one "pixel" per millimetre.
PX_PER_M = 1000.0
#: Where a reach without a wrist marker gets one: this far behind the grip midpoint, m.
WRIST_BEHIND = 0.06
#: Least stillness before a reach's onset the recognition needs, s.
MIN_REST = 0.3
#: With object markers, a movement is a reach when the hand ends at least this share
#: of its starting distance nearer the object (a marker set on the back of the hand
#: stops well short of the object's centre).
APPROACH = 0.4
#: Without object markers, the hand is back from a reach (the next outward movement may
#: be a reach again) when a movement ends within this share of the reach's length of
#: where the reach began.
RETURNED = 0.5
#: Fewest samples a trial needs to be searched for reaches (the low-pass filter's own
#: need is 3 x its order + 1 per seen stretch), and a reach to be scored.
MIN_SAMPLES = 10
#: A hand is still while its low-passed position stays within this, m, over
#: :data:`_STILL_WINDOW`: its speed then is the recording's noise floor.
_STILL_RANGE = 0.002
_STILL_WINDOW = 0.2
_ORIGIN_PX = np.array([2000.0, 2000.0])


def _marker_name(name: str) -> str:
    if not name.strip():
        raise ValueError("a marker's name, not an empty one")
    return name


def _names(value):
    # one name is a tuple of one, not of its letters ("eyeL" -> ("eyeL",))
    return (value,) if isinstance(value, str) else value


#: A marker's name (not empty).
MarkerName = Annotated[str, AfterValidator(_marker_name)]
#: Markers whose mean is taken: a tuple of names (a list, or one name, is taken as one).
MarkerNames = Annotated[tuple[MarkerName, ...], BeforeValidator(_names), Tuple]


@declared
class MarkerMap:
    """Which markers of a recording are the thumb, the finger, the wrist and the object.

    Parameters
    ----------
    thumb, finger : str
        The thumb and index tips' markers.
    wrist : tuple of str
        Markers whose mean is the wrist (none: the grip midpoint carries the
        transport). One name is taken as a tuple of one.
    object : tuple of str
        Markers whose mean is the object's centre (none: where the grip closes).
    """

    thumb: MarkerName = "thumb"
    finger: MarkerName = "index"
    wrist: MarkerNames = ()
    object: MarkerNames = ()

    def __post_init__(self) -> None:
        # one marker in two roles measures nothing: a grip of a marker and itself never
        # opens, a wrist or object that is a digit moves with the grip
        if self.thumb == self.finger:
            raise InputError(f"the thumb and the finger are the same marker {self.thumb!r}: "
                             "each digit needs a marker of its own", None, field="finger")
        digits = {self.thumb: "thumb", self.finger: "finger"}
        for role, names in (("wrist", self.wrist), ("object", self.object)):
            for m in names:
                if m in digits:
                    raise InputError(f"the {role} marker {m!r} is also the {digits[m]}: name "
                                     f"another marker for the {role}", None, field=role)
        both = set(self.wrist) & set(self.object)
        if both:
            raise InputError(f"marker{'s' if len(both) > 1 else ''} "
                             f"{', '.join(map(repr, sorted(both)))} both wrist and object",
                             None, field="object")

    @classmethod
    def guess(cls, names) -> MarkerMap:
        """The mapping a recording's marker names suggest (``thumb*``, ``index*``, ...).

        Tips are preferred (``thumb_tip`` over ``thumb_middle``); markers
        whose name says hand or wrist are the wrist; ``object``, ``pillow``,
        ``target`` or ``cube`` the object.

        Parameters
        ----------
        names : sequence of str
            The recording's marker names.
        """
        names = list(names)
        low = {n: n.lower() for n in names}

        def pick(*words):
            hits = [n for n in names if any(w in low[n] for w in words)]
            tips = [n for n in hits if "tip" in low[n]]
            return (tips or hits or [None])[0]

        thumb = pick("thumb")
        finger = pick("index", "finger")
        wrist = tuple(n for n in names if "wrist" in low[n]) or tuple(
            n for n in names if low[n].startswith("hand"))
        obj = tuple(n for n in names if any(w in low[n] for w in
                                            ("object", "pillow", "target", "cube", "block")))
        return cls(thumb or "thumb", finger or "index", wrist, obj)

    def check(self, names, source) -> None:
        """Refuse a mapping that names a marker the recording lacks."""
        names = set(names)
        for role, wanted in (("thumb", (self.thumb,)), ("finger", (self.finger,)),
                             ("wrist", self.wrist), ("object", self.object)):
            for m in wanted:
                alike = sorted(n for n in names if n.casefold() == m.casefold())
                if m not in names and len(alike) > 1:
                    # which of them was meant is not ours to choose
                    raise InputError(f"{m!r} for the {role} matches {len(alike)} markers but "
                                     f"for case ({', '.join(map(repr, alike))}): name one "
                                     "exactly", source, field="--markers")
                if m not in names:
                    raise InputError(f"no marker {m!r} for the {role} (the recording has "
                                     f"{', '.join(sorted(names))})", source, field="--markers")


@declared
class ReachParams:
    """How reaches are found and brought into their plane.

    Parameters
    ----------
    landmarks : LandmarkParams
        The onset and end rule (and the low-pass filter) that bound a movement.
    cleaning : CleaningParams
        How spikes, held and missing samples are found and which gaps are bridged.
    min_travel : float
        Least distance the transport point goes from a movement's onset to its
        end, m (less is an adjustment, not a movement); also the least on
        each side of a turn that parts two movements.
    min_opening : float
        A grip that opens less than this above its aperture at a movement's
        onset, m, says nothing of a grasp (a whole-hand grasp from a flat
        hand); one that opens more tells a reach from a transport or a lift
        where the transport alone cannot (docs/reaches.md).
    min_speed : float
        Least peak speed of a movement, m/s (a drift of the resting hand is none).
    turn : float
        A movement whose path turns by this much or more, degrees, at a
        minimum of its speed where the grip is closing from its widest (or it
        barely changes) is two movements: a reach and the object's transport
        or a lift. A turn of 135 degrees or more (a withdrawal
        and the next reach) parts them whatever the grip.
    object_moved : float
        The object has moved when its markers' mean is this far from where it
        was at the reach's onset, m (the reach ends where that motion began).
    object_position : (3,) tuple, optional
        The object's centre in the recording's frame, m (instead of markers
        or where the grip closes).
    object_size : float, optional
        The object's size across the grip, m.
    """

    landmarks: LandmarkParams = field(default_factory=LandmarkParams)
    cleaning: CleaningParams = field(default_factory=CleaningParams)
    min_travel: Positive = 0.05
    min_opening: NonNegative = 0.015
    min_speed: Positive = 0.05
    turn: Annotated[float, Field(gt=0, lt=180)] = 45.0
    object_moved: Positive = 0.01
    object_position: Annotated[tuple[float, float, float], Tuple] | None = None
    object_size: Annotated[float, Field(gt=0, lt=1)] | None = None


@dataclass(frozen=True, eq=False)
class Reach:
    """One reach of a recording, in the recording's frame.

    Attributes
    ----------
    name : str
        ``<trial>`` or ``<trial>-reach<k>`` when a trial holds several.
    source : str
        The file.
    time : (N,) array
        Sample times, s, from the sample before the reach's rest to its end's
        padding; never earlier than the end of the movement before it.
    transport : (N, 3) array
        The transport point (grip midpoint, or wrist), m, NaN where lost.
    finger, thumb : (N, 3) arrays
        The digit tips, m.
    wrist : (N, 3) array or None
        The mapped wrist, m.
    object : (3,) array or None
        The object's centre from markers (where it stands before the hand
        moves it) or as given, m.
    onset, end : int
        Rows of the movement's onset and end.
    notes : tuple of str
        What was repaired or inferred.
    onset_bound, end_bound : str
        The rule that placed the onset and the end: the field's (``"5 % of
        peak speed"``), ``"the speed minimum between two movements (N % of
        peak)"`` or ``"the object's first motion"``.
    """

    name: str
    source: str
    time: np.ndarray
    transport: np.ndarray
    finger: np.ndarray
    thumb: np.ndarray
    wrist: np.ndarray | None
    object: np.ndarray | None
    onset: int
    end: int
    notes: tuple[str, ...] = ()
    onset_bound: str = "5 % of peak speed"
    end_bound: str = "5 % of peak speed"

    @property
    def aperture(self) -> np.ndarray:
        """(N,) 3D thumb-index distance, m."""
        return np.linalg.norm(self.finger - self.thumb, axis=1)

    @property
    def bound(self) -> str:
        """Which rules bound the reach, in words (``"5 % of peak speed"``, or onset and end
        apart when they differ)."""
        if self.onset_bound == self.end_bound:
            return self.onset_bound
        return f"onset: {self.onset_bound}; end: {self.end_bound}"


@dataclass(frozen=True)
class Unscored:
    """A trial, or a movement in it, that gives no scored reach, and why.

    Every trial of a recording leaves either reaches or at least one of
    these, so that nothing is dropped without a word.

    Attributes
    ----------
    name : str
        The trial's name, or ``<trial>-reach<k>`` for one movement of it.
    source : str
        The file.
    status : str
        A short word for what happened, the outputs' ``status`` column:
        ``no reach``, ``starts in motion``, ``ends in motion``, ``too short``,
        ``marker lost`` (docs/reaches.md).
    reason : str
        The same in a sentence ("no reach: the hand never moved",
        "too short: 3 samples", "marker lost throughout: index").
    onset_time, end_time : float
        Where the movement starts and ends, s, on the trial's clock (NaN if unknown).
    """

    name: str
    source: str
    status: str
    reason: str
    onset_time: float = math.nan
    end_time: float = math.nan


@dataclass(frozen=True)
class Movement:
    """One movement of the transport point (:func:`find_movements`).

    Attributes
    ----------
    onset, end : int or None
        Rows of its onset and end; None where the recording starts or ends in it.
    peak : int
        Row of its peak speed.
    onset_bound, end_bound : str
        The rule that placed each (see :attr:`Reach.onset_bound`).
    kind : str
        ``"reach"``, ``"after"`` (what follows a reach: transport, lift,
        release, return) or ``"other"``, once classified
        (:func:`classify_movements`); ``""`` before.
    reason : str
        Why a movement is not a reach, in words.
    """

    onset: int | None
    peak: int
    end: int | None
    onset_bound: str
    end_bound: str
    kind: str = ""
    reason: str = ""


def _mean_marker(markers, names, time, params, notes) -> np.ndarray | None:
    if not names:
        return None
    paths = []
    for m in names:
        p, rep = clean_path(time, markers[m], params.cleaning)
        if (line := rep.describe(m)) is not None:
            notes.append(line)
        paths.append(p)
    if len(paths) == 1:
        return paths[0]
    stack = np.stack(paths)
    seen = np.isfinite(stack)
    n = seen.sum(axis=0)
    # the mean of the markers seen; NaN where none is (without numpy's empty-slice warning)
    return np.where(n > 0, np.where(seen, stack, 0.0).sum(axis=0) / np.maximum(n, 1), np.nan)


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
                   aperture: np.ndarray | None = None) -> list[Movement]:
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
    """
    from scipy.signal import find_peaks  # noqa: PLC0415 (as the landmarks take it)

    params = ReachParams() if params is None else params
    lp = params.landmarks
    time = np.asarray(time, dtype=float)
    transport = np.asarray(transport, dtype=float)
    n = len(time)
    if n < 3:
        return []
    speed = lp.speed_of(time, transport)
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
                       aperture: np.ndarray | None = None) -> list[Movement]:
    """Each movement told apart: a reach to grasp, what follows one, or another movement.

    Reach-ness is read from the transport, never from the grip. With an
    object (``object_path``, or ``params.object_position``), a reach ends
    :data:`APPROACH` of its starting distance nearer the object, and it ends
    where the object first moves if that comes before the hand stops (the
    rest of the movement is the object's transport). Without one, a reach
    goes away from where the hand rested; the movements after it are not
    reaches (a transport, a lift, the return) until one ends back within
    :data:`RETURNED` of the reach's length from where it began, unless one
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
    speed = np.nan_to_num(lp.speed_of(time, transport), nan=0.0)
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
            if d0 - d1 >= APPROACH * d0:
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
            back = np.linalg.norm(stop - begin) <= RETURNED * np.linalg.norm(there - begin)
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
    moves = classify_movements(time, transport,
                               find_movements(time, transport, params, aperture), params,
                               object_path, aperture)
    return [(m.onset, m.end) for m in moves
            if m.kind == "reach" and m.onset is not None and m.end is not None]


def _lost_throughout(trial, markers: MarkerMap) -> str | None:
    """The role's markers none of whose samples is seen, named (None if each role is seen)."""
    def seen(name):
        return bool(np.isfinite(np.asarray(trial.markers[name], dtype=float)).all(axis=1).any())

    for names in ((markers.finger,), (markers.thumb,), markers.wrist):
        if names and not any(seen(m) for m in names):
            return ", ".join(names)
    return None


def trial_reaches(trial, markers: MarkerMap | None = None,
                  params: ReachParams | None = None) -> tuple[list[Reach], list[Unscored]]:
    """Every reach to grasp of one trial, and every trial or reach that gives none, and why.

    Never refuses a trial for what it holds: a trial without a reach gives
    one :class:`Unscored` (``no reach``: the hand never moved, or none of its
    movements is a reach, each said; ``too short``; ``marker lost``), and a
    reach that cannot be scored gives one (``starts in motion``, ``ends in
    motion``, ``too short``, ``marker lost``). What follows a reach (the
    object's transport, a lift, the release, the return) is part of the
    trial, not a reach, and is not listed.

    Parameters
    ----------
    trial : MocapTrial
        Its ``time`` (s), ``markers`` (name -> (N, 3) m), ``name`` and ``source``.
    markers : MarkerMap, optional
        Default: :meth:`MarkerMap.guess` from the recording's names.
    params : ReachParams, optional

    Returns
    -------
    list of Reach, list of Unscored

    Raises
    ------
    InputError
        Only for a mapping that names a marker the recording lacks (a mistake
        that holds for every trial of the file).
    """
    params = ReachParams() if params is None else params
    markers = MarkerMap.guess(trial.markers) if markers is None else markers
    markers.check(trial.markers, trial.source)
    source = str(trial.source)
    time = np.asarray(trial.time, dtype=float)

    def unscored(status, reason, name=trial.name, onset=None, end=None):
        return Unscored(name, source, status, reason,
                        math.nan if onset is None else float(time[onset]),
                        math.nan if end is None else float(time[end]))

    if len(time) < MIN_SAMPLES:
        return [], [unscored("too short", f"too short: {len(time)} samples")]
    if (lost := _lost_throughout(trial, markers)) is not None:
        return [], [unscored("marker lost", f"marker lost throughout: {lost}")]
    notes = list(getattr(trial, "notes", ()))
    finger = _mean_marker(trial.markers, (markers.finger,), time, params, notes)
    thumb = _mean_marker(trial.markers, (markers.thumb,), time, params, notes)
    wrist = _mean_marker(trial.markers, markers.wrist, time, params, notes)
    obj = _mean_marker(trial.markers, markers.object, time, params, notes)
    if obj is not None and not np.isfinite(obj).all(axis=1).any():
        notes.append(f"object markers lost throughout ({', '.join(markers.object)}): "
                     "the object is where the grip closes")
        obj = None
    mid = 0.5 * (finger + thumb)
    transport = mid if wrist is None else wrist  # the field's transport marker
    if not np.isfinite(transport).all(axis=1).any():
        what = ", ".join(markers.wrist) if wrist is not None else \
            f"{markers.thumb} and {markers.finger} together"
        return [], [unscored("marker lost", f"marker lost throughout: {what}")]
    aperture = np.linalg.norm(finger - thumb, axis=1)
    moves = classify_movements(time, transport,
                               find_movements(time, transport, params, aperture), params, obj,
                               aperture)
    candidates = [m for m in moves if m.kind == "reach"]
    if not candidates:
        if not moves:
            return [], [unscored("no reach", "no reach: the hand never moved (no movement of "
                                 f"{params.min_travel * 1000:.0f} mm or more)")]
        said = "; ".join(f"{_when(time, m)} {m.reason}" for m in moves)
        return [], [unscored("no reach", f"no reach: {len(moves)} movement"
                             f"{'s' if len(moves) > 1 else ''}, none a reach to grasp ({said})")]
    dt = float(np.median(np.diff(time)))
    reaches, skipped = [], []
    for k, m in enumerate(candidates):
        name = trial.name if len(candidates) == 1 else f"{trial.name}-reach{k + 1}"
        if m.onset is None:
            skipped.append(unscored("starts in motion", "starts in motion: the recording "
                                    "begins during the reach", name, None, m.end))
            continue
        if m.end is None:
            skipped.append(unscored("ends in motion", "ends in motion: the recording stops "
                                    "before the hand does", name, m.onset, None))
            continue
        if m.end - m.onset + 1 < MIN_SAMPLES:
            skipped.append(unscored("too short", f"too short: {m.end - m.onset + 1} samples",
                                    name, m.onset, m.end))
            continue
        gone = [n for n, p in ((markers.finger, finger), (markers.thumb, thumb))
                if not np.isfinite(p[m.onset:m.end + 1]).all(axis=1).any()]
        if gone:
            skipped.append(unscored("marker lost", f"marker lost during the reach: "
                                    f"{', '.join(gone)}", name, m.onset, m.end))
            continue
        i = moves.index(m)
        prev_end = moves[i - 1].end if i and moves[i - 1].end is not None else 0
        nxt = moves[i + 1].onset if i + 1 < len(moves) and moves[i + 1].onset is not None \
            else len(time) - 1
        lo = max(prev_end, m.onset - int(round(2 * MIN_REST / dt)))
        hi = max(m.end, min(nxt, m.end + int(round(0.5 / dt)), len(time) - 1))
        rows = slice(lo, hi + 1)
        obj_at = None
        if params.object_position is not None:
            obj_at = np.asarray(params.object_position, dtype=float)
        elif obj is not None:
            seen = obj[m.onset:m.end + 1]
            seen = seen[np.isfinite(seen).all(axis=1)]
            obj_at = np.median(seen, axis=0) if len(seen) else None
        follows = []
        for o in moves[i + 1:]:
            if o.kind != "after":
                break
            follows.append(f"{_when(time, o)} {o.reason}")
        extra = [f"not part of the reach: {'; '.join(follows)}"] if follows else []
        reaches.append(Reach(
            name=name, source=source, time=time[rows], transport=transport[rows],
            finger=finger[rows], thumb=thumb[rows],
            wrist=None if wrist is None else wrist[rows], object=obj_at,
            onset=m.onset - lo, end=m.end - lo, notes=tuple(notes + extra),
            onset_bound=m.onset_bound, end_bound=m.end_bound))
    return reaches, skipped


def _when(time: np.ndarray, m: Movement) -> str:
    a = "start" if m.onset is None else f"{time[m.onset]:.2f}"
    b = "end" if m.end is None else f"{time[m.end]:.2f}"
    return f"{a}-{b} s:"


def recording_reaches(trial, markers: MarkerMap | None = None,
                      params: ReachParams | None = None) -> list[Reach]:
    """Every reach to grasp in a recording (a :class:`~perception.io.mocap.MocapTrial`).

    :func:`trial_reaches`' reaches; where there are none, its reason is raised.

    Parameters
    ----------
    trial : MocapTrial
        Its ``time`` (s), ``markers`` (name -> (N, 3) m), ``name`` and ``source``.
    markers : MarkerMap, optional
        Default: :meth:`MarkerMap.guess` from the recording's names.
    params : ReachParams, optional

    Raises
    ------
    InputError
        A mapped marker is missing, or no reach is found.
    """
    reaches, unscored = trial_reaches(trial, markers, params)
    if not reaches:
        reason = unscored[0].reason if unscored else "no reach to grasp found"
        raise InputError(f"no reach to grasp found ({reason})", trial.source)
    return reaches


@dataclass(frozen=True)
class PlaneFit:
    """The movement's plane: an origin and two in-plane axes, with how far the path left it.

    Attributes
    ----------
    origin : (3,) array
        The object's centre, m (the model frame's origin).
    x, y : (3,) arrays
        Unit axes: y from start toward the end within the plane, x across it.
    rms, largest : float
        RMS and largest distance of the transport path from the plane, m.
    """

    origin: np.ndarray
    x: np.ndarray
    y: np.ndarray
    rms: float
    largest: float

    def project(self, p: np.ndarray) -> np.ndarray:
        """(N, 3) points -> (N, 2) in-plane coordinates, m."""
        d = np.asarray(p) - self.origin
        return np.stack([d @ self.x, d @ self.y], axis=-1)

    def to_dict(self) -> dict:
        """JSON values (m)."""
        return {"normal": np.cross(self.x, self.y).round(6).tolist(),
                "rms_out_of_plane": round(self.rms, 6),
                "largest_out_of_plane": round(self.largest, 6)}


def fit_plane(reach: Reach, origin: np.ndarray) -> PlaneFit:
    """The plane of a reach's transport path from onset to end (SVD), through ``origin``."""
    seg = reach.transport[reach.onset:reach.end + 1]
    seg = seg[np.isfinite(seg).all(axis=1)]
    if len(seg) < 3:
        raise InputError("the hand is seen too little during the reach to find its plane",
                         reach.source)
    centre = seg.mean(axis=0)
    _, _, vt = np.linalg.svd(seg - centre, full_matrices=False)
    normal = vt[2]
    along = seg[-1] - seg[0]
    y = along - (along @ normal) * normal
    if np.linalg.norm(y) < 1e-9:
        y = vt[0]
    y /= np.linalg.norm(y)
    x = np.cross(y, normal)
    off = (seg - centre) @ normal
    return PlaneFit(np.asarray(origin, dtype=float), x, y, float(np.sqrt(np.mean(off ** 2))),
                    float(np.abs(off).max()))


class ReachTracks(NamedTuple):
    """A reach as the recognition reads it (:func:`reach_tracks`).

    Attributes
    ----------
    tracks : Tracks
        Markers thumb, finger, wrist and object in the movement's plane, 1 px
        = 1 mm, y down; the object's apparent diameter in the tracker attributes.
    info : dict
        What the report says of it: ``plane`` (normal, out-of-plane RMS and
        largest, m), ``object_size`` (m), ``rest_aperture`` (m), ``notes``,
        ``bounds`` (the onset's and end's rows in ``tracks`` and the rules
        that placed them, :attr:`Reach.onset_bound`).
    transport, aperture : (T, 3) and (T,) arrays
        The 3D transport point and aperture, m, row for row with ``tracks``:
        the landmarks are measured on these, not on their projection.
    """

    tracks: Tracks
    info: dict
    transport: np.ndarray
    aperture: np.ndarray


def reach_tracks(reach: Reach, params: ReachParams | None = None) -> ReachTracks:
    """A reach as tracks in its plane (1 px = 1 mm), and what the report says of it.

    Parameters
    ----------
    reach : Reach
        From :func:`recording_reaches`.
    params : ReachParams, optional
        Its ``object_size``, if given, is the object's.
    """
    params = ReachParams() if params is None else params
    notes = list(reach.notes)
    if not 0 <= reach.onset < reach.end < len(reach.time):
        raise InputError(f"{reach.name}: the reach's onset (row {reach.onset}) and end (row "
                         f"{reach.end}) are not in order within its {len(reach.time)} samples",
                         reach.source)
    g = reach.aperture
    seen_end = np.flatnonzero(np.isfinite(reach.transport[:reach.end + 1]).all(axis=1))
    if not len(seen_end):
        raise InputError(f"{reach.name}: the hand is not seen up to the reach's end",
                         reach.source)
    if reach.object is not None:
        origin = reach.object
    else:
        origin = reach.transport[seen_end[-1]]
        notes.append("object: where the grip closes (the reach's end)")
    plane = fit_plane(reach, origin)
    mid = plane.project(0.5 * (reach.finger + reach.thumb))
    near_onset = g[max(0, reach.onset - 5):reach.onset + 1]
    near_onset = near_onset[np.isfinite(near_onset)]
    rest_g = float(np.median(near_onset)) if len(near_onset) else 0.0
    if params.object_size is not None:
        size = float(params.object_size)
    else:
        at_end = g[max(0, reach.end - 2):reach.end + 1]
        at_end = at_end[np.isfinite(at_end)]
        size = (float(np.median(at_end)) if len(at_end) else math.nan) - rest_g
        if size > 0.005:
            notes.append(f"object size: the grip's opening at the reach's end, "
                         f"{size * 1000:.0f} mm")
        else:  # the note gives the size used, and why it is not the opening
            notes.append(f"object size: 5 mm, the least used (the grip's opening at the "
                         f"reach's end, {size * 1000:.0f} mm, is no size)")
    if not size > 0.005:
        size = 0.005
    # the models' hand: a wrist behind the grip, whatever markers the lab put on it
    # (a marker on the back of the hand projects anywhere near the grip)
    wrist = mid - np.array([0.0, WRIST_BEHIND])
    across = np.array([1.0, 0.0])
    finger = mid + 0.5 * g[:, None] * across
    thumb = mid - 0.5 * g[:, None] * across
    obj = np.zeros_like(mid)
    time = reach.time.copy()
    pos = np.stack([thumb, finger, wrist, obj], axis=1)
    solid = np.concatenate([reach.transport, g[:, None]], axis=1)
    dt = float(np.median(np.diff(time)))
    # rest the recognition can read: stillness before the onset, first clean sample held
    whole = np.flatnonzero(np.isfinite(pos[:reach.end + 1, :3]).all(axis=(1, 2)))
    if not len(whole):
        raise InputError(f"{reach.name}: the digits are not seen together up to the reach's "
                         "end", reach.source)
    first = int(whole[0])
    still = time[reach.onset] - time[first]
    shift = -first
    if still < MIN_REST:
        n = int(math.ceil((MIN_REST - still) / dt)) + 1
        notes.append(f"{max(still, 0) * 1000:.0f} ms of rest before the movement: "
                     f"{n * dt * 1000:.0f} ms of its first clean sample added")
        time = np.r_[time[first] - dt * np.arange(n, 0, -1), time[first:]]
        pos = np.concatenate([np.repeat(pos[first:first + 1], n, axis=0), pos[first:]])
        solid = np.concatenate([np.repeat(solid[first:first + 1], n, axis=0), solid[first:]])
        shift += n
    elif first:
        time, pos, solid = time[first:], pos[first:], solid[first:]
    if reach.end_bound == "the object's first motion" or reach.end_bound.startswith(
            "the speed minimum"):
        # the hand goes on (with the object): what the models read ends at the grasp, held
        # there as a hand at rest on the object (what follows is no part of the reach)
        last = reach.end + shift
        k = int(math.ceil(MIN_REST / dt))
        notes.append(f"the reach ends at {reach.end_bound}: its last sample held "
                     f"{k * dt * 1000:.0f} ms in place of what follows")
        time = np.r_[time[:last + 1], time[last] + dt * np.arange(1, k + 1)]
        pos = np.concatenate([pos[:last + 1], np.repeat(pos[last:last + 1], k, axis=0)])
        solid = np.concatenate([solid[:last + 1], np.repeat(solid[last:last + 1], k, axis=0)])
    px = _ORIGIN_PX + PX_PER_M * pos * np.array([1.0, -1.0])
    lost = ~np.isfinite(px).all(axis=-1)
    status = np.where(lost, Status.LOST, Status.TRACKED).astype(np.int8)
    diameter = [math.nan, math.nan, math.nan, size * PX_PER_M]
    tracks = Tracks(frame=np.arange(len(time)), time=time - time[0],
                    markers=("thumb", "finger", "wrist", "object"), position=px,
                    likelihood=np.where(lost, 0.0, 1.0).astype(np.float32), status=status,
                    video={"path": reach.source, "fps_nominal": 1 / dt},
                    tracker={"diameter_px": diameter, "source": "mocap"},
                    attrs={"clip": reach.name})
    info = {"plane": plane.to_dict(), "object_size": size, "notes": notes,
            "rest_aperture": rest_g,
            "bounds": {"onset": max(0, reach.onset + shift), "end": reach.end + shift,
                       "onset_bound": reach.onset_bound, "end_bound": reach.end_bound}}
    return ReachTracks(tracks, info, solid[:, :3], solid[:, 3])


"""The standard reach-to-grasp landmarks of a movement, and what kind of abnormal it is.

The prehension literature describes a reach-to-grasp movement by a handful
of landmarks (Jeannerod 1984; Castiello 2005): its movement time, the
wrist's peak speed and when it comes, the maximum grip aperture (MGA) and
when it comes, the aperture at contact, and the number of times the hand
opens (one, in a normal grasp). They are measured by the field's own
definitions (:class:`LandmarkParams`: onset and end where the transport
speed crosses 5 % of its peak, after a zero-lag Butterworth filter), the
same for video, pose files and motion capture: :func:`movement_landmarks`
on any sampled movement, :func:`observed_landmarks` on an
:class:`~perception.observation.Observation`, :func:`model_landmarks` on a
model's own. :func:`verdict_detail` names the kind of an abnormal grasp
from them, in the field's terms and free of scale: times are fractions of
the movement time, apertures fractions of the reference model's opening
(docs/recognition.md §5; docs/mocap.md for the definitions).

:func:`movement_time` is another quantity: the duration a *model* would
take for a demonstration (from the wrist's middle 80 % of its path), which
the verdict's shape pass scales a clip by (:mod:`perception.recognition.shape`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from perception.observation import Observation

__all__ = ["DETAILS", "MAX_GAP", "MAX_GAP_SHARE", "MODEL_SPAN_FRACTION", "LandmarkParams",
           "Landmarks", "count_peaks", "grip_departs", "hides_a_reopening", "longest_gap",
           "model_landmarks", "movement_bounds", "movement_landmarks", "movement_time",
           "observed_landmarks", "speed_bound", "verdict_detail", "wrist_movement_time"]


#: The wrist covers the middle 80 % of its path (10 % to 90 %) in this
#: fraction of a model's movement time: measured on the default grasp
#: models' own movements at 0.8, 1.0 and 1.2 s (0.458, 0.467, 0.472), never
#: on test clips. The span between two fractions does not depend on where
#: the onset is placed, which the start of a movement leaves uncertain.
MODEL_SPAN_FRACTION = 0.467
#: Kinds of an abnormal verdict (:func:`verdict_detail`).
DETAILS = ("delayed-opening", "re-opening", "no-opening", "other")

#: An aperture peak counts if its prominence is at least this share of the opening...
PEAK_PROMINENCE = 0.25
#: ... and at least this much, m (a few times the tracking noise of an aperture).
PEAK_MIN_PROMINENCE = 0.005
#: The aperture has started to open when it first exceeds rest + this share of the opening.
OPENING_LEVEL = 0.10
#: A gap in the aperture may hide a closing and re-opening when it is longer than
#: this, s, and than :data:`MAX_GAP_SHARE` of the movement: a closing and
#: re-opening takes a share of the movement (the chapter 5 stimuli a third of
#: it), while real trackers drop digits for 0.1-0.2 s of slow, 1-2 s grasps.
MAX_GAP = 0.1
#: ... and this share of the movement time.
MAX_GAP_SHARE = 0.2


def hides_a_reopening(gap: float, movement_time: float) -> bool:
    """Whether a gap of ``gap`` s in the aperture could hide a closing and re-opening.

    Longer than :data:`MAX_GAP` and than :data:`MAX_GAP_SHARE` of the
    movement time (than :data:`MAX_GAP` alone where that is unknown).

    Parameters
    ----------
    gap : float
        The gap, s.
    movement_time : float
        The movement time, s (NaN if unknown).
    """
    limit = MAX_GAP
    if math.isfinite(movement_time) and movement_time > 0:
        limit = max(MAX_GAP, MAX_GAP_SHARE * movement_time)
    return gap > limit + 1e-9

# -- the rule of verdict_detail (docs/recognition.md §5, with its sources) --------------
#: no-opening: the observed opening is below this share of the reference model's.
NO_OPENING = 0.30
#: delayed-opening: the aperture starts to open (exceeds :data:`OPENING_LEVEL` of its
#: opening) later than this share of the movement. Real healthy grips start to open at
#: 3-68 % of the movement by these definitions (a lab's Optotrak grasps: up to 50 % on
#: all but 2 of the 30 dev trials), the chapter 5 delayed stimuli of both synthetic
#: generators at 52-70 %: chosen between, on dev sets only (docs/mocap.md)...
LATE_OPENING = 0.55
#: ... or its maximum comes later than this share (while the reference's comes earlier).
LATE_MGA = 0.95


@dataclass(frozen=True)
class LandmarkParams:
    """The field's definitions of a movement's bounds, and the filter before them.

    A movement begins where the transport speed rises above a threshold and
    ends where it falls below it again: by default 5 % of the movement's
    peak speed (``threshold``), or an absolute speed (``speed``) held for
    ``hold`` seconds, as labs variously define it. Positions are low-pass
    filtered first, without lag (a Butterworth filter run forwards and
    backwards, :func:`scipy.signal.filtfilt`), at ``cutoff`` Hz, as the
    field filters motion capture (6-10 Hz); ``cutoff=None`` measures the
    samples as they are.

    Parameters
    ----------
    threshold : float
        Share of the peak speed that bounds the movement (0-1).
    speed : float, optional
        An absolute speed, m/s, instead of the share.
    hold : float
        The speed must stay beyond the bound this long for a crossing to count, s.
    noise_factor : float
        The share-of-peak bound is raised to this many times the speed's
        noise floor (its 10th percentile over the recording: the still
        stretches' jitter), so that tracking noise of a few pixels neither
        starts a movement early nor keeps it from ending. 0: the share alone.
    cutoff : float, optional
        Low-pass cutoff, Hz (capped below the Nyquist frequency); None: no filter.
    order : int
        The Butterworth filter's order (run twice: zero lag, twice the roll-off).
    """

    threshold: float = 0.05
    speed: float | None = None
    hold: float = 0.0
    noise_factor: float = 2.0
    cutoff: float | None = 10.0
    order: int = 2

    def __post_init__(self):
        if not (0 < self.threshold < 1):
            raise ValueError(f"LandmarkParams.threshold: expected 0 < share < 1, got "
                             f"{self.threshold!r}")
        for name in ("speed", "cutoff"):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise ValueError(f"LandmarkParams.{name}: expected a positive number, got {v!r}")
        if not (math.isfinite(self.hold) and self.hold >= 0):
            raise ValueError(f"LandmarkParams.hold: expected a time >= 0, got {self.hold!r}")
        if not (math.isfinite(self.noise_factor) and self.noise_factor >= 0):
            raise ValueError(f"LandmarkParams.noise_factor: expected a number >= 0, got "
                             f"{self.noise_factor!r}")
        if not (isinstance(self.order, int) and 1 <= self.order <= 8):
            raise ValueError(f"LandmarkParams.order: expected 1-8, got {self.order!r}")

    def lowpass(self, time: np.ndarray, values: np.ndarray) -> np.ndarray:
        """``values`` (N, ...) low-passed without lag; NaN stays NaN.

        Each run of seen samples is filtered on its own (a filter never
        reaches across a gap); runs too short for the filter are kept as they
        are.

        Parameters
        ----------
        time : (N,) array
            Sample times, s (their median step sets the sampling rate).
        values : (N, ...) array
            Values, NaN where missing.
        """
        x = np.array(values, dtype=float)
        if self.cutoff is None or len(time) < 2:
            return x
        from scipy.signal import butter, filtfilt  # noqa: PLC0415 (only when filtering)

        rate = 1.0 / float(np.median(np.diff(time)))
        wn = min(self.cutoff / (0.5 * rate), 0.95)
        b, a = butter(self.order, wn)
        flat = x.reshape(len(x), -1)
        ok = np.isfinite(flat).all(axis=1)
        edges = np.diff(np.r_[0, ok.astype(np.int8), 0])
        for lo, hi in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            if hi - lo > 3 * max(len(a), len(b)):
                flat[lo:hi] = filtfilt(b, a, flat[lo:hi], axis=0)
        return flat.reshape(x.shape)

    def speed_of(self, time: np.ndarray, path: np.ndarray) -> np.ndarray:
        """(N,) speed of a path (N, D) after :meth:`lowpass`, m/s (NaN where lost)."""
        p = self.lowpass(time, path)
        if len(time) < 3:
            return np.full(len(time), np.nan)
        return np.linalg.norm(np.gradient(p, np.asarray(time, dtype=float), axis=0), axis=1)


def movement_bounds(time: np.ndarray, speed: np.ndarray, peak: int,
                    params: LandmarkParams | None = None) -> tuple[int | None, int | None]:
    """Rows of a movement's onset and end around its speed peak.

    The onset is the first row above the bound after the last stretch below
    it (at least ``params.hold`` long) before ``peak``; the end the last row
    before the first such stretch after it. None where the recording starts
    or ends in the movement (the speed never falls below the bound there).

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    speed : (N,) array
        Transport speed, m/s (NaN where lost: neither above nor below).
    peak : int
        Row of the movement's peak speed.
    params : LandmarkParams, optional
    """
    params = LandmarkParams() if params is None else params
    bound = speed_bound(speed, peak, params)
    below = np.isfinite(speed) & (speed < bound)
    edges = np.diff(np.r_[0, below.astype(np.int8), 0])
    runs = [(a, b) for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1))
            if time[b - 1] - time[a] >= params.hold - 1e-9]
    before = [b for a, b in runs if b <= peak]
    after = [a for a, b in runs if a > peak]
    return (int(before[-1]) if before else None, int(after[0]) - 1 if after else None)


def speed_bound(speed: np.ndarray, peak: int, params: LandmarkParams) -> float:
    """The speed that bounds a movement, m/s (see :class:`LandmarkParams`).

    Parameters
    ----------
    speed : (N,) array
        Transport speed, m/s (NaN where lost).
    peak : int
        Row of the movement's peak speed.
    params : LandmarkParams
    """
    if params.speed is not None:
        return float(params.speed)
    seen = speed[np.isfinite(speed)]
    floor = float(np.percentile(seen, 10)) if len(seen) else 0.0
    return max(params.threshold * float(speed[peak]), params.noise_factor * floor)


def _cross_time(time, speed, row, bound, rising) -> float:
    """The bound's crossing between ``row`` and its neighbour outside the movement, s."""
    other = row - 1 if rising else row + 1
    if not 0 <= other < len(time) or not np.isfinite(speed[[row, other]]).all():
        return float(time[row])
    s0, s1 = speed[other], speed[row]
    f = 0.0 if s1 == s0 else float(np.clip((bound - s0) / (s1 - s0), 0, 1))
    return float(time[other] + f * (time[row] - time[other]))


@dataclass(frozen=True)
class Landmarks:
    """The standard landmarks of one reach-to-grasp movement (NaN where not computable).

    Times called shares are fractions of the movement time from its onset
    (0-1); the movement runs from onset to end by :class:`LandmarkParams`.

    Attributes
    ----------
    onset_time, end_time : float
        The movement's onset and end on the recording's clock, s (NaN where
        the recording starts or ends in the movement).
    movement_time : float
        End minus onset, s.
    peak_speed : float
        Peak transport speed, m/s.
    peak_speed_time : float
        When it comes, share.
    deceleration_time : float
        From the peak speed to the end, s.
    mga : float
        Maximum grip aperture, m: the largest tip-to-tip (marker-to-marker)
        distance between onset and end.
    mga_time : float
        When it comes, share.
    contact_aperture : float
        Grip aperture at the movement's end, m.
    aperture_peaks : int or None
        Maxima of the aperture with a prominence of at least
        :data:`PEAK_PROMINENCE` of the opening and :data:`PEAK_MIN_PROMINENCE`
        (see :func:`count_peaks`); None where the aperture is missing for
        long enough to hide a second opening (:func:`hides_a_reopening`) or
        has fewer than 3 samples.
    rest_aperture : float
        Grip aperture at the movement's onset, m.
    opening_time : float
        When the aperture first exceeds ``rest_aperture`` + :data:`OPENING_LEVEL`
        of the opening: the grip starts to open, share.
    peak_opening_speed : float
        The aperture's fastest widening before the MGA, m/s.
    closing_time : float
        From the MGA to the movement's end, s.
    """

    movement_time: float = math.nan
    peak_speed: float = math.nan
    peak_speed_time: float = math.nan
    mga: float = math.nan
    mga_time: float = math.nan
    contact_aperture: float = math.nan
    aperture_peaks: int | None = None
    rest_aperture: float = math.nan
    opening_time: float = math.nan
    onset_time: float = math.nan
    end_time: float = math.nan
    deceleration_time: float = math.nan
    peak_opening_speed: float = math.nan
    closing_time: float = math.nan

    @property
    def opening(self) -> float:
        """How far the hand opened: ``mga - rest_aperture``, m."""
        return self.mga - self.rest_aperture

    @property
    def peak_speed_seconds(self) -> float:
        """When the peak speed comes, s from the onset."""
        return self.peak_speed_time * self.movement_time

    @property
    def mga_seconds(self) -> float:
        """When the MGA comes, s from the onset."""
        return self.mga_time * self.movement_time

    def to_dict(self) -> dict:
        """The landmarks, ``opening``, ``peak_speed_seconds`` and ``mga_seconds`` as JSON
        values (NaN becomes None)."""
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = v if v is None or isinstance(v, int) else _num(v)
        for name in ("opening", "peak_speed_seconds", "mga_seconds"):
            out[name] = _num(getattr(self, name))
        return out

    @classmethod
    def from_dict(cls, d: dict | None) -> Landmarks:
        """From :meth:`to_dict`'s output (None and missing keys read as NaN).

        Parameters
        ----------
        d : dict or None
            A ``kinematics`` entry of ``<clip>.recognition.json``.
        """
        d = d or {}
        kw = {}
        for f in fields(cls):
            v = d.get(f.name)
            if f.name == "aperture_peaks":
                kw[f.name] = None if v is None else int(v)
            else:
                kw[f.name] = math.nan if v is None else float(v)
        return cls(**kw)


def _num(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def count_peaks(values: np.ndarray, min_prominence: float) -> int:
    """Maxima of a sequence whose topographic prominence is at least ``min_prominence``.

    A (plateau-aware) local maximum, the first and last samples included, is
    as prominent as its height above the higher of the lowest points that
    separate it from higher samples on either side; the highest one above
    the lowest sample. (Unlike ``scipy.signal.find_peaks``, a side that
    never reaches a higher sample does not count: a grasp's MGA stands only
    a few cm above the aperture at contact, but the whole opening above its
    rest. numpy only: importing scipy.signal would cost ``recognize`` a
    quarter of a second.)

    Parameters
    ----------
    values : (N,) array
        The sequence, finite (leave out missing samples).
    min_prominence : float
        Least prominence of a peak that counts.
    """
    x = np.asarray(values, dtype=float)
    n = len(x)
    if n == 0:
        return 0
    # runs of equal values: a plateau is one candidate
    starts = np.flatnonzero(np.r_[True, x[1:] != x[:-1]])
    ends = np.r_[starts[1:], n] - 1
    count = 0
    lowest = x.min()
    for a, b in zip(starts, ends):
        h = x[a]
        if (a > 0 and x[a - 1] > h) or (b < n - 1 and x[b + 1] > h):
            continue
        cols = []
        left = np.flatnonzero(x[:a] > h)
        if len(left):
            cols.append(x[left[-1]:a].min())
        right = np.flatnonzero(x[b + 1:] > h)
        if len(right):
            cols.append(x[b + 1:b + 2 + right[0]].min())
        prominence = h - (max(cols) if cols else lowest)
        if prominence >= min_prominence:
            count += 1
    return count


def _crossing(time: np.ndarray, values: np.ndarray, level: float) -> float:
    """First time ``values`` exceed ``level``, interpolated between samples (NaN if never)."""
    ok = np.isfinite(values)
    t, v = time[ok], values[ok]
    above = np.flatnonzero(v > level)
    if not len(above):
        return math.nan
    i = int(above[0])
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - v[i - 1]) / (v[i] - v[i - 1]) * (t[i] - t[i - 1]))


def _progress_time(time: np.ndarray, w: np.ndarray, fraction: float) -> float:
    """When the wrist first covers ``fraction`` of its start-to-end displacement, s."""
    ok = np.isfinite(w).all(axis=1)
    if ok.sum() < 3:
        return float("nan")
    start, end = w[ok][0], w[ok][-1]
    total = float(np.linalg.norm(end - start))
    if total <= 0:
        return float("nan")
    progress = np.linalg.norm(w[ok] - start, axis=1) / total
    t = time[ok]
    i = int(np.argmax(progress >= fraction))
    if i == 0:
        return float(t[0])
    # interpolated between the frames on either side of the crossing
    p0, p1 = progress[i - 1], progress[i]
    return float(t[i - 1] + (t[i] - t[i - 1]) * (fraction - p0) / max(p1 - p0, 1e-12))


def movement_time(obs: Observation) -> float:
    """A demonstration's movement time, s, from the wrist's middle 80 % of its path.

    ``(t90 - t10) / MODEL_SPAN_FRACTION``: the time a model would take for
    a movement that covers its middle 80 % as fast. NaN if the wrist is
    seen too little.

    Parameters
    ----------
    obs : Observation
        The demonstration.
    """
    return wrist_movement_time(obs.time, obs.wrist)


def wrist_movement_time(time: np.ndarray, wrist: np.ndarray) -> float:
    """:func:`movement_time` of a wrist path sampled at ``time``, s.

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    wrist : (N, 2) array
        Wrist positions, m (NaN where lost).
    """
    time, wrist = np.asarray(time, dtype=float), np.asarray(wrist, dtype=float)
    return ((_progress_time(time, wrist, 0.9) - _progress_time(time, wrist, 0.1))
            / MODEL_SPAN_FRACTION)


def longest_gap(time: np.ndarray, values: np.ndarray) -> float:
    """The longest time between two consecutive seen samples of ``values``, s.

    Parameters
    ----------
    time : (N,) array
        Time stamps, s.
    values : (N,) array
        Values, NaN where lost (none seen: the whole span).
    """
    time = np.asarray(time, dtype=float)
    ts = time[np.isfinite(np.asarray(values, dtype=float))]
    if len(ts) < 2:
        return float(time[-1] - time[0]) if len(time) else 0.0
    return float(np.diff(ts).max())


def movement_landmarks(time: np.ndarray, transport: np.ndarray, aperture: np.ndarray,
                       params: LandmarkParams | None = None) -> Landmarks:
    """The landmarks of a sampled movement, by the field's definitions (:class:`LandmarkParams`).

    The movement is the one around the transport's peak speed, from the
    onset to the end where the (low-passed) speed crosses the bound; every
    other landmark is looked for between the two, so shares never exceed 1.
    Where the samples start or end inside the movement, its onset or end is
    missing (NaN) and so is everything measured against it; the peak speed
    and the MGA seen are still given.

    Parameters
    ----------
    time : (N,) array
        Sample times, s, increasing.
    transport : (N, D) array
        The point that carries the transport (the wrist, or the grip
        midpoint), m; NaN where lost.
    aperture : (N,) array
        Grip aperture (tip to tip), m; NaN where lost.
    params : LandmarkParams, optional
    """
    params = LandmarkParams() if params is None else params
    time = np.asarray(time, dtype=float)
    g_raw = np.asarray(aperture, dtype=float)
    if len(time) < 3:
        return Landmarks()
    speed = params.speed_of(time, np.asarray(transport, dtype=float))
    if not np.isfinite(speed).any():
        return Landmarks()
    peak = int(np.nanargmax(speed))
    onset, end = movement_bounds(time, speed, peak, params)
    bound = speed_bound(speed, peak, params)
    t_on = _cross_time(time, speed, onset, bound, True) if onset is not None else math.nan
    t_end = _cross_time(time, speed, end, bound, False) if end is not None else math.nan
    T = t_end - t_on
    lo = onset if onset is not None else 0
    hi = end if end is not None else len(time) - 1
    share = (lambda t: float(np.clip((t - t_on) / T, 0, 1))) if T > 0 else (lambda t: math.nan)
    base = {"onset_time": t_on, "end_time": t_end, "movement_time": T,
            "peak_speed": float(speed[peak]), "peak_speed_time": share(time[peak]),
            "deceleration_time": t_end - float(time[peak])}
    g = params.lowpass(time, g_raw)
    rows = np.arange(lo, hi + 1)
    seen = rows[np.isfinite(g[rows])]
    if len(seen) < 3:
        return Landmarks(**base)
    j = int(seen[np.argmax(g[seen])])
    mga, rest = float(g[j]), float(g[seen[0]])
    opening = mga - rest
    ts = time[seen]
    gaps = np.r_[ts[0] - time[lo], np.diff(ts), time[hi] - ts[-1]]
    peaks = None
    if not hides_a_reopening(float(gaps.max()), T):
        peaks = count_peaks(g[seen], max(PEAK_PROMINENCE * opening, PEAK_MIN_PROMINENCE))
    rate = np.gradient(g, time)
    widening = rate[lo:j + 1][np.isfinite(rate[lo:j + 1])]
    return Landmarks(
        **base, mga=mga, mga_time=share(time[j]), contact_aperture=float(g[seen[-1]]),
        aperture_peaks=peaks, rest_aperture=rest,
        opening_time=share(_crossing(time[lo:hi + 1], g[lo:hi + 1],
                                     rest + OPENING_LEVEL * opening)),
        peak_opening_speed=float(widening.max()) if len(widening) else math.nan,
        closing_time=t_end - float(time[j]))


def observed_landmarks(obs: Observation, params: LandmarkParams | None = None) -> Landmarks:
    """The landmarks of a demonstration, by the field's definitions (:func:`movement_landmarks`).

    Measured on the whole clip's unfiltered positions (``obs.clip_raw``),
    not only the span the models score: the field's end of a slow approach
    may come after it. The transport is the wrist's; the aperture is the
    tip-to-tip distance of the digit markers, as a lab reports it (the
    rest-subtracted opening is :attr:`Landmarks.opening`). Times are on
    the observation's clock (0 at the scored span's onset).

    Parameters
    ----------
    obs : Observation
        The demonstration.
    params : LandmarkParams, optional
    """
    time = getattr(obs, "clip_time", None)
    raw = getattr(obs, "clip_raw", None)
    if time is None or raw is None:
        r = getattr(obs, "raw", None) or {}
        if not all(k in r for k in ("wrist", "finger", "thumb")):
            return movement_landmarks(obs.time, obs.wrist,
                                      obs.g + obs.marker_separation, params)
        time = obs.time
        raw = np.stack([r[k] for k in ("wrist", "finger", "thumb")], axis=1)
    return movement_landmarks(time, raw[:, 0], np.linalg.norm(raw[:, 1] - raw[:, 2], axis=1),
                              params)


def model_landmarks(time: np.ndarray, wrist: np.ndarray, finger: np.ndarray,
                    thumb: np.ndarray, params: LandmarkParams | None = None) -> Landmarks:
    """The landmarks of a model's own (noise-free) movement, by the same definitions.

    Parameters
    ----------
    time : (N,) array
        Time since the movement's (command) onset, s, from rest to past its end.
    wrist, finger, thumb : (N, 2) arrays
        Positions, m.
    params : LandmarkParams, optional
    """
    wrist = np.asarray(wrist, dtype=float)
    # a noise-free movement starts from exact rest: prepend it so the onset is seen
    dt = float(time[1] - time[0])
    pad = 10
    t = np.r_[time[0] - dt * np.arange(pad, 0, -1), time]
    rest = lambda a: np.concatenate([np.repeat(np.asarray(a, dtype=float)[:1], pad, 0),  # noqa: E731
                                     np.asarray(a, dtype=float)])
    return movement_landmarks(t, rest(wrist),
                              np.linalg.norm(rest(finger) - rest(thumb), axis=1), params)


def verdict_detail(observed: Landmarks, reference: Landmarks | None) -> str:
    """What kind of abnormal grasp the landmarks describe (one of :data:`DETAILS`).

    In this order (docs/recognition.md §5 gives the sources):

    * ``no-opening``: the observed opening (MGA − rest aperture) is below
      :data:`NO_OPENING` (30 %) of the reference model's;
    * ``re-opening``: the aperture has 2 or more peaks (:func:`count_peaks`:
      each stands out by at least 25 % of the opening and 5 mm);
    * ``delayed-opening``: the aperture starts to open (exceeds 10 % of its
      opening) after :data:`LATE_OPENING` (55 %) of the movement, or its MGA
      comes after :data:`LATE_MGA` (95 %) while the reference's comes earlier;
    * ``other``: none of these (or not measurable).

    Parameters
    ----------
    observed : Landmarks
        The demonstration's.
    reference : Landmarks, optional
        The reference grasp model's own movement's (None without one: then
        no ``no-opening``, and a late MGA counts on its own).
    """
    ref_opening = reference.opening if reference is not None else math.nan
    if math.isfinite(observed.opening) and math.isfinite(ref_opening) and ref_opening > 0:
        if observed.opening < NO_OPENING * ref_opening:
            return "no-opening"
    if observed.aperture_peaks is not None and observed.aperture_peaks >= 2:
        return "re-opening"
    ref_mga_time = reference.mga_time if reference is not None else math.nan
    late_mga = observed.mga_time > LATE_MGA and not ref_mga_time > LATE_MGA
    if observed.opening_time > LATE_OPENING or late_mga:
        return "delayed-opening"
    return "other"


def grip_departs(observed: Landmarks) -> bool:
    """Whether the grip departs from the transport the way abnormal grasps do.

    The grip starts to open (exceeds 10 % of its opening) after
    :data:`LATE_OPENING` (55 %) of the movement — real healthy adults start
    anywhere up to about half-way (a lab's Optotrak grasps; docs/mocap.md) —
    or the aperture has two or more peaks (:func:`count_peaks`; a normal grasp
    opens once). Either makes a grasp ``abnormal`` even when the models'
    familiarity would pass it: the one-step predictions weigh a late or a
    second opening weakly once the model's filter has followed it.

    Parameters
    ----------
    observed : Landmarks
        The demonstration's landmarks.
    """
    peaks = observed.aperture_peaks
    return bool((peaks is not None and peaks >= 2) or observed.opening_time > LATE_OPENING)

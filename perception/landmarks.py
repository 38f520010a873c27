"""The standard reach-to-grasp landmarks of a movement, and what kind of abnormal it is.

The prehension literature describes a reach-to-grasp movement by a handful
of landmarks (Jeannerod 1984; Castiello 2005): its movement time, the
wrist's peak speed and when it comes, the maximum grip aperture (MGA) and
when it comes, the aperture at contact, and the number of times the hand
opens (one, in a normal grasp). :func:`observed_landmarks` measures them on
an :class:`~perception.observation.Observation`, :func:`movement_landmarks`
on any sampled movement (a model's own), and :func:`verdict_detail` names
the kind of an abnormal grasp from them, in the field's terms and free of
scale: times are fractions of the movement time, apertures fractions of
the reference model's opening (docs/recognition.md §5).

numpy only: ``hammer-mv recognize`` measures every clip, and neither pandas
nor scipy is imported on its path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from perception.observation import Observation

__all__ = ["DETAILS", "MODEL_SPAN_FRACTION", "Landmarks", "count_peaks", "grip_departs",
           "longest_gap", "movement_landmarks", "movement_time", "observed_landmarks",
           "verdict_detail", "wrist_movement_time"]


#: The wrist covers the middle 80 % of its path (10 % to 90 %) in this
#: fraction of a model's movement time: measured on the default grasp
#: models' own movements at 0.8, 1.0 and 1.2 s (0.458, 0.467, 0.472), never
#: on test clips. The span between two fractions does not depend on where
#: the onset is placed, which the start of a movement leaves uncertain.
MODEL_SPAN_FRACTION = 0.467
#: Kinds of an abnormal verdict (:func:`verdict_detail`).
DETAILS = ("delayed-opening", "re-opening", "no-opening", "other")

#: SD of the zero-phase Gaussian smoothing of the unfiltered positions, s:
#: half power at 0.1325 / SD = 6.6 Hz, above the content of reach-to-grasp
#: kinematics (which the field low-passes at 6-10 Hz), about the tracker's
#: noise at 30 frames/s.
SMOOTHING_SD = 0.020
#: An aperture peak counts if its prominence is at least this share of the opening...
PEAK_PROMINENCE = 0.25
#: ... and at least this much, m (a few times the tracking noise of an aperture).
PEAK_MIN_PROMINENCE = 0.005
#: The aperture has started to open when it first exceeds rest + this share of the opening.
OPENING_LEVEL = 0.10
#: A gap in the aperture longer than this, s, may hide a dip: no peak count.
MAX_GAP = 0.1
#: The reference model's movement ends when no hand point moves faster than
#: this, m/s (``ObserveParams.end_speed``: the observation's end rule without
#: tracking noise).
MODEL_END_SPEED = 0.02

# -- the rule of verdict_detail (docs/recognition.md §5, with its sources) --------------
#: no-opening: the observed opening is below this share of the reference model's.
NO_OPENING = 0.30
#: delayed-opening: the aperture starts to open (exceeds :data:`OPENING_LEVEL` of its
#: opening) later than this share of the movement: a normal hand starts to open within
#: the first ~20 % and a smooth opening that peaks by 80 % gets a tenth of the way up a
#: quarter of the way along, 0.2 + 0.26 x 0.6 = 0.36 at the latest...
LATE_OPENING = 0.40
#: ... or its maximum comes later than this share (while the reference's comes earlier).
LATE_MGA = 0.85


@dataclass(frozen=True)
class Landmarks:
    """The standard landmarks of one reach-to-grasp movement (NaN where not computable).

    Attributes
    ----------
    movement_time : float
        From the movement's onset to its end, s.
    peak_speed : float
        Peak speed of the wrist, m/s.
    peak_speed_time : float
        When it comes, fraction of the movement time.
    mga : float
        Maximum grip aperture, m.
    mga_time : float
        When it comes, fraction of the movement time.
    contact_aperture : float
        Grip aperture at the end of the movement, m.
    aperture_peaks : int or None
        Maxima of the aperture with a prominence of at least
        :data:`PEAK_PROMINENCE` of the opening and :data:`PEAK_MIN_PROMINENCE`
        (see :func:`count_peaks`); None where the aperture is missing for
        longer than :data:`MAX_GAP` or has fewer than 3 samples.
    rest_aperture : float
        Grip aperture at the movement's onset, m.
    opening_time : float
        When the aperture first exceeds ``rest_aperture`` + :data:`OPENING_LEVEL`
        of the opening, fraction of the movement time.
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

    @property
    def opening(self) -> float:
        """How far the hand opened: ``mga - rest_aperture``, m."""
        return self.mga - self.rest_aperture

    def to_dict(self) -> dict:
        """The landmarks and ``opening`` as JSON values (NaN becomes None)."""
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = v if v is None or isinstance(v, int) else _num(v)
        out["opening"] = _num(self.opening)
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


def smooth(time: np.ndarray, xy: np.ndarray, sd: float = SMOOTHING_SD) -> np.ndarray:
    """Zero-phase Gaussian smoothing over real time stamps; NaN stays NaN.

    Landmarks are measured after the movement, so they can use a filter
    without lag: the recognition's causal alpha-beta filter delays the
    landmarks by a frame or so and overshoots the MGA by about 5 mm.

    Parameters
    ----------
    time : (N,) array
        Time stamps, s.
    xy : (N, ...) array
        Values; NaN where missing (a missing sample is neither used nor filled).
    sd : float
        SD of the Gaussian kernel, s.
    """
    time = np.asarray(time, dtype=float)
    xy = np.asarray(xy, dtype=float)
    flat = xy.reshape(len(xy), -1)
    ok = np.isfinite(flat).all(axis=1)
    k = np.exp(-0.5 * ((time[:, None] - time[None, :]) / sd) ** 2) * ok[None, :]
    out = (k @ np.where(ok[:, None], flat, 0.0)) / np.maximum(k.sum(axis=1), 1e-300)[:, None]
    out[~ok] = np.nan
    return out.reshape(xy.shape)


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


def movement_landmarks(time: np.ndarray, wrist: np.ndarray, aperture: np.ndarray,
                       duration: float | None = None) -> Landmarks:
    """The landmarks of a movement sampled from its onset (``time`` 0) to its end.

    Parameters
    ----------
    time : (N,) array
        Time since the movement's onset, s, increasing; the movement time
        is the last one unless ``duration`` is given.
    wrist : (N, 2) array
        Wrist positions, m (NaN where lost). Its speed is the distance
        between consecutive positions over their time interval, at the
        interval's middle.
    aperture : (N,) array
        Grip aperture, m (NaN where lost).
    duration : float, optional
        The movement time, s, if known better than from the last sample.
    """
    time = np.asarray(time, dtype=float)
    wrist = np.asarray(wrist, dtype=float)
    g = np.asarray(aperture, dtype=float)
    if len(time) < 2 or not np.isfinite(time[-1]) or time[-1] <= 0:
        return Landmarks()
    T = float(duration) if duration is not None and math.isfinite(duration) and duration > 0 \
        else float(time[-1])
    speed = np.linalg.norm(np.diff(wrist, axis=0), axis=1) / np.diff(time)
    peak_speed = peak_speed_time = math.nan
    if np.isfinite(speed).any():
        i = int(np.nanargmax(speed))
        peak_speed = float(speed[i])
        peak_speed_time = float(0.5 * (time[i] + time[i + 1]) / T)
    seen = np.flatnonzero(np.isfinite(g))
    if len(seen) < 3:
        return Landmarks(T, peak_speed, peak_speed_time)
    j = int(seen[np.argmax(g[seen])])
    mga, rest = float(g[j]), float(g[seen[0]])
    opening = mga - rest
    ts = time[seen]
    gaps = np.r_[ts[0], np.diff(ts), T - ts[-1]]
    peaks = None
    if gaps.max() <= MAX_GAP + 1e-9 or len(seen) == len(g):
        peaks = count_peaks(g[seen], max(PEAK_PROMINENCE * opening, PEAK_MIN_PROMINENCE))
    return Landmarks(
        movement_time=T, peak_speed=peak_speed, peak_speed_time=peak_speed_time,
        mga=mga, mga_time=float(time[j] / T), contact_aperture=float(g[seen[-1]]),
        aperture_peaks=peaks, rest_aperture=rest,
        opening_time=_crossing(time, g, rest + OPENING_LEVEL * opening) / T)


def observed_landmarks(obs: Observation) -> Landmarks:
    """The landmarks of a demonstration, from its onset, over :func:`movement_time`.

    Measured on the unfiltered positions (``obs.raw``) smoothed without lag
    (:func:`smooth`); the grip aperture is the digit markers' distance less
    their separation at rest (``obs.marker_separation``: the markers sit
    outside the tips, across the grip). An observation without unfiltered
    positions is measured on its filtered ones.

    Parameters
    ----------
    obs : Observation
        The demonstration.
    """
    raw = getattr(obs, "raw", None) or {}
    if all(k in raw for k in ("wrist", "finger", "thumb")):
        wrist, finger, thumb = (smooth(obs.time, raw[k]) for k in ("wrist", "finger", "thumb"))
        aperture = np.linalg.norm(finger - thumb, axis=1) - obs.marker_separation
    else:
        wrist, aperture = obs.wrist, obs.g
    # the span's end is where no marker moves faster than the noise floor,
    # which cuts a normal grasp's slow approach short (by 0.09 s on average):
    # the movement time comes from the wrist's path instead (movement_time)
    return movement_landmarks(obs.time, wrist, aperture, movement_time(obs))


def model_landmarks(time: np.ndarray, wrist: np.ndarray, finger: np.ndarray,
                    thumb: np.ndarray, end_speed: float = MODEL_END_SPEED,
                    duration: float | None = None) -> Landmarks:
    """The landmarks of a model's own (noise-free) movement, sampled past its end.

    The movement ends when no hand point moves faster than ``end_speed``
    any more; its movement time is ``duration`` (the planned one) or else
    measured as an observation's (:func:`wrist_movement_time`).

    Parameters
    ----------
    time : (N,) array
        Time since the movement's (command) onset, s.
    wrist, finger, thumb : (N, 2) arrays
        Positions, m.
    end_speed : float
        Speed below which the hand has stopped, m/s.
    duration : float, optional
        The planned movement time, s.
    """
    time = np.asarray(time, dtype=float)
    pts = np.stack([wrist, finger, thumb], axis=1)
    speed = np.linalg.norm(np.diff(pts, axis=0), axis=-1).max(axis=1) / np.diff(time)
    moving = np.flatnonzero(speed > end_speed)
    stop = int(moving[-1]) + 2 if len(moving) else len(time)
    sl = slice(0, max(stop, 2))
    return movement_landmarks(time[sl], np.asarray(wrist)[sl],
                              np.linalg.norm(np.asarray(finger) - np.asarray(thumb),
                                             axis=1)[sl],
                              duration if duration is not None
                              else wrist_movement_time(time[sl], np.asarray(wrist)[sl]))


def verdict_detail(observed: Landmarks, reference: Landmarks | None) -> str:
    """What kind of abnormal grasp the landmarks describe (one of :data:`DETAILS`).

    In this order (docs/recognition.md §5 gives the sources):

    * ``no-opening``: the observed opening (MGA − rest aperture) is below
      :data:`NO_OPENING` (30 %) of the reference model's;
    * ``re-opening``: the aperture has 2 or more peaks (:func:`count_peaks`:
      each stands out by at least 25 % of the opening and 5 mm);
    * ``delayed-opening``: the aperture starts to open (exceeds 10 % of its
      opening) after :data:`LATE_OPENING` (40 %) of the movement, or its MGA
      comes after :data:`LATE_MGA` (85 %) while the reference's comes earlier;
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
    :data:`LATE_OPENING` (40 %) of the movement — healthy adults start
    within its first 20-30 % (Jeannerod 1984; Castiello 2005) — or the
    aperture has two or more peaks (:func:`count_peaks`; a normal grasp
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

"""Reaches in a 3D recording, each brought into the movement's own plane as tracks.

A motion-capture trial holds more than the reach: rest, the reach to the
object, the grasp, often the return, and in a long session many of each.
:func:`find_reaches` finds every reach-to-grasp in one: movements of the
transport point (the wrist markers' mean where a wrist is mapped, else the
grip midpoint) from onset to end by the field's threshold rule
(:func:`perception.landmarks.movement_bounds`), kept when the grip opens
during the movement (a return carries a closed or closing hand) or, with
object markers, when the hand ends :data:`APPROACH` of its distance nearer
the object than it started.

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
  much rest by holding its first clean sample, with a note.

Positions are written as "pixels" of one millimetre (:data:`PX_PER_M`),
y down, so every later stage reads them as it reads a clip's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from perception.cleaning import CleaningParams, clean_path
from perception.errors import InputError
from perception.io.tracks import Status, Tracks
from perception.landmarks import LandmarkParams, movement_bounds

__all__ = ["APPROACH", "MIN_REST", "PX_PER_M", "WRIST_BEHIND", "MarkerMap", "PlaneFit", "Reach",
           "ReachParams", "ReachTracks", "Unscored", "find_reaches", "fit_plane", "reach_tracks",
           "recording_reaches", "trial_reaches"]

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
_ORIGIN_PX = np.array([2000.0, 2000.0])


@dataclass(frozen=True)
class MarkerMap:
    """Which markers of a recording are the thumb, the finger, the wrist and the object.

    Parameters
    ----------
    thumb, finger : str
        The thumb and index tips' markers.
    wrist : tuple of str
        Markers whose mean is the wrist (none: the grip midpoint carries the transport).
    object : tuple of str
        Markers whose mean is the object's centre (none: where the grip closes).
    """

    thumb: str = "thumb"
    finger: str = "index"
    wrist: tuple[str, ...] = ()
    object: tuple[str, ...] = ()

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
                if m not in names:
                    raise InputError(f"no marker {m!r} for the {role} (the recording has "
                                     f"{', '.join(sorted(names))})", source, field="--markers")


@dataclass(frozen=True)
class ReachParams:
    """How reaches are found and brought into their plane.

    Parameters
    ----------
    landmarks : LandmarkParams
        The onset and end rule (and the low-pass filter) that bound a movement.
    cleaning : CleaningParams
        How spikes, held and missing samples are found and which gaps are bridged.
    min_opening : float
        A movement is a reach to grasp when the grip opens at least this
        much above its aperture at the onset, m.
    min_travel : float
        Least distance the transport point travels in a movement, m.
    object_position : (3,) tuple, optional
        The object's centre in the recording's frame, m (instead of markers
        or where the grip closes).
    object_size : float, optional
        The object's size across the grip, m.
    """

    landmarks: LandmarkParams = field(default_factory=LandmarkParams)
    cleaning: CleaningParams = field(default_factory=CleaningParams)
    min_opening: float = 0.015
    min_travel: float = 0.05
    object_position: tuple[float, float, float] | None = None
    object_size: float | None = None


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
        Sample times, s, from the sample before the reach's rest to its end's padding.
    transport : (N, 3) array
        The transport point (grip midpoint, or wrist), m, NaN where lost.
    finger, thumb : (N, 3) arrays
        The digit tips, m.
    wrist : (N, 3) array or None
        The mapped wrist, m.
    object : (3,) array or None
        The object's centre from markers or as given, m.
    onset, end : int
        Rows of the movement's onset and end (:func:`movement_bounds`).
    notes : tuple of str
        What was repaired or inferred.
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

    @property
    def aperture(self) -> np.ndarray:
        """(N,) 3D thumb-index distance, m."""
        return np.linalg.norm(self.finger - self.thumb, axis=1)


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
        ``marker lost``.
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


def find_reaches(time: np.ndarray, transport: np.ndarray, aperture: np.ndarray,
                 params: ReachParams | None = None,
                 object_path: np.ndarray | None = None) -> list[tuple[int, int]]:
    """(onset, end) rows of every reach to grasp in a recording.

    Movements are found from the fastest down: each speed peak above a
    third of the fastest movement's peak, bounded by the threshold rule
    around that peak; peaks inside a movement already found are part of it.

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    transport : (N, 3) array
        The transport point, m (NaN where lost).
    aperture : (N,) array
        Thumb-index distance, m (NaN where lost).
    params : ReachParams, optional
    object_path : (N, 3) array, optional
        The object's centre: a reach ends nearer it than it starts.
    """
    params = ReachParams() if params is None else params
    found: list[tuple[int, int]] = []
    taken = np.zeros(len(time), dtype=bool)
    speed = params.landmarks.speed_of(time, transport)
    if not np.isfinite(speed).any():
        return []
    top = float(np.nanmax(speed))
    order = np.argsort(np.nan_to_num(-speed, nan=0.0))
    for i in order:
        if not speed[i] >= top / 3:
            break
        if taken[i]:
            continue
        onset, end = movement_bounds(time, speed, int(i), params.landmarks)
        lo = 0 if onset is None else onset
        hi = len(time) - 1 if end is None else end
        taken[lo:hi + 1] = True
        if onset is None or end is None:
            continue
        travel = np.linalg.norm(transport[end] - transport[onset])
        if not travel >= params.min_travel:
            continue
        g = aperture[onset:end + 1]
        if object_path is not None and np.isfinite(object_path[[onset, end]]).all():
            d0 = np.linalg.norm(transport[onset] - object_path[onset])
            d1 = np.linalg.norm(transport[end] - object_path[end])
            if not d0 - d1 >= APPROACH * d0:
                continue
        elif not (np.isfinite(g).any() and np.isfinite(g[0])
                  and np.nanmax(g) - g[0] >= params.min_opening):
            continue
        found.append((onset, end))
    return sorted(found)


def recording_reaches(trial, markers: MarkerMap | None = None,
                      params: ReachParams | None = None) -> list[Reach]:
    """Every reach to grasp in a recording (a :class:`~perception.io.mocap.MocapTrial`).

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
    params = ReachParams() if params is None else params
    markers = MarkerMap.guess(trial.markers) if markers is None else markers
    markers.check(trial.markers, trial.source)
    time = np.asarray(trial.time, dtype=float)
    notes = list(getattr(trial, "notes", ()))
    finger = _mean_marker(trial.markers, (markers.finger,), time, params, notes)
    thumb = _mean_marker(trial.markers, (markers.thumb,), time, params, notes)
    wrist = _mean_marker(trial.markers, markers.wrist, time, params, notes)
    obj = _mean_marker(trial.markers, markers.object, time, params, notes)
    mid = 0.5 * (finger + thumb)
    transport = mid if wrist is None else wrist  # the field's transport marker
    aperture = np.linalg.norm(finger - thumb, axis=1)
    spans = find_reaches(time, transport, aperture, params, obj)
    if not spans:
        raise InputError("no reach to grasp found (no movement of the hand during which the "
                         f"grip opens by {params.min_opening * 1000:.0f} mm or more)",
                         trial.source)
    out = []
    for k, (onset, end) in enumerate(spans):
        prev_end = spans[k - 1][1] if k else 0
        nxt = spans[k + 1][0] if k + 1 < len(spans) else len(time) - 1
        dt = float(np.median(np.diff(time)))
        lo = max(prev_end, onset - int(round(2 * MIN_REST / dt)))
        hi = min(nxt, end + int(round(0.5 / dt)), len(time) - 1)
        rows = slice(lo, hi + 1)
        obj_at = None
        if params.object_position is not None:
            obj_at = np.asarray(params.object_position, dtype=float)
        elif obj is not None:
            obj_at = np.nanmean(obj[onset:end + 1], axis=0)
        out.append(Reach(
            name=trial.name if len(spans) == 1 else f"{trial.name}-reach{k + 1}",
            source=str(trial.source), time=time[rows], transport=transport[rows],
            finger=finger[rows], thumb=thumb[rows],
            wrist=None if wrist is None else wrist[rows], object=obj_at,
            onset=onset - lo, end=end - lo, notes=tuple(notes)))
    return out


def trial_reaches(trial, markers: MarkerMap | None = None,
                  params: ReachParams | None = None) -> tuple[list[Reach], list[Unscored]]:
    """Every reach to grasp of one trial, and every trial or movement that gives none, and why.

    Unlike :func:`recording_reaches` this never refuses a trial for what it
    holds (no reach, too short, a marker lost throughout, a movement that
    starts or ends in motion): such a trial or movement comes back as an
    :class:`Unscored` with its reason, so that the caller can account for it.

    Parameters
    ----------
    trial : MocapTrial
    markers : MarkerMap, optional
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
    markers = MarkerMap.guess(trial.markers) if markers is None else markers
    markers.check(trial.markers, trial.source)
    try:
        return recording_reaches(trial, markers, params), []
    except InputError as exc:
        return [], [Unscored(trial.name, str(trial.source), "no reach", exc.problem)]


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
        largest, m), ``object_size`` (m), ``rest_aperture`` (m), ``notes``.
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
    g = reach.aperture
    seen_end = np.flatnonzero(np.isfinite(reach.transport[:reach.end + 1]).all(axis=1))
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
        notes.append(f"object size: the grip's opening at the reach's end, "
                     f"{size * 1000:.0f} mm")
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
    first = int(np.argmax(np.isfinite(pos[:, :3]).all(axis=(1, 2))))
    still = time[reach.onset] - time[first]
    if still < MIN_REST:
        n = int(math.ceil((MIN_REST - still) / dt)) + 1
        notes.append(f"{max(still, 0) * 1000:.0f} ms of rest before the movement: "
                     f"{n * dt * 1000:.0f} ms of its first clean sample added")
        time = np.r_[time[first] - dt * np.arange(n, 0, -1), time[first:]]
        pos = np.concatenate([np.repeat(pos[first:first + 1], n, axis=0), pos[first:]])
        solid = np.concatenate([np.repeat(solid[first:first + 1], n, axis=0), solid[first:]])
    elif first:
        time, pos, solid = time[first:], pos[first:], solid[first:]
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
            "rest_aperture": rest_g}
    return ReachTracks(tracks, info, solid[:, :3], solid[:, 3])


"""Landmarks only: the field's kinematics of every movement in a file, no models involved.

:func:`landmarks` measures reach-to-grasp landmarks
(:func:`perception.landmarks.movement_landmarks`, the field's definitions)
on whatever a lab has:

* a motion-capture recording: every reach in it, in 3D (the grip midpoint
  carries the transport unless a wrist is mapped; the aperture is the 3D
  tip-to-tip distance);
* tracks, a tracks file, a pose file or a video: the wrist carries the
  transport where it is seen, else the digits' midpoint; no object and no
  rest are needed, and a recording that starts or ends in the movement
  still gives what it can (the rest NaN, with ``status`` saying why).

:func:`landmarks` gives Python one row per movement in SI units
(:data:`UNITS`), and one per trial or movement of a recording that gives no
reach, with its ``status`` and ``reason`` and NaN landmarks (:func:`measure`
also counts the trials, and gives each movement as a
:class:`~perception.report.tables.MovementLandmarks`). The files
``hammer-mv landmarks`` writes are :func:`~perception.report.tables.tidy_landmarks`'
lab units, the same table as ``batch``'s ``landmarks.csv``:
:func:`measure_inputs` measures files, folders and manifests, found as
``batch`` finds them (:mod:`perception.discovery`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from perception.errors import InputError
from perception.landmarks import LandmarkParams, Landmarks, movement_landmarks
from perception.report.tables import MovementLandmarks

if TYPE_CHECKING:
    import pandas as pd

    from perception.discovery import BatchItem

__all__ = ["UNITS", "Measured", "landmarks", "landmarks_row", "measure", "measure_inputs",
           "unscored_row"]

#: The table's columns and their units, in order.
UNITS = {
    "onset_time": "s", "end_time": "s", "movement_time": "s", "peak_speed": "m/s",
    "peak_speed_time": "share", "deceleration_time": "s", "mga": "m", "mga_time": "share",
    "opening": "m", "rest_aperture": "m", "contact_aperture": "m", "opening_time": "share",
    "peak_opening_speed": "m/s", "closing_time": "s", "aperture_peaks": "count"}


def landmarks_row(name: str, lm: Landmarks, **extra) -> dict:
    """One table row: the name, ``status``, each landmark of :data:`UNITS`, and ``extra``.

    Parameters
    ----------
    name : str
        The movement's name (``trial`` column).
    lm : Landmarks
        Its landmarks.
    **extra
        More columns.
    """
    d = lm.to_dict()
    row = {"trial": name, "status": lm.status}
    row.update({k: (math.nan if d[k] is None else d[k]) for k in UNITS})
    row.update(extra)
    row.setdefault("reason", "")
    return row


def unscored_row(entry, **extra) -> dict:
    """The table row of a trial or movement that gives no reach: its status and reason,
    its onset and end where known, NaN landmarks.

    Parameters
    ----------
    entry : Unscored
        From :func:`perception.recordings.read_recording`.
    **extra
        More columns.
    """
    row = {"trial": entry.name, "status": entry.status, **{k: math.nan for k in UNITS}}
    row.update(onset_time=entry.onset_time, end_time=entry.end_time)
    row.update(extra)
    row["reason"] = entry.reason
    return row


@dataclass(frozen=True)
class Measured:
    """The landmarks of a file's movements, and how many trials it holds.

    Attributes
    ----------
    table : pandas.DataFrame
        A row per movement, and per trial or movement that gives none
        (:func:`landmarks`).
    trials : int
        The trials read (a video, tracks or pose file is one).
    movements : list of MovementLandmarks
        The same movements for :func:`~perception.report.tables.tidy_landmarks`
        (clip, factors, flags), in order.
    skipped : list of (str, str)
        The files of the folders measured that are not clips, each as
        ``(path, why)`` (:attr:`perception.discovery.Discovery.skipped`).
    """

    table: pd.DataFrame
    trials: int
    movements: list[MovementLandmarks] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)

    @property
    def measured(self) -> int:
        """Rows measured (those without a ``reason``)."""
        return int((self.table["reason"].fillna("") == "").sum()) if len(self.table) else 0


def _transport_lost(tracks) -> str:
    """Why the transport point of ``tracks`` is never seen, as a recording's ``marker lost``
    reason says it (:func:`perception.reaches.trial_reaches`): the markers that carry it
    and are never seen, named."""
    seen = {m: bool(np.isfinite(tracks.marker(m)).all(axis=1).any())
            for m in ("wrist", "thumb", "finger") if m in tracks.markers}
    if seen.get("wrist"):  # the wrist carries it wherever it is seen (_tracks_movement)
        return "marker lost: the wrist is never seen long enough to give a speed"
    never = [m for m, ever in seen.items() if not ever]
    if seen["thumb"] and seen["finger"]:  # never both at once (or too briefly): the midpoint
        never.append("thumb and finger together")
    return f"marker lost throughout: {', '.join(never)}"


def _tracks_movement(tracks, px_per_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time, transport (m) and aperture (m) of tracks in pixels."""
    def get(name):
        return tracks.marker(name) / px_per_m if name in tracks.markers else None

    finger, thumb, wrist = get("finger"), get("thumb"), get("wrist")
    if finger is None or thumb is None:
        raise InputError("the landmarks need the thumb and the finger (have "
                         f"{', '.join(tracks.markers)})", tracks.path or "tracks")
    mid = 0.5 * (finger + thumb)
    transport = mid if wrist is None or not np.isfinite(wrist).any() else wrist
    return np.asarray(tracks.time, dtype=float), transport, np.linalg.norm(finger - thumb, axis=1)


def landmarks(source, *, params: LandmarkParams | None = None, mocap=None,
              px_per_m: float | None = None, object_diameter: float | None = None, pose=None,
              tracks_out=None, object_diameter_px: float | None = None) -> pd.DataFrame:
    """The landmarks of every movement in ``source``, as a table (:func:`measure`'s).

    Parameters
    ----------
    source : str, os.PathLike or Tracks
        A motion-capture file, a video, a tracks or pose file, or tracks in memory.
    params : LandmarkParams, optional
        The onset and end rule and the low-pass filter.
    mocap : MocapImport, optional
        How a motion-capture file is read (markers, rate, units).
    px_per_m : float, optional
        Scale of tracks in pixels.
    object_diameter : float, optional
        The object's real diameter, m, with its apparent one in the tracks.
    pose : PoseImport, optional
        How a pose file becomes tracks.
    tracks_out : str or os.PathLike, optional
        Where a video's tracks are written (default: beside the video).
    object_diameter_px : float, optional
        The object's apparent diameter, px, where the tracks do not give it
        (with ``object_diameter``).
    """
    return measure(source, params=params, mocap=mocap, px_per_m=px_per_m,
                   object_diameter=object_diameter, pose=pose, tracks_out=tracks_out,
                   object_diameter_px=object_diameter_px).table


def measure(source, *, params: LandmarkParams | None = None, mocap=None,
            px_per_m: float | None = None, object_diameter: float | None = None, pose=None,
            tracks_out=None, object_diameter_px: float | None = None) -> Measured:
    """The landmarks of every movement in ``source``, as a table, and its trials' count.

    Parameters
    ----------
    source : str, os.PathLike or Tracks
        A motion-capture file, a video, a tracks or pose file, or tracks in memory.
    params : LandmarkParams, optional
        The onset and end rule and the low-pass filter.
    mocap : MocapImport, optional
        How a motion-capture file is read (markers, rate, units).
    px_per_m : float, optional
        Scale of tracks in pixels (else from the object's apparent diameter
        and ``object_diameter``).
    object_diameter : float, optional
        The object's real diameter, m, with its apparent one in the tracks.
    pose : PoseImport, optional
        How a pose file becomes tracks.
    tracks_out : str or os.PathLike, optional
        Where a video's tracks are written (default: beside the video).
    object_diameter_px : float, optional
        The object's apparent diameter, px, where the tracks do not give it
        (with ``object_diameter``).

    Returns
    -------
    Measured
        Its table: one row per movement: ``trial``, ``status``, the landmarks
        of :data:`UNITS` (NaN where the recording does not show them),
        ``source``, ``reason`` and ``bound`` (the rule that bounded the
        movement, ``5 % of peak speed``); a recording's trial or movement that gives
        no reach is a row with its ``status`` (``no reach``, ``starts in
        motion``, ...) and ``reason``, NaN landmarks. One trial's failure
        never stops the trials after it.

    Raises
    ------
    InputError
        The file cannot be read (or is a table of no known layout), or the
        scale of pixel tracks is unknown.
    """
    from perception.boundary import expect
    from perception.io.tracks import Tracks
    from perception.recordings import MocapImport

    expect(params, LandmarkParams, "landmarks(params=)", optional=True)
    expect(mocap, MocapImport, "landmarks(mocap=)", optional=True)
    params = LandmarkParams() if params is None else params
    if not isinstance(source, Tracks):
        from perception.sources import input_kind

        if not Path(source).exists():  # before its name's ending is read as a layout
            raise InputError("not found", source)
        from perception.recordings import unknown_layout

        kind = input_kind(source)
        if kind is not None and kind.name == "mocap":
            from perception.recordings import read_recording

            mocap = MocapImport() if mocap is None else mocap
            recording = read_recording(source, mocap)
            rows, movements = [], []
            for entry in recording.entries:
                row, movement = _entry_landmarks(entry, params)
                rows.append(row)
                movements.append(movement)
            return Measured(_table(rows), len(recording.trials), movements)
        if (why := unknown_layout(source)) is not None:
            raise InputError(why, source)
        from perception.pipeline import clip_name, load_clip

        name, kind_name = clip_name(source)
        if kind_name == "unknown":  # this takes recordings too: say so, not load_clip's list
            from perception.io.files import input_file
            from perception.sources import files_taken

            what = files_taken("landmarks")
            input_file(source, what, empty=False)  # an empty file is of no kind: it says so
            raise InputError(f"not a {what}", source)
        tracks = load_clip(source, pose=pose, tracks_out=tracks_out)
    else:
        tracks = source
        name = str(tracks.attrs.get("clip", "tracks"))
    scale = px_per_m
    if scale is None:
        # the flag is for tracks that do not give the size (a pose file's): a tracker's
        # measurement stands, as batch and recognize scale a video by it
        dpx = tracks.object_diameter_px()
        dpx = object_diameter_px if dpx is None else dpx
        where = tracks.path or (source if not isinstance(source, Tracks) else "tracks")
        if dpx is not None and object_diameter is None:
            # the half given is named, so that the line asks for the other half
            raise InputError(f"the scale is unknown: the object is {dpx:g} px across, but "
                             "its real diameter is not given "
                             "(landmarks assumes none): give `object_diameter` in m, or "
                             "`px_per_m`", where, field="object_diameter")
        if dpx is None or object_diameter is None:
            raise InputError("the scale is unknown: give `px_per_m`, or the object's diameter "
                             "(`object_diameter`) with its apparent size in the tracks (a "
                             "tracker's, or `object_diameter_px`)", where, field="px_per_m")
        scale = dpx / object_diameter
    time, transport, aperture = _tracks_movement(tracks, scale)
    lm = movement_landmarks(time, transport, aperture, params)
    bound = (f"{params.speed:g} m/s" if params.speed is not None
             else f"{params.threshold * 100:g} % of peak speed")
    # the rule in the table too, as a recording's rows give theirs
    origin = str(getattr(tracks, "path", None) or name)
    if lm.status in ("marker lost", "too short"):  # none given, as by a recording's trial
        reason = (_transport_lost(tracks) if lm.status == "marker lost"
                  else f"too short: {tracks.n_frames} samples")
        row = landmarks_row(name, lm, source=origin, reason=reason)
        return Measured(_table([row]), 1, [MovementLandmarks(name, name, None, lm.status,
                                                             reason)])
    row = landmarks_row(name, lm, source=origin, bound=bound)
    return Measured(_table([row]), 1, [MovementLandmarks(name, name, lm, lm.status,
                                                         bound=bound)])


def _entry_landmarks(entry, params: LandmarkParams) -> tuple[dict, MovementLandmarks]:
    """The SI row and the movement of one recording's entry (a Reach or an Unscored)."""
    from perception.reaches import Reach

    number = getattr(entry, "reach_number", None)
    common = dict(factors=dict(getattr(entry, "factors", None) or {}),
                  trial_number=str(getattr(entry, "trial_number", "") or ""),
                  reach_number="" if number is None else str(number))
    if not isinstance(entry, Reach):
        return (unscored_row(entry, source=str(entry.source)),
                MovementLandmarks(entry.name, entry.name, None, entry.status, entry.reason,
                                  **common))
    lm = movement_landmarks(entry.time, entry.transport, entry.aperture, params,
                            bounds=(entry.onset, entry.end))
    return (landmarks_row(entry.name, lm, source=str(entry.source), bound=entry.bound),
            MovementLandmarks(entry.name, entry.name, lm, lm.status, bound=entry.bound,
                              **common))


def measure_inputs(inputs, *, params: LandmarkParams | None = None, mocap=None,
                   px_per_m: float | None = None, object_diameter: float | None = None,
                   object_diameter_px: float | None = None, pose=None,
                   tracks_out=None, progress=None) -> Measured:
    """The landmarks of every movement in some files, folders and manifests, as ``batch``
    finds them.

    A folder or a manifest (a CSV with ``clip`` and ``video`` columns) is
    listed by :func:`perception.discovery.find_clips` and its recordings
    split by :func:`perception.discovery.expand_recordings`, so that each
    movement has the clip name, condition and factors ``batch`` gives it; a
    clip that cannot be measured there is a ``failed`` row with why, as in a
    batch, and the movements come in clip order, as a batch's. A file named
    on its own is measured as the one clip of a folder holding it (its
    movements in the file's order), and its failure is an error.

    Parameters
    ----------
    inputs : iterable of str or os.PathLike
        Files, folders and manifests, each once.
    params, mocap, px_per_m, object_diameter, pose : optional
        As :func:`measure`'s.
    object_diameter_px : float, optional
        The object's apparent diameter, px, where the tracks do not give it.
    tracks_out : callable, optional
        ``tracks_out(path)``: where a video's tracks are written.
    progress : callable, optional
        ``progress(done, total, what)``, told how far the work is: a large
        table's rows checked and trials read
        (:func:`perception.io.mocap_trial.reading_progress`), then each
        input's movements measured. Nothing is said without it.

    Returns
    -------
    Measured
        Its ``movements`` (its ``table`` the same, in SI units, in the files' order).
    """
    from perception.io.mocap_trial import reading_progress

    with reading_progress(progress):
        return _measure_inputs(list(map(Path, inputs)), params, mocap, progress, dict(
            px_per_m=px_per_m, object_diameter=object_diameter,
            object_diameter_px=object_diameter_px, pose=pose), tracks_out)


def _measure_inputs(inputs: list[Path], params, mocap, progress, kwargs: dict,
                    tracks_out) -> Measured:
    """:func:`measure_inputs`' work."""
    from perception.discovery import BatchItem, expand_recordings, find_clips
    from perception.pipeline import clip_name
    from perception.recordings import MocapImport

    params = LandmarkParams() if params is None else params
    mocap = MocapImport() if mocap is None else mocap
    settings = _MocapSettings(mocap)
    rows, movements, trials, skipped = [], [], 0, []
    for path in inputs:
        listed = path.is_dir() or _is_manifest(path)
        if listed:
            discovery = find_clips(path)
            items = discovery.items
            skipped += [(str(path / name), why) for name, why in discovery.skipped]
        else:
            name, kind = clip_name(path)
            items = [BatchItem(name, path, kind)]
        items = expand_recordings(items, settings)
        trials += _trials(items)
        entries: dict[Path, tuple[list, list]] = {}
        found_here: list[MovementLandmarks] = []
        for k, item in enumerate(items):
            try:
                found = _item_landmarks(item, params, mocap, entries, dict(
                    kwargs, tracks_out=None if tracks_out is None else tracks_out(item.path)))
            except InputError as exc:
                if not listed:
                    raise
                found = _failed(item, str(exc))
            rows += found[0]
            found_here += [_tagged(m, item) for m in found[1]]
            if progress is not None:
                progress(k + 1, len(items), f"measuring {path.name}")
        if listed:  # in clip order, as batch's tables are
            found_here.sort(key=lambda m: m.clip)
        movements += found_here
    # one table of every row: a frame per movement took 1 ms each (2 s for 2,000)
    return Measured(_table(rows), trials, movements, skipped)


@dataclass(frozen=True)
class _MocapSettings:
    """What :func:`perception.discovery.expand_recordings` reads of a batch's settings."""

    mocap: object


def _is_manifest(path: Path) -> bool:
    """Whether ``path`` is a batch manifest: a CSV whose header names ``clip`` and ``video``."""
    if path.suffix.lower() != ".csv" or not path.is_file():
        return False
    with open(path, encoding="utf-8", errors="replace") as f:
        header = f.readline().strip().lstrip("\ufeff")
    names = {c.strip().strip('"') for c in header.split(",")}
    return {"clip", "video"} <= names


def _trials(items: list[BatchItem]) -> int:
    """The trials of ``items``: a recording's trials, one per other clip."""
    trials = {(i.path, i.trial) for i in items if i.kind == "mocap" and i.trial is not None}
    return len(trials) + sum(1 for i in items if i.kind != "mocap" or i.trial is None)


def _item_landmarks(item: BatchItem, params: LandmarkParams, mocap, entries: dict,
                    kwargs: dict) -> tuple[list[dict], list[MovementLandmarks]]:
    """The rows and movements of one batch item: a recording's reach or unscored entry, or
    a clip. ``entries`` keeps each recording's reaches and unscored entries left."""
    from perception.recordings import cached_recording

    if item.kind != "mocap" or (item.reach is None and item.unscored is None):
        found = measure(item.path, params=params, mocap=mocap, **kwargs)
        return found.table.to_dict("records"), found.movements
    if item.path not in entries:  # listed once: a recording's reaches, one list per item, took
        recording = cached_recording(item.path, mocap)  # time in the square of its reaches
        entries[item.path] = (recording.reaches, list(recording.unscored))
    reaches, unscored = entries[item.path]
    if item.reach is not None:
        entry = reaches[item.reach]
    else:  # expand_recordings lists a recording's unscored entries in its order
        entry = unscored.pop(0)
    row, movement = _entry_landmarks(entry, params)
    return [row], [movement]


def _failed(item: BatchItem, why: str) -> tuple[list[dict], list[MovementLandmarks]]:
    """A clip that could not be measured: its row says why, as a batch's does."""
    row = {"trial": item.clip, "status": "failed", **{k: math.nan for k in UNITS},
           "source": str(item.path), "reason": why}
    return [row], [MovementLandmarks(item.clip, item.clip, None, "failed", why)]


def _tagged(m: MovementLandmarks, item: BatchItem) -> MovementLandmarks:
    """``m`` with the batch item's clip name, condition and (manifest) factors."""
    import dataclasses

    factors = {**dict(item.factors), **dict(m.factors)}
    return dataclasses.replace(m, clip=item.clip, condition=item.condition or m.condition,
                               factors=factors)


def _table(rows: list[dict]) -> pd.DataFrame:
    """The rows as the table's columns, in order (an empty table keeps them)."""
    import pandas as pd

    return pd.DataFrame(rows, columns=["trial", "status", *UNITS, "source", "reason", "bound"])

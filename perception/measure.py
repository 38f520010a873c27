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

One row per movement, SI units in the column names' suffixes
(``hammer-mv landmarks`` writes the same table as CSV), and one per trial or
movement of a recording that gives no reach, with its ``status`` and
``reason`` and NaN landmarks (:func:`measure` also counts the trials).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from perception.errors import InputError
from perception.landmarks import LandmarkParams, Landmarks, movement_landmarks

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["UNITS", "Measured", "landmarks", "landmarks_row", "measure", "unscored_row"]

#: The table's columns and their units, in order.
UNITS = {
    "onset_time": "s", "end_time": "s", "movement_time": "s", "peak_speed": "m/s",
    "peak_speed_time": "share", "deceleration_time": "s", "mga": "m", "mga_time": "share",
    "opening": "m", "rest_aperture": "m", "contact_aperture": "m", "opening_time": "share",
    "peak_opening_speed": "m/s", "closing_time": "s", "aperture_peaks": "count"}


def _status(lm: Landmarks) -> str:
    if math.isnan(lm.onset_time) and math.isnan(lm.end_time):
        return "in motion throughout"
    if math.isnan(lm.onset_time):
        return "starts in motion"
    if math.isnan(lm.end_time):
        return "ends in motion"
    return "complete"


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
    row = {"trial": name, "status": _status(lm)}
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
    """

    table: pd.DataFrame
    trials: int

    @property
    def measured(self) -> int:
        """Rows measured (those without a ``reason``)."""
        return int((self.table["reason"].fillna("") == "").sum()) if len(self.table) else 0


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
              tracks_out=None) -> pd.DataFrame:
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
    """
    return measure(source, params=params, mocap=mocap, px_per_m=px_per_m,
                   object_diameter=object_diameter, pose=pose, tracks_out=tracks_out).table


def measure(source, *, params: LandmarkParams | None = None, mocap=None,
            px_per_m: float | None = None, object_diameter: float | None = None, pose=None,
            tracks_out=None) -> Measured:
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

    Returns
    -------
    Measured
        Its table: one row per movement: ``trial``, ``status``, the landmarks
        of :data:`UNITS` (NaN where the recording does not show them),
        ``source`` and ``reason``; a recording's trial or movement that gives
        no reach is a row with its ``status`` (``no reach``, ``starts in
        motion``, ...) and ``reason``, NaN landmarks. One trial's failure
        never stops the trials after it.

    Raises
    ------
    InputError
        The file cannot be read (or is a table of no known layout), or the
        scale of pixel tracks is unknown.
    """
    from perception.io.tracks import Tracks

    params = LandmarkParams() if params is None else params
    rows = []
    if not isinstance(source, Tracks):
        from pathlib import Path

        from perception.io.mocap import is_mocap_file

        if not Path(source).exists():  # before its name's ending is read as a layout
            raise InputError("not found", source)
        from perception.recordings import unknown_layout

        if is_mocap_file(source):
            from perception.reaches import Reach
            from perception.recordings import MocapImport, read_recording

            mocap = MocapImport() if mocap is None else mocap
            recording = read_recording(source, mocap)
            for entry in recording.entries:
                if not isinstance(entry, Reach):
                    rows.append(unscored_row(entry, source=str(source)))
                    continue
                lm = movement_landmarks(entry.time, entry.transport, entry.aperture, params,
                                        bounds=(entry.onset, entry.end))
                rows.append(landmarks_row(entry.name, lm, source=str(source),
                                          bound=entry.bound))
            return Measured(_table(rows), len(recording.trials))
        if (why := unknown_layout(source)) is not None:
            raise InputError(why, source)
        from perception.pipeline import clip_name, load_clip

        name = clip_name(source)[0]
        tracks = load_clip(source, pose=pose, tracks_out=tracks_out)
    else:
        tracks = source
        name = str(tracks.attrs.get("clip", "tracks"))
    scale = px_per_m
    if scale is None:
        dpx = tracks.object_diameter_px()
        if dpx is None or object_diameter is None:
            where = tracks.path or (source if not isinstance(source, Tracks) else "tracks")
            raise InputError("the scale is unknown: give px_per_m (--px-per-m), or the object's "
                             "diameter (--object-diameter) with its apparent size in the tracks",
                             where, field="--px-per-m")
        scale = dpx / object_diameter
    time, transport, aperture = _tracks_movement(tracks, scale)
    lm = movement_landmarks(time, transport, aperture, params)
    rows.append(landmarks_row(name, lm, source=str(getattr(tracks, "path", None) or name)))
    return Measured(_table(rows), 1)


def _table(rows: list[dict]) -> pd.DataFrame:
    """The rows as the table's columns, in order (an empty table keeps them)."""
    import pandas as pd

    return pd.DataFrame(rows, columns=["trial", "status", *UNITS, "source", "reason", "bound"])

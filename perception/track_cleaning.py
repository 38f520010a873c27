"""Tracks cleaned by the motion-capture rules: DeepLabCut jumps are the pose files' spikes.

A markerless tracker's errors are the motion-capture system's: a keypoint
that jumps to the other hand for a frame (a *spike*), one frozen where it
was last seen (*held*), frames without it (*missing*). :func:`clean_tracks`
finds and handles them with the very rules and code motion capture is
cleaned with (:func:`perception.cleaning.clean_path`: a Hampel filter for
spikes, exact repeats for held samples — sparing a rounded but live
marker — and short gaps bridged by PCHIP), marker by marker, in metres: the
pixels are converted through the clip's scale where it is known
(:attr:`TrackCleaning.px_per_m`, else the object's apparent diameter over
its real one) and through :attr:`TrackCleaning.default_px_per_m` where it
is not. A sample found lost becomes NaN (status lost, likelihood 0); one
bridged keeps a position with status interpolated.

It runs where a file is read (:func:`perception.io.pose.read_pose`), so
that ``recognize``, ``landmarks`` and ``watch`` of the same file read the
same cleaned tracks (the filter is centred, not causal: a live camera
stream is not cleaned). What was repaired is kept in the tracks' ``/tracker``
attribute ``cleaning`` and said in the observation's notes
(:func:`cleaning_notes`). docs/cleaning.md gives the rules for every source.
"""

from __future__ import annotations

import json
import math
from dataclasses import field
from typing import Any

import numpy as np

from perception.cleaning import CleaningParams, Repairs, clean_path
from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.io.tracks import INTERPOLATED_LIKELIHOOD, Status, Tracks
from perception.validation import Positive, declared

__all__ = ["DEFAULT_PX_PER_M", "TrackCleaning", "clean_tracks", "cleaning_notes"]

#: The image scale assumed where a clip's is not known, px/m: a camera that
#: sees about a metre across 1000 pixels (a 10 mm spike is then 10 px).
DEFAULT_PX_PER_M = 1000.0
#: The ``/tracker`` attribute that records the cleaning.
ATTRIBUTE = "cleaning"


@declared
class TrackCleaning:
    """How tracks in pixels are cleaned: the motion-capture rules at the clip's scale.

    Parameters
    ----------
    cleaning : CleaningParams
        The rules, in metres and seconds, as for motion capture.
    px_per_m : float, optional
        The clip's image scale, px/m. Default: the object's apparent
        diameter (the tracks' ``diameter_px``) over ``object_diameter``,
        else ``default_px_per_m``.
    object_diameter : float
        The object's real diameter, m, for the scale from its apparent one.
    default_px_per_m : float
        The scale assumed where the clip's is not known, px/m.
    """

    cleaning: CleaningParams = field(default_factory=CleaningParams)
    px_per_m: Positive | None = None
    object_diameter: Positive = DEFAULT_OBJECT_DIAMETER
    default_px_per_m: Positive = DEFAULT_PX_PER_M

    def scale(self, tracks: Tracks) -> tuple[float, str]:
        """The scale the distances are converted with, px/m, and where it came from.

        Parameters
        ----------
        tracks : Tracks
            The clip's tracks (their object's apparent diameter).
        """
        if self.px_per_m is not None:
            return float(self.px_per_m), "given"
        dpx = tracks.object_diameter_px()
        if dpx is not None:
            return dpx / self.object_diameter, "the object's size"
        return float(self.default_px_per_m), "assumed (the clip's is not known)"

    def to_dict(self) -> dict[str, Any]:
        """The settings as JSON-able data."""
        c = self.cleaning
        return {"spike_distance": c.spike_distance, "spike_window": c.spike_window,
                "held_samples": c.held_samples, "max_bridge": c.max_bridge,
                "quantum": c.quantum, "px_per_m": self.px_per_m,
                "object_diameter": self.object_diameter,
                "default_px_per_m": self.default_px_per_m}


def _still(position: np.ndarray) -> np.ndarray:
    """(T, M) bool: every *other* marker repeats its previous position exactly there."""
    same = np.zeros(position.shape[:2], dtype=bool)
    same[1:] = (np.diff(position, axis=0) == 0).all(axis=-1)
    m = position.shape[1]
    return np.stack([np.delete(same, j, axis=1).all(axis=1) if m > 1
                     else np.zeros(len(same), dtype=bool) for j in range(m)], axis=1)


def _cleanable_time(time: np.ndarray) -> bool:
    return len(time) >= 3 and bool(np.isfinite(time).all()) and bool(np.all(np.diff(time) > 0))


def clean_tracks(tracks: Tracks, params: TrackCleaning | None = None) -> Tracks:
    """The tracks with spikes, held and missing samples lost and short gaps bridged.

    Every marker is cleaned by :func:`perception.cleaning.clean_path` at the
    clip's scale (:meth:`TrackCleaning.scale`). Tracks already cleaned (a
    ``cleaning`` record in ``/tracker``) and tracks whose times are not
    increasing seconds (the observation refuses them with its own message)
    come back as they are.

    Parameters
    ----------
    tracks : Tracks
        In pixels.
    params : TrackCleaning, optional

    Returns
    -------
    Tracks
        A new object, ``/tracker`` attribute ``cleaning`` recording the scale
        and each marker's :class:`~perception.cleaning.Repairs`.
    """
    params = TrackCleaning() if params is None else params
    if ATTRIBUTE in tracks.tracker:
        return tracks
    time = np.asarray(tracks.time, dtype=float)
    if not _cleanable_time(time):
        return tracks
    scale, source = params.scale(tracks)
    position = np.array(tracks.position, dtype=float)
    likelihood = np.array(tracks.likelihood, dtype=np.float32)
    status = np.array(tracks.status, dtype=np.int8)
    still = _still(position)
    repairs: dict[str, dict] = {}
    notes: list[str] = []
    for j, marker in enumerate(tracks.markers):
        old = position[:, j].copy()
        path, rep = clean_path(time, old / scale, params.cleaning, still=still[:, j])
        # untouched samples keep their pixels exactly (no round trip through metres)
        new = np.where(np.isfinite(old) & (np.abs(path * scale - old) < 1e-9), old, path * scale)
        position[:, j] = new
        _mark(likelihood[:, j], status[:, j], old, new)
        repairs[marker] = _repairs_dict(rep)
        if line := rep.describe(marker):
            notes.append(line)
    record = {"px_per_m": round(scale, 6), "scale": source, "repairs": repairs, "notes": notes,
              "settings": params.to_dict()}
    return tracks.replace(position=position, likelihood=likelihood, status=status,
                          tracker={**tracks.tracker, ATTRIBUTE: json.dumps(record)})


def _mark(likelihood: np.ndarray, status: np.ndarray, old: np.ndarray,
          new: np.ndarray) -> None:
    """Status and likelihood of one marker's samples after cleaning (in place).

    ``old`` and ``new``: its (T, 2) positions before and after.
    """
    seen = np.isfinite(old).all(axis=-1)
    kept = np.isfinite(new).all(axis=-1)
    likelihood[~kept] = 0.0
    status[~kept] = Status.LOST
    # a sample lost (missing, or found off the path or held) and filled is a bridge,
    # marked as Tracks.interpolate marks one: less certain than either end
    filled = kept & (~seen | (new != old).any(axis=-1))
    for k in np.flatnonzero(filled):
        ends = [likelihood[i] for i in (k - 1, k + 1)
                if 0 <= i < len(likelihood) and kept[i] and not filled[i]]
        likelihood[k] = INTERPOLATED_LIKELIHOOD * (min(ends) if ends else 1.0)
        status[k] = Status.INTERPOLATED


def _repairs_dict(rep: Repairs) -> dict:
    return {"spikes": rep.spikes, "held": rep.held, "missing": rep.missing,
            "bridged": rep.bridged, "longest_gap": round(rep.longest_gap, 6)}


def cleaning_record(tracks) -> dict | None:
    """The ``cleaning`` record of some tracks (None where they were not cleaned)."""
    value = getattr(tracks, "tracker", {}).get(ATTRIBUTE)
    if value is None:
        return None
    if isinstance(value, bytes):
        value = value.decode()
    if isinstance(value, str):
        try:
            value = json.loads(value)
        except ValueError:
            return None
    return value if isinstance(value, dict) else None


def cleaning_notes(tracks) -> tuple[str, ...]:
    """What the cleaning repaired, one line per marker (none where nothing was found).

    Parameters
    ----------
    tracks : Tracks
        Tracks returned by :func:`clean_tracks` (any others: no notes).
    """
    record = cleaning_record(tracks)
    if not record:
        return ()
    notes = [str(n) for n in record.get("notes", ())]
    scale = record.get("px_per_m")
    if notes and isinstance(scale, (int, float)) and math.isfinite(scale):
        notes = [f"{n} (cleaned as motion capture, at {scale:g} px/m, {record.get('scale')})"
                 for n in notes]
    return tuple(notes)

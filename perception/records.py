"""One movement in metres, whatever it was read from.

A video's tracks and a pose file's are pixels, y down, at a scale the object
tells; a motion-capture reach's are metres in its movement's plane, y up.
:func:`~perception.observation.movement_record` brings any of them to one
:class:`MovementRecord`: the
wrist (the transport point), finger, thumb and object in metres, x right and y
up, about the object's centre as the first frames show it, with the clock,
which samples each marker was seen in, the scale taken and where from, and the
notes of how the input was read. Every source's loader ends here
(:func:`perception.loading.load_movements`), and so does the observation
(:func:`perception.observation.observe`), which turns the record into the
model frame by a rotation alone (the approach): recognition, landmarks and
the online recogniser see one record, online and offline alike.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from perception.errors import InputError
from perception.geometry import SimilarityTransform
from perception.io.pose import is_pose_file
from perception.track_cleaning import cleaning_notes

if TYPE_CHECKING:
    import pandas as pd

    from perception.observation import ObserveParams

__all__ = ["MARKERS", "MovementRecord", "check_markers", "make_record", "reading_notes"]

#: The record's markers: the transport point, the digits and the object.
MARKERS = ("wrist", "finger", "thumb", "object")


@dataclass(frozen=True, eq=False)
class MovementRecord:
    """A movement in metres, x right and y up, about the object's centre at rest.

    Attributes
    ----------
    clip : str
        The clip's (or reach's) name.
    source : str
        The file it was read from, else the clip.
    time : (T,) array
        Time stamps, s, on the input's clock (a motion-capture reach's from its first
        sample: add ``clock_offset`` for the recording's).
    frame : (T,) int array
        The input's frame of each sample (a motion-capture reach's sample, counted from
        its first; a start held still, as recognition holds one, repeats its first frame:
        see the notes).
    wrist, finger, thumb, object : (T, 2) arrays
        Positions, m; NaN where the marker was not seen.
    input_transform : SimilarityTransform
        Input units -> these metres (:meth:`~perception.geometry.SimilarityTransform.
        to_plane`): the object's centre in the input's units (``origin_px``),
        the scale (``px_per_m``: 1 for an input in metres) and whether the
        input's y runs down. With the approach's rotation set, it is the
        observation's scene (:attr:`~perception.observation.Observation.scene`).
    scale_from : str
        Where the scale came from: ``metres`` (the input is in metres),
        ``px_per_m`` (given) or ``object`` (its apparent diameter over
        ``object_diameter``).
    object_diameter : float
        The object's diameter, m.
    notes : tuple of str
        What reading and cleaning the input took on trust or repaired (a
        motion-capture reach's wrist is the models' own, placed behind the grip).
    clock_offset : float
        Seconds to add to ``time`` for the input's own clock.
    """

    clip: str
    source: str
    time: np.ndarray = field(repr=False)
    frame: np.ndarray = field(repr=False)
    wrist: np.ndarray = field(repr=False)
    finger: np.ndarray = field(repr=False)
    thumb: np.ndarray = field(repr=False)
    object: np.ndarray = field(repr=False)
    input_transform: SimilarityTransform = field(repr=False)
    scale_from: str = "metres"
    object_diameter: float = 0.0
    notes: tuple[str, ...] = ()
    clock_offset: float = 0.0

    @property
    def px_per_m(self) -> float:
        """Input units per metre (1 for an input in metres)."""
        return self.input_transform.px_per_m

    @property
    def seen(self) -> dict[str, np.ndarray]:
        """(T,) bool per marker: where it was seen."""
        return {m: np.isfinite(getattr(self, m)).all(axis=-1) for m in MARKERS}

    def to_pandas(self) -> pd.DataFrame:
        """Wide table: ``time``, ``frame``, then ``<marker>_x``, ``<marker>_y`` (m) and
        ``<marker>_seen`` per marker."""
        import pandas as pd

        data = {"time": self.time, "frame": self.frame}
        for m, seen in self.seen.items():
            xy = getattr(self, m)
            data |= {f"{m}_x": xy[:, 0], f"{m}_y": xy[:, 1], f"{m}_seen": seen}
        return pd.DataFrame(data)


def check_markers(markers, path=None, *, field: str | None = None) -> None:
    """Refuse marker names that lack one the recognition needs (:data:`MARKERS`).

    Parameters
    ----------
    markers : sequence of str
        The tracks' marker names.
    path : str or os.PathLike, optional
        What the error names (the clip).
    field : str, optional
        The field it names (default: the first marker missing).

    Raises
    ------
    InputError
        Naming every marker missing and those there are.
    """
    missing = [m for m in MARKERS if m not in markers]
    if missing:
        names = ", ".join(f"'{m}'" for m in missing)
        said = f"marker {names} is" if len(missing) == 1 else f"markers {names} are"
        raise InputError(f"{said} not in the tracks (have {', '.join(markers) or 'none'})",
                         path, field=field or missing[0])


def _positions(tracks, params: ObserveParams, name: str) -> dict[str, np.ndarray]:
    """(T, 2) positions of every needed marker in the input's units; refuses tracks that
    cannot be scored."""
    markers = list(tracks.markers)
    check_markers(markers, name)
    pos = np.asarray(tracks.position, dtype=float)
    out = {}
    for m in MARKERS:
        what = "object" if m == "object" else f"marker '{m}'"
        out[m] = pos[:, markers.index(m)]
        if not np.isfinite(out[m]).all(axis=1).any():
            raise InputError(f"{what} is never seen in the clip", name, field=m)
        if np.isinf(out[m]).any():
            raise InputError(f"marker '{m}' has infinite positions", name, field=m)
    if len(pos) < params.min_frames:
        raise InputError(f"clip too short to score: {len(pos)} frames "
                         f"(need at least {params.min_frames})", name)
    return out


def _frame_times(tracks, params: ObserveParams, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Time stamps (T,) s and frame periods (T-1,) s, checked."""
    time = np.asarray(tracks.time, dtype=float)
    if not np.isfinite(time).all():
        raise InputError(f"{int((~np.isfinite(time)).sum())} time stamps are not finite", name)
    dts = np.diff(time)
    if np.any(dts <= 0):
        raise InputError("time stamps do not increase", name)
    lo, hi = params.frame_period_range
    dt = float(np.median(dts))
    if not lo * (1 - 1e-6) <= dt <= hi * (1 + 1e-6):  # 1000 frames/s in float steps
        raise InputError(f"implausible frame period {dt:g} s (time stamps must be in "
                         f"seconds, {1 / hi:g}-{1 / lo:g} frames/s)", name)
    return time, dts


def _plane(pos: dict[str, np.ndarray], tracks, params: ObserveParams,
           name: str) -> tuple[SimilarityTransform, str]:
    """Input units -> metres about the object, y up; and where the scale came from."""
    rest = slice(0, params.rest_frames)
    for m in MARKERS:
        if not np.isfinite(pos[m][rest]).all():
            what = "object" if m == "object" else f"marker '{m}'"
            raise InputError(f"the clip must start with the hand at rest and visible: the "
                             f"{what} is lost in its first {params.rest_frames} frames",
                             name, field=m)
    # The object stays put while the hand is away: twice the rest frames average its centre
    # better, long before the hand arrives; over the frames it is seen (the hand may hide it)
    early = pos["object"][: 2 * params.rest_frames]
    seen = early[np.isfinite(early).all(axis=1)]
    if not len(seen):
        raise InputError("the object is never seen in the first "
                         f"{2 * params.rest_frames} frames", name, field="object")
    metric = tracks.units == "m"  # a reach in its plane: metres, y up (no scale to find)
    scale, scale_from = (1.0, "metres") if metric else (params.px_per_m, "px_per_m")
    if scale is None:
        dpx = tracks.object_diameter_px()
        if dpx is None:
            pose = "`object_diameter_px` (the object in pixels) or " if is_pose_file(name) else ""
            raise InputError(f"image scale unknown: the tracks carry no object size; give "
                             f"{pose}`px_per_m`", name)
        scale, scale_from = dpx / params.object_diameter, "object"
    return SimilarityTransform(np.median(seen, axis=0), float(scale), y_down=not metric), scale_from


def reading_notes(tracks) -> tuple[str, ...]:
    """What reading the tracks took on trust (a pose file's keypoints guessed from their
    names, an object placed where the grip ends: ``/tracker`` ``reading_notes``) and what
    cleaning them repaired (:func:`~perception.track_cleaning.cleaning_notes`)."""
    raw = getattr(tracks, "tracker", {}).get("reading_notes")
    read = tuple(str(n) for n in json.loads(raw)) if isinstance(raw, str) and raw else ()
    return (*read, *cleaning_notes(tracks))


def make_record(tracks, params: ObserveParams, clip: str | None = None, *,
                notes: bool = True) -> MovementRecord:
    """:func:`perception.observation.movement_record` of checked arguments: the record of
    ``tracks`` at ``params``' scale and rest, named ``clip`` (default: the tracks'); without
    its ``notes`` where the caller gives them (a scene fixed while a start is settled)."""
    name = clip or getattr(tracks, "name", None) or "clip"
    path = getattr(tracks, "path", None)
    source = str(path) if path is not None else name
    pos = _positions(tracks, params, source)
    time, _ = _frame_times(tracks, params, source)
    to_metres, scale_from = _plane(pos, tracks, params, source)
    xy = {m: to_metres.to_plane(pos[m]) for m in MARKERS}
    frame = np.asarray(getattr(tracks, "frame", np.arange(len(time))))
    return MovementRecord(name, source, time, frame, input_transform=to_metres,
                          scale_from=scale_from, object_diameter=float(params.object_diameter),
                          notes=reading_notes(tracks) if notes else (), **xy)

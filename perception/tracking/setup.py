"""A tracking setup: the colour models and marker sizes of one filming session.

A lab films many clips in one setup (same markers, lights, camera). ``hammer-mv
calibrate VIDEO -o setup.toml`` learns, from the first frames of one clip,
each marker's colour (hue, saturation and value ranges of its own pixels) and
the markers' physical sizes (against the object's known diameter), and
writes a setup file; ``track``, ``recognize`` and ``batch`` take it with
``--setup setup.toml``. The file (docs/markers.md)::

    [setup]                   # where it was learned (informative)
    source = "clip.mp4"
    frames = 5

    [sizes]                   # TrackerParams sizes, m
    object_diameter = 0.1
    marker_diameter = 0.0121
    band_size = [0.0702, 0.0249]

    [markers.thumb]           # MarkerColour fields, as in a colours file
    bgr = [40, 35, 190]
    hue = [[174, 4]]
    sat_min = 160
    val_min = 70

    [tracker]                 # any other TrackerParams field (optional)
    size_tolerance = 3.0

Unknown tables and keys are refused, naming the nearest valid one.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

import cv2
import numpy as np
from pydantic import Field

from perception.errors import InputError
from perception.io.atomic import write_text
from perception.io.config import check_keys, from_table, read_toml, renamed, sub_table
from perception.io.files import input_file
from perception.tracking.blobs import blob_at, principal_axes
from perception.tracking.markers import MarkerColour, MarkerSet, default_markers
from perception.tracking.measurement import soft_diameter
from perception.tracking.params import TrackerParams
from perception.validation import Int, declared

__all__ = ["TrackingSetup", "calibrate", "load_setup", "write_setup"]

_TABLES = ("setup", "sizes", "markers", "tracker")
_SIZES = ("object_diameter", "marker_diameter", "band_size")
#: Hue units (0..179) added to each side of the hue range a marker shows.
_HUE_PAD = 4
#: Saturation units below the 5th percentile a marker shows that still count.
_SAT_PAD = 25
#: Fraction of the 5th percentile of value that still counts (shade, flicker).
_VAL_FRACTION = 0.55


@dataclass(frozen=True)
class TrackingSetup:
    """Colour models and tracker parameters (with the marker sizes) of one session.

    Parameters
    ----------
    markers : MarkerSet
        The colour models.
    params : TrackerParams
        Tracker parameters, including ``object_diameter``, ``marker_diameter``
        and ``band_size``.
    source : str
        Where it was learned (a video), informative.
    frames : int
        Frames it was learned from.
    """

    markers: MarkerSet = field(default_factory=default_markers)
    params: TrackerParams = field(default_factory=TrackerParams)
    source: str = ""
    frames: int = 0

    def to_dict(self) -> dict[str, Any]:
        """The setup file's tables (``tracker`` holds only fields off their defaults)."""
        p, base = self.params, TrackerParams()
        tracker = {f.name: _toml_value(getattr(p, f.name)) for f in dataclasses.fields(p)
                   if f.name not in _SIZES and getattr(p, f.name) != getattr(base, f.name)}
        out = {"setup": {"source": self.source, "frames": self.frames},
               "sizes": {k: _toml_value(getattr(p, k)) for k in _SIZES},
               "markers": self.markers.to_dict()}
        if tracker:
            out["tracker"] = tracker
        return out


def _toml_value(v: Any) -> Any:
    if isinstance(v, tuple):
        return [_toml_value(x) for x in v]
    if isinstance(v, float):
        return round(v, 6)
    return v


def _toml(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    return repr(v)


def write_setup(path: str | os.PathLike, setup: TrackingSetup) -> Path:
    """Write ``setup`` as a TOML setup file (atomically).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    setup : TrackingSetup
        What to write.
    """
    d = setup.to_dict()
    tables = {"setup": d["setup"], "sizes": d["sizes"],
              **{f"markers.{name}": fields for name, fields in d["markers"].items()}}
    if "tracker" in d:
        tables["tracker"] = d["tracker"]
    lines = ["# hammer-mv tracking setup (hammer-mv calibrate); docs/markers.md", ""]
    for title, values in tables.items():
        lines += [f"[{title}]", *(f"{k} = {_toml(v)}" for k, v in values.items()), ""]
    return write_text(path, "\n".join(lines))


@declared
class _SetupTable:
    """A setup file's ``[setup]`` table."""

    source: str = ""
    frames: Annotated[Int, Field(ge=0, le=1_000_000)] = 0


def load_setup(path: str | os.PathLike) -> TrackingSetup:
    """Read a setup file.

    Every value is checked for its type and range (those :class:`TrackerParams`
    and :class:`MarkerColour` declare) before anything is built from it.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file ``hammer-mv calibrate`` writes (or one written by hand).

    Raises
    ------
    InputError
        Missing, not a regular file (a FIFO) or unparsable file, a table that
        is not a table, an unknown table or key (the nearest valid one is
        named), or a value of the wrong type or out of range; the message
        names the file and the field (``[tracker] search_scale``).
    """
    p = input_file(path, "setup file")
    data = read_toml(p, "setup file")
    check_keys(data, _TABLES, "the top level", p)
    meta = from_table(_SetupTable, data.get("setup", {}), "[setup]", p)
    sizes = sub_table(data, "sizes", "[sizes]", p)
    check_keys(sizes, _SIZES, "[sizes]", p)
    tracker = sub_table(data, "tracker", "[tracker]", p)
    check_keys(tracker, [k for k in TrackerParams.__dataclass_fields__ if k not in _SIZES],
               "[tracker]", p)
    markers = sub_table(data, "markers", "[markers]", p)
    for name in markers:
        check_keys({name: None}, default_markers().names, "[markers]", p)
        sub_table(markers, name, f"[markers.{name}]", p)
    try:
        params = TrackerParams(**{**tracker, **sizes})
    except InputError as exc:
        raise renamed(exc, lambda key: f"{'[sizes]' if key in _SIZES else '[tracker]'} {key}",
                      p) from None
    try:
        colours = default_markers().with_overrides(markers)
    except InputError as exc:  # exc.location: ("thumb", "hue")
        name, key = (*exc.location, "", "")[:2]
        field = f"[markers.{name}] {key}".strip() if name else "[markers]"
        raise InputError(exc.problem, p, field=field) from None
    return TrackingSetup(colours, params, meta.source, meta.frames)


# -- calibration ------------------------------------------------------------------
def _hue_range(hues: np.ndarray) -> tuple[int, int]:
    """The hue range (OpenCV units, may wrap through 0) holding 98 % of ``hues``."""
    h = hues.astype(int)
    # Centre the data away from the wrap before taking percentiles.
    centre = int(np.degrees(np.angle(np.exp(1j * np.radians(h * 2.0)).mean())) / 2) % 180
    shifted = (h - centre + 90) % 180
    lo, hi = np.percentile(shifted, [1, 99])
    lo = int(math.floor(lo)) - _HUE_PAD + centre - 90
    hi = int(math.ceil(hi)) + _HUE_PAD + centre - 90
    if hi - lo >= 179:
        return 0, 179
    return lo % 180, hi % 180


def _learn_colour(colour: MarkerColour, frame: np.ndarray, hsv: np.ndarray,
                  centre: Sequence[float], half: int) -> tuple[MarkerColour, np.ndarray]:
    """The marker's colour model from its own pixels around ``centre``; and its mask."""
    h, w = frame.shape[:2]
    cx, cy = int(round(centre[0])), int(round(centre[1]))
    x0, y0 = max(cx - half, 0), max(cy - half, 0)
    x1, y1 = min(cx + half + 1, w), min(cy + half + 1, h)
    region = hsv[y0:y1, x0:x1]
    mask = blob_at(colour.backproject(region), (cx - x0, cy - y0))
    if mask is None:
        raise ValueError(f"{colour.name}: no pixels of its colour at ({cx}, {cy}) px")
    pix = region[mask]
    lo, hi = _hue_range(pix[:, 0])
    learned = dataclasses.replace(
        colour,
        bgr=tuple(int(v) for v in np.median(frame[y0:y1, x0:x1][mask], axis=0)),
        hue=((lo, hi),),
        sat_min=int(max(np.percentile(pix[:, 1], 5) - _SAT_PAD, 40)),
        val_min=int(max(_VAL_FRACTION * np.percentile(pix[:, 2], 5), 30)),
    )
    full = np.zeros((h, w), bool)
    full[y0:y1, x0:x1] = mask
    return learned, full


def calibrate(frames: Sequence[np.ndarray], *, rois: Mapping[str, tuple[int, int, int, int]]
              | None = None, markers: MarkerSet | None = None,
              params: TrackerParams | None = None, source: str = "") -> TrackingSetup:
    """Learn a setup from the first frames of a clip (the hand at rest, every marker in view).

    The markers are found as the tracker finds them (automatically, or in
    the given ROIs); each marker's hue range, saturation and value minimums
    are then taken from its own pixels, and the markers' sizes measured
    against the object's apparent diameter and its known
    ``params.object_diameter``.

    Parameters
    ----------
    frames : sequence of (H, W, 3) uint8
        The clip's first frames (BGR); the first is measured, the last is
        the stillness test's look ahead.
    rois : mapping of str to (x, y, w, h), optional
        Where markers are on the first frame, px.
    markers : MarkerSet, optional
        Colour models to start from (default: the defaults).
    params : TrackerParams, optional
        Parameters to start from (its ``object_diameter`` sets the scale).
    source : str
        Where the frames come from (recorded in the setup).

    Raises
    ------
    InputError
        A marker not found, or ambiguous, on the first frames: the message
        names it and asks for a ROI.
    """
    from perception.tracking.tracker import Tracker

    if not frames:
        raise InputError("no frames to calibrate from")
    params = TrackerParams() if params is None else params
    tracker = Tracker(markers, params, rois)
    if len(frames) > 1:
        tracker.look_ahead(frames[-1])
    position, _, _ = tracker.update(frames[0])
    missing = [n for j, n in enumerate(tracker.markers.names)
               if not np.isfinite(position[j]).all()]
    if missing:
        why = "; ".join(f"{m}: {tracker.why_not_found(m)}" for m in missing)
        raise InputError(f"cannot calibrate: {why}; give `rois` "
                         f"{missing[0]} X Y W H around it on the first frame")
    hsv = cv2.cvtColor(frames[0], cv2.COLOR_BGR2HSV)
    learned, masks = [], {}
    for j, colour in enumerate(tracker.markers):
        half = int(max(tracker._tracks[j].win)) + 6
        try:
            model, mask = _learn_colour(colour, frames[0], hsv, position[j], half)
        except ValueError as exc:
            raise InputError(f"cannot calibrate: {exc}") from None
        learned.append(model)
        masks[colour.name] = mask
    scale = tracker.px_per_m
    if scale is None:
        raise InputError("cannot calibrate: the object's size could not be measured")
    sizes = {}
    digits = []
    for j, name in enumerate(tracker.markers.names):
        if name in ("thumb", "finger"):
            # unbiased by the partly coloured rim, which is large on small discs
            d = soft_diameter(frames[0], tracker.markers[name], position[j],
                              tracker._tracks[j].win, tracker.params)
            digits.append((d if np.isfinite(d) else 2 * math.sqrt(masks[name].sum() / math.pi))
                          / scale)
    if digits:
        sizes["marker_diameter"] = float(np.mean(digits))
    if "wrist" in masks:
        # a uniform band of length L has variance L^2 / 12 along it
        major, minor, _ = principal_axes(masks["wrist"].astype(np.uint8))
        sizes["band_size"] = tuple(math.sqrt(12) * math.sqrt(max(v, 0.0)) / scale
                                   for v in (major, minor))
    return TrackingSetup(MarkerSet(tuple(learned)), dataclasses.replace(params, **sizes),
                         source, len(frames))

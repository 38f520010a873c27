"""Colour models of the markers, shared by the renderer and the tracker.

One :class:`MarkerColour` per marker says how the renderer paints it (``bgr``)
and which pixels the tracker counts as that marker: hue inside one of the
``hue`` ranges, saturation >= ``sat_min`` and value >= ``val_min``. Hue is in
OpenCV units, 0..179 (degrees / 2); a range with ``lo > hi`` wraps through 0,
which red needs.

The defaults are the thesis set: thumb red, index finger green, wrist band
blue, object yellow, always in that order in files (:data:`MARKER_NAMES`).
Users override any field from a JSON or TOML file (``--colours FILE``)::

    [thumb]              # one table per marker to change; omitted ones keep defaults
    bgr = [30, 30, 210]  # or rgb = [...]; render colour
    hue = [[172, 6]]     # inclusive ranges; [172, 6] wraps through 0
    sat_min = 140
    val_min = 60
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Mapping
from dataclasses import field, fields, replace
from functools import cached_property
from typing import Annotated, Any

import cv2
import numpy as np
from pydantic import BeforeValidator, Field

from perception.errors import InputError
from perception.io.config import check_keys, read_toml, suggest
from perception.io.files import input_file
from perception.validation import Int, Tuple, declared

#: Marker names in file order (``/tracks/markers``).
MARKER_NAMES: tuple[str, ...] = ("thumb", "finger", "wrist", "object")

_FIELDS = ("bgr", "rgb", "hue", "sat_min", "val_min")


def to_hsv(bgr: np.ndarray) -> np.ndarray:
    """A BGR image or crop in OpenCV HSV, converted as one row of pixels.

    OpenCV converts row by row, 32 pixels at a time with SIMD and a row's
    remainder one pixel at a time, five times slower: a 95 px wide crop
    costs as much as a 300 px one. Copied into one contiguous row, the
    pixels convert at full speed; the values are the same (the conversion
    is per pixel, and its SIMD and one-pixel paths agree on every 8-bit
    colour).

    Parameters
    ----------
    bgr : (H, W, 3) uint8
        Image or a view into one (a crop of a frame).

    Returns
    -------
    (H, W, 3) uint8
        Its hue (0..179), saturation and value.
    """
    h, w = bgr.shape[:2]
    row = np.ascontiguousarray(bgr).reshape(1, h * w, 3)
    return cv2.cvtColor(row, cv2.COLOR_BGR2HSV).reshape(h, w, 3)


def _hue(hue: Any) -> tuple[tuple[int, int], ...]:
    """Accept ``[lo, hi]`` or ``[[lo, hi], ...]``; return a tuple of int pairs."""
    bad = ValueError("[lo, hi] or a list of [lo, hi] ranges with integers 0..179 "
                     "(lo > hi wraps through 0)")
    try:
        arr = np.asarray(hue)
    except (TypeError, ValueError):
        raise bad from None
    if arr.dtype == object or arr.size > 2 * 180:
        raise bad
    arr = np.atleast_2d(arr)
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] == 0:
        raise bad
    if arr.dtype.kind not in "iu" and not (
        arr.dtype.kind == "f" and np.all(np.isfinite(arr)) and np.all(arr == np.round(arr))
    ):
        raise bad
    if np.any(arr < 0) or np.any(arr > 179):
        raise bad
    return tuple((int(lo), int(hi)) for lo, hi in arr)


_Byte = Annotated[Int, Field(ge=0, le=255)]


@declared
class MarkerColour:
    """How one marker looks: its render colour and the tracker's colour gate.

    Parameters
    ----------
    name : str
        Marker name (one of :data:`MARKER_NAMES` in the default set).
    bgr : tuple of 3 int
        Render colour, 0..255 each, OpenCV channel order.
    hue : tuple of (lo, hi) int pairs
        Accepted hue ranges, inclusive, OpenCV units 0..179; ``lo > hi`` wraps
        through 0 (e.g. ``(172, 6)`` for red).
    sat_min, val_min : int
        Minimum saturation and value (0..255) of an accepted pixel; they keep
        greyish, dark and skin-coloured pixels out of the back-projection.
    """

    name: str
    bgr: Annotated[tuple[_Byte, _Byte, _Byte], Tuple]
    hue: Annotated[tuple[tuple[int, int], ...], BeforeValidator(_hue)]
    sat_min: _Byte = 100
    val_min: _Byte = 50

    @cached_property
    def hsv(self) -> tuple[int, int, int]:
        """Render colour in OpenCV HSV (hue 0..179, saturation and value 0..255)."""
        px = np.array([[self.bgr]], dtype=np.uint8)
        return tuple(int(c) for c in cv2.cvtColor(px, cv2.COLOR_BGR2HSV)[0, 0])

    @cached_property
    def _bounds(self) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        # cv2.inRange takes one box per call: split wrapping ranges in two.
        boxes = []
        for lo, hi in self.hue:
            for a, b in [(lo, hi)] if lo <= hi else [(lo, 179), (0, hi)]:
                boxes.append((np.array([a, self.sat_min, self.val_min], dtype=np.uint8),
                              np.array([b, 255, 255], dtype=np.uint8)))
        return tuple(boxes)

    def backproject(self, hsv: np.ndarray) -> np.ndarray:
        """Back-project the colour model onto an HSV image.

        Parameters
        ----------
        hsv : (H, W, 3) uint8
            Image in OpenCV HSV.

        Returns
        -------
        (H, W) uint8
            255 where the pixel matches the model, 0 elsewhere.
        """
        boxes = self._bounds
        mask = cv2.inRange(hsv, *boxes[0])
        for lo, hi in boxes[1:]:
            mask = cv2.bitwise_or(mask, cv2.inRange(hsv, lo, hi))
        return mask

    def matches(self, bgr: tuple[int, int, int]) -> bool:
        """Whether a single BGR colour passes this marker's colour gate."""
        hsv = cv2.cvtColor(np.array([[bgr]], dtype=np.uint8), cv2.COLOR_BGR2HSV)
        return bool(self.backproject(hsv)[0, 0])

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (JSON-ready), the same fields a colours file uses."""
        return {
            "bgr": list(self.bgr),
            "hue": [list(r) for r in self.hue],
            "sat_min": self.sat_min,
            "val_min": self.val_min,
        }


@declared
class MarkerSet:
    """The colour models of every marker, in file order.

    Parameters
    ----------
    markers : tuple of MarkerColour
        One per marker; names must be unique.
    """

    markers: Annotated[tuple[MarkerColour, ...], Tuple] = field(
        default_factory=lambda: DEFAULT_MARKERS.markers)

    def __post_init__(self) -> None:
        names = [m.name for m in self.markers]
        if not names or len(set(names)) != len(names):
            raise InputError(f"expected unique marker names, got {names}",
                             location=("MarkerSet", "markers"))

    @property
    def names(self) -> tuple[str, ...]:
        """Marker names in order."""
        return tuple(m.name for m in self.markers)

    def __getitem__(self, name: str) -> MarkerColour:
        for m in self.markers:
            if m.name == name:
                return m
        raise KeyError(f"no marker {name!r} (markers: {', '.join(self.names)})")

    def __iter__(self) -> Iterator[MarkerColour]:
        return iter(self.markers)

    def __len__(self) -> int:
        return len(self.markers)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """``{name: fields}`` in marker order, the shape of a colours file."""
        return {m.name: m.to_dict() for m in self.markers}

    def to_json(self) -> str:
        """JSON of :meth:`to_dict` (stored in ``/tracker`` attrs)."""
        return json.dumps(self.to_dict())

    def with_overrides(self, overrides: Mapping[str, Any], source: str = "") -> MarkerSet:
        """Return a copy with fields replaced from ``{marker: {field: value}}``.

        Parameters
        ----------
        overrides : mapping
            Marker name -> mapping of :class:`MarkerColour` fields (``bgr`` or
            ``rgb``, ``hue``, ``sat_min``, ``val_min``).
        source : str
            Where the overrides come from (``"[markers]"``), put before the
            field an error names.

        Raises
        ------
        InputError
            Unknown marker or field, or an invalid value; its field is
            ``marker.field`` (after ``source``), its location
            ``(marker, field)``.
        """
        def where(field: str | None = None) -> str | None:
            return " ".join(p for p in (source, field) if p) or None

        if not isinstance(overrides, Mapping):
            raise InputError(f"expected a table of markers, got {type(overrides).__name__}",
                             field=where())
        by_name = {m.name: m for m in self.markers}
        for name, table in overrides.items():
            if name not in by_name:
                raise InputError(f"unknown marker {name!r}{suggest(str(name), self.names)} "
                                 f"(expected one of {', '.join(self.names)})", field=where())
            if not isinstance(table, Mapping):
                raise InputError(f"expected a table of fields, got {table!r}"[:120],
                                 field=where(str(name)), location=(str(name),))
            unknown = sorted(set(table) - set(_FIELDS))
            if unknown:
                raise InputError(f"unknown field{suggest(unknown[0], _FIELDS)} "
                                 f"(expected {', '.join(_FIELDS)})",
                                 field=where(f"{name}.{unknown[0]}"),
                                 location=(str(name), unknown[0]))
            if "bgr" in table and "rgb" in table:
                raise InputError("give bgr or rgb, not both", field=where(str(name)),
                                 location=(str(name),))
            changes = {k: v for k, v in table.items() if k != "rgb"}
            if "rgb" in table:
                rgb = table["rgb"]
                changes["bgr"] = list(rgb)[::-1] if isinstance(rgb, (list, tuple)) else rgb
            try:
                by_name[name] = replace(by_name[name], **changes)
            except InputError as exc:
                key = exc.location[-1] if exc.location else ""
                key = "rgb" if key == "bgr" and "rgb" in table else key
                raise InputError(exc.problem, field=where(f"{name}.{key}"),
                                 location=(str(name), key)) from None
        return MarkerSet(tuple(by_name[n] for n in self.names))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "colours") -> MarkerSet:
        """Build from a full ``{name: fields}`` mapping (as :meth:`to_dict` writes)."""
        markers = []
        known = {f.name for f in fields(MarkerColour)}
        for name, table in data.items():
            kwargs = {k: v for k, v in dict(table).items() if k in known}
            try:
                markers.append(MarkerColour(name=name, **kwargs))
            except (ValueError, TypeError) as exc:
                raise ValueError(f"{source}: {exc}") from None
        return cls(tuple(markers))


def default_markers() -> MarkerSet:
    """The default colour models: thumb red, finger green, wrist blue, object yellow."""
    return DEFAULT_MARKERS


def load_markers(path: str | os.PathLike, base: MarkerSet | None = None) -> MarkerSet:
    """Read colour overrides from a JSON (``.json``) or TOML (other) file.

    Parameters
    ----------
    path : str or os.PathLike
        The colours file; its top-level keys are marker names.
    base : MarkerSet, optional
        Models to override (default :func:`default_markers`).

    Raises
    ------
    InputError
        Missing or unparsable file; an unknown marker or field (the nearest
        valid name is suggested); an invalid value (the message names
        ``marker.field``). The message names the file.
    """
    p = input_file(path, "colours file")
    base = default_markers() if base is None else base
    if p.suffix.lower() == ".json":
        try:
            raw = p.read_bytes()
        except OSError as exc:
            raise InputError(f"cannot read colours file ({exc.strerror})", p) from None
        try:
            data = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
            raise InputError(f"not valid JSON: {exc}", p) from None
    else:
        data = read_toml(p, "colours file")
    # Here rather than in with_overrides: a hand-written file's usual
    # mistake is a misspelling, and the nearest valid name fixes it.
    if isinstance(data, Mapping):
        check_keys(data, base.names, "the top level", p)
        for name, table in data.items():
            if isinstance(table, Mapping):
                check_keys(table, _FIELDS, f"marker {name!r}", p)
    try:
        return base.with_overrides(data)
    except InputError as exc:
        raise InputError(exc.problem, p, field=exc.field) from None


# Saturations sit well above skin's (~110) so a skin-coloured hand never
# passes the red gate even though its hue is only ~10 units away.
DEFAULT_MARKERS = MarkerSet(
    (
        MarkerColour("thumb", bgr=(30, 30, 210), hue=((172, 6),), sat_min=140, val_min=50),
        MarkerColour("finger", bgr=(50, 170, 40), hue=((48, 78),), sat_min=100, val_min=50),
        MarkerColour("wrist", bgr=(190, 80, 30), hue=((98, 124),), sat_min=110, val_min=40),
        MarkerColour("object", bgr=(30, 200, 220), hue=((20, 34),), sat_min=120, val_min=60),
    )
)

"""What a tracks file may hold: the checks :meth:`Tracks.load` runs on what it reads.

:meth:`~perception.io.tracks.Tracks.load` is the boundary where a corrupt or
hostile ``.tracks.h5`` stops, so everything it reads from HDF5 is checked
here before a :class:`~perception.io.tracks.Tracks` is built: the shapes the
``/tracks`` datasets claim (against :mod:`perception.limits`, before any is
read), the ``/video`` attributes, every value of the datasets (positions
within :func:`position_bounds` of the frame, likelihoods in 0..1, known status
codes) and the ``/tracker`` attributes readers use (marker sizes, the
``colour_models`` JSON).

Split from :mod:`perception.io.tracks` by topic (that module holds the
:class:`~perception.io.tracks.Tracks` object and its writer);
:func:`position_bounds` stays importable from there. This module must not
import :mod:`perception.io.tracks` (an import cycle), so the status codes the
checks accept are passed in.
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from perception.errors import InputError
from perception.io.hdf5 import check_dataset, decode_attrs
from perception.limits import (
    MAX_FPS,
    MAX_FRAMES,
    MAX_MARKERS,
    MAX_VIDEO_SIDE,
    POSITION_MARGIN,
)


def _check_shapes(fh, path: Path) -> None:
    """The shapes the datasets claim, checked against the limits before any is read."""
    shapes = {name: check_dataset(fh, f"tracks/{name}", kind, ndim, path).shape
              for name, (kind, ndim) in _DATASETS.items()}
    t, m = shapes["frame"][0], shapes["markers"][0]
    if t > MAX_FRAMES:
        raise InputError(f"claims {t} frames, more than the {MAX_FRAMES} a tracks file may "
                         "hold", path, field="/tracks/frame")
    if not 1 <= m <= MAX_MARKERS:
        raise InputError(f"claims {m} markers, expected 1 to {MAX_MARKERS}", path,
                         field="/tracks/markers")
    for name, shape in _row_shapes(t, m).items():
        if tuple(shapes[name]) != shape:
            raise InputError(f"has shape {tuple(shapes[name])}, expected {shape} "
                             f"({t} frames, {m} markers)", path, field=f"/tracks/{name}")


def _row_shapes(t: int, m: int) -> dict[str, tuple[int, ...]]:
    return {"frame": (t,), "time": (t,), "position": (t, m, 2), "likelihood": (t, m),
            "status": (t, m)}


def _check_video(video: Mapping[str, Any], path: Path) -> None:
    for key in ("width", "height"):
        v = video.get(key)
        if v is not None and not 1 <= v <= MAX_VIDEO_SIDE:
            raise InputError(f"is {v}, expected 1 to {MAX_VIDEO_SIDE} px", path,
                             field=f"/video.{key}")
    fps = video.get("fps_nominal")
    if fps is not None and not 0 <= fps <= MAX_FPS:
        raise InputError(f"is {fps:g}, expected a frame rate of 0 to {MAX_FPS:g} frames/s",
                         path, field="/video.fps_nominal")
    for key in ("n_frames", "n_frames_header"):
        v = video.get(key)
        if v is not None and not 0 <= v <= MAX_FRAMES:
            raise InputError(f"is {v}, expected 0 to {MAX_FRAMES}", path, field=f"/video.{key}")
    sha = video.get("sha256")
    if sha and not (len(sha) == 64 and all(c in "0123456789abcdef" for c in sha.lower())):
        raise InputError("is not a hex SHA-256", path, field="/video.sha256")


def position_bounds(video: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest believable ``(x, y)`` of a tracked position, px.

    :data:`~perception.limits.POSITION_MARGIN` frame sizes around the frame
    (of ``width`` x ``height`` from ``/video``; of the largest video read
    when the tracks do not say).

    Parameters
    ----------
    video : mapping
        ``/video`` attributes.
    """
    size = np.array([video.get("width") or MAX_VIDEO_SIDE, video.get("height") or MAX_VIDEO_SIDE],
                    dtype=float)
    return -POSITION_MARGIN * size, (1 + POSITION_MARGIN) * size


def _check_values(data: dict[str, np.ndarray], markers: tuple[str, ...],
                  video: Mapping[str, Any], path: Path, status_codes: Sequence[int]) -> None:
    """Every value of the datasets within range: the boundary where a corrupt file stops.

    ``status_codes`` are the known ``/tracks/status`` codes (``Status``'s values,
    passed in by :mod:`perception.io.tracks`, which this module must not import).
    """
    if len(set(markers)) != len(markers) or not all(markers):
        raise InputError("marker names must be distinct and non-empty", path,
                         field="/tracks/markers")
    frame, time = data["frame"], data["time"]
    if frame.size and (frame.min() < 0 or np.any(np.diff(frame) <= 0)):
        raise InputError("frame indices must be >= 0 and increasing", path,
                         field="/tracks/frame")
    time = np.asarray(time, dtype=float)
    if not np.all(np.isfinite(time)) or np.any(np.diff(time) < 0):
        raise InputError("times must be finite and non-decreasing", path, field="/tracks/time")
    pos = np.asarray(data["position"], dtype=float)
    if np.isinf(pos).any():
        raise InputError("an infinite position (lost points are NaN)", path,
                         field="/tracks/position")
    lo, hi = position_bounds(video)
    with np.errstate(invalid="ignore"):
        outside = (pos < lo) | (pos > hi)
    if outside.any():
        t, j, _ = np.argwhere(outside)[0]
        raise InputError(f"frame row {t}, marker {markers[j]}: position "
                         f"({pos[t, j, 0]:.6g}, {pos[t, j, 1]:.6g}) px lies far outside the "
                         f"frame ({hi[0] / (1 + POSITION_MARGIN):g} x "
                         f"{hi[1] / (1 + POSITION_MARGIN):g} px)", path,
                         field="/tracks/position")
    lik = np.asarray(data["likelihood"], dtype=float)
    if not np.all((lik >= 0) & (lik <= 1)):
        raise InputError("likelihoods must lie in 0..1", path, field="/tracks/likelihood")
    status = data["status"]
    if status.size and not np.isin(status, list(status_codes)).all():
        known = ", ".join(str(c) for c in status_codes)
        raise InputError(f"unknown status code (expected {known})", path,
                         field="/tracks/status")


def _check_tracker(tracker: Mapping[str, Any], markers: tuple[str, ...], path: Path) -> None:
    """The ``/tracker`` attributes readers use, of the type and range they expect."""
    for key in ("diameter_px", "reference_mass_px"):
        if key not in tracker:
            continue
        value = tracker[key]
        ok = isinstance(value, int | float | np.ndarray) and not isinstance(value, bool)
        if ok:
            arr = np.atleast_1d(np.asarray(value))
            ok = arr.dtype.kind in "iuf" and arr.ndim == 1 and len(arr) in (1, len(markers))
            if ok:
                arr = arr.astype(float)
                ok = bool(np.all(np.isnan(arr) | ((arr >= 0) & (arr < 1e9))))
        if not ok:
            raise InputError(f"expected one non-negative number per marker, got {value!r:.80}",
                             path, field=f"/tracker.{key}")
    if "colour_models" in tracker:
        value = tracker["colour_models"]
        models = None
        if isinstance(value, str):
            with contextlib.suppress(ValueError):
                models = json.loads(value)
        if not isinstance(models, dict):
            raise InputError("expected a JSON object of marker colour models", path,
                             field="/tracker.colour_models")
        for name, model in models.items():
            if not isinstance(model, dict):
                raise InputError(f"marker {name!r}: expected an object", path,
                                 field="/tracker.colour_models")
            bgr = model.get("bgr")
            if bgr is not None and not (
                    isinstance(bgr, list) and len(bgr) == 3
                    and all(isinstance(c, int) and not isinstance(c, bool) and 0 <= c <= 255
                            for c in bgr)):
                raise InputError(f"marker {name!r}: bgr must be 3 integers 0..255", path,
                                 field="/tracker.colour_models")


#: The datasets of ``/tracks``: (kind of dtype, number of dimensions).
_DATASETS = {"frame": ("integer", 1), "time": ("number", 1), "markers": ("string", 1),
             "position": ("number", 3), "likelihood": ("number", 2), "status": ("integer", 2)}
#: ``/video`` attributes readers use, and what each must be.
_VIDEO_ATTRS = {"path": "string", "sha256": "string", "fps_nominal": "number",
                "n_frames": "integer", "n_frames_header": "integer", "width": "integer",
                "height": "integer", "fourcc": "string", "time_source": "string"}


def _group_attrs(fh, name: str, path: Path) -> dict[str, Any]:
    import h5py

    if name not in fh:
        return {}
    if not isinstance(fh.get(name, getlink=True), h5py.HardLink) or not isinstance(
            fh[name], h5py.Group):
        raise InputError(f"/{name} is not a group stored in the file", path)
    return decode_attrs(fh[name].attrs, f"/{name}", path)

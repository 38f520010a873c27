"""Marker tracks: the :class:`Tracks` object and its HDF5 file (``<clip>.tracks.h5``).

Schema (docs/tracks-format.md), written with h5py::

    /            attrs: schema="hammer-mv/tracks", schema_version, software_version
    /video       attrs: path, sha256, fps_nominal, n_frames, width, height, fourcc
    /tracks/frame      int64   (T,)      decoded frame index
    /tracks/time       float64 (T,)      s, from the container's timestamps
    /tracks/markers    str     (M,)      thumb, finger, wrist, object
    /tracks/position   float64 (T,M,2)   px; NaN where lost (never 0)
    /tracks/likelihood float32 (T,M)     0..1; 0 where lost
    /tracks/status     int8    (T,M)     0 tracked, 1 reacquired, 2 lost, 3 interpolated,
                                        4 ambiguous
    /tracker     attrs: colour models, termination criteria, parameters

The datasets are chunked and resizable; :class:`TracksWriter` appends to them
a chunk at a time while tracking, so memory does not grow with the video.
Extra groups (e.g. ``/truth`` in rendered ground truth) are allowed and
ignored by :meth:`Tracks.load`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import h5py  # imported where a file is opened: a pose or motion-capture file needs none
    import pandas as pd  # imported by the table methods: `hammer-mv track` starts without it

from minvar import __version__
from perception.errors import InputError
from perception.io.atomic import atomic_hdf5
from perception.io.hdf5 import check_schema, decode_attrs, open_hdf5, read_dataset, scalar_attr
from perception.io.tracks_checks import (
    _DATASETS,
    _VIDEO_ATTRS,
    _check_shapes,
    _check_tracker,
    _check_values,
    _check_video,
    _group_attrs,
    _row_shapes,
)
from perception.io.tracks_checks import position_bounds as position_bounds  # re-exported
from perception.provenance import code_digest

SCHEMA = "hammer-mv/tracks"
SCHEMA_VERSION = 1

#: An interpolated point's likelihood is this fraction of the weaker of the
#: two detections it bridges: below DeepLabCut's default cutoff (0.6), so
#: tools that filter by likelihood never take a bridge for a detection.
INTERPOLATED_LIKELIHOOD = 0.5

#: The per-frame datasets of ``/tracks`` and their dtypes, in the order they are written.
#: What a position is in (:attr:`Tracks.units`): image pixels, or metres in a plane.
UNITS = ("px", "m")
_DTYPES = {"frame": np.int64, "time": np.float64, "position": np.float64,
           "likelihood": np.float32, "status": np.int8}


class Status(enum.IntEnum):
    """Per-frame, per-marker status codes (``/tracks/status``)."""

    TRACKED = 0
    REACQUIRED = 1
    LOST = 2
    INTERPOLATED = 3
    AMBIGUOUS = 4


def _attr_value(value: Any) -> Any:
    """Make a value storable as an HDF5 attribute (JSON for anything structured)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, Path):
        value = os.fspath(value)
    if isinstance(value, str):
        # HDF5 strings are UTF-8: a file name's undecodable bytes (lone
        # surrogates in Python) are stored as visible escapes
        return value.encode("utf-8", "backslashreplace").decode("utf-8")
    if isinstance(value, (int, float, np.integer, np.floating)):
        return value
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        return value  # numeric arrays as read back from a file: store them as they are
    if isinstance(value, (list, tuple)) and value and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        return np.asarray(value)
    return json.dumps(value)


def _write_attrs(attrs: h5py.AttributeManager, values: Mapping[str, Any]) -> None:
    for key, value in values.items():
        attrs[key] = _attr_value(value)


@dataclass(frozen=True, eq=False)
class Tracks:
    """Marker positions over time, as tracked (or as rendered ground truth).

    Attributes
    ----------
    frame : (T,) int64
        Decoded frame index of each row.
    time : (T,) float64
        Frame time, s (container timestamps).
    markers : tuple of str
        Marker names, M of them, in column order.
    position : (T, M, 2) float64
        Image position (x right, y down), px; NaN where lost. Metres, x right
        and y up, where :attr:`units` is ``"m"`` (a motion-capture reach in
        its movement's plane).
    likelihood : (T, M) float32
        0..1; 0 where lost.
    status : (T, M) int8
        :class:`Status` codes.
    video : mapping
        ``/video`` attributes.
    tracker : mapping
        ``/tracker`` attributes.
    attrs : mapping
        Root attributes beyond the schema's own (e.g. a rendered clip's label).
    path : Path or None
        File the tracks were loaded from.
    """

    frame: np.ndarray
    time: np.ndarray
    markers: tuple[str, ...]
    position: np.ndarray
    likelihood: np.ndarray
    status: np.ndarray
    video: Mapping[str, Any] = field(default_factory=dict)
    tracker: Mapping[str, Any] = field(default_factory=dict)
    attrs: Mapping[str, Any] = field(default_factory=dict)
    path: Path | None = None

    def __post_init__(self) -> None:
        if isinstance(self.markers, str):  # not one marker per letter
            raise ValueError(f"Tracks.markers: expected a sequence of marker names, got the "
                             f"string {self.markers!r}")
        markers = tuple(str(m) for m in self.markers)
        arrays = {name: np.asarray(getattr(self, name), dtype=dtype)
                  for name, dtype in _DTYPES.items()}
        frame = arrays["frame"]
        t, m = frame.shape[0] if frame.ndim == 1 else -1, len(markers)
        for name, shape in _row_shapes(t, m).items():
            if arrays[name].shape != shape:
                raise ValueError(f"Tracks.{name}: expected shape {shape} (T, M={m}), "
                                 f"got {arrays[name].shape}")
        for name, value in {"markers": markers, **arrays}.items():
            object.__setattr__(self, name, value)
        for name in ("video", "tracker", "attrs"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))
        if self.units not in UNITS:
            raise ValueError(f"Tracks.tracker['units']: expected one of {', '.join(UNITS)}, "
                             f"got {self.units!r}")

    def __reduce__(self):
        # MappingProxyType does not pickle: batch workers send tracks between processes
        return Tracks, (self.frame, self.time, self.markers, self.position, self.likelihood,
                        self.status, dict(self.video), dict(self.tracker), dict(self.attrs),
                        self.path)

    # -- basic views --------------------------------------------------------
    @property
    def n_frames(self) -> int:
        """T, the number of rows."""
        return int(self.frame.shape[0])

    def __len__(self) -> int:
        return self.n_frames

    def index(self, name: str) -> int:
        """Column of marker ``name``."""
        try:
            return self.markers.index(name)
        except ValueError:
            raise KeyError(f"no marker {name!r} (markers: {', '.join(self.markers)})") from None

    @property
    def units(self) -> str:
        """``"px"`` (image pixels, y down) or ``"m"`` (metres in a plane, y up): the
        ``/tracker`` attribute ``units``, pixels where it is absent."""
        return str(self.tracker.get("units", "px"))

    def object_diameter_px(self, name: str = "object") -> float | None:
        """Apparent diameter of the round object in pixels, if the tracks can tell.

        The ``/tracker`` attribute ``diameter_px``: what the tracker measured
        when it first found the object (fully visible, before the hand
        reaches it) from its colour-unmixed area, or, in a rendered clip's
        ground truth, the true apparent diameter. Files written before that
        attribute existed give the diameter of a disc of the object's
        reference blob area (about 3 % large on blurred footage).

        Parameters
        ----------
        name : str
            The object's marker name.
        """
        if name not in self.markers:
            return None
        j = self.markers.index(name)
        for key, to_diameter in (("diameter_px", float),
                                 ("reference_mass_px", lambda a: 2 * np.sqrt(a / np.pi))):
            values = self.tracker.get(key)
            if values is None:
                continue
            values = np.atleast_1d(np.asarray(values, dtype=float))
            if len(values) == len(self.markers) and np.isfinite(values[j]) and values[j] > 0:
                return float(to_diameter(values[j]))
        return None

    def marker(self, name: str) -> np.ndarray:
        """(T, 2) px positions of one marker (a view; NaN where lost)."""
        return self.position[:, self.index(name)]

    @property
    def valid(self) -> np.ndarray:
        """(T, M) bool, True where the position is known (not lost)."""
        return np.isfinite(self.position).all(axis=-1)

    def __repr__(self) -> str:
        span = f"{self.time[0]:.3f}-{self.time[-1]:.3f} s" if self.n_frames else "empty"
        where = f", {self.path.name}" if self.path is not None else ""
        return (f"Tracks({self.n_frames} frames, {span}, markers {', '.join(self.markers)}"
                f"{where})")

    def replace(self, **changes: Any) -> Tracks:
        """Copy with some attributes replaced."""
        return dataclasses.replace(self, **changes)

    # -- processing ---------------------------------------------------------
    def interpolate(self, max_gap: int = 5) -> Tracks:
        """Fill short gaps linearly in time; filled samples get status 3.

        A gap is a run of lost frames with a known position on both sides;
        runs at the start or end, and runs longer than ``max_gap`` frames, stay
        NaN. A filled sample's likelihood is :data:`INTERPOLATED_LIKELIHOOD`
        times the lower of the two bounding likelihoods: a bridge is less
        certain than either end, and stays below the usual likelihood cutoffs.

        Parameters
        ----------
        max_gap : int
            Longest gap filled, frames (0 fills nothing).

        Returns
        -------
        Tracks
            A new object; this one is unchanged.
        """
        if max_gap < 0:
            raise ValueError(f"interpolate: max_gap: expected >= 0 frames, got {max_gap}")
        position = self.position.copy()
        likelihood = self.likelihood.copy()
        status = self.status.copy()
        valid = self.valid
        for j in range(len(self.markers)):
            ok = np.flatnonzero(valid[:, j])
            if ok.size < 2:
                continue
            for g in np.flatnonzero(np.diff(ok) > 1):
                a, b = ok[g], ok[g + 1]
                if b - a - 1 > max_gap:
                    continue
                inner = slice(a + 1, b)
                w = (self.time[inner] - self.time[a]) / (self.time[b] - self.time[a])
                position[inner, j] = position[a, j] + w[:, None] * (position[b, j] - position[a, j])
                weaker = min(likelihood[a, j], likelihood[b, j])
                likelihood[inner, j] = INTERPOLATED_LIKELIHOOD * weaker
                status[inner, j] = Status.INTERPOLATED
        return self.replace(position=position, likelihood=likelihood, status=status)

    def rows(self, start: int, stop: int) -> Tracks:
        """Rows ``[start, stop)`` as a view (``frame`` keeps the original frame indices).

        ``attrs["trimmed_rows"]`` records ``(start, stop)``; the tracks file
        itself always keeps every frame.

        Parameters
        ----------
        start, stop : int
            Row range, as in a slice.
        """
        s = slice(start, stop)
        return self.replace(frame=self.frame[s], time=self.time[s], position=self.position[s],
                            likelihood=self.likelihood[s], status=self.status[s],
                            attrs={**self.attrs, "trimmed_rows": (start, stop)})

    # -- tables -----------------------------------------------------------
    def to_dlc(self, scorer: str = "hammer-mv") -> pd.DataFrame:
        """DeepLabCut-style wide table.

        Index: frame. Columns: MultiIndex ``(scorer, bodyparts, coords)`` with
        coords ``x, y, likelihood`` per marker. NaN where lost.
        """
        import pandas as pd

        cols = pd.MultiIndex.from_product([[scorer], list(self.markers), ["x", "y", "likelihood"]],
                                          names=["scorer", "bodyparts", "coords"])
        data = np.concatenate([self.position, self.likelihood[..., None].astype(np.float64)],
                              axis=-1).reshape(self.n_frames, -1)
        return pd.DataFrame(data, index=pd.Index(self.frame, name="frame"), columns=cols)

    def to_trackpy(self) -> pd.DataFrame:
        """trackpy-style long table, one row per frame and *seen* marker.

        Columns: ``frame, time, particle`` (marker column index), ``marker,
        x, y, likelihood, status``. Lost points have no row: trackpy's
        ``link`` and ``imsd`` expect only real positions.
        """
        import pandas as pd

        t, m = self.n_frames, len(self.markers)
        markers = np.tile(np.array(self.markers, dtype=object), t)
        table = pd.DataFrame({
            "frame": np.repeat(self.frame, m),
            "time": np.repeat(self.time, m),
            "particle": np.tile(np.arange(m), t),
            "marker": pd.Categorical(markers, categories=list(self.markers)),
            "x": self.position[..., 0].ravel(),
            "y": self.position[..., 1].ravel(),
            "likelihood": self.likelihood.ravel(),
            "status": self.status.ravel(),
        })
        return table[self.valid.ravel()].reset_index(drop=True)

    def to_status(self) -> pd.DataFrame:
        """Status codes as a wide table: ``frame`` then one column per marker (:class:`Status`)."""
        import pandas as pd

        data: dict[str, Any] = {"frame": self.frame}
        data.update({name: self.status[:, j] for j, name in enumerate(self.markers)})
        return pd.DataFrame(data)

    def to_pandas(self) -> pd.DataFrame:
        """Plain wide table: ``frame, time`` then ``<marker>_x, _y, _likelihood, _status``."""
        import pandas as pd

        data: dict[str, Any] = {"frame": self.frame, "time": self.time}
        for j, name in enumerate(self.markers):
            data[f"{name}_x"] = self.position[:, j, 0]
            data[f"{name}_y"] = self.position[:, j, 1]
            data[f"{name}_likelihood"] = self.likelihood[:, j]
            data[f"{name}_status"] = self.status[:, j]
        return pd.DataFrame(data)

    # -- files ----------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> Path:
        """Write this object as a tracks file (atomically); return the path."""
        with TracksWriter(path, self.markers, video=self.video, tracker=self.tracker,
                          attrs=self.attrs) as w:
            w.extend(self.frame, self.time, self.position, self.likelihood, self.status)
        return Path(path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Tracks:
        """Read a tracks file, checking its schema, version and every object it reads.

        Parameters
        ----------
        path : str or os.PathLike
            The ``.tracks.h5`` (or ``.truth.h5``) file.

        Raises
        ------
        InputError
            Missing file, not HDF5, another schema or version, a missing,
            linked, misshapen or mistyped dataset or attribute; the message
            names the file and the object.
        """
        p = Path(path)
        with open_hdf5(p, "tracks file") as fh:
            root = decode_attrs(fh.attrs, "/", p)
            check_schema(root, SCHEMA, SCHEMA_VERSION, "tracks file", p)
            for key in ("schema", "schema_version", "software_version"):
                root.pop(key, None)
            _check_shapes(fh, p)
            data = {name: read_dataset(fh, f"tracks/{name}", kind, ndim, p)
                    for name, (kind, ndim) in _DATASETS.items()}
            markers = tuple(m.decode("utf-8") if isinstance(m, bytes) else str(m)
                            for m in data.pop("markers"))
            video = _group_attrs(fh, "video", p)
            for key, kind in _VIDEO_ATTRS.items():
                scalar_attr(video, key, kind, "/video", p)
            _check_video(video, p)
            tracker = _group_attrs(fh, "tracker", p)
        _check_values(data, markers, video, p, [int(s) for s in Status])
        _check_tracker(tracker, markers, p)
        try:
            return cls(markers=markers, video=video, tracker=tracker, attrs=root, path=p, **data)
        except ValueError as exc:
            raise InputError(f"inconsistent datasets: {exc}", p, field="/tracks") from None


def marker_counts(path: str | os.PathLike) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """The markers of a tracks file this process has just written, (T, M) whether each was
    placed, and (M,) its ambiguous frames: three datasets read, nothing checked
    (:meth:`Tracks.load` checks the whole file: 10 ms at the end of every ``track``).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.tracks.h5`` file.
    """
    import h5py

    with h5py.File(path, "r") as fh:
        markers = tuple(m.decode("utf-8") if isinstance(m, bytes) else str(m)
                        for m in fh["tracks/markers"][()])
        placed = np.isfinite(fh["tracks/position"][()]).all(axis=-1)
        ambiguous = (fh["tracks/status"][()] == Status.AMBIGUOUS).sum(axis=0)
    return markers, placed, ambiguous


class TracksWriter:
    """Stream tracks into a new HDF5 file, a chunk of frames at a time.

    Rows are buffered in memory ``chunk_frames`` at a time and appended to
    chunked, resizable datasets, so memory stays flat however long the video.
    The file is built in memory (a few tens of bytes per frame) and written
    under a temporary name, renamed when the block exits cleanly; if it
    raises, or the disk is full, nothing is left behind.

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    markers : sequence of str
        Marker names, M of them.
    video, tracker, attrs : mapping, optional
        ``/video``, ``/tracker`` and extra root attributes; may be updated
        with :meth:`update` before the block ends.
    chunk_frames : int
        Rows per HDF5 chunk and per write.

    Examples
    --------
    >>> with TracksWriter("clip.tracks.h5", ["thumb"]) as w:  # doctest: +SKIP
    ...     w.append(0, 0.0, [[10.0, 20.0]], [1.0], [0])
    """

    def __init__(self, path: str | os.PathLike, markers: Sequence[str], *,
                 video: Mapping[str, Any] | None = None, tracker: Mapping[str, Any] | None = None,
                 attrs: Mapping[str, Any] | None = None, chunk_frames: int = 512):
        self.path = Path(path)
        self.markers = tuple(markers)
        if not self.markers:
            raise ValueError("TracksWriter.markers: expected at least one marker")
        if chunk_frames < 1:
            raise ValueError(f"TracksWriter.chunk_frames: expected >= 1, got {chunk_frames}")
        self.meta = {"video": dict(video or {}), "tracker": dict(tracker or {}),
                     "attrs": dict(attrs or {})}
        self.chunk = int(chunk_frames)
        self._buf = {name: np.empty(shape, _DTYPES[name])
                     for name, shape in _row_shapes(self.chunk, len(self.markers)).items()}
        self._n_buf = 0
        self.n_written = 0
        self._stack: contextlib.ExitStack | None = None
        self._fh: h5py.File | None = None

    def update(self, *, video=None, tracker=None, attrs=None) -> None:
        """Add or replace ``/video``, ``/tracker`` or root attributes (written at close)."""
        for key, values in (("video", video), ("tracker", tracker), ("attrs", attrs)):
            if values:
                self.meta[key].update(values)

    def __enter__(self) -> TracksWriter:
        # An error here exits the atomic output with it (its temporary file is removed);
        # pop_all keeps the file open past the block otherwise.
        with contextlib.ExitStack() as stack:
            import h5py

            fh = stack.enter_context(atomic_hdf5(self.path))
            g = fh.create_group("tracks")
            g.create_dataset("markers", data=np.array(self.markers, dtype=object),
                             dtype=h5py.string_dtype())
            for name, buf in self._buf.items():
                row = buf.shape[1:]
                g.create_dataset(name, shape=(0, *row), maxshape=(None, *row), chunks=buf.shape,
                                 dtype=buf.dtype, fillvalue=np.nan if name == "position" else 0)
            self._stack, self._fh = stack.pop_all(), fh
        return self

    def append(self, frame: int, time: float, position, likelihood, status) -> None:
        """Append one frame's row.

        Parameters
        ----------
        frame : int
            Frame index.
        time : float
            Frame time, s.
        position : (M, 2) array_like
            px; NaN where lost.
        likelihood : (M,) array_like
            0..1.
        status : (M,) array_like of int
            :class:`Status` codes.
        """
        for buf, value in zip(self._buf.values(), (frame, time, position, likelihood, status)):
            buf[self._n_buf] = value
        self._n_buf += 1
        if self._n_buf == self.chunk:
            self.flush()

    def extend(self, frame, time, position, likelihood, status) -> None:
        """Append many rows at once (arrays with a leading T axis)."""
        self.flush()
        values = (frame, time, position, likelihood, status)
        arrays = {name: np.asarray(v, dtype) for (name, dtype), v in zip(_DTYPES.items(), values)}
        t = arrays["frame"].shape[0]
        for name, shape in _row_shapes(t, len(self.markers)).items():
            if arrays[name].shape != shape:
                raise ValueError(f"TracksWriter.extend: {name}: expected shape {shape}, "
                                 f"got {arrays[name].shape}")
        self._write(arrays, t)

    def flush(self) -> None:
        """Write buffered rows to the file."""
        if self._n_buf:
            n = self._n_buf
            self._write({k: v[:n] for k, v in self._buf.items()}, n)
            self._n_buf = 0

    def _write(self, arrays: Mapping[str, np.ndarray], n: int) -> None:
        if n == 0:
            return
        g = self._fh["tracks"]
        start = self.n_written
        for name, arr in arrays.items():
            ds = g[name]
            ds.resize(start + n, axis=0)
            ds[start : start + n] = arr
        self.n_written = start + n

    def __exit__(self, exc_type, exc, tb) -> bool:
        assert self._stack is not None and self._fh is not None
        if exc_type is not None:
            return bool(self._stack.__exit__(exc_type, exc, tb))
        with self._stack:  # an error while finishing removes the temporary file too
            self.flush()
            fh = self._fh
            # software_digest: what tracks reuse is keyed on (perception.pipeline.current_tracks)
            fh.attrs.update(schema=SCHEMA, schema_version=SCHEMA_VERSION,
                            software_version=__version__, software_digest=code_digest())
            _write_attrs(fh.attrs, self.meta["attrs"])
            _write_attrs(fh.require_group("video").attrs, self.meta["video"])
            _write_attrs(fh.require_group("tracker").attrs, self.meta["tracker"])
        return False

    @property
    def file(self) -> h5py.File:
        """The open (temporary) HDF5 file, for writers adding their own groups."""
        assert self._fh is not None, "TracksWriter: use inside a with block"
        return self._fh


def tracks_path_for(video: str | os.PathLike) -> Path:
    """Default tracks file of a video: ``<stem>.tracks.h5`` beside it."""
    v = Path(video)
    return v.with_name(f"{v.stem}.tracks.h5")

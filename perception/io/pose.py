"""Pose files of other tools <-> :class:`~perception.io.tracks.Tracks`.

Markerless trackers write keypoints, not colour markers: DeepLabCut (``.h5``
and ``.csv``), SLEAP (analysis ``.h5``, labels ``.slp``), Lightning Pose
(``.csv``) and NWB files, all read through the ``movement`` package, and
``movement``'s own datasets saved as netCDF (``.nc``). :func:`read_pose`
turns one of them into tracks of the four markers recognition needs — thumb,
finger, wrist and object — by a keypoint mapping (:class:`PoseImport`);
points below the likelihood cutoff (DeepLabCut's ``pcutoff``, 0.6 by default)
count as lost, and the tracks are cleaned as motion capture is (DeepLabCut's
single-frame jumps are spikes: :mod:`perception.track_cleaning`, here where
the file is read, so that every command reads the same tracks).
:mod:`perception.io.exports` goes the other way.
Files DeepLabCut and SLEAP name after their video (:func:`pose_output`) without
a frame rate take that video's (:func:`video_beside`).

``movement`` pulls in many packages (xarray, netCDF4, PyTables, pynwb,
sleap-io), so it is an optional extra: ``pip install 'hammer-mv[pose]'``.
It is imported through :mod:`perception.io.movement_import`, which keeps its
import from writing under HOME. A DeepLabCut csv of plain numbers (as DeepLabCut
writes it) is read without movement or pandas (:func:`_plain_dlc`,
:mod:`perception.io.plain_tables`), exactly as they read it: their imports were
most of a ``recognize``'s start-up.
docs/pose-files.md describes the mapping, the scale and every format.
"""

from __future__ import annotations

import functools
import importlib.util
import itertools
import json
import logging
import math
import os
import re
import types
import warnings
from collections.abc import Mapping
from dataclasses import field
from pathlib import Path
from types import MappingProxyType
from typing import Annotated, Any

import numpy as np
from pydantic import Field, PlainValidator

from perception.errors import InputError
from perception.io.files import input_file
from perception.io.movement_import import DLC_KEY, dlc_inputs, require_movement
from perception.io.movement_import import POSE_EXTRA as _EXTRA
from perception.io.movement_import import VALIDATOR as _VALIDATOR
from perception.io.movement_import import movement_loaders as _movement
from perception.io.names import POSE_SUFFIXES, TRACKS_SUFFIX, VIDEO_SUFFIXES
from perception.io.plain_tables import dlc_table
from perception.io.pose_arrays import (
    PoseTable,
    check_sizes,
    check_space,
    frame_times,
    marker_keys,
    pick_individual,
    unique_fill,
)
from perception.io.pose_mapping import keypoint_mapping, object_at_grip
from perception.io.pose_sleap_csv import is_sleap_csv, sleap_csv_dataset
from perception.io.tracks import Status, Tracks, position_bounds
from perception.limits import MAX_FPS, MAX_FRAMES, MAX_KEYPOINTS, MAX_POSE_POINTS
from perception.track_cleaning import TrackCleaning, clean_tracks
from perception.validation import Positive, Share, declared

__all__ = [
    "DLC_KEY",
    "MARKERS",
    "POSE_SUFFIXES",
    "PoseImport",
    "is_pose_file",
    "load_pose_config",
    "pose_output",
    "read_pose",
    "video_beside",
]

log = logging.getLogger(__name__)

#: The markers recognition needs, in the tracks' column order.
MARKERS = ("thumb", "finger", "wrist", "object")
#: ``movement``'s name for each source, by how the file is recognised.
_SOURCES = {"dlc": "DeepLabCut", "sleap": "SLEAP", "lp": "LightningPose", "nwb": "NWB"}
_VIDEO = r"\.(?:mp4|avi|mkv|mov|m4v)"
#: ``<video stem>`` and a DeepLabCut scorer (``DLC_…``; ``DeepCut_…`` before DeepLabCut 2.1).
_DLC = r"(?P<video>.+?)(?-i:DLC|DeepCut)_.+?"
#: What DeepLabCut and SLEAP write beside a video (docs/pose-files.md), first match
#: wins: the rank of a pose file among those of its video (the highest is scored), or
#: why the file is not one.
_OUTPUTS = tuple((re.compile(pattern, re.IGNORECASE), what) for pattern, what in (
    (_DLC + r"_?filtered\.h5", 3),
    (_DLC + r"_?filtered\.csv", 2),
    (_DLC + r"_skeleton\.(?:h5|csv)", "DeepLabCut's bone lengths (analyzeskeleton), not poses"),
    (_DLC + r"\.h5", 1),
    (_DLC + r"\.csv", 0),
    (_DLC + r"\.nwb", -1),
    (_DLC + r"\.pickle", "DeepLabCut's metadata or raw detections, not poses"),
    (_DLC + r"(?:labeled|_full)" + _VIDEO, "DeepLabCut's labelled video, not a trial"),
    (r"(?:.*\.\d{3}_)?(?P<video>.+?)(?:" + _VIDEO + r")?(?:\.predictions)?\.analysis\.h5", 1),
    (r"(?:.*\.\d{3}_)?(?P<video>.+?)(?:" + _VIDEO + r")?(?:\.predictions)?\.analysis\.csv", 0),
    (r"(?P<video>.+?)(?:" + _VIDEO + r")?\.predictions\.slp", 0),
))


def _keypoints(value: Any) -> Mapping[str, str]:
    """A pose file's marker -> keypoint mapping, each marker on a keypoint of its own."""
    mapping = dict(value) if isinstance(value, Mapping) else None
    if mapping is None or not all(isinstance(v, str) and v for v in mapping.values()):
        raise InputError("expected marker=KEYPOINT with a keypoint name")
    unknown = sorted(set(mapping) - set(MARKERS))
    if unknown:
        raise InputError(f"unknown marker {unknown[0]!r} (expected {', '.join(MARKERS)})")
    resolved = {m: mapping.get(m, m) for m in MARKERS}
    for i, m in enumerate(MARKERS):
        other = [o for o in MARKERS[:i] if resolved[o] == resolved[m]]
        if other:
            raise InputError(f"{other[0]} and {m} both map to keypoint {resolved[m]!r}: "
                             "each marker needs its own keypoint (markers left out map "
                             "to a keypoint of their own name)")
    return MappingProxyType(mapping)


@declared
class PoseImport:
    """How a pose file becomes tracks.

    Parameters
    ----------
    keypoints : mapping of str to str
        Marker (``thumb``, ``finger``, ``wrist``, ``object``) -> keypoint name
        in the file. Markers left out map to a keypoint of the same name.
    individual : str, optional
        The individual to take from a multi-individual file (required when
        the file holds more than one).
    pcutoff : float
        Points whose likelihood is below this count as lost (DeepLabCut's
        default plotting cutoff, 0.6).
    fps : float, optional
        Frame rate, frames/s, for files that carry none (DeepLabCut and
        Lightning Pose tables, SLEAP analysis files); a file's own rate wins
        when it has one. Without it, the rate the header of the video beside
        the file states (:func:`video_beside`).
    object_diameter_px : float, optional
        The object's apparent diameter in pixels, which sets the metric
        scale with ``--object-diameter`` (a pose file cannot carry it); or
        give the scale outright with ``--px-per-m`` when recognising.
    cleaning : TrackCleaning, optional
        How the keypoints' spikes, held samples and gaps are cleaned (the
        motion-capture rules at the clip's scale: give it the scale the
        recognition uses, ``TrackCleaning(px_per_m=...)``); None: not cleaned.
    """

    keypoints: Annotated[Mapping[str, str], PlainValidator(_keypoints)] = field(
        default_factory=lambda: MappingProxyType({}))
    individual: str | None = None
    pcutoff: Share = 0.6
    fps: Annotated[float, Field(gt=0, le=MAX_FPS)] | None = None
    object_diameter_px: Positive | None = None
    cleaning: TrackCleaning | None = field(default_factory=TrackCleaning)

    def __reduce__(self):
        # MappingProxyType does not pickle: batch workers get the options sent
        return PoseImport, (dict(self.keypoints), self.individual, self.pcutoff, self.fps,
                            self.object_diameter_px, self.cleaning)

    def to_dict(self) -> dict[str, Any]:
        """The options as JSON-able data (for reports and resume fingerprints)."""
        return {"keypoints": dict(self.keypoints), "individual": self.individual,
                "pcutoff": self.pcutoff, "fps": self.fps,
                "object_diameter_px": self.object_diameter_px,
                "cleaning": None if self.cleaning is None else self.cleaning.to_dict()}

    def keypoint(self, marker: str) -> str:
        """The keypoint asked for ``marker``: the mapping's, else the marker's own name
        (a file without it has one taken by its name on reading:
        :func:`~perception.io.pose_mapping.keypoint_mapping`; ``/tracker keypoints``
        records what was read).

        Parameters
        ----------
        marker : str
            One of :data:`MARKERS`.
        """
        return self.keypoints.get(marker, marker)


#: Keys of a pose config file besides its ``[keypoints]`` table.
_CONFIG_KEYS = ("individual", "pcutoff", "fps", "object_diameter_px")


def load_pose_config(path: str | os.PathLike) -> PoseImport:
    """Read a pose config (TOML) for a batch of pose files.

    ::

        pcutoff = 0.6               # optional, as the options of the same names
        fps = 30
        object_diameter_px = 82.0
        individual = "mouse1"

        [keypoints]                 # marker = keypoint name in the files
        thumb = "Thumb_tip"
        finger = "Index_tip"
        wrist = "Wrist"
        object = "ball"

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Raises
    ------
    InputError
        Missing or malformed file, an unknown table or key, or bad values.
    """
    from perception.io.config import check_keys, read_toml

    cfg = read_toml(path, "pose config")
    try:
        check_keys(cfg, ("keypoints", *_CONFIG_KEYS), "the top level")
        mapping = cfg.get("keypoints", {})
        if not isinstance(mapping, dict):
            raise ValueError("[keypoints] must be a table of marker = keypoint name")
        check_keys(mapping, MARKERS, "[keypoints]")
        return PoseImport(keypoints={k: str(v) for k, v in mapping.items()},
                          **{k: cfg[k] for k in _CONFIG_KEYS if k in cfg})
    except InputError as exc:
        key = exc.location[-1] if exc.location else None
        where = "[keypoints]" if key == "keypoints" else key
        raise InputError(f"bad pose config: {exc.problem}", path, field=where) from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"bad pose config: {exc}", path) from None


def is_pose_file(path: str | os.PathLike) -> bool:
    """Whether ``path`` looks like a pose file (by its name; the content decides on reading).

    Parameters
    ----------
    path : str or os.PathLike
        A file name.
    """
    name = Path(path).name.lower()
    return name.endswith(POSE_SUFFIXES) and not name.endswith(TRACKS_SUFFIX)


def pose_output(name: str) -> tuple[str, int | str] | None:
    """``(video stem, rank)`` of a pose file DeepLabCut or SLEAP named after its video (a
    video's highest is scored), ``(video stem, why not)`` of their other outputs, else None.

    Parameters
    ----------
    name : str
        A file name (``trial01DLC_resnet50_reachJan1shuffle1_100000.h5``: ``trial01``).
    """
    for pattern, what in _OUTPUTS:
        if found := pattern.fullmatch(name):
            return found["video"], what
    return None


def video_beside(path: str | os.PathLike) -> Path | None:
    """The video a pose file was made from: ``<video stem>.mp4`` (``.avi``, …) beside it.

    Parameters
    ----------
    path : str or os.PathLike
        A pose file; its video stem is its own (``trial01.h5``) or that of
        its DeepLabCut or SLEAP name (:func:`pose_output`).
    """
    stem = _video_stem(Path(path))
    videos = (Path(path).with_name(stem + s) for e in VIDEO_SUFFIXES for s in (e, e.upper()))
    return next((v for v in videos if v.is_file()), None)


def _video_stem(path: Path) -> str:
    found = pose_output(path.name)
    return found[0] if found else path.stem


def _video_rate(path: Path) -> float:
    """The frame rate the header of the video beside a pose file states."""
    video = video_beside(path)
    if video is None:
        raise InputError(f"the pose file has no frame rate, and there is no video "
                         f"{_video_stem(path)}.mp4 (.avi, .mkv, .mov, .m4v) beside it: give it "
                         "with `fps`", path, field="fps")
    from perception.io.video import FrameSource  # OpenCV only when there is a video

    try:
        source = FrameSource(video, prefetch=0, hash=False)
    except InputError as exc:
        raise InputError(f"the pose file has no frame rate, nor has its video {video.name}: "
                         f"{exc.problem.removesuffix('; give the true rate with `fps`')}; "
                         "give it with `fps`", path, field="fps") from None
    source.close()
    return source.header.fps_nominal


#: DeepLabCut's labelled frames (``labeled-data/<video>/CollectedData_<scorer>.csv``/``.h5``).
_LABELLED = ("DeepLabCut's labelled frames (CollectedData: a row per labelled image), not a "
             "video's keypoints: give the .h5 or .csv DeepLabCut's analyze_videos wrote")


def _source(path: Path) -> str:
    """Which tool wrote a pose file: ``dlc``, ``sleap``, ``lp``, ``nwb`` or ``movement``."""
    suffix = path.suffix.lower()
    output = pose_output(path.name)
    if output is not None and isinstance(output[1], str):  # DeepLabCut's, but not poses
        raise InputError(output[1], path)
    by_suffix = {".nc": "movement", ".slp": "sleap", ".nwb": "nwb"}
    if suffix in by_suffix:
        return by_suffix[suffix]
    if suffix == ".csv":
        with open(path, encoding="utf-8", errors="replace") as fh:
            first = fh.readline().strip().lower()
        if first.startswith("scorer,,"):  # the index is folder, video and image: 3 columns
            raise InputError(_LABELLED, path)
        if is_sleap_csv(first):
            return "sleap"
        # DeepLabCut's first header row names the scorer; Lightning Pose writes the same table
        return "dlc" if first.startswith("scorer") else "lp"
    import h5py

    try:
        with h5py.File(path, "r") as fh:
            if fh.attrs.get("schema") is not None:
                raise InputError("a hammer-mv HDF5 file, not a pose file "
                                 "(tracks files end in .tracks.h5)", path)
            if DLC_KEY in fh:
                return "dlc"
            if "tracks" in fh and "node_names" in fh:
                return "sleap"
            if "keypoints" in fh:
                raise InputError(_LABELLED, path)
    except OSError:
        raise InputError("not an HDF5 file (or unreadable)", path) from None
    raise InputError("an HDF5 file that is neither a DeepLabCut table "
                     f"(key {DLC_KEY!r}) nor a SLEAP analysis file", path)


def _check_hdf5_sizes(path: Path, source: str) -> None:
    """What an HDF5 pose file's datasets claim, checked before anything is read."""
    import h5py

    found: list[tuple[str, tuple[int, ...], int]] = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            dtype = obj.dtype
            width = max(len(dtype.fields), dtype.itemsize // 8, 1) if dtype.fields else 1
            found.append((f"/{name}", tuple(int(n) for n in obj.shape or ()), width))

    try:
        with h5py.File(path, "r") as fh:
            fh.visititems(visit)
    except OSError:
        raise InputError("not an HDF5 file (or unreadable)", path) from None
    for name, shape, width in found:
        values = math.prod(shape) * width
        if values > 3 * MAX_POSE_POINTS:
            raise InputError(f"claims shape {shape} ({values:.3g} values), more than a pose "
                             f"file may hold ({MAX_POSE_POINTS:.3g} points)", path, field=name)
        rows = shape[-1] if source == "sleap" and name == "/tracks" and shape else (
            shape[0] if source == "dlc" and name.startswith(f"/{DLC_KEY}") and shape else 0)
        if rows > MAX_FRAMES:
            raise InputError(f"claims {rows} frames, more than the {MAX_FRAMES} a pose file may "
                             "hold", path, field=name)
        if source == "sleap" and name == "/tracks" and len(shape) == 4 and (
                shape[2] > MAX_KEYPOINTS):
            raise InputError(f"claims {shape[2]} keypoints, more than {MAX_KEYPOINTS}", path,
                             field=name)


#: Largest text table read, bytes (x, y and likelihood of MAX_POSE_POINTS).
_MAX_TABLE_BYTES = 24 * MAX_POSE_POINTS


def _csv_levels(path: Path) -> list[str]:
    """The header rows of a DeepLabCut csv: with ``individuals`` where it is multi-animal."""
    with open(path, encoding="utf-8", errors="replace") as fh:
        second = fh.readline() and fh.readline()
    return (["scorer", "individuals", "bodyparts", "coords"]
            if second.lower().startswith("individuals") else ["scorer", "bodyparts", "coords"])


def _plain_dlc(path: Path, fps: float | None) -> tuple[PoseTable, np.ndarray] | None:
    """A DeepLabCut csv of plain numbers as :func:`dlc_inputs` and :func:`_own_frames` read
    it through pandas, read without pandas or movement (their imports are most of a
    ``recognize``'s start-up: issue 45); None for any other table, read as before.

    The common case only: DeepLabCut's header (``x``, ``y``, ``likelihood`` of each
    keypoint, individuals and keypoints in order), integer frame numbers, numbers or empty
    cells (:mod:`perception.io.plain_tables`); whatever movement's validator would refuse
    (or pandas read otherwise) is left to them, so errors read the same.
    """
    levels = _csv_levels(path)
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        return None  # pandas says why
    read = dlc_table(text, len(levels))
    if read is None:
        return None
    columns, frames, values = read
    keyed = [c[1:] for c in columns]  # (individual,) bodypart, coord
    names = [list(dict.fromkeys(c[k] for c in keyed)) for k in range(len(keyed[0]))]
    individuals = names[0] if len(levels) == 4 else ["individual_0"]
    keypoints, coords = names[-2], names[-1]
    if coords != ["x", "y", "likelihood"] or keyed != list(itertools.product(*names)):
        return None
    _check_table_size(len(values), len(columns), path)
    # movement's arrays: (time, coords, keypoints, individuals), as dlc_inputs makes them
    tracks = values.reshape((-1, len(individuals), len(keypoints), 3)).transpose(0, 3, 2, 1)
    fps = None if fps is None else float(fps)  # movement's converter: a rate <= 0 is none
    valid = types.SimpleNamespace(
        position_array=tracks[:, [0, 1], :, :], confidence_array=tracks[:, 2, :, :],
        individual_names=individuals, keypoint_names=keypoints,
        fps=None if fps is not None and fps <= 0 else fps, source_software="DeepLabCut")
    return PoseTable(valid), _own_frames(frames, len(frames))


def _dlc_table(path: Path):
    """A DeepLabCut table as DeepLabCut writes it: its own frame index, MultiIndex columns."""
    import pandas as pd

    if path.suffix.lower() == ".csv":
        levels = _csv_levels(path)
        df = pd.read_csv(path, header=list(range(len(levels))))
        df = df.set_index(df.columns[0])
        df.index.name = None
        df.columns = pd.MultiIndex.from_tuples(df.columns, names=levels)
        return df
    try:
        import tables  # noqa: F401 - pandas' HDF reader needs PyTables
    except ImportError:
        raise InputError(_EXTRA, path) from None
    return pd.DataFrame(pd.read_hdf(path, key=DLC_KEY))


def _own_frames(index, n: int) -> np.ndarray | None:
    """A table's row index as frame numbers, if it is one (integers, >= 0, increasing)."""
    try:
        values = np.asarray(index, dtype=float)
    except (TypeError, ValueError):
        return None  # labelled-image paths, not frame numbers
    if (values.shape != (n,) or not np.all(np.isfinite(values))
            or not np.all(values == np.round(values)) or (n and values.min() < 0)
            or np.any(np.diff(values) <= 0) or (n and values.max() > 2 ** 53)):
        return None
    return values.astype(np.int64)


def _load_dataset(path: Path, source: str, fps: float | None):
    """The file as a ``movement`` poses dataset, and the file's own frame numbers (or None)."""
    if source == "dlc":  # a DeepLabCut table needs only movement's validator (dlc_inputs)
        if importlib.util.find_spec("movement") is None:  # found, not imported (0.4 s)
            require_movement(_VALIDATOR)  # the error naming the extra
    else:
        load_dataset, _ = _movement()
    suffix = path.suffix.lower()
    if suffix in (".h5", ".slp", ".nwb", ".nc"):
        try:
            _check_hdf5_sizes(path, source)
        except InputError:
            if suffix != ".nc":  # a netCDF3 file is not HDF5: xarray checks it lazily below
                raise
        if suffix == ".slp":
            _check_untracked(path)
    elif path.stat().st_size > _MAX_TABLE_BYTES:
        raise InputError(f"a table of {path.stat().st_size / 1e9:.3g} GB holds more than the "
                         f"{MAX_POSE_POINTS:.3g} points a pose file may hold", path)
    try:
        with warnings.catch_warnings():
            # movement's own notes (a file without individuals, say) are not the user's business
            warnings.simplefilter("ignore")
            if source == "movement":
                import xarray as xr

                with xr.open_dataset(path) as lazy:
                    _check_sizes(lazy, path)
                    ds = lazy.load()
                if "position" not in ds or ds.attrs.get("ds_type", "poses") != "poses":
                    raise InputError("a netCDF file that is not a movement poses dataset", path)
                return ds, None
            if source == "dlc":
                plain = _plain_dlc(path, fps) if suffix == ".csv" else None
                if plain is not None:
                    return plain
                require_movement(_VALIDATOR)
                df = _dlc_table(path)
                if len(df) and str(df.index[0]).lower().endswith((".png", ".jpg", ".jpeg")):
                    raise InputError(_LABELLED, path)  # DeepLabCut 2.1's one-column index
                _check_sizes_table(df, path)
                ds = PoseTable(dlc_inputs(df, fps))
                return ds, _own_frames(df.index, len(df))
            if suffix == ".csv" and source == "sleap":  # movement reads SLEAP's HDF5 only
                return sleap_csv_dataset(path, fps), None
            return load_dataset(path, source_software=_SOURCES[source], fps=fps), None
    except InputError:
        raise
    except MemoryError:
        raise InputError("too large to read", path) from None
    except (OSError, ValueError, KeyError, TypeError, AttributeError, IndexError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputError(f"not a readable {_SOURCES.get(source, source)} pose file: {first}",
                         path) from None


def _check_untracked(path: Path) -> None:
    """Refuse a SLEAP labels file whose frames hold several instances of no track: which is
    which from frame to frame is not known (movement keeps one of each frame's, silently:
    two hands would be read as one hand jumping between them)."""
    import h5py

    try:
        with h5py.File(path, "r") as fh:
            if "instances" not in fh:
                return
            inst = fh["instances"].fields(["frame_id", "instance_type", "track"])[:]
    except (OSError, KeyError, ValueError):
        return  # movement says what is wrong with the file
    free = inst[inst["track"] < 0]
    if not len(free):
        return
    # a user's instance beside the prediction it corrects is one animal: count each kind
    _, counts = np.unique(np.stack([free["frame_id"].astype(np.int64),
                                    free["instance_type"].astype(np.int64)]), axis=1,
                          return_counts=True)
    if counts.max() > 1:
        raise InputError(f"frames hold up to {int(counts.max())} instances without a track: "
                         "which is which from frame to frame is not known; track them in "
                         "SLEAP (a track per animal or hand, then choose one with "
                         "`individual`) or keep one instance a frame", path)


def _check_sizes(ds, path: Path) -> None:
    check_sizes(dict(ds.sizes), path)


def _check_sizes_table(df, path: Path) -> None:
    _check_table_size(len(df), len(df.columns), path)


def _check_table_size(rows: int, columns: int, path: Path) -> None:
    if rows > MAX_FRAMES:
        raise InputError(f"holds {rows} frames, more than the {MAX_FRAMES} a pose file may "
                         "hold", path)
    if columns > 3 * MAX_KEYPOINTS * 16 or rows * columns > 3 * MAX_POSE_POINTS:
        raise InputError(f"holds {columns} columns of {rows} frames, more than a pose "
                         "file may hold", path)


def _seen(position, table: bool) -> list[str] | None:
    """The individuals with a position in some frame (None: the file has no individuals)."""
    if table:
        finite = np.isfinite(np.asarray(position.position, dtype=np.float64))
        return [n for n, f in zip(position.individuals, finite.any(axis=(0, 1, 2))) if f]
    if "individuals" not in position.dims:
        return None
    finite = position["position"].notnull().any([d for d in position["position"].dims
                                                 if d != "individuals"])
    return [str(n) for n, f in zip(position["individuals"].values, finite.values) if f]


def _marker_arrays(ds, keys: Mapping[str, str], path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(T, M, 2) px positions and (T, M) likelihoods of the markers' keypoints ``keys``."""
    keys = marker_keys([str(k) for k in ds["keypoints"].values], keys, path)
    pos = ds["position"].transpose("time", "keypoints", "space")
    check_space(pos.sizes["space"], path)
    xy = np.asarray(pos.sel(keypoints=keys).values, dtype=np.float64)
    if "confidence" in ds and bool(ds["confidence"].notnull().any()):  # NaN: no scores
        conf = ds["confidence"].transpose("time", "keypoints").sel(keypoints=keys).values
        conf = np.nan_to_num(np.asarray(conf, dtype=np.float64), nan=0.0)
    else:  # a file without scores: every seen point is as good as the file says
        conf = np.isfinite(xy).all(axis=-1).astype(np.float64)
    return xy, np.clip(conf, 0.0, 1.0)


def _markers(ds, options: PoseImport, path: Path, own: np.ndarray | None):
    """Frames, times (s), frame rate, (T, 4, 2) px positions, (T, 4) likelihoods and the
    keypoint of each marker (None: an object placed where the grip ends its reach), with
    notes on what was guessed, of a ``movement`` dataset or a DeepLabCut table
    (:class:`PoseTable`)."""
    check_sizes(dict(ds.sizes), path)
    rate = functools.partial(_video_rate, path)
    table = isinstance(ds, PoseTable)
    names = ds.keypoints if table else [str(k) for k in ds["keypoints"].values]
    mapping, notes = keypoint_mapping(names, options.keypoints, MARKERS)
    keys = {m: k for m, k in mapping.items() if k is not None}
    individuals = ds.individuals if table else (
        [str(n) for n in ds["individuals"].values] if "individuals" in ds.dims else [])
    try:
        seen = _seen(ds, table)
    except (TypeError, ValueError):  # text in a column: said where the arrays are read
        seen = None
    who, more = pick_individual(individuals, options.individual, path, seen)
    notes += more
    if table:
        frames, time, fps = frame_times(ds.sizes["time"], ds.time, ds.attrs, options.fps, own,
                                        rate, path)

        def arrays(name):
            return ds.markers(name, keys, path)
    else:
        frames, time, fps = frame_times(ds.sizes["time"], ds["time"].values, ds.attrs,
                                        options.fps, own, rate, path)

        def arrays(name):
            return _marker_arrays(ds if name is None else ds.sel(individuals=name), keys, path)
    filled = unique_fill(individuals, who, keys, arrays)
    if filled is None:
        xy, conf = arrays(who if individuals else None)
    else:
        xy, conf, more = filled
        notes += more
    if mapping["object"] is None:
        hand = np.where((conf >= options.pcutoff)[..., None], xy, np.nan)
        place = object_at_grip(hand)
        xy = np.concatenate([xy, place[:, None]], axis=1)
        conf = np.concatenate([conf, np.isfinite(place).all(axis=1)[:, None] * 1.0], axis=1)
    return frames, time, fps, xy, conf, mapping, notes


def _check_positions(xy: np.ndarray, mapping: Mapping[str, str | None], path: Path) -> None:
    """Positions NaN (not found) or within a believable distance of any frame, px."""
    lo, hi = position_bounds({})
    with np.errstate(invalid="ignore"):
        bad = np.isinf(xy) | (xy < lo) | (xy > hi)
    if bad.any():
        t, j, _ = np.argwhere(bad)[0]
        raise InputError(f"keypoint {mapping[MARKERS[j]]!r} at row {t} lies at "
                         f"({xy[t, j, 0]:.6g}, {xy[t, j, 1]:.6g}) px, beyond any frame "
                         f"(at most {hi[0]:g} px)", path, field="position")


def read_pose(path: str | os.PathLike, options: PoseImport | None = None) -> Tracks:
    """Read a pose file as tracks of thumb, finger, wrist and object.

    Parameters
    ----------
    path : str or os.PathLike
        A DeepLabCut ``.h5``/``.csv``, SLEAP ``.h5``/``.slp``, Lightning Pose
        ``.csv``, NWB ``.nwb`` or ``movement`` netCDF ``.nc`` file.
    options : PoseImport, optional
        Keypoint mapping, individual, likelihood cutoff, frame rate, object size.

    Returns
    -------
    Tracks
        Positions in the file's pixels; a point below ``pcutoff`` (or missing)
        is lost: NaN, likelihood 0, status lost. Cleaned by
        ``options.cleaning`` (:func:`~perception.track_cleaning.clean_tracks`):
        spikes and held points lost, short gaps bridged (status
        interpolated). ``/tracker`` records the source and the repairs.

    Raises
    ------
    InputError
        Missing or unreadable file, an unknown format, a keypoint or individual
        not in the file, no frame rate (nor video beside it), or the ``pose`` extra
        not installed.
    """
    options = PoseImport() if options is None else options
    path = Path(path)
    if not os.path.exists(path):
        raise InputError("no such file", path)
    input_file(path, "pose file", empty=False)  # a FIFO or device would block or never end
    source = _source(path)
    ds, own = _load_dataset(path, source, options.fps)
    frames, time, fps, xy, conf, mapping, notes = _markers(ds, options, path, own)
    _check_positions(xy, mapping, path)
    seen = np.isfinite(xy).all(axis=-1) & (conf >= options.pcutoff)
    position = np.where(seen[..., None], xy, np.nan)
    diameter = [options.object_diameter_px if m == "object" and options.object_diameter_px
                else math.nan for m in MARKERS]
    software = ds.attrs.get("source_software") or _SOURCES.get(source, "movement")
    for note in notes:  # the one line a command shows of what it took on trust
        log.warning("%s: %s", path.name, note)
    tracker = {"method": f"pose:{software}", "source_file": os.fspath(path),
               "keypoints": json.dumps(mapping), "reading_notes": json.dumps(notes),
               "individual": options.individual or "", "pcutoff": options.pcutoff,
               "diameter_px": diameter}
    video = {"path": os.fspath(path), "fps_nominal": fps, "n_frames": int(len(time))}
    tracks = Tracks(frame=frames, time=time, markers=MARKERS, position=position,
                    likelihood=np.where(seen, conf, 0.0).astype(np.float32),
                    status=np.where(seen, Status.TRACKED, Status.LOST).astype(np.int8),
                    video=video, tracker=tracker, path=path)
    return tracks if options.cleaning is None else clean_tracks(tracks, options.cleaning)

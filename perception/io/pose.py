"""Pose files of other tools <-> :class:`~perception.io.tracks.Tracks`.

Markerless trackers write keypoints, not colour markers: DeepLabCut (``.h5``
and ``.csv``), SLEAP (analysis ``.h5``, labels ``.slp``), Lightning Pose
(``.csv``) and NWB files, all read through the ``movement`` package, and
``movement``'s own datasets saved as netCDF (``.nc``). :func:`read_pose`
turns one of them into tracks of the four markers recognition needs — thumb,
finger, wrist and object — by a keypoint mapping (:class:`PoseImport`);
points below the likelihood cutoff (DeepLabCut's ``pcutoff``, 0.6 by default)
count as lost. :func:`write_dlc` and :func:`write_movement` go the other way.

``movement`` pulls in many packages (xarray, netCDF4, PyTables, pynwb,
sleap-io), so it is an optional extra: ``pip install 'hammer-mv[pose]'``.
docs/pose-files.md describes the mapping, the scale and every format.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from perception.errors import InputError
from perception.io.atomic import atomic_path
from perception.io.tracks import Status, Tracks

__all__ = [
    "DLC_KEY",
    "MARKERS",
    "POSE_SUFFIXES",
    "PoseImport",
    "is_pose_file",
    "read_pose",
    "write_dlc",
    "write_movement",
]

#: The markers recognition needs, in the tracks' column order.
MARKERS = ("thumb", "finger", "wrist", "object")
#: File endings read as pose files (a ``.h5`` is a pose file unless it is a tracks file).
POSE_SUFFIXES = (".h5", ".csv", ".slp", ".nc", ".nwb")
#: The pandas HDF key of a DeepLabCut ``.h5`` table (as DeepLabCut writes it).
DLC_KEY = "df_with_missing"
#: ``movement``'s name for each source, by how the file is recognised.
_SOURCES = {"dlc": "DeepLabCut", "sleap": "SLEAP", "lp": "LightningPose", "nwb": "NWB"}
_EXTRA = "reading and writing pose files needs the optional extra: pip install 'hammer-mv[pose]'"


def _movement():
    """The ``movement`` package's loaders and savers, or a one-line error naming the extra."""
    try:
        from movement.io import load_poses, save_poses
    except ImportError:
        raise InputError(_EXTRA) from None
    return load_poses, save_poses


@dataclass(frozen=True)
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
        Lightning Pose tables); a file's own rate wins when it has one.
    object_diameter_px : float, optional
        The object's apparent diameter in pixels, which sets the metric
        scale with ``--object-diameter`` (a pose file cannot carry it); or
        give the scale outright with ``--px-per-m`` when recognising.
    """

    keypoints: Mapping[str, str] = field(default_factory=dict)
    individual: str | None = None
    pcutoff: float = 0.6
    fps: float | None = None
    object_diameter_px: float | None = None

    def __post_init__(self) -> None:
        mapping = dict(self.keypoints)
        unknown = sorted(set(mapping) - set(MARKERS))
        if unknown:
            raise ValueError(f"--keypoints: unknown marker {unknown[0]!r} "
                             f"(expected {', '.join(MARKERS)})")
        object.__setattr__(self, "keypoints", MappingProxyType(mapping))
        if not (isinstance(self.pcutoff, int | float) and 0 <= self.pcutoff <= 1):
            raise ValueError(f"--pcutoff: expected a likelihood between 0 and 1, "
                             f"got {self.pcutoff!r}")
        for name in ("fps", "object_diameter_px"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise ValueError(f"--{name.replace('_', '-')}: expected a positive number, "
                                 f"got {value!r}")

    def to_dict(self) -> dict[str, Any]:
        """The options as JSON-able data (for reports and resume fingerprints)."""
        return {"keypoints": dict(self.keypoints), "individual": self.individual,
                "pcutoff": self.pcutoff, "fps": self.fps,
                "object_diameter_px": self.object_diameter_px}

    def keypoint(self, marker: str) -> str:
        """The file's keypoint name for ``marker``.

        Parameters
        ----------
        marker : str
            One of :data:`MARKERS`.
        """
        return self.keypoints.get(marker, marker)


def is_pose_file(path: str | os.PathLike) -> bool:
    """Whether ``path`` looks like a pose file (by its name; the content decides on reading).

    Parameters
    ----------
    path : str or os.PathLike
        A file name.
    """
    name = Path(path).name.lower()
    return name.endswith(POSE_SUFFIXES) and not name.endswith(".tracks.h5")


def _source(path: Path) -> str:
    """Which tool wrote a pose file: ``dlc``, ``sleap``, ``lp``, ``nwb`` or ``movement``."""
    suffix = path.suffix.lower()
    if suffix == ".nc":
        return "movement"
    if suffix == ".slp":
        return "sleap"
    if suffix == ".nwb":
        return "nwb"
    if suffix == ".csv":
        with open(path, encoding="utf-8", errors="replace") as fh:
            first = fh.readline().strip().lower()
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
    except OSError:
        raise InputError("not an HDF5 file (or unreadable)", path) from None
    raise InputError("an HDF5 file that is neither a DeepLabCut table "
                     f"(key {DLC_KEY!r}) nor a SLEAP analysis file", path)


def _load_dataset(path: Path, source: str, fps: float | None):
    """The file as a ``movement`` poses dataset."""
    load_poses, _ = _movement()
    try:
        if source == "movement":
            import xarray as xr

            ds = xr.load_dataset(path)
            if "position" not in ds or ds.attrs.get("ds_type", "poses") != "poses":
                raise InputError("a netCDF file that is not a movement poses dataset", path)
            return ds
        return load_poses.from_file(path, source_software=_SOURCES[source], fps=fps)
    except InputError:
        raise
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputError(f"not a readable {_SOURCES.get(source, source)} pose file: {first}",
                         path) from None


def _pick_individual(ds, options: PoseImport, path: Path):
    names = [str(n) for n in ds["individuals"].values] if "individuals" in ds.dims else []
    if options.individual is not None:
        if options.individual not in names:
            raise InputError(f"--individual {options.individual!r}: not in the file "
                             f"(individuals: {', '.join(names) or 'none'})", path)
        return ds.sel(individuals=options.individual)
    if len(names) > 1:
        raise InputError(f"the file holds {len(names)} individuals ({', '.join(names)}): "
                         "choose one with --individual", path)
    return ds.isel(individuals=0) if names else ds


def _frame_times(ds, options: PoseImport, path: Path) -> tuple[np.ndarray, np.ndarray, float]:
    """Frame indices, times (s) and the frame rate of a dataset."""
    n = ds.sizes["time"]
    coords = np.asarray(ds["time"].values, dtype=float)
    unit = ds.attrs.get("time_unit", "frames")
    fps = ds.attrs.get("fps")
    fps = float(fps) if fps is not None and np.isfinite(float(fps)) and float(fps) > 0 else None
    if unit == "seconds" and fps:
        return np.rint(coords * fps).astype(np.int64), coords, fps
    fps = fps or options.fps
    if fps is None:
        raise InputError("the pose file has no frame rate: give it with --fps", path)
    frames = coords.astype(np.int64) if len(coords) == n else np.arange(n)
    return frames, frames / fps, fps


def _marker_arrays(ds, options: PoseImport, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(T, 4, 2) px positions and (T, 4) likelihoods of the mapped keypoints."""
    names = [str(k) for k in ds["keypoints"].values]
    missing = [f"{m}={options.keypoint(m)}" for m in MARKERS if options.keypoint(m) not in names]
    if missing:
        raise InputError(f"keypoint {missing[0].split('=')[1]!r} (for "
                         f"{missing[0].split('=')[0]}) is not in the file (keypoints: "
                         f"{', '.join(names)}); map the markers with --keypoints "
                         "thumb=NAME finger=NAME wrist=NAME object=NAME", path)
    pos = ds["position"].transpose("time", "keypoints", "space")
    if pos.sizes["space"] != 2:
        raise InputError(f"expected 2-D poses (x, y), got {pos.sizes['space']} coordinates",
                         path)
    keys = [options.keypoint(m) for m in MARKERS]
    xy = np.asarray(pos.sel(keypoints=keys).values, dtype=np.float64)
    if "confidence" in ds:
        conf = ds["confidence"].transpose("time", "keypoints").sel(keypoints=keys).values
        conf = np.nan_to_num(np.asarray(conf, dtype=np.float64), nan=0.0)
    else:  # a file without scores: every seen point is as good as the file says
        conf = np.isfinite(xy).all(axis=-1).astype(np.float64)
    return xy, np.clip(conf, 0.0, 1.0)


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
        is lost: NaN, likelihood 0, status lost. ``/tracker`` records the source.

    Raises
    ------
    InputError
        Missing or unreadable file, an unknown format, a keypoint or individual
        not in the file, no frame rate, or the ``pose`` extra not installed.
    """
    options = PoseImport() if options is None else options
    path = Path(path)
    if not path.is_file():
        raise InputError("no such file", path)
    source = _source(path)
    ds = _pick_individual(_load_dataset(path, source, options.fps), options, path)
    frames, time, fps = _frame_times(ds, options, path)
    xy, conf = _marker_arrays(ds, options, path)
    seen = np.isfinite(xy).all(axis=-1) & (conf >= options.pcutoff)
    position = np.where(seen[..., None], xy, np.nan)
    diameter = [options.object_diameter_px if m == "object" and options.object_diameter_px
                else math.nan for m in MARKERS]
    software = ds.attrs.get("source_software") or _SOURCES.get(source, "movement")
    tracker = {"method": f"pose:{software}", "source_file": os.fspath(path),
               "keypoints": json.dumps({m: options.keypoint(m) for m in MARKERS}),
               "individual": options.individual or "", "pcutoff": options.pcutoff,
               "diameter_px": diameter}
    video = {"path": os.fspath(path), "fps_nominal": fps, "n_frames": int(len(time))}
    return Tracks(frame=frames, time=time, markers=MARKERS, position=position,
                  likelihood=np.where(seen, conf, 0.0).astype(np.float32),
                  status=np.where(seen, Status.TRACKED, Status.LOST).astype(np.int8),
                  video=video, tracker=tracker, path=path)


def write_dlc(tracks: Tracks, path: str | os.PathLike, *, scorer: str = "hammer-mv") -> Path:
    """Write tracks as a DeepLabCut table: a real ``.h5`` (pandas HDF) or a ``.csv``.

    The ``.h5`` holds the table under the key ``df_with_missing`` with the
    ``scorer / bodyparts / coords`` column MultiIndex, as DeepLabCut writes
    it; the ``.csv`` has DeepLabCut's three header rows.

    Parameters
    ----------
    tracks : Tracks
        What to write.
    path : str or os.PathLike
        Output file ending in ``.h5`` or ``.csv``.
    scorer : str
        The ``scorer`` level of the columns.
    """
    path = Path(path)
    table = tracks.to_dlc(scorer).rename_axis(None)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        with atomic_path(path) as tmp:
            table.to_csv(tmp, na_rep="NaN")
        return path
    if suffix != ".h5":
        raise InputError("a DeepLabCut file ends in .h5 or .csv", path)
    try:
        import tables  # noqa: F401 - pandas' HDF writer needs PyTables
    except ImportError:
        raise InputError(_EXTRA, path) from None
    with atomic_path(path) as tmp:
        table.to_hdf(tmp, key=DLC_KEY, mode="w", format="table")
    return path


def write_movement(tracks: Tracks, path: str | os.PathLike) -> Path:
    """Write tracks as a ``movement`` poses dataset in netCDF (``.nc``).

    One individual (``hammer-mv``), the markers as keypoints, the likelihood
    as ``confidence``, times in seconds; ``status`` (per frame and marker)
    rides along as an extra data variable.

    Parameters
    ----------
    tracks : Tracks
        What to write.
    path : str or os.PathLike
        Output file (``.nc``).
    """
    load_poses, _ = _movement()
    path = Path(path)
    fps = _fps(tracks)
    pos = np.transpose(tracks.position, (0, 2, 1))[..., None]  # (time, space, keypoints, ind)
    ds = load_poses.from_numpy(pos, tracks.likelihood.astype(np.float64)[..., None],
                               individual_names=["hammer-mv"],
                               keypoint_names=list(tracks.markers), fps=fps,
                               source_software="hammer-mv")
    ds = ds.assign_coords(time=tracks.time)  # the real time stamps, not index / fps
    ds["status"] = (("time", "keypoints", "individuals"), tracks.status[..., None])
    ds.attrs["frame_offset"] = int(tracks.frame[0]) if tracks.n_frames else 0
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp)
    return path


def _fps(tracks: Tracks) -> float:
    """The tracks' frame rate: from the video header, else from the time stamps."""
    nominal = float(tracks.video.get("fps_nominal", 0) or 0)
    if nominal > 0:
        return nominal
    dt = np.diff(tracks.time)
    return float(1.0 / np.median(dt)) if len(dt) else 30.0

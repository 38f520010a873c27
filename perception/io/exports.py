"""Tracks as the tables and files other tools read (``hammer-mv tracks export``).

=========== ============================================================
format      what is written
=========== ============================================================
``dlc``     DeepLabCut: a real ``.h5`` (pandas HDF, key ``df_with_missing``)
            or a ``.csv`` with DeepLabCut's three header rows, by the
            output's ending; the status codes go to ``<stem>.status.csv``
            beside it (DeepLabCut's table has no place for them)
``movement`` a ``movement`` poses dataset in netCDF (``.nc``)
``trackpy`` a long table, one row per frame and seen marker (lost points
            have no row)
``csv``     a plain wide table: ``frame, time`` and per marker ``_x, _y,
            _likelihood, _status``
=========== ============================================================

docs/tracks-format.md gives every column.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

import numpy as np

from perception.errors import InputError
from perception.io.atomic import write_bytes, write_text
from perception.io.movement_import import DLC_KEY, POSE_EXTRA, movement_loaders
from perception.io.tracks import Tracks
from perception.limits import MAX_MARKERS

__all__ = ["EXPORT_FORMATS", "export_tracks", "status_path_for", "write_dlc", "write_movement"]

#: Formats of :func:`export_tracks`.
EXPORT_FORMATS = ("dlc", "trackpy", "csv", "movement")


def status_path_for(path: str | os.PathLike) -> Path:
    """The status side file of a DeepLabCut export: ``<stem>.status.csv`` beside it.

    Parameters
    ----------
    path : str or os.PathLike
        The DeepLabCut file.
    """
    p = Path(path)
    return p.with_name(f"{p.stem}.status.csv")


def _write_csv(table, path: Path) -> None:
    # the whole text in memory, written and synced under a temporary name and
    # renamed: a full disk is an OSError and leaves nothing behind
    write_text(path, table.to_csv(index=False, na_rep="NaN"))


def export_tracks(tracks: Tracks, path: str | os.PathLike, format: str) -> list[Path]:
    """Write ``tracks`` in ``format`` to ``path``; return the files written.

    Parameters
    ----------
    tracks : Tracks
        What to write.
    path : str or os.PathLike
        Output file (for ``dlc``, its ending picks ``.h5`` or ``.csv``; for
        ``movement``, ``.nc``).
    format : {"dlc", "trackpy", "csv", "movement"}
        See the module's table.

    Raises
    ------
    InputError
        An unknown format, or an ending the format cannot write.
    """
    path = Path(path)
    if format not in EXPORT_FORMATS:
        raise InputError(f"expected one of {', '.join(EXPORT_FORMATS)}, got {format!r}",
                         field="format")
    _check_markers(tracks, tracks.path)
    if format == "dlc":
        write_dlc(tracks, path)
        status = status_path_for(path)
        try:
            _write_csv(tracks.to_status(), status)
        except BaseException:
            # both files or neither: a table without its status codes is not the export
            with contextlib.suppress(OSError):
                path.unlink()
            raise
        return [path, status]
    if format == "movement":
        if path.suffix.lower() != ".nc":
            raise InputError("a movement dataset is written as netCDF: end the name in .nc",
                             path)
        return [write_movement(tracks, path)]
    _write_csv(tracks.to_trackpy() if format == "trackpy" else tracks.to_pandas(), path)
    return [path]


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
    _check_markers(tracks, path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".h5"):
        raise InputError("a DeepLabCut file ends in .h5 or .csv", path)
    table = tracks.to_dlc(scorer).rename_axis(None)
    if suffix == ".csv":
        write_text(path, table.to_csv(na_rep="NaN"))
        return path
    try:
        import tables  # noqa: F401 - pandas' HDF writer needs PyTables
    except ImportError:
        raise InputError(POSE_EXTRA, path) from None
    write_bytes(path, _hdf_image(table))
    return path


def _hdf_image(table) -> bytes:
    """A DataFrame as the bytes of a pandas HDF file (key ``df_with_missing``), built in memory.

    PyTables' own writes to a full disk fail late or not at all (leaving a
    table of zeros); the image is written with :func:`write_bytes` instead,
    whose failure is an :class:`OSError` and leaves nothing behind.
    """
    import pandas as pd

    with pd.HDFStore(f"hammer-mv-{id(table)}.h5", mode="w", driver="H5FD_CORE",
                     driver_core_backing_store=0) as store:
        store.put(DLC_KEY, table, format="table", track_times=False)
        store.flush()
        return bytes(store._handle.get_file_image())


def _check_markers(tracks: Tracks, path: Path) -> None:
    if len(tracks.markers) > MAX_MARKERS:
        raise InputError(f"the tracks hold {len(tracks.markers)} markers, more than the "
                         f"{MAX_MARKERS} an export may hold", path, field="markers")


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
    _, load_poses = movement_loaders()
    path = Path(path)
    _check_markers(tracks, path)
    fps = _fps(tracks)
    pos = np.transpose(tracks.position, (0, 2, 1))[..., None]  # (time, space, keypoints, ind)
    ds = load_poses.from_numpy(pos, tracks.likelihood.astype(np.float64)[..., None],
                               individual_names=["hammer-mv"],
                               keypoint_names=list(tracks.markers), fps=fps,
                               source_software="hammer-mv")
    ds = ds.assign_coords(time=tracks.time)  # the real time stamps, not index / fps
    ds["status"] = (("time", "keypoints", "individuals"), tracks.status[..., None])
    ds.attrs["frame_offset"] = int(tracks.frame[0]) if tracks.n_frames else 0
    # Built in memory and written whole: netCDF's own writes onto a full disk
    # fail late (or crash the process) and leave a partial file.
    try:
        image = ds.to_netcdf(engine="h5netcdf")
    except (ImportError, ValueError):
        image = ds.to_netcdf()
    write_bytes(path, bytes(image))
    return path


def _fps(tracks: Tracks) -> float:
    nominal = float(tracks.video.get("fps_nominal", 0) or 0)
    if nominal > 0:
        return nominal
    dt = np.diff(tracks.time)
    return float(1.0 / np.median(dt)) if len(dt) else 30.0

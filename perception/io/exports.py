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

from perception.errors import InputError
from perception.io.atomic import write_text
from perception.io.pose import _check_markers, write_dlc, write_movement
from perception.io.tracks import Tracks

__all__ = ["EXPORT_FORMATS", "export_tracks", "status_path_for"]

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

"""Motion-capture recordings -> :class:`MocapTrial`: 3D marker positions in metres.

The layouts read, each by its own module: Qualisys Track Manager TSV exports
(:mod:`~perception.io.mocap_qtm`), Vicon Nexus CSV exports
(:mod:`~perception.io.vicon`), OptiTrack Motive CSV exports
(:mod:`~perception.io.motive`), OpenSim TRC files (:mod:`~perception.io.mocap_trc`:
Motion Analysis Cortex, and the TRC exports of Vicon, Qualisys, OpenCap,
Pose2Sim, ...), tables whose header names X, Y and Z columns
per marker and headerless tables of X, Y, Z per marker
(:mod:`~perception.io.mocap_tables`), and C3D files through ``ezc3d``
(:mod:`~perception.io.mocap_c3d`, an optional extra: ``pip install
'hammer-mv[mocap]'``). Positions come back in metres whatever the file's
unit; lost samples (empty cells, NaN, a marker at exactly (0, 0, 0), a C3D
residual below 0) are NaN. The reader repairs nothing else: spikes and gaps
are left for a later stage. docs/mocap-formats.md describes each layout.
"""

from __future__ import annotations

import os
from pathlib import Path

from perception.errors import InputError
from perception.factors import FACTOR_FLAG, factor_names
from perception.io import mocap_stream
from perception.io.files import input_file, is_regular_file
from perception.io.mocap_c3d import read_c3d
from perception.io.mocap_dlc3d import is_dlc3d, read_dlc3d
from perception.io.mocap_qtm import is_qtm, read_qtm
from perception.io.mocap_stream import stream_xyz_table
from perception.io.mocap_tables import (
    leading_columns,
    marker_columns,
    read_headerless,
    read_xyz_table,
    two_row_header,
)
from perception.io.mocap_text import TableText, delimiter, is_number, split, table_text
from perception.io.mocap_trc import is_trc, read_trc
from perception.io.mocap_trial import UNITS, MocapTrial, TrialStream, check_rate, check_unit
from perception.io.motive import is_motive, read_motive
from perception.io.vicon import is_vicon, read_vicon

__all__ = ["LAYOUTS", "LAYOUTS_READ", "LAYOUT_READERS", "MOCAP_SUFFIXES", "UNITS", "MocapTrial",
           "is_mocap_file", "read_mocap", "table_layout", "unknown_layout"]

#: File endings read as motion-capture files (a table's first lines decide on reading; a
#: ``.c3d`` and a ``.trc`` are of their layout by name).
MOCAP_SUFFIXES = (".c3d", ".tsv", ".txt", ".csv", ".trc")
#: The layouts that name their own markers and hold one trial (vendor exports).
#: The reader of each layout a vendor's header names. Each is called as
#: ``reader(path, source, text, rate, units, trial_column, time_column)``: the file, the
#: file as the caller named it, its text (:class:`~perception.io.mocap_text.TableText`),
#: and the rest as :func:`read_mocap` takes them (checked there); it returns the trials.
LAYOUT_READERS = {"qtm": read_qtm, "vicon-nexus": read_vicon, "motive": read_motive,
                  "trc": read_trc, "dlc-3d": read_dlc3d}
_VENDOR = tuple(LAYOUT_READERS)
#: Each layout :func:`table_layout` names, and what it is, in words.
LAYOUTS = {
    "qtm": "a Qualisys TSV export (NO_OF_FRAMES, FREQUENCY, MARKER_NAMES, ...)",
    "vicon-nexus": "a Vicon Nexus CSV export (a Trajectories block)",
    "motive": "an OptiTrack Motive CSV export (Format Version, ...)",
    "trc": "an OpenSim TRC file (PathFileType, DataRate ..., Frame# Time and the markers' "
           "names)",
    "dlc-3d": "a DeepLabCut 3-D table (the rows scorer, bodyparts and coords x, y, z)",
    "xyz-table": "a table whose header names X, Y and Z columns per marker (thumb_x, thumb_y, "
                 "thumb_z, ...)",
    "headerless": "a table of numbers without a header, X Y Z per marker (named with `columns`)",
    "c3d": "a C3D file",
}
#: The layouts read, in one line (for a message that a file is none of them).
LAYOUTS_READ = ("expected " + ", ".join(LAYOUTS[k] for k in _VENDOR)
                + ", " + LAYOUTS["xyz-table"] + ", or " + LAYOUTS["headerless"])
#: Bytes read to tell a file's layout.
_SNIFF = 65536


def _sniff(text: TableText) -> str | None:
    """The layout of a table's text (see :data:`LAYOUTS`), or None."""
    first = text.first
    if not first:
        return None
    if is_trc(first):
        return "trc"
    if is_qtm(first):
        return "qtm"
    if is_motive(first):
        return "motive"
    if is_vicon(text.lines, text.skip):
        return "vicon-nexus"
    if is_dlc3d(text.lines[text.skip:text.skip + 4]):
        return "dlc-3d"
    cells = split(first, delimiter(first))
    if marker_columns(cells) or two_row_header(text, delimiter(first)):
        return "xyz-table"
    while cells and not cells[-1]:
        cells.pop()
    if cells and all(is_number(c) for c in cells) and (
            len(cells) % 3 == 0 or leading_columns(text, len(cells) % 3)):
        return "headerless"
    return None


def _head(path: Path) -> TableText | None:
    try:
        return table_text(path, head=_SNIFF)
    except (OSError, InputError):
        return None


def table_layout(path: str | os.PathLike) -> str | None:
    """The layout of a motion-capture file, by its name and first bytes, or None.

    One of ``"qtm"``, ``"vicon-nexus"``, ``"motive"``, ``"trc"``,
    ``"xyz-table"``, ``"headerless"`` (numbers only, a multiple of 3 per line)
    or ``"c3d"`` (:data:`LAYOUTS`); None for a file of another kind or layout.
    A ``.c3d`` and a ``.trc`` are of their layout by name (their reader
    refuses one that is not, saying what it found).

    Parameters
    ----------
    path : str or os.PathLike
        A file name.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix in (".c3d", ".trc"):
        return suffix[1:]
    if suffix not in MOCAP_SUFFIXES or not is_regular_file(p):
        return None
    text = _head(p)
    return None if text is None else _sniff(text)


def is_mocap_file(path: str | os.PathLike) -> bool:
    """Whether ``path`` looks like a motion-capture file.

    A ``.c3d`` or ``.trc`` is one by its name; a ``.tsv``, ``.txt`` or ``.csv`` is one when
    its first lines are of a layout :func:`table_layout` names. Only the
    file's first bytes are read.

    Parameters
    ----------
    path : str or os.PathLike
        A file name.
    """
    return table_layout(path) is not None


def unknown_layout(path: str | os.PathLike) -> InputError:
    """The error for a table of no layout read: what it holds, and what was expected.

    For a dispatcher that finds a ``.csv``/``.tsv``/``.txt`` that is neither a
    pose file nor a motion-capture table (:func:`table_layout` is None).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    """
    p = Path(path)
    text = _head(p)
    if text is None or not text.first:
        found = "an empty or unreadable file"
    else:
        cells = split(text.first, delimiter(text.first))
        while cells and not cells[-1]:
            cells.pop()
        if cells and all(is_number(c) for c in cells):
            found = (f"a table without a header, {len(cells)} columns (not 3 per marker, "
                     "X Y Z)")
        else:
            found = f"its first line is {text.first[:60]!r}"
    return InputError(f"not a table of a layout read ({found}): {LAYOUTS_READ}", p)


def read_mocap(path: str | os.PathLike, *, rate: float | None = None, units: str | None = None,
               trial_column: str | None = None, time_column: str | None = None,
               columns=None, factors=None) -> list[MocapTrial]:
    """Read a motion-capture file of any layout in :data:`LAYOUTS`.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.tsv``, ``.txt``, ``.csv``, ``.trc`` or ``.c3d`` file.
    rate : float, optional
        Samples/s (up to 1000). Needed for a table without a time column. A
        file whose times come from its header's rate (C3D, Vicon, a table
        without a time column) is timed by the rate given instead, with a
        note; a file with a time column must agree with it within 1 %
        (otherwise give ``time_column="none"`` to time it by the rate).
    units : {"mm", "cm", "m"}, optional
        The file's length unit; wins over the file's own, or what is inferred.
    trial_column : str, optional
        The column of a long table that names the trial (default: a column
        called ``trial``, ``trialN``, ``trial_id``, ...). Tables only.
    time_column : str, optional
        The column of a table that holds the time (default: ``time``, ``t``,
        ``time_s``, ``Time (s)``, ...), or ``"none"`` to ignore any and time
        the samples by the rate.
    columns : sequence of str, or str, optional
        The markers of a table without a header, in column order, three
        columns (X, Y, Z) each: ``("object", "thumb", "index")`` or
        ``"object,thumb,index"``.
    factors : sequence of str, or str, optional
        Columns of a table with a header row to read as the design's factors
        (``"participant,block"``), text or numbers, each constant within a
        trial; a column called participant, subject, condition, session,
        block or group (any case) is one by default where it is constant
        within every trial (:func:`perception.factors.table_factors`). Each
        trial's :attr:`MocapTrial.factors`.

    Returns
    -------
    list of MocapTrial, or TrialStream
        One per trial of a long table, in file order; otherwise one. A long
        table whose header names X, Y, Z per marker, larger than
        :data:`~perception.io.mocap_stream.STREAM_BYTES`, comes as a
        :class:`~perception.io.mocap_trial.TrialStream`: a sequence of the
        same trials, checked whole now and read one by one on each pass, in
        the memory of one trial (docs/mocap.md, "Large tables").

    Raises
    ------
    InputError
        A missing or unreadable file, a layout not read, no marker columns,
        ragged rows, a non-numeric value, a bad rate or unit, a time that does
        not increase or counts frames, a rate that disagrees with the time
        column, a trial id met in two places, a factor column the table
        lacks or that varies within a trial, or (for C3D) the ``mocap``
        extra not installed.
    """
    p = input_file(path, "motion-capture file", empty=False)
    if p.suffix.lower() not in MOCAP_SUFFIXES:
        raise InputError("expected a .c3d, .trc, .tsv, .txt or .csv motion-capture file", p)
    if units is not None:
        units = check_unit(units, p, "units")
    if rate is not None:
        rate = check_rate(rate, p, "rate")
    source = os.fspath(path)
    factors = factor_names(factors)
    if factors and p.suffix.lower() == ".c3d":
        raise InputError("a C3D file has no columns to read factors from: `factors` names a "
                         "table's columns (`factors_from_name` reads them from file names)",
                         p, field=FACTOR_FLAG)
    if p.suffix.lower() == ".c3d":
        if trial_column is not None or columns is not None:
            raise InputError("a C3D file holds named points of one trial: `trial_column` and "
                             "`columns` are for tables", p, field="columns"
                             if columns is not None else "trial_column")
        return read_c3d(p, source, rate, units)
    if p.stat().st_size > mocap_stream.STREAM_BYTES and p.suffix.lower() != ".trc":
        trials = _streamed(p, source, rate, units, trial_column, time_column, columns, factors)
        if trials is not None:
            return trials
    text = table_text(p)
    if not text.first:
        raise InputError("the file is empty", p)
    layout = "trc" if p.suffix.lower() == ".trc" else _sniff(text)
    args = (p, source, text, rate, units, trial_column, time_column)
    if layout in _VENDOR and columns is not None:
        raise InputError(f"`columns` names the markers of a table without a header; this is "
                         f"{LAYOUTS[layout]}, which names its own", p, field="columns")
    if layout in _VENDOR and trial_column is not None:
        raise InputError(f"this is {LAYOUTS[layout]}, which holds one trial: it has no trial "
                         "column", p, field="trial_column")
    cells = split(text.first, delimiter(text.first))
    headerless = bool(cells) and all(is_number(c) for c in cells if c)
    if factors and (layout in _VENDOR or headerless):
        raise InputError(f"this is {LAYOUTS['headerless' if headerless else layout]}, with no "
                         "columns to read factors from: `factors` names the columns of a "
                         "table whose header names X, Y and Z per marker (`factors_from_name` "
                         "reads them from file names)", p, field=FACTOR_FLAG)
    if layout in LAYOUT_READERS:
        return LAYOUT_READERS[layout](*args)
    if headerless:
        return read_headerless(*args, columns)
    return read_xyz_table(*args, columns, factors)


def _streamed(p: Path, source: str, rate, units, trial_column, time_column, columns,
              factors) -> TrialStream | None:
    """A large long table whose header names X, Y, Z per marker, read trial by trial
    (:func:`~perception.io.mocap_stream.stream_xyz_table`); None for any other file."""
    text = table_text(p, head=mocap_stream.HEAD_BYTES)
    cells = split(text.first, delimiter(text.first))
    if (columns is not None or _sniff(text) != "xyz-table"
            or all(is_number(c) for c in cells if c)
            or two_row_header(text, delimiter(text.first))):  # read whole: a rare layout
        return None
    return stream_xyz_table(p, source, text, rate, units, trial_column, time_column, factors)

"""OpenSim TRC marker files -> a trial: the layout Motion Analysis Cortex writes natively and
Vicon Nexus, Qualisys QTM, OpenCap, Pose2Sim, Theia and Visual3D export.

The layout, as OpenSim's ``TRCFileAdapter`` reads it::

    PathFileType  4  (X/Y/Z)  trial.trc         <- line 1 (the name may be absent)
    DataRate CameraRate NumFrames NumMarkers Units OrigDataRate OrigDataStartFrame OrigNumFrames
    100.00   100.00     515       3          mm    100.00       1                  515
    Frame#  Time  thumb  (2 empty cells)  index  (2 empty cells)  wrist ...
                  X1  Y1  Z1  X2  Y2  Z2  X3  Y3  Z3 ...
    (perhaps a blank line)
    1  0.000  160.0  40.0  200.0  ...                 <- an empty cell or NaN: a lost sample

The cells are tab-separated (some writers pad them with spaces, or part the
first line by spaces; a few write white space throughout; a file opened in a
spreadsheet and saved as CSV has every line parted by commas, or by
semicolons, each padded with empty cells to the widest line). What writers do
differently, each read here: the names not above their X column (OpenSim's
own example files put an extra tab before the first), trailing tabs, a file
ending before the rows' last markers (lost: NaN), ``NaN``/``nan`` or empty
cells for lost samples, fewer values than keys on line 3 (Pose2Sim), a
``NumFrames`` that is not the rows' count (a note), ``Times`` for ``Time``,
CRLF line ends. A marker's X, Y, Z are the three columns at its place in
the names' order, after Frame# and Time, as OpenSim reads them.
"""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np

from perception.errors import InputError
from perception.io.mocap_tables import no_clock, table_trials
from perception.io.mocap_text import TableText, decimal_mark, delimiter, split
from perception.io.mocap_trial import RATE_TOLERANCE, MocapTrial, check_rate, strip_subject
from perception.limits import MAX_FRAMES

__all__ = ["is_trc", "read_trc"]

#: A coordinate column's label on line 5: X1, Y1, Z1, X2, ...
_AXIS = re.compile(r"([XYZ])(\d*)", re.IGNORECASE)
#: The words a Units value may be written in, and the unit each is.
_UNIT_WORDS = {"mm": "mm", "millimeters": "mm", "millimetres": "mm", "cm": "cm",
               "centimeters": "cm", "centimetres": "cm", "m": "m", "meters": "m",
               "metres": "m"}
#: "nan" in every case, signed or not: OpenSim reads them all as a lost sample (its own test
#: files write ``NaN``, ``nan``, ``Nan``, ``NAN``).
_NANS = sorted({sign + "".join(c.upper() if k >> i & 1 else c for i, c in enumerate("nan"))
                for k in range(8) for sign in ("", "-", "+")})
#: A TRC file's first word (line 1), and a spreadsheet's separator after it.
_FIRST_WORD = re.compile(r"\s*pathfiletype(?:\s|[,;]|$)", re.IGNORECASE)
_SAVED = re.compile(r"\s*pathfiletype\s*([,;])", re.IGNORECASE)
#: The header's keys as OpenSim writes them (line 2).
_KEYS = "DataRate CameraRate NumFrames NumMarkers Units OrigDataRate OrigDataStartFrame " \
        "OrigNumFrames"


def is_trc(first_line: str) -> bool:
    """Whether a file's first line opens a TRC file (``PathFileType 4 (X/Y/Z) ...``).

    Parameters
    ----------
    first_line : str
        The line.
    """
    return _FIRST_WORD.match(first_line) is not None


def _saved_as_csv(lines: list[str], top: int) -> tuple[list[str], str | None]:
    """The lines of a TRC file a spreadsheet saved as CSV (``PathFileType,4,(X/Y/Z),...``,
    parted by commas or semicolons) with its header lines parted by tabs as a TRC writer parts
    them, and that separator; other files' lines as they are, and None. The rows are left as
    they are (read as any table's)."""
    found = _SAVED.match(lines[top])
    if found is None or "\t" in lines[top]:
        return lines, None
    sep = found.group(1)
    last = top + 4  # past the names; past the X1 Y1 Z1 row under them, where there is one
    coords = [c for c in split(lines[last], sep) if c] if last < len(lines) else []
    if coords and all(_AXIS.fullmatch(c) for c in coords):
        last += 1
    header = ["\t".join(split(line, sep)) for line in lines[top + 1: last]]
    return lines[: top + 1] + header + lines[last:], sep


def _cells(line: str, sep: str) -> list[str]:
    """A header line's cells, stripped: by tabs where it has them, else by white space."""
    return [c.strip() for c in line.split("\t")] if sep == "\t" else line.split()


def _fields(line: str, sep: str) -> int:
    """The fields of a data line (trailing empty ones included)."""
    return len(line.split()) if sep == r"\s+" else line.count(sep) + 1


def read_trc(path: Path, source: str, text: TableText, rate, units, trial_column,
             time_column) -> list[MocapTrial]:
    """A TRC file's markers, timed by its Time column.

    One of :data:`perception.io.mocap.LAYOUT_READERS`, called as they all are:
    ``(path, source, text, rate, units, trial_column, time_column)``.
    """
    clockless = no_clock(time_column)
    if time_column is not None and not clockless:
        raise InputError("a TRC file's clock is its Time column: leave `time_column` out to "
                         "use it, or give `time_column` none", path, field="time_column")
    if not is_trc(text.first):
        raise InputError(f"not an OpenSim TRC file: its first line is {text.first[:60]!r}; "
                         "expected 'PathFileType 4 (X/Y/Z) ...'", path, field="PathFileType")
    lines = text.all_lines()
    top = text.skip  # the PathFileType line; the lines below are numbered from it for messages
    lines, saved = _saved_as_csv(lines, top)
    notes = []
    if saved is not None:
        notes.append(f"a TRC file saved as CSV (cells parted by {saved!r}): read as the tabbed "
                     "layout")
    if len(lines) < top + 4:
        raise InputError(f"the file ends before its marker names (line {top + 4})", path,
                         field="Frame#")
    meta, more = _meta(lines[top + 1], lines[top + 2], top, path)
    notes = list(text.notes) + notes + more
    time_label, names = _names(lines[top + 3], top, path)
    start = top + 4
    coords = lines[start].split() if start < len(lines) else []
    if coords and all(_AXIS.fullmatch(c) for c in coords):
        _check_coordinates(coords, names, lines[top + 3], top, path)
        start += 1
    else:
        notes.append("no X1 Y1 Z1 ... row under the marker names: the rows are read as X, Y, "
                     "Z per marker in the names' order")
    stated = meta.get("nummarkers", "")
    if stated.isdigit() and int(stated) != len(names):
        notes.append(f"NumMarkers says {stated}; line {top + 4} names {len(names)} markers: "
                     "those are read")
    used, more = strip_subject(names)
    notes += more
    df = _rows(path, lines[start:], len(names), time_label, top)
    df = _cut_rows(df, time_label, meta, notes)
    groups = {name: tuple(f"c{2 + 3 * k + a}" for a in range(3)) for k, name in enumerate(used)}
    own_rate = _data_rate(meta, path, notes, clock=not clockless)
    time_col = None if clockless else time_label
    if clockless:
        notes.append(f"time column {time_label!r} ignored (`time_column` none): the samples "
                     "are timed by the rate")
    elif own_rate is not None and not _clock_agrees(df, own_rate[0], time_label, notes):
        own_rate = None  # the clock's own steps give the rate (and its frame-count check)
    unit = meta.get("units")
    own_units = (_UNIT_WORDS.get(unit.lower(), unit), "Units") if unit else None
    return table_trials(path, source, df, groups, time_col, None, rate, units, own_units, notes,
                        extra=False, own_rate=own_rate)


def _meta(keys_line: str, values_line: str, top: int,
          path: Path) -> tuple[dict[str, str], list[str]]:
    """The header's keys (lower case) -> values, and a note where their counts differ
    (``top``: the lines above the header, for the messages' line numbers)."""
    keys, values = keys_line.split(), values_line.split()
    if not keys or keys[0].lower() != "datarate":
        raise InputError(f"expected the header keys {_KEYS!r} on line {top + 2}, got "
                         f"{keys_line[:60]!r}", path, field="DataRate")
    notes = []
    if len(values) != len(keys):  # Pose2Sim's 7 values for 8 keys: the first five hold
        notes.append(f"line {top + 3} holds {len(values)} values for the {len(keys)} keys of "
                     f"line {top + 2}: read in order")
    return {k.lower(): v for k, v in zip(keys, values)}, notes


def _names(line: str, top: int, path: Path) -> tuple[str, list[str]]:
    """The time column's label and the markers' names, in order, of line 4 (``Frame#  Time
    name ...``)."""
    sep = "\t" if "\t" in line else r"\s+"
    labels = [c for c in _cells(line, sep) if c]  # a name's X column is not where it sits
    if (len(labels) < 2 or labels[0].lower().replace(" ", "").rstrip("#") not in ("frame",
                                                                                  "frames")
            or not labels[1].lower().startswith("time")):
        raise InputError(f"expected 'Frame#, Time' and the markers' names on line {top + 4}, got "
                         f"{line[:60]!r}", path, field="Frame#")
    names = labels[2:]
    if not names:
        raise InputError(f"line {top + 4} names no marker after 'Frame#, Time'", path,
                         field="Frame#")
    return labels[1], names


def _check_coordinates(coords: list[str], names: list[str], names_line: str, top: int,
                       path: Path) -> None:
    """Refuse coordinate labels (line 5) that are not X, Y, Z for each marker named."""
    if len(coords) != 3 * len(names):
        spaced = ("; in a file parted by spaces a marker's name cannot hold a space"
                  if "\t" not in names_line and len(coords) < 3 * len(names) else "")
        raise InputError(f"line {top + 4} names {len(names)} markers ({_shown(names)}); line "
                         f"{top + 5} labels "
                         f"{len(coords)} coordinate columns ({_per_marker(len(coords))}): "
                         f"each marker needs its name and its X, Y, Z{spaced}", path,
                         field="NumMarkers")
    axes = "".join(_AXIS.fullmatch(c).group(1).upper() for c in coords)
    if axes != "XYZ" * len(names):
        bad = next(k for k in range(len(coords)) if axes[k] != "XYZ"[k % 3])
        raise InputError(f"the coordinate labels of line {top + 5} are not X, Y, Z per marker "
                         f"({coords[bad]!r} where {'XYZ'[bad % 3]}{bad // 3 + 1} belongs)",
                         path, field="NumMarkers")


def _shown(names: list[str]) -> str:
    return ", ".join(map(repr, names[:4])) + (", ..." if len(names) > 4 else "")


def _per_marker(columns: int) -> str:
    if columns % 3:
        return "not 3 per marker"
    return f"X, Y, Z of {columns // 3} marker{'s' if columns != 3 else ''}"


def _rows(path: Path, data: list[str], markers: int, time_label: str, top: int):
    """The rows below the header as a table: ``Frame#``, the time, then ``c2``, ``c3``, ...

    A row may end early (its last markers lost: NaN); a row holding more
    columns than the markers named is refused.
    """
    import pandas as pd

    body = [line for line in data if line.strip(" \t,;")]  # a row of empty cells is blank
    if not body:
        raise InputError("no data rows below the header", path, field="Frame#")
    sep = delimiter(body[0])
    width = 2 + 3 * markers
    widest = max(_fields(line, sep) for line in body)
    decimal = decimal_mark(body, sep)
    try:
        df = pd.read_csv(io.StringIO("\n".join(body)), sep=sep, header=None,
                         names=range(max(widest, width)), index_col=False, decimal=decimal,
                         na_values=_NANS, skipinitialspace=True, nrows=MAX_FRAMES + 1,
                         low_memory=False)
    except pd.errors.ParserError as exc:
        raise InputError(f"rows that cannot be read: "
                         f"{str(exc).rpartition('C error: ')[2].strip()}", path) from None
    beyond = df.iloc[:, width:].notna().any(axis=1).to_numpy()
    if beyond.any():
        row = int(np.flatnonzero(beyond)[0])
        held = int(np.flatnonzero(df.iloc[row].notna().to_numpy())[-1]) + 1
        raise InputError(f"data row {row + 1} holds {held} columns ({_per_marker(held - 2)} "
                         f"after Frame# and Time); line {top + 4} names {markers} marker"
                         f"{'s' if markers != 1 else ''} ({width} columns): each marker's "
                         "columns need its name", path, field="NumMarkers")
    df = df.iloc[:, :width]
    df.columns = ["Frame#", time_label, *(f"c{j}" for j in range(2, width))]
    return df


def _cut_rows(df, time_label: str, meta: dict[str, str], notes: list[str]):
    """The rows without a last one cut before its time; a note where NumFrames differs."""
    import pandas as pd

    time = pd.to_numeric(df[time_label], errors="coerce").to_numpy()
    cut = 0
    while cut < len(time) - 1 and not np.isfinite(time[len(time) - 1 - cut]):
        cut += 1
    if cut:
        df = df.iloc[: len(df) - cut]
        notes.append(f"the last {'row is' if cut == 1 else f'{cut} rows are'} cut short "
                     "(no time): left out")
    stated = meta.get("numframes", "")
    if stated.isdigit() and int(stated) != len(df):
        if int(stated) > len(df):
            notes.append(f"the file is cut short: its header states {stated} frames (NumFrames), "
                         f"it holds {len(df)}: those {len(df)} are read")
        else:
            notes.append(f"NumFrames says {stated}; the file holds {len(df)} frames: all "
                         f"{len(df)} are read")
    return df


def _data_rate(meta: dict[str, str], path: Path, notes: list[str], *,
               clock: bool) -> tuple[float, str] | None:
    """``(DataRate, "DataRate")``; None, with a note, where the header states no rate and the
    Time column (``clock``) can give it."""
    value = meta.get("datarate", "")
    try:
        return check_rate(value.replace(",", "."), path, "DataRate"), "DataRate"
    except InputError:
        if not clock:
            raise
    notes.append(f"DataRate {value!r} is not a rate: the rate is the Time column's")
    return None


def _clock_agrees(df, own: float, label: str, notes: list[str]) -> bool:
    """Whether the Time column keeps DataRate (else a note: the column is the clock).

    A header left as it was when the rows were resampled (OpenSim's own
    ``std_walking2_markers.trc``: DataRate 250, times 0.04 s apart) states a
    rate the times do not keep. The time from the first row to the last is
    compared with the frames between them (Frame#, so that frames left out
    count; else the rows) at DataRate, allowing for 1 % and for the times'
    rounding (3.067, 3.083, 3.100 at 60 Hz).
    """
    import pandas as pd

    t = pd.to_numeric(df[label], errors="coerce").to_numpy()
    frame = pd.to_numeric(df["Frame#"], errors="coerce").to_numpy()
    if len(t) < 2 or not np.isfinite(t).all() or (np.diff(t) <= 0).any():
        return True  # one sample, or a clock that does not increase: the table's rules say so
    if not np.isfinite(frame).all() or (np.diff(frame) <= 0).any():
        frame = np.arange(len(t), dtype=float)
    span, frames = float(t[-1] - t[0]), float(frame[-1] - frame[0])
    if abs(span - frames / own) <= max(_resolution(t), RATE_TOLERANCE * frames / own):
        return True
    notes.append(f"DataRate says {own:g}; the time column {label!r} steps at "
                 f"{frames / span:.6g} samples/s: the time column is the clock")
    return False


def _resolution(t: np.ndarray) -> float:
    """The step of the last decimal the times are written to (0.001 for 3.067)."""
    for digits in range(10):
        scaled = t * 10.0 ** digits
        if (np.abs(scaled - np.round(scaled)) < 1e-3).all():
            return 10.0 ** -digits
    return 0.0

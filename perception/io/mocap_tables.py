"""Tables of marker columns -> trials: the markers, the trials, the clock.

Two layouts are read here: a table whose header row names X, Y and Z columns
per marker (Optotrak/NDI exports, lab scripts; one recording, or many trials
in a long table with a trial column), and a table with no header at all
whose columns are X, Y, Z per marker in an order the caller names
(``columns=``, as RTMocap writes them). The vendor layouts (Qualisys, Vicon,
OptiTrack) reuse :func:`table_trials` for the trial and clock rules, so that
a time column is judged the same way whatever wrote it.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from perception.errors import InputError
from perception.factors import table_factors
from perception.io.mocap_text import (
    TableText,
    check_header,
    decimal_mark,
    delimiter,
    load,
    numeric,
    split,
)
from perception.io.mocap_trial import (
    MocapTrial,
    assemble,
    check_rate,
    clock_rate,
    header_rate,
    strip_subject,
    unique_name,
)

__all__ = ["leading_columns", "marker_columns", "no_clock", "read_headerless", "read_xyz_table",
           "table_trials"]

TIME = re.compile(r"(?:t|time|times|timestamp)(?:[\s_]*[(\[]?(s|sec|secs|seconds|ms|msec)[)\]]?)?",
                  re.IGNORECASE)
_TRIAL = re.compile(r"trial[\s_.-]*(?:n|no|nr|num|number|id|index|idx)?", re.IGNORECASE)
_SEPS = " _.:-|/"
#: Share of a non-increasing time column's values within half its median of it:
#: above this it holds the steps between samples (a frame interval), not a clock.
_STEP_LIKE = 0.9


#: Two numbers in one field, parted by spaces.
_SPACED = re.compile(r"\d\s+[-+.\d]")


def marker_columns(columns) -> dict[str, tuple]:
    """Marker name -> its (X, Y, Z) columns, found by the axis letter each name carries.

    Parameters
    ----------
    columns : sequence of str
        A header row's names.
    """
    keys: dict[tuple[str, str], dict] = {}
    for col in columns:
        name = str(col).strip()
        for i, ch in enumerate(name):
            if ch.lower() in "xyz":
                entry = keys.setdefault((name[:i].lower(), name[i + 1:].lower()),
                                        {"parts": (name[:i], name[i + 1:])})
                entry.setdefault(ch.lower(), col)
    found = sorted((e for e in keys.values() if all(a in e for a in "xyz")),
                   key=lambda e: list(columns).index(e["x"]))
    groups, used = {}, set()
    for entry in found:
        cols = (entry["x"], entry["y"], entry["z"])
        if used & set(cols) or len(set(cols)) < 3:
            continue
        # "Thumb (X)": the brackets around the axis letter are no part of the name
        before, after = (part.strip(_SEPS).removesuffix("(").removesuffix("[")
                         .removeprefix(")").removeprefix("]").strip(_SEPS)
                         for part in entry["parts"])
        name = before or after or "marker"
        groups[unique_name(f"{before}_{after}".strip(_SEPS) if name in groups else name,
                           groups)] = cols
        used.update(cols)
    return groups


#: A units row's cells under a two-row header (``mm, mm, mm, ...``; the clock's ``s``).
_UNIT_CELL = re.compile(r"\(?\[?\s*(mm|cm|m|s|ms|sec)?\s*\]?\)?", re.IGNORECASE)


def two_row_header(text: TableText, sep: str) -> tuple[list[str], int] | None:
    """A header of two rows, the markers' names above their ``X Y Z`` (a third of units
    below them is passed over): each column's name as one row would give it
    (``thumb_X``), and the header's rows; None for any other table.

    Parameters
    ----------
    text : TableText
        The table's text.
    sep : str
        Its separator.
    """
    lines = text.lines[text.skip:text.skip + 3]
    if len(lines) < 2:
        return None
    top, axes = split(lines[0], sep), split(lines[1], sep)
    labels = [a.strip().lower() for a in axes]
    at = [i for i, a in enumerate(labels) if a in ("x", "y", "z")]
    axis = set(at)
    if not at or any(a for i, a in enumerate(labels) if i not in axis) \
            or len(at) % 3 or any(labels[i:i + 3] != ["x", "y", "z"] for i in at[::3]):
        return None
    names, owner = [], ""
    for i in range(max(len(top), len(labels))):
        cell = top[i].strip() if i < len(top) else ""
        if i in axis:
            if labels[i] == "x":
                owner = cell
            if not owner or (cell and cell != owner):
                return None  # an axis without its marker's name above its X
            names.append(f"{owner}_{axes[i].strip()}")
        else:
            names.append(cell)
    units = split(lines[2], sep) if len(lines) > 2 else []
    if not units or not all(_UNIT_CELL.fullmatch(c.strip()) for c in units):
        return names, 2
    # a units row: each coordinate's unit goes with its name, as a one-row header says it
    return [f"{n} ({u.strip()})" if i in axis and u.strip() else n
            for i, (n, u) in enumerate(zip(names, [*units, *[""] * len(names)]))], 3


def _find_column(columns, asked: str | None, pattern: re.Pattern, path: Path, flag: str):
    if asked is not None:
        if asked not in columns:
            shown = ", ".join(map(repr, columns[:12])) + (", ..." if len(columns) > 12 else "")
            raise InputError(f"no column {asked!r} (the columns are {shown})", path, field=flag)
        return asked
    return next((c for c in columns if pattern.fullmatch(c)), None)


def no_clock(time_column) -> bool:
    """Whether ``time_column`` is ``"none"``: any time column is ignored, the samples timed by
    the rate."""
    return isinstance(time_column, str) and time_column.strip().lower() == "none"


def _spans(rows) -> str:
    return f"{rows[0] + 1}-{rows[-1] + 1}" if len(rows) > 1 else f"{rows[0] + 1}"


def trial_rows(df, trial_col: str, path: Path) -> list[tuple[str, np.ndarray]]:
    """``(name suffix, rows)`` per trial of a long table, in file order.

    Each trial must be one block of consecutive rows: an id met again further
    down (a repeated trial, or a column that labels phases within every trial)
    is refused rather than merged into one trial with a jump.

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    trial_col : str
        Its trial column.
    path : Path
        The file.
    """
    if df[trial_col].isna().any():
        raise InputError(f"empty trial (data row {int(np.argmax(df[trial_col].isna())) + 1})",
                         path, field=trial_col)
    # the ids as text only where the column changes (a million str() calls took 7 s)
    raw = df[trial_col].to_numpy()
    first_rows = np.flatnonzero(np.r_[True, raw[1:] != raw[:-1]])
    return [(suffix, np.arange(s, e))
            for suffix, s, e in trial_spans(raw[first_rows], first_rows, len(raw), trial_col,
                                            path)]


def trial_spans(ids, first_rows: np.ndarray, rows: int, trial_col: str,
                path: Path) -> list[tuple[str, int, int]]:
    """``(name suffix, first row, end row)`` per trial, from where the trial column changes.

    Runs whose ids read alike as text (``1`` then ``1.0``) are one; an id met
    in two blocks is refused (:func:`trial_rows`).

    Parameters
    ----------
    ids : ndarray
        The trial column's value at each row where it changes.
    first_rows : ndarray of int
        Those rows (the first is 0).
    rows : int
        The table's rows.
    trial_col : str
        The trial column.
    path : Path
        The file.
    """
    import pandas as pd

    texts = (pd.Series(ids).astype(str).str.strip()
             .str.replace(r"\.0+$", "", regex=True).to_numpy())
    new_run = np.r_[True, texts[1:] != texts[:-1]]
    starts, runs = first_rows[new_run], texts[new_run]
    ends = np.r_[starts[1:], rows]
    values, counts = np.unique(runs, return_counts=True)
    if (counts > 1).any():
        recurring = set(values[counts > 1])
        first = next(v for v in runs if v in recurring)
        blocks = [range(s, e) for s, e, v in zip(starts, ends, runs) if v == first]
        where = ", ".join(_spans(b) for b in blocks[:3]) + (", ..." if len(blocks) > 3 else "")
        if len(runs) >= 2 * len(values):
            raise InputError(f"column {trial_col!r} does not number the trials: its "
                             f"{len(values)} values recur in {len(runs)} blocks ({first!r} at "
                             f"data rows {where}); name the column that numbers the trials "
                             "with `trial_column`", path, field=trial_col)
        raise InputError(f"trial {first} appears in {len(blocks)} separate blocks (data rows "
                         f"{where}): each trial needs an id of its own", path, field=trial_col)
    return [(f"-trial{v}", int(s), int(e)) for s, e, v in zip(starts, ends, runs)]


def _increasing(df, rows, skip: set) -> list[str]:
    """Numeric columns (outside ``skip``) that increase within every trial: clocks."""
    out = []
    for c in df.columns:
        if c in skip or df[c].dtype.kind not in "biuf":
            continue
        v = df[c].to_numpy(dtype=float)
        if all(len(r) > 1 and (np.diff(v[r]) > 0).all() for _, r in rows):
            out.append(c)
    return out


def _not_a_clock(df, time_col: str, t: np.ndarray, rows, skip: set, path: Path) -> InputError:
    """The refusal of a time column that does not increase: what it holds and what might."""
    step = int(np.flatnonzero(np.diff(t) <= 0)[0])
    med = float(np.median(t)) if len(t) else math.nan
    if (t > 0).all() and (np.abs(t - med) <= 0.5 * med).mean() >= _STEP_LIKE:
        what = (f"the time column {time_col!r} does not increase: it holds steps between "
                f"samples (median {med:.4g}), not a clock")
    else:
        what = f"the time does not increase ({t[step]:g} then {t[step + 1]:g})"
    others = _increasing(df, rows, skip | {time_col})
    if others:
        which = "columns that increase" if len(others) > 1 else "a column that increases"
        what += (f"; {which}: {', '.join(map(repr, others[:5]))}: name the clock with "
                 "`time_column` NAME, or give `time_column` none and `rate`")
    else:
        what += "; name the clock with `time_column` NAME, or give `time_column` none and `rate`"
    return InputError(what, path, field=time_col)


def _clock(df, time_col: str, rows, rate, own: tuple[float, str] | None, skip: set,
           path: Path, notes: list[str]) -> tuple[list[np.ndarray], float]:
    """Per-trial times from a time column, and the rate; ``own`` is a header's rate beside
    the column (vendor exports write s, so no unit is guessed then)."""
    time = numeric(df[time_col], path, time_col)
    if not np.isfinite(time).all():
        raise InputError("empty or non-numeric time", path, field=time_col)
    times = [time[r] for _, r in rows]
    for t in times:
        if (np.diff(t) <= 0).any():
            raise _not_a_clock(df, time_col, t, rows, skip, path)
    steps = np.concatenate([np.diff(t) for t in times])
    named = TIME.fullmatch(time_col)
    stated = (named.group(1) or "").lower() if named else ""
    if own is not None:
        rate = clock_rate(rate, own[0], path, time_col, own[1])
        return times, rate
    integral = len(steps) and (time == np.round(time)).all() and np.median(steps) == 1
    if integral and stated not in ("ms", "msec"):
        if rate is None:
            raise InputError(f"the time column {time_col!r} counts frames (whole numbers in "
                             "steps of 1), not a clock in s or ms: give the rate with `rate` "
                             "(the frames are then timed frame / rate), or name the clock with "
                             "`time_column` NAME", path, field="rate")
        notes.append(f"time column {time_col!r} counts frames: the time is frame / {rate:g}")
        return [t / rate for t in times], rate
    step = float(np.median(steps)) if len(steps) else math.nan
    if stated in ("ms", "msec") or (not stated and step > 0.5):
        notes.append(f"time column {time_col!r} in ms (from its "
                     f"{'name' if stated else 'steps'}): converted to s")
        times, step = [t / 1000 for t in times], step / 1000
    if not math.isfinite(step):
        if rate is None:
            raise InputError("one sample per trial: give the sampling rate", path,
                             field="rate")
        return times, rate
    own_rate = check_rate(round(1 / step, 6), path, time_col)
    if rate is None:
        notes.append(f"rate {own_rate:g} samples/s from the time column")
    return times, clock_rate(rate, own_rate, path, time_col, "its steps")


def table_trials(path: Path, source: str, df, groups, time_col, trial_col, rate, units,
                 own_units, notes: list[str], *, extra: bool = True,
                 own_rate: tuple[float, str] | None = None,
                 factors=None) -> list[MocapTrial]:
    """Split a table into trials; read its markers, time and (``extra``) other numbers.

    Parameters
    ----------
    path : Path
        The file.
    source : str
        The file as the caller named it.
    df : pandas.DataFrame
        The table.
    groups : dict of str to tuple
        Marker name -> its X, Y, Z columns.
    time_col : str or None
        The clock's column (None: the samples are timed by the rate).
    trial_col : str or None
        The column numbering the trials.
    rate : float or None
        The rate given.
    units : str or None
        The unit given.
    own_units : tuple of str, or None
        The file's own unit and its field.
    notes : list of str
        Notes so far.
    extra : bool
        Keep the other numeric columns.
    own_rate : tuple of (float, str), optional
        A header's rate and its field (Qualisys ``FREQUENCY``, Motive's export rate).
    factors : sequence of str, optional
        Columns to read as the design's factors (``--factors``); by default
        those named as :data:`perception.factors.DEFAULT_FACTORS` are, where
        each holds one value per trial (:func:`perception.factors.table_factors`).
    """
    markers = {m: np.column_stack([numeric(df[c], path, c) for c in cols])
               for m, cols in groups.items()}
    used = {c for cols in groups.values() for c in cols} | {time_col, trial_col}
    rows = [("", np.arange(len(df)))]
    if trial_col is not None:
        rows = trial_rows(df, trial_col, path)
    per_trial, taken = table_factors(df, [r for _, r in rows], factors, path, notes,
                                     skip=used)
    numbers = [suffix[len("-trial"):] if suffix else str(k + 1)
               for k, (suffix, _) in enumerate(rows)]
    others = {}
    for c in df.columns if extra else ():
        if c in used or df[c].isna().all():
            continue
        if df[c].dtype.kind in "biuf":
            others[c] = df[c].to_numpy(dtype=float)
        elif c not in taken:
            notes.append(f"column {c!r} is not numeric: not read (`factors` {c} reads it as "
                         "a factor)")
    if time_col is None:
        if own_rate is not None:
            rate, more = header_rate(rate, own_rate[0], path, own_rate[1])
            notes += more
        elif rate is None:
            raise InputError("the table has no time column: give the sampling rate "
                             "(samples/s) with `rate`, or name the time column with "
                             "`time_column` NAME", path, field="rate")
        times = [np.arange(len(r)) / rate for _, r in rows]
    else:
        skip = {c for cols in groups.values() for c in cols} | {trial_col}
        times, rate = _clock(df, time_col, rows, rate, own_rate, skip, path, notes)
    pieces = [(suffix, t, {m: xyz[r] for m, xyz in markers.items()},
               {c: v[r] for c, v in others.items()}) for (suffix, r), t in zip(rows, times)]
    return assemble(path, source, pieces, rate, units, own_units, notes,
                    list(zip(numbers, per_trial)))


def time_column_of(columns, time_column, path: Path, notes: list[str]):
    """The clock's column: the one named, none (``"none"``), or one called ``time``, ``t``, ...

    Parameters
    ----------
    columns : list of str
        The header's names.
    time_column : str or None
        What the caller asked.
    path : Path
        The file.
    notes : list of str
        Gets a note when a time column is ignored.
    """
    if no_clock(time_column):
        found = _find_column(columns, None, TIME, path, "time_column")
        if found is not None:
            notes.append(f"time column {found!r} ignored (`time_column` none): the samples "
                         "are timed by the rate")
        return None
    return _find_column(columns, time_column, TIME, path, "time_column")


def read_xyz_table(path: Path, source: str, text: TableText, rate, units, trial_column,
                   time_column, columns, factors=None) -> list[MocapTrial]:
    """A table whose header row names X, Y and Z columns per marker.

    Parameters
    ----------
    path : Path
        The file.
    source : str
        The file as the caller named it.
    text : TableText
        Its text.
    rate, units, trial_column, time_column, columns, factors
        As :func:`perception.io.mocap.read_mocap` takes them.
    """
    if columns is not None:
        raise InputError("`columns` names the markers of a table without a header row; this "
                         f"one has a header ({text.first[:60]!r}): leave `columns` out",
                         path, field="columns")
    sep = delimiter(text.first)
    sep, mixed = _mixed_spaces(text, sep, path)
    two = None if marker_columns(split(text.first, sep)) else two_row_header(text, sep)
    rows = 1 if two is None else two[1]
    check_header(split(text.first, sep) if two is None else [n for n in two[0] if n], path)
    decimal = decimal_mark(text.lines[text.skip + rows:], sep)
    if two is None:
        df = load(path, text.raw, sep, text.skip, 0, decimal)
    else:  # the markers' names above their X, Y, Z: one name per column, as one row gives
        df = load(path, text.raw, sep, text.skip + rows, None, decimal)
        df.columns = [n or f"column {k + 1}" for k, n in enumerate(two[0][:df.shape[1]])]
        mixed = [*mixed, "a header of two rows: the markers' names above their X, Y, Z"]
    names = list(df.columns)
    notes = list(text.notes) + (["decimal commas read"] if decimal == "," else []) + mixed
    time_col = time_column_of(names, time_column, path, notes)
    trial_col = _find_column(names, trial_column, _TRIAL, path, "trial_column")
    groups = marker_columns([c for c in names if c not in (time_col, trial_col)
                             and c not in (factors or ())])
    if not groups:
        raise InputError("no marker columns: expected X, Y and Z columns for each marker "
                         "(such as thumb_x, thumb_y, thumb_z)", path, field="header")
    if any(":" in name for name in groups):  # Vicon's Subject:Marker, kept by a lab's export
        short, more = strip_subject(list(groups))
        groups, notes = dict(zip(short, groups.values())), notes + more
    # a unit given wins over the columns' own (and settles columns that disagree)
    own = _stated_unit(groups, path) if units is None else None
    return table_trials(path, source, df, groups, time_col, trial_col, rate, units, own, notes,
                        factors=factors)


#: A unit in a coordinate column's name: ``(cm)``, ``[mm]``, ``(m)``, or ``_mm``, `` cm``
#: at its end (a bare ``m`` only in brackets: ``thumb_x_m`` may be anything).
_UNIT = re.compile(r"[(\[]\s*(mm|cm|m)\s*[)\]]|(?:^|[\s_.-])(mm|cm)$", re.IGNORECASE)


def _stated_unit(groups: dict[str, tuple], path: Path) -> tuple[str, str] | None:
    """The unit every coordinate column that states one states (``Thumb X (cm)``), and the
    field that says it; None where none does. Columns that state different ones are
    refused: which is meant is not ours to choose.

    Parameters
    ----------
    groups : dict of str to tuple
        Marker name -> its X, Y, Z columns (:func:`marker_columns`).
    path : Path
        The file.
    """
    stated = {}
    for cols in groups.values():
        for col in cols:
            match = _UNIT.search(str(col).strip())
            if match:
                stated[col] = (match.group(1) or match.group(2)).lower()
    if len(set(stated.values())) > 1:
        shown = ", ".join(f"{c!r} ({u})" for c, u in list(stated.items())[:4])
        raise InputError(f"the coordinate columns state different units ({shown}): give "
                         "`units`", path, field="units")
    if not stated:
        return None
    return next(iter(stated.values())), f"the column names ({next(iter(stated))!r})"


def _mixed_spaces(text: TableText, sep: str, path: Path) -> tuple[str, list[str]]:
    """The separator of a tab-separated table some of whose fields are parted by spaces.

    A tab field holding numbers parted by spaces is two fields written with a
    space: read as parted by white space where that gives every line as many
    fields as the header, else refused naming the line (read by tabs alone,
    a column would swallow its neighbour).
    """
    if sep != "\t":
        return sep, []
    first = text.skip + 1
    lines = text.lines[first:first + 1000]
    mixed = next((k for k, line in enumerate(lines)
                  if any(_SPACED.search(f) for f in line.split("\t"))), None)
    if mixed is None:
        return sep, []
    width = len(text.first.split())
    uneven = next((k for k, line in enumerate(lines) if line.strip()
                   and len(line.split()) != width), None)
    if uneven is not None:
        raise InputError(f"line {first + mixed + 1} parts its fields by tabs and spaces, and "
                         f"line {first + uneven + 1} then has {len(lines[uneven].split())} fields "
                         f"where the header has {width}: write one separator", path)
    return r"\s+", [f"tabs and spaces both part the fields (line {first + mixed + 1}): read as "
                    "parted by white space"]


def marker_list(columns, path: Path) -> list[str]:
    """``columns=`` as a list of marker names: each given, each once.

    Parameters
    ----------
    columns : str or sequence of str
        ``"object,thumb,index"`` or ``("object", "thumb", "index")``.
    path : Path
        The file, for the message.
    """
    if isinstance(columns, str):
        columns = columns.split(",")
    try:
        names = [str(c).strip() for c in columns]
    except TypeError:
        raise InputError(f"expected marker names, got {columns!r}", path,
                         field="columns") from None
    if not names or not all(names):
        raise InputError(f"expected a marker name for every 3 columns, got {columns!r}", path,
                         field="columns")
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise InputError(f"marker {repeated[0]!r} named twice", path, field="columns")
    return names


def headerless_width(text: TableText) -> tuple[int, int]:
    """The fields of a table's first line: all, and without trailing empty ones.

    Empty cells at the end are a trailing separator, or a last marker lost in
    that row: which, only the number of markers named tells.

    Parameters
    ----------
    text : TableText
        The table.
    """
    fields = split(text.first, delimiter(text.first))
    full = len(fields)
    while fields and not fields[-1]:
        fields.pop()
    return full, len(fields)


#: Data lines looked at to tell a headerless table's leading columns.
_LEADING_SAMPLE = 50


def leading_columns(text: TableText, count: int) -> tuple[str, ...] | None:
    """The ``count`` (1 or 2) columns before the markers' X, Y, Z of a headerless table, as
    lab exports write them (a Vicon Nexus block without its header, pyomeca's
    ``markers_without_header.csv``): ``("frame",)``, ``("frame", "sub frame")`` or
    ``("frame", "time")``, told from its first lines; None when they are not those.

    The frame column holds whole numbers in steps of 1; a sub frame column one value
    throughout; a time column increasing values.

    Parameters
    ----------
    text : TableText
        The table.
    count : int
        Columns before the markers' (the first line's fields modulo 3).
    """
    if count not in (1, 2):
        return None
    sep = delimiter(text.first)
    rows = [split(line, sep)[:count] for line in text.lines[text.skip:text.skip + _LEADING_SAMPLE]
            if line.strip()]
    try:
        values = np.array([[float(c) for c in row] for row in rows if len(row) == count])
    except ValueError:
        return None
    if len(values) < 2 or len(values) < len(rows) or not (np.diff(values[:, 0]) == 1).all() \
            or (values[:, 0] != np.round(values[:, 0])).any():
        return None
    if count == 1:
        return ("frame",)
    second = values[:, 1]
    if (second == second[0]).all():
        return ("frame", "sub frame")
    return ("frame", "time") if (np.diff(second) > 0).all() else None


def _leading_words(kinds: tuple[str, ...]) -> str:
    return {("frame",): "a frame counter", ("frame", "sub frame"): "a frame counter, sub frames",
            ("frame", "time"): "a frame counter, a time column"}[kinds]


def read_headerless(path: Path, source: str, text: TableText, rate, units, trial_column,
                    time_column, columns) -> list[MocapTrial]:
    """A table of numbers with no header: X, Y, Z per marker, named by ``columns``.

    Parameters
    ----------
    path : Path
        The file.
    source : str
        The file as the caller named it.
    text : TableText
        Its text.
    rate, units, trial_column, time_column, columns
        As :func:`perception.io.mocap.read_mocap` takes them.
    """
    full, width = headerless_width(text)
    kinds = leading_columns(text, width % 3) or ()
    if columns is None:
        per = ("X, Y, Z for each of " f"{width // 3} markers" if width % 3 == 0
               else f"{_leading_words(kinds)} and X, Y, Z for each of {width // 3} markers"
               if kinds else "not a multiple of 3 (X, Y, Z per marker)")
        raise InputError(f"a table without a header row, {width} columns ({per}): name its "
                         "markers in column order with `columns` NAME,NAME,...", path,
                         field="columns")
    names = marker_list(columns, path)
    if 3 * len(names) == full:
        width = full
    lead = len(kinds) if kinds and 3 * len(names) + len(kinds) == width else 0
    if 3 * len(names) + lead != width:
        raise InputError(f"`columns` names {len(names)} markers, {3 * len(names)} columns "
                         f"(X, Y, Z each); the table has {width} columns", path,
                         field="columns")
    if trial_column is not None:
        raise InputError("a table without a header row has no trial column to name", path,
                         field="trial_column")
    if time_column is not None and not no_clock(time_column):
        raise InputError(f"a table without a header row has no column {time_column!r}: its "
                         "samples are timed by `rate`", path, field="time_column")
    time_col = "time" if lead and "time" in kinds and not no_clock(time_column) else None
    if rate is None and time_col is None:
        raise InputError("a table without a header row has no time column: give the sampling "
                         "rate (samples/s) with `rate`", path, field="rate")
    sep = delimiter(text.first)
    decimal = decimal_mark(text.lines[text.skip:], sep)
    df = load(path, text.raw, sep, text.skip, None, decimal)
    if df.shape[1] > width:
        raise InputError(f"a row has {df.shape[1]} fields; the first has {width}", path,
                         field="columns")
    for k in range(df.shape[1], width):  # a last marker lost throughout: empty cells
        df[k] = np.nan
    df.columns = [*kinds[:lead], *(f"{n} {a}" for n in names for a in "XYZ")]
    groups = {n: tuple(f"{n} {a}" for a in "XYZ") for n in names}
    notes = list(text.notes) + [f"no header row: columns read as X, Y, Z of "
                                f"{', '.join(names)} (`columns`)"]
    if lead:
        said = " and ".join(kinds[:lead])
        notes.append(f"the first {lead} column{'s' if lead > 1 else ''} read as the {said}"
                     f"{', the clock' if time_col else ''}, not markers")
    if decimal == ",":
        notes.append("decimal commas read")
    return table_trials(path, source, df, groups, time_col, None, rate, units, None, notes,
                        extra=False)

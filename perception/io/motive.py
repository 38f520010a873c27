"""OptiTrack Motive CSV exports -> a trial: markers, rigid-body markers and rigid bodies.

The layout followed is OptiTrack's ("Data Export: CSV", docs.optitrack.com,
Motive 2.x and 3.x, export format version 1.2x) as Motive writes it and as
pathviewr's ``read_motive_csv`` (rOpenSci) parses it::

    Format Version,1.23,Take Name,...,Capture Frame Rate,120.000000,
        Export Frame Rate,120.000000,...,Length Units,Millimeters,...
    (blank)
    ,Type,Marker,Marker,Marker,Rigid Body,...
    ,Name,Hand:Thumb,Hand:Thumb,Hand:Thumb,Cup,...
    ,ID,1,1,1,"9E20...",...
    ,,Position,Position,Position,Rotation,...
    Frame,Time (Seconds),X,Y,Z,X,...
    0,0.000000,102.5,208.3,-3.7,...     <- an empty cell is a lost sample

A marker's (and a rigid-body marker's) position is read under its name (a
rigid-body marker also exported as a measured marker of that name is
``NAME (rigid body)``); a rigid body's position (its pivot) as a marker named
after the body; the
rotations, marker qualities and mean marker errors are not read. The rate is
the export's (``Export Frame Rate``), the unit ``Length Units``, and the time
column (``Time (Seconds)``) is the clock.
"""

from __future__ import annotations

from pathlib import Path

from perception.errors import InputError
from perception.io.mocap_tables import no_clock, table_trials
from perception.io.mocap_text import TableText, delimiter, is_number, load, split
from perception.io.mocap_trial import MocapTrial, check_rate, strip_subject

__all__ = ["is_motive", "read_motive"]

_LENGTH_UNITS = {"millimeters": "mm", "centimeters": "cm", "meters": "m"}


def is_motive(first_line: str) -> bool:
    """Whether a file's first line is Motive's export header (``Format Version,...``).

    Parameters
    ----------
    first_line : str
        The line.
    """
    cells = split(first_line, delimiter(first_line))
    return bool(cells) and cells[0].strip().lower() == "format version"


def _read_type(kind: str) -> bool:
    """Whether columns of this Motive type hold a marker position that is read."""
    kind = kind.strip().lower()
    return kind == "rigid body" or kind.endswith("marker")


def _names(entries: dict[tuple, dict], notes: list[str]) -> list[str]:
    """Each entry's name; a rigid body's marker written under a marker's name too is named
    apart (Motive exports a rigid body's markers where its solve puts them, and the same
    markers as measured: ``Rigid Body Marker`` and ``Marker`` columns of one name)."""
    measured = {name for kind, name, _ in entries if kind.strip().lower() == "marker"}
    names, both = [], []
    for kind, name, _ in entries:
        if kind.strip().lower() == "rigid body marker" and name in measured:
            both.append(name)
            name = f"{name} (rigid body)"
        names.append(name)
    if both:
        more = f" (and {len(both) - 1} more)" if len(both) > 1 else ""
        notes.append(f"{both[0]!r}{more} written as a Marker (as measured) and as a Rigid Body "
                     f"Marker (where the rigid body's solve puts it): the Marker keeps the "
                     f"name, the other is read as {both[0] + ' (rigid body)'!r}")
    return names


def read_motive(path: Path, source: str, text: TableText, rate, units, trial_column,
                time_column) -> list[MocapTrial]:
    """A Motive CSV export's marker and rigid-body positions.

    One of :data:`perception.io.mocap.LAYOUT_READERS`, called as they all are:
    ``(path, source, text, rate, units, trial_column, time_column)``.
    """
    lines = text.lines
    sep = delimiter(text.first)
    cells = split(text.first, sep)
    meta = {cells[i].strip().lower(): cells[i + 1].strip() for i in range(0, len(cells) - 1, 2)}
    axis_at = next((i for i in range(text.skip + 1, min(len(lines), text.skip + 40))
                    if split(lines[i], sep)[:1] == ["Frame"]), None)
    if axis_at is None:
        raise InputError("expected the column row 'Frame, Time (Seconds), X, Y, Z, ...' below "
                         "the export header", path, field="Frame")
    rows = {}
    for i in range(text.skip + 1, axis_at):
        row = split(lines[i], sep)
        if len(row) > 1 and row[1] in ("Type", "Name", "ID"):
            rows[row[1]] = row
    component = split(lines[axis_at - 1], sep)
    axes = split(lines[axis_at], sep)
    if "Type" not in rows or "Name" not in rows or component[1:2] != [""]:
        raise InputError("expected the Type, Name and ID rows and the Position/Rotation row "
                         "above the column row", path, field="Type")
    kinds, names = rows["Type"], rows["Name"]
    ids = rows.get("ID", [])
    entries: dict[tuple, dict] = {}
    skipped = set()
    for j in range(2, len(axes)):
        kind = kinds[j] if j < len(kinds) else ""
        if not _read_type(kind):
            if kind:
                skipped.add(kind)
            continue
        part = component[j] if j < len(component) else ""
        if part.lower() != "position" or axes[j].upper() not in ("X", "Y", "Z"):
            continue
        key = (kind, names[j] if j < len(names) else "", ids[j] if j < len(ids) else "")
        entries.setdefault(key, {})[axes[j].upper()] = j
    entries = {k: v for k, v in entries.items() if all(a in v for a in "XYZ")}
    if not entries:
        raise InputError("no marker or rigid-body positions (export the markers or the rigid "
                         "bodies' positions)", path, field="Type")
    notes = list(text.notes)
    if skipped:
        notes.append(f"{', '.join(sorted(skipped))} columns not read")
    used, more = strip_subject(_names(entries, notes))
    notes += more
    df = load(path, text.raw, sep, axis_at + 1, None)
    df.columns = [f"c{j}" for j in range(df.shape[1])]
    for j in range(df.shape[1], len(axes)):  # trailing markers lost throughout
        df[f"c{j}"] = float("nan")
    groups = {name: tuple(f"c{cols[a]}" for a in "XYZ")
              for name, cols in zip(used, entries.values())}
    time_col = None
    if len(axes) > 1 and axes[1].lower().startswith("time"):
        time_col = axes[1]
        df = df.rename(columns={"c1": time_col})
    if time_column is not None:
        if not no_clock(time_column):
            raise InputError(f"a Motive export's clock is its {axes[1]!r} column: leave "
                             "`time_column` out to use it, or give `time_column` none",
                             path, field="time_column")
        if time_col is not None:
            notes.append(f"time column {time_col!r} ignored (`time_column` none): the samples "
                         "are timed by the rate")
        time_col = None
    own_rate = None
    for key in ("export frame rate", "capture frame rate"):
        if is_number(meta.get(key, "")):
            own_rate = (check_rate(meta[key], path, key.title()), key.title())
            break
    if own_rate is None and rate is None and time_col is None:
        raise InputError("no frame rate in the export header: give it with `rate`", path,
                         field="Export Frame Rate")
    own_units = None
    stated = meta.get("length units")
    if stated:
        if stated.lower() not in _LENGTH_UNITS:
            raise InputError(f"unknown Length Units {stated!r} (expected Millimeters, "
                             "Centimeters or Meters)", path, field="Length Units")
        own_units = (_LENGTH_UNITS[stated.lower()], "Length Units")
    return table_trials(path, source, df, groups, time_col, None, rate, units, own_units, notes,
                        extra=False, own_rate=own_rate)

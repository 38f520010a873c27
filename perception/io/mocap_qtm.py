"""Qualisys Track Manager 3D TSV exports -> trials.

A header block of ``KEY<TAB>value...`` lines (``NO_OF_FRAMES``,
``FREQUENCY``, ``MARKER_NAMES``, ...), then one row per frame: with a column
header (``Frame  Time  name X  name Y  name Z ...``) in newer exports, without
one in older ones. QTM writes millimetres.
"""

from __future__ import annotations

import re
from pathlib import Path

from perception.errors import InputError
from perception.io.mocap_tables import table_trials, time_column_of
from perception.io.mocap_text import TableText, decimal_mark, load
from perception.io.mocap_trial import MocapTrial, check_rate
from perception.io.plain_tables import numeric_table
from perception.limits import MAX_FRAMES

__all__ = ["is_qtm", "read_qtm"]

_QTM_KEY = re.compile(r"[A-Z][A-Z0-9_]*")


def is_qtm(first_line: str) -> bool:
    """Whether a file's first line is a QTM header key.

    Parameters
    ----------
    first_line : str
        The line.
    """
    key = first_line.split("\t", 1)[0].strip()
    return key == "FILE_VERSION" or key.startswith("NO_OF_")


def _name_notes(names: list[str], named: list[str], header: dict) -> list[str]:
    """What a reader of MARKER_NAMES should know: names left empty, a count that disagrees,
    names apart only in case."""
    notes = []
    while named and not named[-1]:  # a line ending in a tab names nothing more
        named = named[:-1]
    empty = [i + 1 for i, n in enumerate(named) if not n]
    if empty:
        notes.append(f"MARKER_NAMES leaves name{'s' if len(empty) > 1 else ''} "
                     f"{', '.join(map(str, empty))} empty: not read")
    stated = (header.get("NO_OF_MARKERS") or [""])[0]
    if stated and stated != str(len(names)):
        notes.append(f"NO_OF_MARKERS says {stated}; MARKER_NAMES lists {len(names)} "
                     f"({', '.join(names)}): only those are read")
    folded: dict[str, list[str]] = {}
    for n in names:
        folded.setdefault(n.casefold(), []).append(n)
    alike = [", ".join(map(repr, v)) for v in folded.values() if len(v) > 1]
    if alike:
        notes.append(f"marker names apart only in case ({'; '.join(alike)}): read as "
                     "written, each its own marker (`markers` names them exactly)")
    return notes


def _unread_notes(columns: list[str], groups: dict[str, tuple]) -> list[str]:
    """What the columns besides the markers' X, Y, Z and the clock are, said as not read:
    QTM writes a timecode (``SMPTE``) and, when asked, a ``name Type`` column per
    marker (Measured, Gap-filled, ...) beside those of the markers it lists."""
    listed = {c for cols in groups.values() for c in cols} | {"Frame", "Time"}
    other = [c for c in columns if c not in listed and not c.startswith("Unnamed: ")]
    own = [c for c in other if c.rsplit(" ", 1)[0] in groups]
    xyz = [c for c in other if c not in own and c.rsplit(" ", 1)[-1] in ("X", "Y", "Z")]
    rest = [c for c in other if c not in own and c not in xyz]
    notes = []
    if xyz:
        unlisted = sorted({c.rsplit(" ", 1)[0] for c in xyz})
        notes.append(f"columns of markers MARKER_NAMES does not list, not read: "
                     f"{', '.join(map(repr, unlisted[:5]))}")
    if own:
        kinds = sorted({c.rsplit(" ", 1)[1] for c in own})
        notes.append(f"the markers' {', '.join(map(repr, kinds))} columns not read "
                     f"({len(own)} columns)")
    if rest:
        notes.append(f"column{'s' if len(rest) > 1 else ''} {', '.join(map(repr, rest[:5]))} "
                     "not read (not a marker's X, Y, Z)")
    return notes


def read_qtm(path: Path, source: str, text: TableText, rate, units, trial_column,
             time_column) -> list[MocapTrial]:
    """A QTM 3D TSV export.

    One of :data:`perception.io.mocap.LAYOUT_READERS`, called as they all are:
    ``(path, source, text, rate, units, trial_column, time_column)``.
    """
    lines = text.lines
    header: dict[str, list[str]] = {}
    skip = text.skip
    named: list[str] = []
    for line in lines[text.skip:]:
        fields = [f.strip() for f in line.split("\t")]
        if not _QTM_KEY.fullmatch(fields[0]):
            break
        header.setdefault(fields[0], [f for f in fields[1:] if f])
        if fields[0] == "MARKER_NAMES":
            named = fields[1:]
        skip += 1
    included = " ".join(header.get("DATA_INCLUDED", ["3D"]))
    if included.upper() != "3D":  # QTM's 6DOF, skeleton and analysis exports name no markers
        what = header.get("DATA_TYPES") or header.get("BODY_NAMES") or []
        held = f" ({', '.join(what[:4])}{', ...' if len(what) > 4 else ''})" if what else ""
        raise InputError(f"a QTM export of {included!r} data{held}, not markers' positions: "
                         "export the 3D data (DATA_INCLUDED 3D, the markers' X, Y, Z)", path,
                         field="DATA_INCLUDED")
    names = header.get("MARKER_NAMES")
    if not names:
        raise InputError("expected the markers' names, each once", path, field="MARKER_NAMES")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:  # which column is which cannot be told
        raise InputError(f"expected the markers' names, each once: {', '.join(map(repr, twice))} "
                         "named more than once", path, field="MARKER_NAMES")
    notes = list(text.notes) + _name_notes(names, named, header)
    own_rate = None
    if header.get("FREQUENCY"):
        own_rate = (check_rate(header["FREQUENCY"][0], path, "FREQUENCY"), "FREQUENCY")
    elif rate is None:
        raise InputError("no sampling rate: give it with `rate`", path, field="FREQUENCY")
    groups = {m: tuple(f"{m} {a}" for a in "XYZ") for m in names}
    first = lines[skip].split("\t")[0].strip() if skip < len(lines) else ""
    titled = bool(first) and not re.fullmatch(r"[-+0-9.,eE]+", first)
    # a QTM export opened and saved again by a European spreadsheet writes decimal commas
    decimal = decimal_mark(lines[skip + titled:], "\t")
    # the plain case without pandas (its import is most of a recognize's start-up)
    df = numeric_table(text.raw, "\t", skip, MAX_FRAMES) if titled and decimal == "." else None
    if df is None:
        df = load(path, text.raw, "\t", skip, 0 if titled else None, decimal)
    if not titled:  # older exports: X Y Z per marker, perhaps after Frame and Time
        columns = [c for cols in groups.values() for c in cols]
        if df.shape[1] not in (len(columns), len(columns) + 2):
            raise InputError(f"the rows have {df.shape[1]} fields; {len(names)} markers need "
                             f"{len(columns)} (X Y Z each) or {len(columns) + 2} (after Frame "
                             "and Time)", path, field="MARKER_NAMES")
        df.columns = ["Frame", "Time", *columns][len(columns) + 2 - df.shape[1]:]
    missing = next((c for cols in groups.values() for c in cols if c not in df.columns), None)
    if missing:
        raise InputError(f"no column {missing!r} for a marker it lists", path,
                         field="MARKER_NAMES")
    notes += _unread_notes(list(df.columns), groups)
    stated = (header.get("NO_OF_FRAMES") or [""])[0]
    if stated and stated != str(len(df)):
        notes.append(f"NO_OF_FRAMES says {stated}; the file holds {len(df)} frames")
    if time_column is None:
        time_col = "Time" if "Time" in df.columns else None
    else:
        time_col = time_column_of(list(df.columns), time_column, path, notes)
    own_units = ((header.get("UNITS") or ["mm"])[0], "UNITS")  # QTM writes mm
    return table_trials(path, source, df, groups, time_col, None, rate, units, own_units,
                        notes, extra=False, own_rate=own_rate)


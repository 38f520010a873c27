"""Vicon Nexus CSV exports -> a trial: the ``Trajectories`` block as Nexus writes it.

Nexus writes one block per kind of data, each as (Vicon Nexus "Export CSV";
the layout followed here is the one public Nexus readers parse: PaulT95's
Import_Vicon_Data, and the exports quoted in lab scripts that read them)::

    Trajectories                      <- the block's title
    100                               <- its rate, frames/s
    ,,Subject:LFIN,,,Subject:RFIN,,,  <- a marker's name above its X column
    Frame,Sub Frame,X,Y,Z,X,Y,Z       <- the columns
    ,,mm,mm,mm,mm,mm,mm               <- their units
    1,0,512.3,-31.9,874.2,,,          <- data; an empty cell is a lost sample
    (a blank line ends the block)

A ``Devices`` block (analog channels at their own, higher rate, several sub
frames per frame) may come before it and ``Model Outputs``, ``Joints`` or
``Segments`` blocks after it; only the trajectories are read. Some locales
write semicolons for commas; the separator is told from the column row.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from perception.errors import InputError
from perception.io.mocap_tables import no_clock
from perception.io.mocap_text import TableText, decimal_mark, delimiter, is_number, load, split
from perception.io.mocap_trial import MocapTrial, assemble, check_unit, header_rate, strip_subject

__all__ = ["VICON_BLOCKS", "is_vicon", "read_vicon"]

#: The titles of the blocks a Nexus CSV export holds.
VICON_BLOCKS = ("Trajectories", "Devices", "Model Outputs", "Joints", "Segments")


def _title(line: str) -> str | None:
    """The block title a line holds (trailing separators allowed), else None."""
    sep = delimiter(line)
    cells = [c for c in split(line, sep) if c] if sep != r"\s+" else [line.strip()]
    return cells[0] if len(cells) == 1 and cells[0] in VICON_BLOCKS else None


def is_vicon(lines: list[str], start: int) -> bool:
    """Whether the lines from ``start`` open a Nexus export: a block title, then its rate.

    Parameters
    ----------
    lines : list of str
        A file's first lines.
    start : int
        The first line of content.
    """
    if start + 1 >= len(lines) or _title(lines[start]) is None:
        return False
    cells = [c for c in split(lines[start + 1], delimiter(lines[start + 1])) if c]
    return len(cells) == 1 and is_number(cells[0])


def _blocks(lines: list[str], start: int) -> list[tuple[str, int]]:
    """``(title, line)`` of every block: a title line right after a blank one (or the start)."""
    out = []
    for i in range(start, len(lines) - 1):
        if (i == start or not lines[i - 1].strip(" \t,;")) and _title(lines[i]):
            out.append((_title(lines[i]), i))
    return out


def read_vicon(path: Path, source: str, text: TableText, rate, units, trial_column,
               time_column) -> list[MocapTrial]:
    """The ``Trajectories`` block of a Nexus CSV export.

    One of :data:`perception.io.mocap.LAYOUT_READERS`, called as they all are:
    ``(path, source, text, rate, units, trial_column, time_column)``.
    """
    if time_column is not None and not no_clock(time_column):
        raise InputError("a Vicon Nexus export has no time column: its frames are timed by "
                         "the Trajectories block's rate", path, field="time_column")
    lines = text.all_lines()
    blocks = _blocks(lines, text.skip)
    found = [i for title, i in blocks if title == "Trajectories"]
    if not found:
        held = ", ".join(dict.fromkeys(title for title, _ in blocks)) or "no block"
        raise InputError(f"a Vicon Nexus export without a Trajectories block (it holds {held}):"
                         " export the trajectories (marker positions) too", path,
                         field="Trajectories")
    top = found[0]
    if top + 4 >= len(lines):
        raise InputError("the Trajectories block ends before its units row", path,
                         field="Trajectories")
    sep = delimiter(lines[top + 3])
    own_rate = [c for c in split(lines[top + 1], sep) if c]
    labels, heads, unit_row = (split(lines[top + k], sep) for k in (2, 3, 4))
    if [h.lower() for h in heads[:2]] != ["frame", "sub frame"]:
        raise InputError(f"expected the column row 'Frame, Sub Frame, X, Y, Z, ...' on line "
                         f"{top + 4}, got {lines[top + 3][:40]!r}", path, field="Trajectories")
    end = next((i for i in range(top + 5, len(lines)) if not lines[i].strip(" \t,;")),
               len(lines))
    if end == top + 5:
        raise InputError("the Trajectories block has no data rows", path, field="Trajectories")
    width = len(heads)
    while width > 2 and not heads[width - 1]:
        width -= 1
    starts = [j for j in range(2, width) if j < len(labels) and labels[j]]
    if not starts:
        raise InputError("no marker names above the Trajectories' X columns", path,
                         field="Trajectories")
    notes = list(text.notes)
    groups, names, skipped = {}, [], []
    for k, j in enumerate(starts):
        span = range(j, starts[k + 1] if k + 1 < len(starts) else width)
        axes = {heads[c].upper(): c for c in span if c < len(heads)}
        if all(a in axes for a in "XYZ"):
            names.append(labels[j])
            groups[labels[j]] = tuple(axes[a] for a in "XYZ")
        else:
            skipped.append(labels[j])
    if skipped:
        notes.append(f"no X, Y, Z columns under {', '.join(map(repr, skipped[:5]))}: not read")
    if not groups:
        raise InputError("no marker has X, Y and Z columns in the Trajectories block", path,
                         field="Trajectories")
    block = "\n".join(lines[top + 5:end]).encode("utf-8")
    decimal = decimal_mark(lines[top + 5:end], sep)
    df = load(path, block, sep, 0, None, decimal)
    if df.shape[1] > width and df.iloc[:, width:].notna().any().any():
        raise InputError(f"a Trajectories row has {df.shape[1]} fields; the column row has "
                         f"{width}", path, field="Trajectories")
    for c in range(df.shape[1], width):  # trailing markers lost throughout: empty cells
        df[c] = np.nan
    frame = _column(df, 0, path, "Frame")
    sub = _column(df, 1, path, "Sub Frame")
    if not np.isfinite(frame).all():
        raise InputError("a Trajectories row without its frame number", path, field="Frame")
    keep = sub == 0
    if not keep.all():
        notes.append(f"{int((~keep).sum())} rows of sub frames other than 0 left out: the "
                     "frames are read")
    frame = frame[keep]
    if (np.diff(frame) <= 0).any():
        bad = int(np.flatnonzero(np.diff(frame) <= 0)[0])
        raise InputError(f"the frames do not increase ({frame[bad]:g} then {frame[bad + 1]:g})",
                         path, field="Frame")
    if not own_rate or not is_number(own_rate[0]):
        raise InputError(f"expected the Trajectories' rate on line {top + 2}, got "
                         f"{lines[top + 1][:40]!r}", path, field="Trajectories")
    rate, more = header_rate(rate, own_rate[0].replace(",", "."), path, "Trajectories rate")
    notes += more
    skipped_blocks = [title for title, i in blocks if i != top]
    if skipped_blocks:
        notes.append(f"{', '.join(dict.fromkeys(skipped_blocks))} block"
                     f"{'s' if len(set(skipped_blocks)) > 1 else ''} skipped: only the "
                     "Trajectories are read")
    unit = _unit(unit_row, groups, path)
    names_used, more = strip_subject(names)
    notes += more
    markers = {new: np.column_stack([_column(df, c, path, old)[keep] for c in groups[old]])
               for new, old in zip(names_used, names)}
    time = (frame - 1) / rate  # Nexus numbers frames from 1
    return assemble(path, source, [("", time, markers, {})], rate, units,
                    (unit, "Trajectories units") if unit else None, notes)


def _column(df, j: int, path: Path, name: str) -> np.ndarray:
    import pandas as pd

    values = pd.to_numeric(df.iloc[:, j], errors="coerce")
    bad = np.flatnonzero(values.isna().to_numpy() & df.iloc[:, j].notna().to_numpy())
    if len(bad):
        raise InputError(f"not a number: {df.iloc[bad[0], j]!r} (Trajectories data row "
                         f"{bad[0] + 1})", path, field=name)
    return values.to_numpy(dtype=float)


def _unit(row: list[str], groups: dict, path: Path) -> str | None:
    """The markers' unit from the units row (one for all of them)."""
    found = {row[c] for cols in groups.values() for c in cols if c < len(row) and row[c]}
    if len(found) > 1:
        raise InputError(f"the markers' units differ ({', '.join(sorted(found))}): expected "
                         "one length unit", path, field="Trajectories units")
    return check_unit(found.pop(), path, "Trajectories units") if found else None

"""DeepLabCut 3-D tables: the triangulated keypoints of a DeepLabCut 3D project.

DeepLabCut's ``triangulate`` writes a table (``.h5`` and, with
``save_as_csv``, ``.csv``) of the same shape as its 2-D predictions, but
with ``x, y, z`` coordinates and no likelihood: the header rows ``scorer``,
``bodyparts`` (``individuals`` before it in a multi-animal project) and
``coords``, then one row per frame, its index first. The coordinates are in
the unit of the calibration board's squares (mm or cm, usually), which no
header states: it is inferred, or given with ``units``; no time either: the
samples are timed by ``rate``. Each keypoint is a marker; one of several
individuals is ``individual:keypoint``.
"""

from __future__ import annotations

import io
from pathlib import Path

from perception.errors import InputError
from perception.io.mocap_tables import no_clock, table_trials
from perception.io.mocap_text import TableText, delimiter, split
from perception.io.mocap_trial import MocapTrial

__all__ = ["is_dlc3d", "read_dlc3d"]

#: The header rows' first cells, top to bottom (``individuals`` in multi-animal projects).
_ROWS = ("scorer", "individuals", "bodyparts", "coords")


def _header(lines: list[str]) -> dict[str, list[str]] | None:
    """The header rows by their first cell (``scorer`` ... ``coords``), None if not one."""
    rows: dict[str, list[str]] = {}
    for line in lines[:4]:
        cells = [c.strip() for c in split(line, delimiter(line))]
        if not cells or cells[0].lower() not in _ROWS:
            break
        rows[cells[0].lower()] = cells[1:]
    if {"scorer", "bodyparts", "coords"} - set(rows):
        return None
    axes = [c.lower() for c in rows["coords"]]
    if not axes or len(axes) % 3 or axes != ["x", "y", "z"] * (len(axes) // 3):
        return None
    return rows


def is_dlc3d(lines: list[str]) -> bool:
    """Whether a table's first lines are a DeepLabCut 3-D table's header."""
    return _header(lines) is not None


def read_dlc3d(path: Path, source: str, text: TableText, rate, units, trial_column,
               time_column) -> list[MocapTrial]:
    """A DeepLabCut 3-D table's keypoints as markers, timed by ``rate``.

    One of :data:`perception.io.mocap.LAYOUT_READERS`, called as they all are:
    ``(path, source, text, rate, units, trial_column, time_column)``.
    """
    import pandas as pd

    if time_column is not None and not no_clock(time_column):
        raise InputError("a DeepLabCut 3-D table has no time column: its samples are timed "
                         "by `rate`", path, field="time_column")
    lines = text.all_lines()[text.skip:]
    rows = _header(lines)
    if rows is None:
        raise InputError("not a DeepLabCut 3-D table: expected the rows scorer, bodyparts and "
                         "coords (x, y, z for each keypoint)", path, field="coords")
    parts = rows["bodyparts"]
    who = rows.get("individuals")
    if len(parts) != len(rows["coords"]) or (who is not None and len(who) != len(parts)):
        raise InputError(f"the header rows name {len(parts)} columns of keypoints and "
                         f"{len(rows['coords'])} coordinates: they must match", path,
                         field="bodyparts")
    several = who is not None and len(set(who)) > 1
    names = [f"{w}:{b}" if several else b for w, b in zip(who or parts, parts)]
    groups: dict[str, tuple[str, ...]] = {}
    for k in range(0, len(names), 3):
        if len(set(names[k:k + 3])) != 1:
            raise InputError(f"keypoint {names[k]!r} lacks its x, y, z columns together",
                             path, field="bodyparts")
        if names[k] in groups:
            raise InputError(f"keypoint {names[k]!r} is named twice", path, field="bodyparts")
        groups[names[k]] = tuple(f"c{k + a + 1}" for a in range(3))
    sep = delimiter(lines[0])
    body = "\n".join(lines[len(rows):])
    df = pd.read_csv(io.StringIO(body), sep=sep, header=None,
                     names=["frame", *(f"c{k + 1}" for k in range(len(names)))],
                     skip_blank_lines=True, engine="python" if sep == r"\s+" else "c")
    if not len(df):
        raise InputError("the table has a header and no rows", path)
    notes = list(text.notes) + ["a DeepLabCut 3-D table: no time column and no unit; the "
                                "samples are timed by the rate"]
    return table_trials(path, source, df, groups, None, None, rate, units, None, notes,
                        extra=False)

"""Tidy landmark tables: R-safe column names, the design's factors, one unit convention.

Every table a batch writes carries the manifest's own columns (participant,
session, any factor) after ``clip`` and ``condition``. :func:`tidy_landmarks`
is the one builder of the long landmark table, one row per landmark per
movement in lab units (mm, mm/s, ms, % of the movement, count: :data:`LANDMARK_COLUMNS`),
that ``batch`` writes as ``landmarks.csv`` (:func:`landmark_table`) and
``hammer-mv landmarks`` writes by default (:func:`wide_landmarks` is its
``--wide`` form); every value has its ``unit``, ``clock`` and ``flag``
(``ok``, or why it is doubtful or missing), and a movement that gives no
reach keeps its rows. A table without a ``unit`` column gets a sidecar
``<table>.units.json`` (:func:`write_units`). Names are such that pandas and
R's ``read.csv`` take them as they are.
"""

from __future__ import annotations

import array
import itertools
import math
import re
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pandas only where a table is written
    import pandas as pd

    from perception.landmarks import Landmarks
    from perception.report.clip import ClipSummary

__all__ = ["LANDMARK_CLOCKS", "LANDMARK_COLUMNS", "LANDMARK_UNITS", "NOT_SCORED", "TABLES",
           "MovementLandmarks", "factor_columns", "in_lab_units", "landmark_table", "r_name",
           "records", "write_landmark_table",
           "tidy_landmarks",
           "units_of", "units_path", "wide_landmarks", "with_r_aliases", "write_units"]

#: The batch tables of this module and :mod:`perception.report.statistics`.
TABLES = ("landmarks.csv", "participant_means.csv", "landmark_statistics.csv")

#: Every landmark column of every landmark table: its unit and its clock, in the
#: long table's order. The :class:`~perception.landmarks.Landmarks` fields,
#: ``opening``, and the times of the peak speed and the MGA from the onset. Units:
#: ms, mm, mm/s, % (of the movement time, from its onset), count. Clocks:
#: ``recording`` (s since the recording's first sample, or its time column's
#: zero, given in ms), ``onset`` (from the movement's onset), empty for
#: durations, sizes, speeds, shares and counts.
LANDMARK_COLUMNS = {
    "movement_time": ("ms", ""), "peak_speed": ("mm/s", ""), "peak_speed_time": ("%", ""),
    "mga": ("mm", ""), "mga_time": ("%", ""), "contact_aperture": ("mm", ""),
    "aperture_peaks": ("count", ""), "rest_aperture": ("mm", ""), "opening_time": ("%", ""),
    "onset_time": ("ms", "recording"), "end_time": ("ms", "recording"),
    "deceleration_time": ("ms", ""), "peak_opening_speed": ("mm/s", ""),
    "closing_time": ("ms", ""), "movements": ("count", ""), "opening": ("mm", ""),
    "time_to_peak_speed": ("ms", "onset"), "time_to_mga": ("ms", "onset")}
#: ``landmarks.csv``'s landmarks and their units (:data:`LANDMARK_COLUMNS`).
LANDMARK_UNITS = {name: unit for name, (unit, _) in LANDMARK_COLUMNS.items()}
#: The landmarks' clocks (:data:`LANDMARK_COLUMNS`).
LANDMARK_CLOCKS = {name: clock for name, (_, clock) in LANDMARK_COLUMNS.items()}
#: The flag of every landmark of a movement that gives no reach (its ``reason`` says why).
NOT_SCORED = "not scored"
#: The report's SI value (s, m, m/s, a share) times this is the value in the unit.
_SCALE = {"ms": 1e3, "mm": 1e3, "mm/s": 1e3, "%": 100.0, "count": 1.0}
#: :class:`~perception.landmarks.Landmarks` names of the landmarks named otherwise here.
_KEYS = {"time_to_peak_speed": "peak_speed_seconds", "time_to_mga": "mga_seconds"}
#: The long table's columns about the movement, before the factors, and after them.
_HEAD = ("clip", "trial", "condition")
_NUMBERS = ("trial_number", "reach_number")
_LONG = ("landmark", "value", "unit", "clock", "flag", "status", "reason")
_SAFE = re.compile(r"[a-z][a-z0-9_]*")


def r_name(name: str) -> str:
    """``name`` as a plain snake_case name that R and pandas take unquoted.

    ``conf_grasp-0.5s`` becomes ``conf_grasp_0_5s``: lower case, each run of
    other characters one ``_``, ``x_`` before a name that does not start
    with a letter.

    Parameters
    ----------
    name : str
        A column name.
    """
    safe = re.sub(r"[^a-z0-9]+", "_", str(name).lower()).strip("_")
    return safe if _SAFE.fullmatch(safe) else f"x_{safe}"


def with_r_aliases(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with an R-safe alias (:func:`r_name`) beside each column that needs one.

    The columns stay as they are; an alias that would repeat a column is not added.

    Parameters
    ----------
    table : pandas.DataFrame
    """
    out = table.copy()
    for column in table.columns:
        alias = r_name(column)
        if not _SAFE.fullmatch(str(column)) and alias not in out.columns:
            out.insert(out.columns.get_loc(column) + 1, alias, table[column])
    return out


def r_aliases(columns) -> set[str]:
    """The columns of ``columns`` that are another column's alias (:func:`with_r_aliases`)."""
    return {r_name(c) for c in columns if not _SAFE.fullmatch(str(c))} & set(columns)


def factor_columns(summary: pd.DataFrame) -> list[str]:
    """The R-safe names of the manifest's columns in ``summary.csv`` (between
    ``condition`` and ``winner``, each original or its alias).

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`perception.batch.summary_table`.
    """
    cols = list(summary.columns)
    if "condition" not in cols or "winner" not in cols:
        return []
    between = cols[cols.index("condition") + 1:cols.index("winner")]
    return [c for c in between if _SAFE.fullmatch(str(c))]


@dataclass(frozen=True)
class MovementLandmarks:
    """One movement of a landmark table, or a trial or movement that gives no reach.

    Attributes
    ----------
    clip : str
        Its name in a batch (the report's clip).
    trial : str
        The movement's name (``<trial>`` or ``<trial>-reach<k>``).
    landmarks : Landmarks or None
        Its landmarks in SI units (s, m, m/s, shares); None where it gives no reach.
    status : str
        ``complete``, ``starts in motion``, ... (:attr:`Landmarks.status`), or
        the status of a movement that gives no reach (``no reach``, ``failed``, ...).
    reason : str
        Why it gives no reach (empty for a measured movement).
    condition : str or None
        Its condition.
    factors : mapping of str to str
        The design's other factors (participant, session, ...), as written.
    trial_number, reach_number : str
        Its trial's number and which reach of the trial it is (empty if unknown).
    bound : str
        Which rules bound the movement, in words (``5 % of peak speed``, or a
        reach finder's own: the wide table's ``bound``).
    clock_offset : float or None
        Seconds added to the landmarks' ``onset_time`` and ``end_time`` to put
        them on the recording's clock; None where unknown (a report written
        before it was recorded: the times stay on the report's own clock,
        ``clock`` saying ``observation``).
    """

    clip: str
    trial: str
    landmarks: Landmarks | None
    status: str
    reason: str = ""
    condition: str | None = None
    factors: Mapping[str, str] = field(default_factory=dict, compare=False)
    trial_number: str = ""
    reach_number: str = ""
    bound: str = ""
    clock_offset: float | None = 0.0

    def values(self) -> Iterable[tuple[str, float, str, str, str]]:
        """Each landmark of :data:`LANDMARK_COLUMNS` as ``(name, value, unit, clock,
        flag)``, the value in its unit (NaN where missing; every value of a movement
        that gives no reach, flagged :data:`NOT_SCORED`)."""
        lm = self.landmarks
        d = lm.to_dict() if lm is not None else {}
        for name, (unit, clock) in LANDMARK_COLUMNS.items():
            if clock == "recording" and self.clock_offset is None:
                clock = "observation"
            if lm is None:
                yield name, math.nan, unit, clock, NOT_SCORED
                continue
            key = _KEYS.get(name, name)
            v = d.get(key)
            value = math.nan if v is None else float(v)
            if clock == "recording" and self.clock_offset:
                value += self.clock_offset
            yield name, value * _SCALE[unit], unit, clock, lm.flag(key)

    @property
    def flagged(self) -> list[str]:
        """The landmarks of a measured movement whose flag is not ``ok``."""
        if self.landmarks is None:
            return []
        return [name for name, *_, flag in self.values() if flag != "ok"]


def _factor_names(movements: list[MovementLandmarks]) -> list[str]:
    """The factors of ``movements`` as R-safe columns (:func:`r_name`), in first-seen order
    (:func:`_renamed`)."""
    names = dict.fromkeys(r_name(f) for m in movements for f in _own_factors(m))
    return _renamed(names, ("flags", "bound"))


def _renamed(factors: Iterable[str], more: Iterable[str] = ()) -> list[str]:
    """``factors`` as the table's columns: one named like a column of the table (or one of
    ``more``) gets ``manifest_`` before it."""
    own = {*_HEAD, *_NUMBERS, *_LONG, *more}
    return [f"manifest_{f}" if f in own else f for f in factors]


def _own_factors(m: MovementLandmarks) -> dict[str, str]:
    """``m``'s factors by R-safe name, without its condition (a column of its own)."""
    return {r_name(k): v for k, v in m.factors.items()
            if not (r_name(k) == "condition" and m.condition is not None)}


def _cells(m: MovementLandmarks, factors: list[str]) -> dict:
    """The columns that name ``m``: clip, trial, condition, factors, numbers."""
    given = _own_factors(m)
    condition = m.condition if m.condition is not None else given.pop("condition", None)
    own = {f.removeprefix("manifest_") if f.startswith("manifest_")
           and f.removeprefix("manifest_") in given else f: f for f in factors}
    cells = {"clip": m.clip, "trial": m.trial, "condition": condition}
    cells.update({column: given.get(name) for name, column in own.items()})
    cells.update(trial_number=m.trial_number, reach_number=m.reach_number)
    return cells


def tidy_landmarks(movements: Iterable[MovementLandmarks],
                   factors: list[str] | None = None) -> pd.DataFrame:
    """The long landmark table: one row per landmark (:data:`LANDMARK_COLUMNS`) per movement.

    The one builder of ``batch``'s ``landmarks.csv`` and of ``hammer-mv
    landmarks``' table, so that the two cannot drift apart.

    Parameters
    ----------
    movements : iterable of MovementLandmarks
        The movements, and the trials or movements that give no reach, in order.
    factors : list of str, optional
        The factor columns, in order (default: those of the movements, R-safe,
        in first-seen order).

    Returns
    -------
    pandas.DataFrame
        Columns ``clip``, ``trial``, ``condition``, the factors,
        ``trial_number``, ``reach_number``, ``landmark``, ``value`` (in
        ``unit``; empty where missing, ``flag`` saying why), ``unit``, ``clock``
        (``recording``, ``onset`` or empty), ``flag`` (``ok``, ``inside a gap:
        ...``, ``not seen: ...``, ``bound raised to N % of peak``, ``not
        scored``), ``status`` and ``reason``.
    """
    import pandas as pd

    if factors is None:  # else taken one at a time (a batch's are read from disk)
        movements = list(movements)
        factors = _factor_names(movements)
    names = [*_HEAD, *factors, *_NUMBERS, *_LONG]
    columns = _long_columns(movements, names)
    if not columns["clip"]:
        return pd.DataFrame([], columns=names).astype({"trial_number": str,
                                                       "reach_number": str})
    table = pd.DataFrame(columns, columns=names)
    return table.astype({"trial_number": str, "reach_number": str})


def _long_columns(movements: Iterable[MovementLandmarks], names: list[str]
                  ) -> dict[str, list]:
    """:func:`tidy_landmarks`' columns (``names``: the factors among them) as lists."""
    # a list a column, not a dict a row: a 10,000-trial study's 70,000 dicts were
    # the batch report's largest peak of memory (12 kB a trial)
    factors = names[len(_HEAD):-len(_NUMBERS) - len(_LONG)]
    columns: dict[str, list] = {c: [] for c in names}
    own = [c for c in names if c not in _LONG]
    for m in movements:
        cells = _cells(m, factors)
        rows = list(m.values())  # (landmark, value, unit, clock, flag) a landmark
        k = len(rows)
        for c in own:  # a movement's cells on each of its rows; missing: NaN, as from rows
            columns[c].extend([cells.get(c, math.nan)] * k)
        for j, c in enumerate(_LONG[:5]):
            columns[c].extend(row[j] for row in rows)
        columns["status"].extend([m.status] * k)
        columns["reason"].extend([m.reason] * k)
    return columns


def wide_landmarks(movements: Iterable[MovementLandmarks],
                   factors: list[str] | None = None) -> pd.DataFrame:
    """:func:`tidy_landmarks`' values as one row per movement, a column per landmark.

    The same values in the same units (:func:`units_of` gives each column's unit
    and clock, for the sidecar :func:`write_units` writes); ``flags`` lists the
    landmarks whose flag is not ``ok`` (``peak_speed: inside a gap: ...; ...``).

    Parameters
    ----------
    movements : iterable of MovementLandmarks
    factors : list of str, optional
        As :func:`tidy_landmarks`'.
    """
    import pandas as pd

    movements = list(movements)
    factors = _factor_names(movements) if factors is None else list(factors)
    rows = []
    for m in movements:
        row = {**_cells(m, factors), "status": m.status, "bound": m.bound}
        said = []
        for name, value, _unit, _clock, flag in m.values():
            row[name] = value
            if flag not in ("ok", NOT_SCORED):
                said.append(f"{name}: {flag}")
        row["flags"] = "; ".join(said)
        row["reason"] = m.reason
        rows.append(row)
    table = pd.DataFrame(rows, columns=[*_HEAD, *factors, *_NUMBERS, "status", "bound",
                                        *LANDMARK_COLUMNS, "flags", "reason"])
    counts = [name for name, (unit, _) in LANDMARK_COLUMNS.items() if unit == "count"]
    # a count: 1, not 1.0 (empty where unknown), as summary.csv writes it
    return table.astype({**{c: "Int64" for c in counts}, "trial_number": str,
                         "reach_number": str})


def units_of(columns: Iterable[str]) -> dict[str, dict[str, str]]:
    """The unit and clock of each landmark column of ``columns`` (:data:`LANDMARK_COLUMNS`):
    a units sidecar's content, ``{column: {"unit": ..., "clock": ...}}``.

    Parameters
    ----------
    columns : iterable of str
        A table's columns; those that are no landmark are left out.
    """
    return {c: {"unit": LANDMARK_COLUMNS[c][0], "clock": LANDMARK_COLUMNS[c][1]}
            for c in columns if c in LANDMARK_COLUMNS}


def in_lab_units(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with each landmark column (:data:`LANDMARK_COLUMNS`) from SI units (s, m,
    m/s, shares 0-1) to the landmark tables' (ms, mm, mm/s, %), other columns as they are.

    For ``summary.csv``'s landmark columns, with :func:`write_units` beside it.

    Parameters
    ----------
    table : pandas.DataFrame
        A table whose landmark columns are in SI units.
    """
    out = table.copy()
    for column in table.columns:
        if column in LANDMARK_COLUMNS and _SCALE[LANDMARK_COLUMNS[column][0]] != 1.0:
            out[column] = table[column].astype(float) * _SCALE[LANDMARK_COLUMNS[column][0]]
    return out


def units_path(table: str | Path) -> Path:
    """Where the units sidecar of ``table`` goes: ``<table>.units.json`` beside it
    (``landmarks.csv``: ``landmarks.units.json``).

    Parameters
    ----------
    table : str or Path
        The table's path.
    """
    table = Path(table)
    return table.with_name(f"{table.stem}.units.json")


def write_units(table: str | Path, columns: Iterable[str],
                units: Mapping[str, Mapping[str, str]] | None = None) -> Path:
    """Write the units sidecar of ``table`` atomically (:func:`units_path`); return its path.

    Parameters
    ----------
    table : str or Path
        The table's path.
    columns : iterable of str
        Its columns (the landmark columns among them are described).
    units : mapping, optional
        Units and clocks to write instead of :func:`units_of`'s (a table whose
        landmark columns are in other units says so).
    """
    from perception.io.atomic import write_json

    return write_json(units_path(table), dict(units) if units is not None
                      else units_of(columns))


def landmark_table(summary: pd.DataFrame, recognitions: Mapping[str, ClipSummary]
                   ) -> pd.DataFrame:
    """``landmarks.csv``: :func:`tidy_landmarks` of a batch's clips.

    A scored clip's landmarks are its report's ``kinematics.observed``; a clip
    that failed or a trial that gives no reach keeps its rows (empty values
    flagged ``not scored``, its ``status`` and ``reason``).

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`perception.batch.summary_table` (clips, conditions, factors).
    recognitions : mapping of str to ClipSummary
        The scored clips by name: their ``kinematics.observed`` landmarks (each
        read once, when its rows are made).

    Returns
    -------
    pandas.DataFrame
        :func:`tidy_landmarks`' columns, the factors those of
        :func:`factor_columns` (one named like a column here gets
        ``manifest_`` before it).
    """
    factors = [f for f in factor_columns(summary) if f not in _NUMBERS]
    # a movement at a time, each clip's summary read when its rows are made
    return tidy_landmarks(_movements(summary, recognitions, factors), _renamed(factors))


#: Movements a chunk of :func:`write_landmark_table`.
LANDMARKS_CHUNK = 500


def write_landmark_table(summary: pd.DataFrame, recognitions: Mapping[str, ClipSummary],
                         path: str | Path, keep: Iterable[str] = (),
                         shown: Callable[[pd.DataFrame], pd.DataFrame] | None = None,
                         chunk: int = LANDMARKS_CHUNK) -> tuple[list[str], dict[str, list]]:
    """Write :func:`landmark_table` to ``path`` as CSV, a chunk of movements at a time.

    The same file as ``landmark_table(summary, recognitions).to_csv(path,
    index=False)``, atomically, without the whole table at once (a
    10,000-trial study's is 180,000 rows, 2 kB a trial, and twice that while
    it is built); what the report reads of it after are the columns ``keep``.

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`perception.batch.summary_table`.
    recognitions : mapping of str to ClipSummary
        The scored clips by name (each read once).
    path : str or Path
        The CSV file.
    keep : iterable of str
        Columns to give back, whole (those the table lacks are left out).
    shown : callable, optional
        What each chunk becomes before it is written (the report's escaping of
        text that is not UTF-8).
    chunk : int
        Movements a chunk.

    Returns
    -------
    columns : list of str
        The table's columns.
    kept : dict of str to list
        The values of each of ``keep``'s columns the table has, every row.
    """
    import pandas as pd

    from perception.io.atomic import write_csv_chunks

    factors = [f for f in factor_columns(summary) if f not in _NUMBERS]
    columns = [*_HEAD, *_renamed(factors), *_NUMBERS, *_LONG]
    # the values a float64 array (a float object each was 32 bytes), the rest lists
    kept: dict[str, list] = {c: array.array("d") if c == "value" else []
                             for c in keep if c in columns}
    movements = _movements(summary, recognitions, factors)

    def tables():  # a chunk of movements at a time; the first (its header) even if empty
        first = True
        while True:
            some = list(itertools.islice(movements, chunk))
            if some or first:
                raw = _long_columns(some, columns)
                for c, values in kept.items():
                    values.extend(raw[c])
                table = (pd.DataFrame(raw, columns=columns) if raw["clip"]
                         else pd.DataFrame([], columns=columns)).astype(
                    {"trial_number": str, "reach_number": str})
                del raw
                yield shown(table) if shown else table
            first = False
            if len(some) < chunk:
                return

    write_csv_chunks(path, tables())
    return columns, kept


def _movements(summary: pd.DataFrame, recognitions: Mapping[str, ClipSummary],
               factors: list[str]) -> Iterator[MovementLandmarks]:
    """:func:`landmark_table`'s movements, one at a time."""
    from perception.landmarks import Landmarks

    for r in records(summary):
        s = recognitions.get(r["clip"]) if r["status"] == "ok" else None
        common = dict(clip=r["clip"], condition=_text(r.get("condition")),
                      factors={f: _text(r.get(f)) for f in factors},
                      trial_number=_text(r.get("trial_number")) or "",
                      reach_number=_text(r.get("reach_number")) or "")
        if s is None:
            why = _text(r.get("reason")) or _text(r.get("error")) or "not scored"
            status = r["status"] if r["status"] != "ok" else "failed"
            yield MovementLandmarks(trial=r["clip"], landmarks=None, status=status,
                                    reason=why, **common)
            continue
        lm = Landmarks.from_dict((s.kinematics or {}).get("observed"))
        mocap = s.extras.get("mocap") or {}
        # the report's times are on the observation's clock; its origin puts them on the
        # recording's (unknown in reports written before it was recorded)
        origin = float(getattr(s, "time_origin", math.nan))
        yield MovementLandmarks(
            trial=str(mocap.get("trial") or r["clip"]), landmarks=lm, status=lm.status,
            clock_offset=origin if math.isfinite(origin) else None, **common)


#: Rows a chunk of :func:`records`.
RECORDS_CHUNK = 1000


def records(table: pd.DataFrame, chunk: int = RECORDS_CHUNK) -> Iterator[dict]:
    """``table.to_dict("records")``, the same dicts, made a chunk of rows at a time.

    ``to_dict`` makes every row's dict at once: a 10,000-trial summary's
    60 columns, 3 kB a row, for a loop that reads one.

    Parameters
    ----------
    table : pandas.DataFrame
    chunk : int
        Rows made at once.
    """
    for start in range(0, len(table), chunk):
        yield from table.iloc[start:start + chunk].to_dict("records")


def _text(value) -> str | None:
    """A table cell as text (None for an empty one)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return None
    text = str(value)
    return text if text else None

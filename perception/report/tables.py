"""Tidy batch tables: R-safe column names, the manifest's factors, the long ``landmarks.csv``.

Every table a batch writes carries the manifest's own columns (participant,
session, any factor) after ``clip`` and ``condition``; ``landmarks.csv``
holds one row per landmark per trial in lab units (mm, mm/s, ms, % of the
movement), named so that pandas and R's ``read.csv`` take them as they are.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pandas only where a batch report is written
    import pandas as pd

    from perception.report.clip import ClipSummary

__all__ = ["LANDMARK_UNITS", "TABLES", "factor_columns", "landmark_table", "r_name",
           "with_r_aliases"]

#: The batch tables of this module and :mod:`perception.report.statistics`.
TABLES = ("landmarks.csv", "participant_means.csv", "landmark_statistics.csv")

#: ``landmarks.csv``'s landmarks and their units: the
#: :class:`~perception.landmarks.Landmarks` fields, ``opening``, and the
#: times of the peak speed and the MGA from the onset.
LANDMARK_UNITS = {
    "movement_time": "ms", "peak_speed": "mm/s", "peak_speed_time": "%", "mga": "mm",
    "mga_time": "%", "contact_aperture": "mm", "aperture_peaks": "count",
    "rest_aperture": "mm", "opening_time": "%", "onset_time": "ms", "end_time": "ms",
    "deceleration_time": "ms", "peak_opening_speed": "mm/s", "closing_time": "ms",
    "movements": "count", "opening": "mm", "time_to_peak_speed": "ms", "time_to_mga": "ms"}
#: The report's SI value (s, m, m/s, a share) times this is the value in the unit.
_SCALE = {"ms": 1e3, "mm": 1e3, "mm/s": 1e3, "%": 100.0, "count": 1.0}
#: ``kinematics.observed`` keys of the landmarks named otherwise there.
_KEYS = {"time_to_peak_speed": "peak_speed_seconds", "time_to_mga": "mga_seconds"}
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


def landmark_table(summary: pd.DataFrame, recognitions: dict[str, ClipSummary]
                   ) -> pd.DataFrame:
    """``landmarks.csv``: one row per landmark (:data:`LANDMARK_UNITS`) per scored clip.

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`perception.batch.summary_table` (clips, conditions, factors).
    recognitions : dict of ClipSummary
        The scored clips by name: their ``kinematics.observed`` landmarks.

    Returns
    -------
    pandas.DataFrame
        Columns ``clip``, ``condition``, the manifest's columns (one named
        like a column here gets ``manifest_`` before it), ``landmark``,
        ``value`` (empty where not measurable) and ``unit``.
    """
    import pandas as pd

    factors = factor_columns(summary)
    own = ("clip", "condition", "landmark", "value", "unit")
    rename = {f: f"manifest_{f}" if f in own else f for f in factors}
    rows = []
    for r in summary[summary["status"] == "ok"].to_dict("records"):
        s = recognitions.get(r["clip"])
        if s is None:
            continue
        cells = {"clip": r["clip"], "condition": r["condition"],
                 **{rename[f]: r[f] for f in factors}}
        for name, unit in LANDMARK_UNITS.items():
            v = s.landmark(_KEYS.get(name, name))
            rows.append({**cells, "landmark": name, "unit": unit,
                         "value": float("nan") if v is None else v * _SCALE[unit]})
    columns = ["clip", "condition", *rename.values(), "landmark", "value", "unit"]
    return pd.DataFrame(rows, columns=columns)

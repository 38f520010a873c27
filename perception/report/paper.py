"""Figures for a paper: each condition's kinematics, mean ± SD, and every trial's landmarks.

:func:`condition_kinematics_figure` draws the transport's speed (mm/s: the
wrist's, or the grip midpoint's where no wrist was recorded,
:func:`transport_name`) and the grip aperture (mm) of each condition, mean
± SD over its trials, against
the share of the movement (0-100 %, from each trial's onset to its end by
the field's definitions: the landmarks' ``onset_time`` and ``end_time``,
:class:`~perception.landmarks.LandmarkParams`); :func:`kinematic_profiles`
is its table. :func:`landmark_strip_figure` shows each landmark of every
trial as a point per condition, coloured by participant where the table
names them, with the condition's mean ± SD beside them. The per-trial
figure is :func:`~perception.report.kinematics.kinematics_figure`; save any
of them as PNG, SVG or PDF with :func:`~perception.report.figures.write_figure`.

The curves are those the landmarks are measured on
(:func:`~perception.report.kinematics.kinematic_traces`: the low-passed
wrist speed and marker-to-marker aperture over the whole clip), taken from
a :class:`~perception.recognition.result.Recognition`'s observation, or from
a :class:`~perception.report.clip.ClipSummary` 's ``traces`` (``time``,
``wrist_speed``, ``aperture``; s, m/s, m) where its report has them. A
summary without them gives its aperture (the report's ``aperture``: the
scored samples' tip-to-tip aperture, the digit markers' separation at rest
taken off) and no speed.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from perception.report.clip import ClipSummary
from perception.report.conditions import stacked_curves
from perception.report.figures import (
    LEFT,
    LEGEND_PT,
    RIGHT,
    _figure,
    _legend,
    _panel,
    _title,
    condition_colour,
)
from perception.report.kinematics import MM, kinematic_traces

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from perception.recognition.result import Recognition

__all__ = ["LANDMARKS", "PARTICIPANT_COLUMNS", "condition_kinematics_figure",
           "kinematic_profiles", "landmark_strip_figure", "transport_name"]

#: Samples of the movement (0-100 %) of the profiles.
POINTS = 101
#: The landmarks of :func:`landmark_strip_figure`: name, label, unit, and the factor from
#: ``summary.csv``'s SI value (s, m/s, m, share) to the unit.
LANDMARKS = (("movement_time", "movement time", "ms", 1e3),
             ("peak_speed", "peak speed", "mm/s", 1e3),
             ("peak_speed_time", "time to peak speed", "%", 100.0),
             ("mga", "MGA", "mm", 1e3),
             ("mga_time", "time to MGA", "%", 100.0),
             ("opening_time", "opening starts", "%", 100.0))
#: Columns naming the participant, the first found colours the points.
PARTICIPANT_COLUMNS = ("participant", "subject")
MOVEMENT = "movement (% from onset to end)"


def _trial(rec: Recognition | ClipSummary) -> tuple[np.ndarray, np.ndarray, np.ndarray, float,
                                                      float]:
    """A trial's time (s), wrist speed (m/s), aperture (m), onset and end (s)."""
    if not isinstance(rec, ClipSummary):
        lm = rec.landmarks[0]
        return (*kinematic_traces(rec.observation, rec.rules.landmarks), lm.onset_time,
                lm.end_time)
    traces = getattr(rec, "traces", None) or rec.extras.get("traces")
    if traces:
        curves = [np.array(traces[k], dtype=float) for k in ("time", "wrist_speed", "aperture")]
    else:
        curves = [rec.time, np.full(len(rec.time), np.nan), rec.aperture]
    return (*curves, rec.landmark("onset_time"), rec.landmark("end_time"))


def transport_name(recognitions: Sequence[Recognition | ClipSummary]) -> str:
    """What the trials' speed curves are the speed of, in words.

    ``wrist``, ``grip midpoint`` (no wrist recorded: the one the reports
    name, :attr:`~perception.recognition.result.Recognition.transport_point`),
    or ``transport (wrist or grip midpoint)`` where the trials differ.

    Parameters
    ----------
    recognitions : sequence of Recognition or ClipSummary
        The trials.
    """
    points = {getattr(rec, "transport_point", "wrist") for rec in recognitions}
    if len(points) == 1:
        return points.pop()
    return "transport (wrist or grip midpoint)" if points else "wrist"


def _resampled(time: np.ndarray, values: np.ndarray, onset: float, end: float,
               share: np.ndarray) -> np.ndarray | None:
    """``values`` at ``share`` of the movement from onset to end; NaN beyond the samples."""
    seen = np.isfinite(time) & np.isfinite(values)
    if not (math.isfinite(onset) and math.isfinite(end) and end > onset) or seen.sum() < 2:
        return None
    at = (time[seen] - onset) / (end - onset)
    return np.interp(share, at, values[seen], left=np.nan, right=np.nan)


def kinematic_profiles(recognitions: Sequence[Recognition | ClipSummary],
                       conditions: Sequence[str | None]) -> pd.DataFrame:
    """Wrist speed and grip aperture per condition, mean ± SD over its trials' movements.

    Each trial's curves are resampled at :data:`POINTS` shares of its
    movement, onset to end (NaN where its samples do not reach); a trial
    without an onset or an end is left out.

    Parameters
    ----------
    recognitions : sequence of Recognition or ClipSummary
        The trials.
    conditions : sequence of str or None
        Their conditions (None: ``unlabelled``).

    Returns
    -------
    pandas.DataFrame
        Columns ``condition``, ``movement`` (0-100 %), ``speed_mean``,
        ``speed_sd`` (mm/s), ``speed_n``, ``aperture_mean``, ``aperture_sd``
        (mm), ``aperture_n`` (the trials with a curve; SD 0 for one).
    """
    share = np.linspace(0.0, 1.0, POINTS)
    conds = [cond if isinstance(cond, str) else "unlabelled" for cond in conditions]
    conds = conds[:len(recognitions)]
    tables: dict[str, dict] = {cond: {"condition": cond, "movement": share * 100}
                               for cond in conds}
    # a curve at a time over every trial (a batch's are read back from disk one by one):
    # one resampled curve a trial held, not two
    for key, which in (("speed", 1), ("aperture", 2)):
        def curve(rec, which=which) -> np.ndarray | None:
            values = _trial(rec)
            c = _resampled(values[0], values[which], values[3], values[4], share)
            return c * MM if c is not None and np.isfinite(c).any() else None

        curves, _ = stacked_curves(recognitions, conds, curve, POINTS)
        for cond, arr in curves.items():
            table = tables[cond]
            with warnings.catch_warnings():  # a point no trial reaches: NaN, not a warning
                warnings.simplefilter("ignore", RuntimeWarning)
                table[f"{key}_mean"] = (np.nanmean(arr, axis=0) if len(arr)
                                        else np.full(POINTS, np.nan))
                table[f"{key}_sd"] = (np.nanstd(arr, axis=0, ddof=1) if len(arr) > 1
                                      else np.zeros(POINTS) if len(arr)
                                      else np.full(POINTS, np.nan))
            table[f"{key}_n"] = len(arr)
        del curves
    columns = ["condition", "movement", "speed_mean", "speed_sd", "speed_n", "aperture_mean",
               "aperture_sd", "aperture_n"]
    return (pd.concat([pd.DataFrame(t) for t in tables.values()], ignore_index=True)[columns]
            if tables else pd.DataFrame(columns=columns))


def condition_kinematics_figure(recognitions: Sequence[Recognition | ClipSummary],
                                conditions: Sequence[str | None], *,
                                profiles: pd.DataFrame | None = None,
                                point: str | None = None) -> Figure:
    """Transport speed (mm/s) and grip aperture (mm) per condition, mean ± SD, onset to end.

    Left the speed (named for its point, :func:`transport_name`), right the
    aperture, against the share of the movement (0-100 %); one line per
    condition over a band of ± 1 SD, each panel's legend giving the trials
    behind its lines (:func:`kinematic_profiles`).

    Parameters
    ----------
    recognitions : sequence of Recognition or ClipSummary
        The trials.
    conditions : sequence of str or None
        Their conditions (None: ``unlabelled``).
    profiles : pandas.DataFrame, optional
        Their :func:`kinematic_profiles`, if made already (each is a pass over
        the trials: a batch reads its trials back from disk).
    point : str, optional
        Their :func:`transport_name`, if known already.
    """
    if profiles is None:
        profiles = kinematic_profiles(recognitions, conditions)
    conds = list(dict.fromkeys(profiles["condition"]))
    fig, axes = _figure((11.0, 4.8), 2, titled=True)
    speed = f"{point or transport_name(recognitions)} speed"
    for ax, key, title, unit in zip(axes, ("speed", "aperture"), (speed, "grip aperture"),
                                    ("mm/s", "mm")):
        lines = []
        for cond, g in profiles.groupby("condition", sort=False):
            n = int(g[f"{key}_n"].iloc[0])
            if not n:
                continue
            colour = condition_colour(cond, conds)
            x, mean, sd = (g[c].to_numpy(float) for c in ("movement", f"{key}_mean",
                                                           f"{key}_sd"))
            ax.fill_between(x, mean - sd, mean + sd, color=colour, alpha=0.2, lw=0)
            lines += ax.plot(x, mean, color=colour, lw=1.8, label=f"{cond} (n={n})", gid=cond)
        _panel(ax, f"{title}, mean ± SD", MOVEMENT, f"{title} ({unit})")
        ax.set_xlim(0.0, 100.0)
        ax.set_ylim(bottom=0.0)
        if lines:
            _legend(ax, lines)
        else:
            ax.text(0.5, 0.5, f"no {title} in these reports", transform=ax.transAxes,
                    ha="center", va="center", color="0.4", parse_math=False)
    _title(fig, "kinematics per condition, from each trial's onset to its end")
    return fig


def _long(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` as one row per trial and landmark: condition, landmark, value (its unit)."""
    if {"landmark", "value"} <= set(table.columns):
        # landmarks.csv: already in its units; its status is the movement's (complete,
        # starts in motion, ...), and a movement not measured has no value to draw
        return table[table["landmark"].isin([name for name, *_ in LANDMARKS])]
    if "status" in table:  # summary.csv: the clips scored
        table = table[table["status"] == "ok"]
    keep = [c for c in table.columns if c not in {name for name, *_ in LANDMARKS}]
    parts = [table[keep].assign(landmark=name, value=pd.to_numeric(table[name]) * scale)
             for name, _, _, scale in LANDMARKS if name in table]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(
        columns=[*keep, "landmark", "value"])


def landmark_strip_figure(table: pd.DataFrame) -> Figure:
    """Each landmark of every trial, a point per trial, by condition, with mean ± SD.

    Six panels (:data:`LANDMARKS`: movement time in ms, peak speed in
    mm/s, its time in %, MGA in mm, its time in %, the opening's start in %
    of the movement); in each, a column of points per condition (spread
    sideways so that none hides another), each trial a point coloured by
    its participant where the table has a participant column
    (:data:`PARTICIPANT_COLUMNS`), by its condition otherwise, and beside
    them the condition's mean ± SD. A landmark the table lacks (``summary.csv``
    has no ``opening_time``) leaves its panel out; an unmeasured value (NaN)
    is not drawn.

    Parameters
    ----------
    table : pandas.DataFrame
        ``summary.csv`` (one row per clip, SI units; failed clips left out)
        or ``landmarks.csv`` (one row per clip and landmark, ``value`` in its unit).
    """
    data = _long(table)
    data = data.assign(condition=data["condition"].where(data["condition"].notna(),
                                                         "unlabelled"))
    who = next((c for c in PARTICIPANT_COLUMNS if c in data and data[c].notna().any()), None)
    conds = list(dict.fromkeys(data["condition"]))
    people = list(dict.fromkeys(data[who].dropna())) if who else []
    palette = _person_colours(people)  # once: a colour map's call per point was 0.2 ms
    shown = [spec for spec in LANDMARKS if (data["landmark"] == spec[0]).any()]
    fig = _grid(len(shown), legend_rows=-(-len(people) // 8) + 1 if people else 0)
    rng = np.random.default_rng(0)  # the same spread every time
    for ax, (name, label, unit, _) in zip(fig.axes, shown):
        rows = data[(data["landmark"] == name) & data["value"].notna()]
        for i, cond in enumerate(conds):
            g = rows[rows["condition"] == cond]
            values = g["value"].to_numpy(float)
            x = i - 0.08 + rng.uniform(-0.12, 0.12, len(g))
            colours = ([palette.get(p, _NO_PERSON) for p in g[who]] if who
                       else [condition_colour(cond, conds)] * len(g))
            ax.scatter(x, values, s=22, c=colours, edgecolors="k", linewidths=0.4, zorder=3,
                       gid="trials")
            if len(values):
                sd = values.std(ddof=1) if len(values) > 1 else 0.0
                ax.errorbar([i + 0.22], [values.mean()], yerr=[sd], fmt="_", color="k", ms=12,
                            capsize=3, lw=1.2, zorder=4)
        ax.set_xticks(range(len(conds)), [f"{c}\n(n={int((rows['condition'] == c).sum())})"
                                          for c in conds])
        for tick in ax.get_xticklabels():
            tick.set_parse_math(False)
        ax.set_xlim(-0.6, len(conds) - 0.4)
        _panel(ax, label, "", f"{label} ({unit})")
        ax.tick_params(axis="x", labelsize=LEGEND_PT)
    if people:
        from matplotlib.lines import Line2D

        _legend(fig, [Line2D([], [], ls="", marker="o", ms=5, mfc=palette[p],
                             mec="k", mew=0.4, label=str(p)) for p in people], "lower center",
                ncols=min(len(people), 8), title=f"{who}; black bars: the condition's mean ± SD",
                frameon=False)
    _title(fig, "landmarks per condition: every trial a point, mean ± SD beside it")
    return fig


#: The colour of a trial whose participant is not given (a study where only some are).
_NO_PERSON = (0.6, 0.6, 0.6, 1.0)


def _person_colours(people: list) -> dict:
    """Each participant's colour, by their order (tab10, or tab20 beyond ten; repeating)."""
    from matplotlib import colormaps

    cmap = colormaps["tab10" if len(people) <= 10 else "tab20"]
    return {p: cmap(i % cmap.N) for i, p in enumerate(people)}


def _grid(panels: int, legend_rows: int) -> Figure:
    """A figure with ``panels`` axes in rows of three, room below for a legend."""
    from matplotlib.figure import Figure

    from perception.report.canvas import new_canvas

    rows, cols = max(1, -(-panels // 3)), min(max(panels, 1), 3)
    width, height = 4.0 * cols, 3.4 * rows + 0.7 + 0.25 * legend_rows
    fig = Figure(figsize=(width, height))
    new_canvas(fig)
    spec = fig.add_gridspec(rows, cols, left=LEFT / width, right=1 - RIGHT / width,
                            bottom=(0.75 + 0.25 * legend_rows) / height, top=1 - 0.7 / height,
                            wspace=0.45, hspace=0.55)
    for k in range(panels):
        fig.add_subplot(spec[k // cols, k % cols])
    return fig

"""Report figures (thesis chapter 5), each built as a chart and drawn by Pillow or matplotlib.

Per clip: every model's confidence and log-likelihood (:func:`confidence_chart`)
and the demonstration against the reference grasp model's own movement
(:func:`paths_chart`, Figs. 5.5-5.7). Per batch: grip aperture per condition
against the model's (:func:`aperture_chart`, Fig. 5.4d), the reference
model's confidence on one clip per condition (:func:`confidence_single_chart`,
Fig. 5.8a) and on every clip (:func:`confidence_all_chart`, Fig. 5.8b), and
mean ± SD per condition at select points (:func:`condition_chart`, Fig. 5.8c).
Each is a :class:`~perception.report.chart.Chart`: the reports draw them with
Pillow in milliseconds (:func:`~perception.report.chart.render_png`), and each
``*_figure`` function (:func:`confidence_figure`, :func:`aperture_figure`, …)
gives the same figure in matplotlib. Confidence is drawn in cm (weighted),
×100 of its value in the files.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from perception.recognition.result import Recognition
from perception.report.chart import Band, Chart, ErrorBars, Legend, Line, Panel, to_matplotlib

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

    from perception.report.clip import ClipSummary

__all__ = ["aperture_chart", "aperture_figure", "condition_chart", "condition_colour",
           "condition_figure", "confidence_all_chart", "confidence_all_figure",
           "confidence_chart", "confidence_figure", "confidence_single_chart",
           "confidence_single_figure", "paths_chart", "paths_figure"]


CM = 100.0
#: Colours of the chapter 5 conditions; others take the next free colour.
CONDITION_COLOURS = {"normal": "C0", "delayed": "C1", "open-close-open": "C3", "reach": "C2",
                     "unlabelled": "0.4"}
_SPARE = ("C4", "C5", "C6", "C7", "C8", "C9")


def condition_colour(condition: str, seen: Sequence[str] = ()) -> str:
    """The colour of a condition (a fixed one for the chapter 5 conditions).

    Parameters
    ----------
    condition : str
        Condition name.
    seen : sequence of str
        Conditions in the figure, in order (others get spare colours in this order).
    """
    if condition in CONDITION_COLOURS:
        return CONDITION_COLOURS[condition]
    others = [c for c in dict.fromkeys(seen) if c not in CONDITION_COLOURS]
    i = others.index(condition) if condition in others else len(others)
    return _SPARE[i % len(_SPARE)]


def _verdict_line(rec: Recognition) -> str:
    d = rec.decision
    if d.verdict is None:
        return f"winner {rec.winner} ({rec.rule} rule)"
    return (f"verdict {d.verdict} (familiarity {d.familiarity:.2f}, margin {d.margin:.1f}); "
            f"winner {rec.winner} ({rec.rule} rule)")


TIME = "time since onset (s)"


def confidence_chart(rec: Recognition) -> Chart:
    """Confidence profiles of every model (thesis rule) and the log-likelihood.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    styles = {"grasp": "-", "reach": "--"}
    conf, ll = [], []
    for k, (name, kind, c, l) in enumerate(zip(rec.names, rec.kinds, rec.confidence,
                                               rec.log_likelihood)):
        look = dict(colour=f"C{k % 10}", width=2.6 if name == rec.winner else 1.2,
                    style=styles.get(kind, "-"), label=name)
        conf.append(Line(rec.time, c * CM, **look))
        ll.append(Line(rec.time, l, **look))
    return Chart(
        (Panel("thesis rule: confidence C (eqs. 5.6-5.8)", TIME, "C (cm, weighted)",
               tuple(conf), hlines=(0.0,)),
         Panel("likelihood rule: cumulative log-likelihood", TIME, "log-likelihood",
               tuple(ll), hlines=(0.0,))),
        title=f"{rec.clip}: {_verdict_line(rec)}", size=(12, 5),
        legend=Legend(columns=min(len(rec.names), 5),
                      title="grasp models solid, reach dashed; the winner thick"))


def confidence_figure(rec: Recognition) -> Figure:
    """:func:`confidence_chart` as a matplotlib figure.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    return to_matplotlib(confidence_chart(rec))


def paths_chart(rec: Recognition, model: str | None = None) -> Chart:
    """The demonstration against a grasp model's own movement (thesis Figs. 5.5-5.7).

    Left, the observed wrist, finger and thumb paths and the model's own
    noise-free movement from the same start; right, the grip aperture over
    time: observed, the model's own, and the model's one-step predictions.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    model : str, optional
        Model drawn (default: the reference grasp model, the grasp model with
        the highest log-likelihood; the winner if there is no grasp model).
    """
    model = model or rec.reference_model or rec.winner
    i = rec.names.index(model)
    obs, own = rec.observation, rec.nominal(model)
    paths = []
    for key, colour in (("finger", "g"), ("thumb", "r"), ("wrist", "b")):
        seen, plan = getattr(obs, key), own[key]
        paths.append(Line(seen[:, 0], seen[:, 1], colour, 1.8, "-", f"{key} observed"))
        paths.append(Line(plan[:, 0], plan[:, 1], colour, 1.5, "--", f"{key}, {model}"))
    circle = np.linspace(0, 2 * np.pi, 100)
    rad = obs.object_diameter / 2
    paths.append(Line(rad * np.cos(circle), rad * np.sin(circle), "y", 2.0, "-", "object"))
    own_g = np.linalg.norm(own["finger"] - own["thumb"], axis=1)
    aperture = (Line(rec.time, obs.g * CM, "k", 2.0, "-", "observed"),
                Line(rec.time, own_g * CM, "k", 1.5, "--", f"{model}'s own movement"),
                Line(rec.time, rec.predicted_g[i] * CM, "0.45", 1.2, ":",
                     f"{model}, one step ahead"))
    return Chart(
        (Panel(f"paths: observed (solid) and {model}'s own movement (dashed)", "x (m)",
               "y (m), toward the object", tuple(paths), equal_aspect=True,
               legend=Legend("best", columns=2)),
         Panel("grip aperture", TIME, "grip aperture (cm)", aperture,
               legend=Legend("best"))),
        title=f"{rec.clip}: {_verdict_line(rec)}", size=(12, 5.5))


def paths_figure(rec: Recognition, model: str | None = None) -> Figure:
    """:func:`paths_chart` as a matplotlib figure.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    model : str, optional
        Model drawn (default: the reference grasp model).
    """
    return to_matplotlib(paths_chart(rec, model))


MOVEMENT_TIME = "movement time (%)"
#: Error bars of Fig. 5.8c: at this many evenly spaced phases.
SD_POINTS = 11


def _n_label(cond: str, g: pd.DataFrame) -> str:
    return f"{cond} (n={int(g['n'].iloc[0])})"


def condition_chart(profiles: pd.DataFrame, model: str) -> Chart:
    """Mean ± SD confidence per condition at select points (thesis Fig. 5.8c).

    The total confidence, and its transport and grip terms when
    ``profiles`` has them (``transport_mean``, ``grip_mean``, …): a mean
    curve per condition with SD bars at :data:`SD_POINTS` evenly spaced
    phases, the legend in the first panel.

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`~perception.report.conditions.condition_profiles`.
    model : str
        The model profiled (for the title).
    """
    parts = [("", "confidence C")]
    if "transport_mean" in profiles.columns:
        parts += [("transport_", "transport term"), ("grip_", "grip term")]
    conds = list(dict.fromkeys(profiles["condition"]))
    panels = []
    for k, (prefix, title) in enumerate(parts):
        lines, bars = [], []
        for cond, g in profiles.groupby("condition", sort=False):
            colour = condition_colour(cond, conds)
            x = g["phase"].to_numpy() * 100
            mean, sd = g[f"{prefix}mean"].to_numpy() * CM, g[f"{prefix}sd"].to_numpy() * CM
            lines.append(Line(x, mean, colour, 1.8, label=_n_label(cond, g)))
            at = np.unique(np.round(np.linspace(0, len(g) - 1, SD_POINTS)).astype(int))
            bars.append(ErrorBars(x[at], mean[at], sd[at], colour, 1.0, 3.0))
        panels.append(Panel(f"{title}: mean ± SD", MOVEMENT_TIME, f"{title} (cm, weighted)",
                            tuple(lines), hlines=(0.0,), errorbars=tuple(bars),
                            legend=Legend("best") if k == 0 else None))
    return Chart(tuple(panels), title=f"{model}'s confidence by condition (Fig. 5.8c)",
                 size=(5.2 * len(parts), 4.8))


def condition_figure(profiles: pd.DataFrame, model: str) -> Figure:
    """:func:`condition_chart` as a matplotlib figure (thesis Fig. 5.8c).

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`~perception.report.conditions.condition_profiles`.
    model : str
        The model profiled (for the title).
    """
    return to_matplotlib(condition_chart(profiles, model))


def aperture_chart(profiles: pd.DataFrame, model: pd.DataFrame | None = None,
                   model_name: str = "") -> Chart:
    """Grip aperture per condition, mean ± SD, against the model's (thesis Fig. 5.4d).

    A mean curve per condition over a band of ± 1 SD; the model's own
    aperture dashed black over a grey band.

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`~perception.report.conditions.aperture_profiles`
        (condition, phase, mean, sd, n; m).
    model : pandas.DataFrame, optional
        The model's own aperture (phase, mean, sd; m), drawn dashed.
    model_name : str
        The model's name, for the legend.
    """
    conds = list(dict.fromkeys(profiles["condition"]))
    curves = [(g, condition_colour(cond, conds), 0.2, "-", _n_label(cond, g))
              for cond, g in profiles.groupby("condition", sort=False)]
    if model is not None and len(model):
        curves.append((model, "k", 0.12, "--", f"model {model_name}"))
    lines, bands = [], []
    for g, colour, alpha, style, label in curves:
        x, mean, sd = (g[c].to_numpy(dtype=float) for c in ("phase", "mean", "sd"))
        lines.append(Line(x * 100, mean * CM, colour, 1.8, style, label))
        bands.append(Band(x * 100, (mean - sd) * CM, (mean + sd) * CM, colour, alpha))
    return Chart((Panel("grip aperture, mean ± SD (Fig. 5.4d)", MOVEMENT_TIME,
                        "grip aperture (cm)", tuple(lines), bands=tuple(bands),
                        legend=Legend("best")),), size=(7.5, 5))


def aperture_figure(profiles: pd.DataFrame, model: pd.DataFrame | None = None,
                    model_name: str = "") -> Figure:
    """:func:`aperture_chart` as a matplotlib figure (thesis Fig. 5.4d).

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`~perception.report.conditions.aperture_profiles`
        (condition, phase, mean, sd, n; m).
    model : pandas.DataFrame, optional
        The model's own aperture (phase, mean, sd; m), drawn dashed.
    model_name : str
        The model's name, for the legend.
    """
    return to_matplotlib(aperture_chart(profiles, model, model_name))


def _confidence_panel(model: str, title: str, lines: list[Line]) -> Chart:
    return Chart((Panel(title, TIME, f"C of {model} (cm, weighted)", tuple(lines),
                        hlines=(0.0,), legend=Legend("best")),), size=(7.5, 5))


def confidence_single_chart(clips: Sequence[ClipSummary], conditions: Sequence[str],
                            model: str) -> Chart:
    """The model's confidence on one clip per condition (thesis Fig. 5.8a).

    Parameters
    ----------
    clips : sequence of ClipSummary
        One clip per condition.
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose confidence is drawn.
    """
    return _confidence_panel(model, "one clip per condition (Fig. 5.8a)", [
        Line(rec.time, rec.confidence[rec.index(model)] * CM,
             condition_colour(cond, conditions), 1.8, label=f"{cond}: {rec.clip}")
        for rec, cond in zip(clips, conditions)])


def confidence_single_figure(clips: Sequence[ClipSummary], conditions: Sequence[str],
                             model: str) -> Figure:
    """:func:`confidence_single_chart` as a matplotlib figure (thesis Fig. 5.8a).

    Parameters
    ----------
    clips : sequence of ClipSummary
        One clip per condition.
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose confidence is drawn.
    """
    return to_matplotlib(confidence_single_chart(clips, conditions, model))


def confidence_all_chart(clips: Sequence[ClipSummary], conditions: Sequence[str],
                         model: str) -> Chart:
    """The model's confidence on every clip, coloured by condition (thesis Fig. 5.8b).

    One thin line a clip, in the clips' order; the legend names each
    condition once.

    Parameters
    ----------
    clips : sequence of ClipSummary
        Scored clips.
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose confidence is drawn.
    """
    lines, labelled = [], set()
    for rec, cond in zip(clips, conditions):
        lines.append(Line(rec.time, rec.confidence[rec.index(model)] * CM,
                          condition_colour(cond, conditions), 1.0,
                          label=None if cond in labelled else cond))
        labelled.add(cond)
    return _confidence_panel(model, f"every clip ({len(clips)}; Fig. 5.8b)", lines)


def confidence_all_figure(clips: Sequence[ClipSummary], conditions: Sequence[str],
                          model: str) -> Figure:
    """:func:`confidence_all_chart` as a matplotlib figure (thesis Fig. 5.8b).

    Parameters
    ----------
    clips : sequence of ClipSummary
        Scored clips.
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose confidence is drawn.
    """
    return to_matplotlib(confidence_all_chart(clips, conditions, model))

"""Report figures (thesis chapter 5).

Per clip: every model's confidence and log-likelihood (:func:`confidence_chart`)
and the demonstration against the reference grasp model's own movement
(:func:`paths_chart`, Figs. 5.5-5.7), built as :class:`~perception.report.chart.Chart`
s: the report draws them with Pillow in milliseconds
(:func:`~perception.report.chart.render_png`), and :func:`confidence_figure`
and :func:`paths_figure` give the same figures in matplotlib. Per batch
(matplotlib): grip aperture per condition against the model's
(:func:`aperture_figure`, Fig. 5.4d), the reference model's confidence on
one clip per condition (:func:`confidence_single_figure`, Fig. 5.8a) and on
every clip (:func:`confidence_all_figure`, Fig. 5.8b), and mean ± SD per
condition at select points (:func:`condition_figure`, Fig. 5.8c). Confidence
is drawn in cm (weighted), ×100 of its value in the files.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from perception.recognition.result import Recognition
from perception.report.chart import Chart, Legend, Line, Panel, to_matplotlib

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

    from perception.report.clip import ClipSummary

__all__ = ["aperture_figure", "condition_colour", "condition_figure", "confidence_all_figure",
           "confidence_chart", "confidence_figure", "confidence_single_figure", "paths_chart",
           "paths_figure"]


def _new_figure(*args, **kwargs):
    # matplotlib (about a second to import) only when a batch figure is drawn:
    # `recognize` draws its two with Pillow (perception.report.chart)
    from minvar.plotting import new_figure

    return new_figure(*args, **kwargs)

CM = 100.0
#: Colours of the chapter 5 conditions; others take the next free colour.
CONDITION_COLOURS = {"normal": "C0", "delayed": "C1", "open-close-open": "C3", "reach": "C2",
                     "unlabelled": "0.4"}
_SPARE = ("C4", "C5", "C6", "C7", "C8", "C9")
LEGEND = dict(fontsize=9, frameon=False)


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


def _mean_sd_points(a, g: pd.DataFrame, colour: str, label: str, scale: float,
                    points: int = 11) -> None:
    """A mean curve with SD bars at ``points`` evenly spaced phases."""
    x = g["phase"].to_numpy() * 100
    a.plot(x, g["mean"] * scale, color=colour, lw=1.8, label=label)
    idx = np.unique(np.round(np.linspace(0, len(g) - 1, points)).astype(int))
    a.errorbar(x[idx], g["mean"].to_numpy()[idx] * scale, yerr=g["sd"].to_numpy()[idx] * scale,
               fmt="none", ecolor=colour, capsize=3, lw=1)


def condition_figure(profiles: pd.DataFrame, model: str) -> Figure:
    """Mean ± SD confidence per condition at select points (thesis Fig. 5.8c).

    The total confidence, and its transport and grip terms when
    ``profiles`` has them (``transport_mean``, ``grip_mean``, …).

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
    import pandas as pd

    fig, ax = _new_figure(1, len(parts), size=(5.2 * len(parts), 4.8))
    conds = list(dict.fromkeys(profiles["condition"]))
    for a, (prefix, title) in zip(ax[0], parts):
        for cond, g in profiles.groupby("condition", sort=False):
            part = pd.DataFrame({"phase": g["phase"], "mean": g[f"{prefix}mean"],
                                 "sd": g[f"{prefix}sd"]})
            _mean_sd_points(a, part, condition_colour(cond, conds),
                            f"{cond} (n={int(g['n'].iloc[0])})", CM)
        a.set_xlabel("movement time (%)")
        a.set_ylabel(f"{title} (cm, weighted)")
        a.set_title(f"{title}: mean ± SD")
        a.axhline(0, color="0.7", lw=0.6)
    ax[0, 0].legend(**LEGEND)
    fig.suptitle(f"{model}'s confidence by condition (Fig. 5.8c)")
    return fig


def aperture_figure(profiles: pd.DataFrame, model: pd.DataFrame | None = None,
                    model_name: str = "") -> Figure:
    """Grip aperture per condition, mean ± SD, against the model's (thesis Fig. 5.4d).

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
    fig, ax = _new_figure(1, 1, size=(7.5, 5))
    a = ax[0, 0]
    conds = list(dict.fromkeys(profiles["condition"]))
    for cond, g in profiles.groupby("condition", sort=False):
        colour = condition_colour(cond, conds)
        x = g["phase"] * 100
        a.plot(x, g["mean"] * CM, color=colour, lw=1.8, label=f"{cond} (n={int(g['n'].iloc[0])})")
        a.fill_between(x, (g["mean"] - g["sd"]) * CM, (g["mean"] + g["sd"]) * CM,
                       color=colour, alpha=0.2, lw=0)
    if model is not None and len(model):
        x = model["phase"] * 100
        a.plot(x, model["mean"] * CM, "k--", lw=1.8, label=f"model {model_name}")
        a.fill_between(x, (model["mean"] - model["sd"]) * CM,
                       (model["mean"] + model["sd"]) * CM, color="k", alpha=0.12, lw=0)
    a.set_xlabel("movement time (%)")
    a.set_ylabel("grip aperture (cm)")
    a.set_title("grip aperture, mean ± SD (Fig. 5.4d)")
    a.legend(**LEGEND)
    return fig


def _confidence_axes(a, model: str, title: str) -> None:
    a.set_xlabel("time since onset (s)")
    a.set_ylabel(f"C of {model} (cm, weighted)")
    a.set_title(title)
    a.axhline(0, color="0.7", lw=0.6)


def confidence_single_figure(clips: Sequence[ClipSummary], conditions: Sequence[str],
                             model: str) -> Figure:
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
    fig, ax = _new_figure(1, 1, size=(7.5, 5))
    for rec, cond in zip(clips, conditions):
        ax[0, 0].plot(rec.time, rec.confidence[rec.index(model)] * CM, lw=1.8,
                      color=condition_colour(cond, conditions), label=f"{cond}: {rec.clip}")
    _confidence_axes(ax[0, 0], model, "one clip per condition (Fig. 5.8a)")
    ax[0, 0].legend(**LEGEND)
    return fig


def confidence_all_figure(clips: Sequence[ClipSummary], conditions: Sequence[str],
                          model: str) -> Figure:
    """The model's confidence on every clip, coloured by condition (thesis Fig. 5.8b).

    Parameters
    ----------
    clips : sequence of ClipSummary
        Scored clips.
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose confidence is drawn.
    """
    fig, ax = _new_figure(1, 1, size=(7.5, 5))
    labelled = set()
    for rec, cond in zip(clips, conditions):
        ax[0, 0].plot(rec.time, rec.confidence[rec.index(model)] * CM, lw=1.0, alpha=0.8,
                      color=condition_colour(cond, conditions),
                      label=None if cond in labelled else cond)
        labelled.add(cond)
    _confidence_axes(ax[0, 0], model, f"every clip ({len(clips)}; Fig. 5.8b)")
    ax[0, 0].legend(**LEGEND)
    return fig

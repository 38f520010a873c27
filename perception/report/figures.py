"""Report figures (thesis chapter 5).

Per clip: every model's confidence and log-likelihood (:func:`confidence_figure`)
and the demonstration against the reference grasp model's own movement
(:func:`paths_figure`, Figs. 5.5-5.7). Per batch: grip aperture per
condition against the model's (:func:`aperture_figure`, Fig. 5.4d), the
reference model's confidence on one clip per condition
(:func:`confidence_single_figure`, Fig. 5.8a) and on every clip
(:func:`confidence_all_figure`, Fig. 5.8b), and mean ± SD per condition at
select points (:func:`condition_figure`, Fig. 5.8c). Confidence is drawn in
cm (weighted), ×100 of its value in the files.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from perception.recognition.result import Recognition

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from perception.report.clip import ClipSummary

__all__ = ["aperture_figure", "condition_colour", "condition_figure", "confidence_all_figure",
           "confidence_figure", "confidence_single_figure", "paths_figure"]


def _new_figure(*args, **kwargs):
    # matplotlib (about a second to import) only when a figure is drawn:
    # `recognize --no-figures` and the batch's tables never pay for it
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


def confidence_figure(rec: Recognition) -> Figure:
    """Confidence profiles of every model (thesis rule) and the log-likelihood.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    fig, ax = _new_figure(1, 2, size=(12, 5))
    styles = {"grasp": "-", "reach": "--"}
    for name, kind, c, ll in zip(rec.names, rec.kinds, rec.confidence, rec.log_likelihood):
        lw = 2.6 if name == rec.winner else 1.2
        ax[0, 0].plot(rec.time, c * CM, styles.get(kind, "-"), label=name, lw=lw)
        ax[0, 1].plot(rec.time, ll, styles.get(kind, "-"), label=name, lw=lw)
    ax[0, 0].set_title("thesis rule: confidence C (eqs. 5.6-5.8)")
    ax[0, 0].set_ylabel("C (cm, weighted)")
    ax[0, 1].set_title("likelihood rule: cumulative log-likelihood")
    ax[0, 1].set_ylabel("log-likelihood")
    for a in ax[0]:
        a.set_xlabel("time since onset (s)")
        a.axhline(0, color="0.7", lw=0.6)
    fig.legend(*ax[0, 0].get_legend_handles_labels(), loc="outside lower center",
               ncol=min(len(rec.names), 5), title="grasp models solid, reach dashed; "
               "the winner thick", **LEGEND)
    fig.suptitle(f"{rec.clip}: {_verdict_line(rec)}")
    return fig


def paths_figure(rec: Recognition, model: str | None = None) -> Figure:
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
    fig, ax = _new_figure(1, 2, size=(12, 5.5))
    a = ax[0, 0]
    for key, colour in (("finger", "g"), ("thumb", "r"), ("wrist", "b")):
        a.plot(*getattr(obs, key).T, "-", color=colour, lw=1.8, label=f"{key} observed")
        a.plot(*own[key].T, "--", color=colour, lw=1.5, label=f"{key}, {model}")
    circle = np.linspace(0, 2 * np.pi, 100)
    rad = obs.object_diameter / 2
    a.plot(rad * np.cos(circle), rad * np.sin(circle), "y-", lw=2, label="object")
    a.set_aspect("equal", adjustable="datalim")
    a.set_xlabel("x (m)")
    a.set_ylabel("y (m), toward the object")
    a.set_title(f"paths: observed (solid) and {model}'s own movement (dashed)")
    a.legend(ncol=2, loc="lower left", **LEGEND)
    b = ax[0, 1]
    b.plot(rec.time, obs.g * CM, "k-", lw=2, label="observed")
    own_g = np.linalg.norm(own["finger"] - own["thumb"], axis=1)
    b.plot(rec.time, own_g * CM, "k--", lw=1.5, label=f"{model}'s own movement")
    b.plot(rec.time, rec.predicted_g[i] * CM, ":", color="0.45", lw=1.2,
           label=f"{model}, one step ahead")
    b.set_xlabel("time since onset (s)")
    b.set_ylabel("grip aperture (cm)")
    b.set_title("grip aperture")
    b.legend(loc="upper left", **LEGEND)
    fig.suptitle(f"{rec.clip}: {_verdict_line(rec)}")
    return fig


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

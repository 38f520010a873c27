"""Figures of the chapter-4 sweeps (thesis Figs. 4.2-4.5, 4.7-4.16).

Each figure function takes a finished
:class:`~minvar.grasp_experiments.GraspExperiment` (its tables and statistics)
and returns a :class:`matplotlib.figure.Figure`; :func:`experiment_figures`
builds every figure of one experiment, keyed by the file stem named after the
thesis's figure (``fig4_10_object_size_mga``). Units as in
:mod:`minvar.plotting.grasp`: cm for positions, micrometres for SDs.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle

from ..grasp import plan_grasp
from .canvas import new_figure
from .grasp import CM, UM, _draw_object, _draw_posture

if TYPE_CHECKING:  # pragma: no cover - results are duck-typed at run time
    from ..grasp_experiments import GraspExperiment

__all__ = [
    "EXPERIMENT_FIGURES",
    "experiment_figures",
    "paths_figure",
    "viapoint_height_paths_figure",
    "accuracy_figure",
    "mga_figure",
    "sd_time_figure",
    "sd_peaks_figure",
]

#: How each swept quantity is displayed: (label, scale, unit).
_DISPLAY = {
    "object_size": ("object size", 100.0, "cm"),
    "distance": ("wrist start to object centre", 100.0, "cm"),
    "transport_distance": ("transport distance (wrist travel)", 100.0, "cm"),
    "duration": ("movement time", 1000.0, "ms"),
    "viapoint_offset": ("via-point distance from object", 100.0, "cm"),
    "viapoint_height": ("via-point height above the target line", 100.0, "cm"),
    "viapoint_time": ("via-point time", 100.0, "% of movement"),
}


def _display(parameter: str) -> tuple[str, float, str]:
    return _DISPLAY.get(parameter, (parameter, 1.0, ""))


def _axis_label(parameter: str) -> str:
    label, _, unit = _display(parameter)
    return f"{label} ({unit})" if unit else label


def _subset(n: int, most: int = 6) -> list[int]:
    """Indices of at most ``most`` evenly spaced settings (every k-th from the first)."""
    step = int(np.ceil(n / most))
    return list(range(0, n, step))


def _colours(k: int):
    from matplotlib import colormaps

    cmap = colormaps["viridis"]
    return [cmap(x) for x in np.linspace(0.0, 0.9, max(k, 1))]


def _x(exp: GraspExperiment) -> np.ndarray:
    """The displayed quantity per setting, in display units."""
    return exp.summary[exp.shown].to_numpy() * _display(exp.shown)[1]


def _mean_paths(ax, exp: GraspExperiment, idx: list[int]) -> None:
    label, _, unit = _display(exp.shown)
    cols = _colours(len(idx))
    handles = []
    for c, i in zip(cols, idx):
        cur = exp.curves[exp.curves.setting == i]
        v = _x(exp)[i]
        ax.plot(cur.finger_x * CM, cur.finger_y * CM, ":", color=c, lw=1.4)
        ax.plot(cur.thumb_x * CM, cur.thumb_y * CM, "--", color=c, lw=1.4)
        handles.append(Line2D([], [], color=c, lw=2, label=f"{v:g} {unit}"))
    # the line styles as the title names them: finger dotted, thumb dashed
    handles += [Line2D([], [], color="k", ls=":", lw=1.4, label="finger"),
                Line2D([], [], color="k", ls="--", lw=1.4, label="thumb")]
    # the objects drawn: each one shown if size is swept, else the base object
    sizes = exp.values[idx] if exp.parameter == "object_size" else [exp.base.object_size]
    for s in sizes:
        if s > 0:
            ax.add_patch(Circle((0, 0), s / 2 * CM, fc="none", ec="0.6", lw=0.6))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    ax.legend(handles=handles, fontsize=7, title=label, title_fontsize=7)


def paths_figure(exp: GraspExperiment) -> Figure:
    """Mean digit paths, speed profiles and aperture per setting (thesis Figs. 4.4, 4.7, 4.9).

    Panels: (a) mean finger (dotted) and thumb (dashed) paths; (b) their mean
    speed; (c) mean grip aperture over time. At most six settings are drawn.

    Parameters
    ----------
    exp : GraspExperiment
        A sweep from :mod:`minvar.grasp_experiments`.
    """
    idx = _subset(len(exp.values))
    fig, ax = new_figure(1, 3, size=(14, 4.6))
    _mean_paths(ax[0, 0], exp, idx)
    ax[0, 0].set_title("(a) digit paths (finger dotted, thumb dashed)", fontsize=9)
    for c, i in zip(_colours(len(idx)), idx):
        cur = exp.curves[exp.curves.setting == i]
        rt = cur.relative_time * 100
        ax[0, 1].plot(rt, cur.finger_speed, ":", color=c)
        ax[0, 1].plot(rt, cur.thumb_speed, "--", color=c)
        ax[0, 2].plot(rt, cur.aperture * CM, "-", color=c)
    ax[0, 1].set_title("(b) digit speed", fontsize=9)
    ax[0, 1].set_ylabel("speed (m/s)")
    ax[0, 2].set_title("(c) grip aperture", fontsize=9)
    ax[0, 2].set_ylabel("aperture (cm)")
    for a in ax[0, 1:]:
        a.set_xlabel("time (% of movement)")
    fig.suptitle(f"{exp.name}: mean of {exp.summary.trials.iloc[0]} repetitions per setting")
    return fig


def viapoint_height_paths_figure(exp: GraspExperiment) -> Figure:
    """Via-point lines and mean digit paths per via-point height (thesis Fig. 4.2).

    Panels: (a) the hand's starting posture drawn at the wrist target (the
    frame the grip is planned in: closed tips ``tip_start`` ahead of the
    wrist), its posture at the goal (grey), the target line and each
    setting's via-points; (b) mean digit paths.

    Parameters
    ----------
    exp : GraspExperiment
        The via-point height sweep.
    """
    idx = _subset(len(exp.values))
    cols = _colours(len(idx))
    fig, ax = new_figure(1, 2, size=(11, 5))
    a = ax[0, 0]
    task = exp.base
    plan = plan_grasp(task)
    _draw_posture(a, plan, plan.arm.q_goal, plan.finger.q_goal, plan.thumb.q_goal,
                  dict(color="0.6", marker="o", ms=3, lw=1.0, label="hand at the goal"))
    _draw_posture(a, plan, plan.arm.q_goal, plan.finger.q_start, plan.thumb.q_start,
                  dict(color="k", marker="o", ms=3, lw=1.2, label="starting posture"))
    _draw_object(a, task)
    half = task.object_size / 2 + task.viapoint_offset
    for c, i in zip(cols, idx):
        h = exp.values[i]
        a.plot(np.array([-half, half]) * CM, [h * CM, h * CM], "s--", color=c, ms=5,
               label=f"{h * CM:+g} cm")
    a.axhline(0, color="k", lw=0.6)
    a.set_xlim(-(half + 0.03) * CM, (half + 0.03) * CM)
    a.set_ylim(-(task.wrist_offset + 0.02) * CM, 0.04 * CM)
    a.set_aspect("equal", adjustable="box")
    a.set_xlabel("x (cm)")
    a.set_ylabel("y (cm)")
    a.legend(fontsize=7, title="via-point line (hand frame)", title_fontsize=7)
    a.set_title("(a) starting hand, target line (black) and via-points", fontsize=9)
    _mean_paths(ax[0, 1], exp, idx)
    ax[0, 1].set_title("(b) mean digit paths (finger dotted, thumb dashed)", fontsize=9)
    return fig


def accuracy_figure(exp: GraspExperiment) -> Figure:
    """Digit end-point accuracy per setting (thesis Figs. 4.3, 4.5).

    Panels: (a) finger end-point distance from its target, each repetition a
    cross, the mean a line; (b) the same for the thumb; (c) finger end-point
    SD in x and y (markers: repetitions; lines: exact); (d) thumb.

    Parameters
    ----------
    exp : GraspExperiment
        A sweep from :mod:`minvar.grasp_experiments`.
    """
    x = _x(exp)
    scale = _display(exp.shown)[1]
    fig, ax = new_figure(2, 2, size=(10, 8))
    tr = exp.trials
    span = np.ptp(x) if len(x) > 1 else 1.0
    jitter = np.random.default_rng(0).uniform(-0.01, 0.01, len(tr)) * span  # display only
    n = exp.summary.trials.iloc[0]
    for j, digit in enumerate(("finger", "thumb")):
        a = ax[0, j]
        a.plot(tr[exp.shown] * scale + jitter, tr[f"{digit}_distance"] * UM, "x", ms=2,
               alpha=0.3, color="tab:blue")
        a.plot(x, exp.summary[f"{digit}_distance_mean"] * UM, "k-", lw=1.5,
               label=f"mean of {n}")
        a.plot(x, exp.summary[f"{digit}_distance_exact"] * UM, "--", color="tab:red", lw=1,
               label="exact")
        a.set_ylabel("end-point distance from target (µm)")
        a.set_title(f"({'ab'[j]}) {digit} end-point distance", fontsize=9)
        a.legend(fontsize=8)
        b = ax[1, j]
        for axis, mk, c in (("x", "o", "tab:orange"), ("y", "s", "tab:purple")):
            b.plot(x, exp.summary[f"{digit}_sd_{axis}"] * UM, mk, color=c, mfc="none",
                   label=f"{axis} ({n} repetitions)")
            b.plot(x, exp.summary[f"{digit}_sd_{axis}_exact"] * UM, "-", color=c,
                   label=f"{axis} exact")
        b.set_ylabel("end-point SD (µm)")
        b.set_title(f"({'cd'[j]}) {digit} end-point SD", fontsize=9)
        b.legend(fontsize=7)
    for a in ax.ravel():
        a.set_xlabel(_axis_label(exp.shown))
    return fig


def mga_figure(exp: GraspExperiment) -> Figure:
    """Maximum grip aperture and its timing per setting (thesis Figs. 4.8, 4.10).

    Panels: (a) mean MGA (bars: 95 % interval of the mean) with its
    regression line and equation; (b) mean relative time of the MGA, and the
    60-80 % band of human studies.

    Parameters
    ----------
    exp : GraspExperiment
        A sweep from :mod:`minvar.grasp_experiments` with MGA statistics.
    """
    x = _x(exp)
    scale = _display(exp.shown)[1]
    s = exp.summary
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    a = ax[0, 0]
    a.errorbar(x, s.mga_mean * CM, yerr=(s.mga_mean - s.mga_ci_low) * CM, fmt="o", color="k",
               ms=4, capsize=2)
    slope = exp.stats.get("mga_slope")
    if slope is not None:
        icpt = exp.stats["mga_intercept"]
        xs = np.array([x.min(), x.max()]) / scale
        a.plot(xs * scale, (slope * xs + icpt) * CM, "-", color="tab:blue")
        a.text(0.04, 0.92, f"MGA = {slope:.2f} x + {icpt * CM:.2f} cm",
               transform=a.transAxes, fontsize=9)
    a.set_ylabel("maximum grip aperture (cm)")
    a.set_title("(a) maximum grip aperture", fontsize=9)
    b = ax[0, 1]
    b.errorbar(x, s.mga_time_mean * 100, yerr=(s.mga_time_mean - s.mga_time_ci_low) * 100,
               fmt="o-", color="k", ms=4, capsize=2)
    b.axhspan(60, 80, color="0.9", zorder=0, label="60-80 % (human studies)")
    b.set_ylabel("time of MGA (% of movement)")
    b.set_title("(b) relative time of the maximum", fontsize=9)
    b.legend(fontsize=8)
    for a in ax.ravel():
        a.set_xlabel(_axis_label(exp.shown))
    return fig


def sd_time_figure(exp: GraspExperiment) -> Figure:
    """Wrist and aperture SD over normalised time per setting (thesis Figs. 4.11, 4.13, 4.15).

    Parameters
    ----------
    exp : GraspExperiment
        A variability sweep from :mod:`minvar.grasp_experiments`.
    """
    label, _, unit = _display(exp.shown)
    fig, ax = new_figure(1, 2, size=(11, 4.4))
    for c, (i, v) in zip(_colours(len(exp.values)), enumerate(_x(exp))):
        cur = exp.curves[exp.curves.setting == i]
        rt = cur.relative_time * 100
        ax[0, 0].plot(rt, cur.wrist_sd * UM, color=c, label=f"{v:g} {unit}")
        ax[0, 1].plot(rt, cur.aperture_sd * UM, color=c)
    ax[0, 0].set_title("(a) wrist position SD", fontsize=9)
    ax[0, 1].set_title("(b) grip aperture SD", fontsize=9)
    for via in {v.fraction for v in exp.base.via_schedule}:
        ax[0, 1].axvline(via * 100, color="tab:red", lw=0.6, ls="--", alpha=0.6)
    for a in ax.ravel():
        a.set_xlabel("time (% of movement)")
        a.set_ylabel("SD (µm)")
    ax[0, 0].legend(fontsize=7, title=label, title_fontsize=7)
    return fig


def _change_text(exp: GraspExperiment, col: str, scale: float, unit: str) -> str:
    """``"change a (95 % CI b to c) unit"`` from the experiment's statistics."""
    change = exp.stats.get(f"{col}_change")
    if change is None:
        return ""
    lo, hi = exp.stats[f"{col}_change_ci"]
    return f"change {change * scale:+.3g} {unit} (95 % CI {lo * scale:+.3g} to {hi * scale:+.3g})"


def sd_peaks_figure(exp: GraspExperiment) -> Figure:
    """Peak SD and its relative time per setting (thesis Figs. 4.12, 4.14, 4.16).

    Panels: (a) wrist peak SD, (b) its time, (c) aperture peak SD, (d) its
    time; markers from the repetitions with 95 % bootstrap intervals, lines
    exact; each title gives the change from the first to the last setting
    with its interval.

    Parameters
    ----------
    exp : GraspExperiment
        A variability sweep from :mod:`minvar.grasp_experiments`.
    """
    x = _x(exp)
    s = exp.summary
    fig, ax = new_figure(2, 2, size=(10, 8))
    for row, comp in enumerate(("wrist", "aperture")):
        for col, (k, scale, unit, ylabel) in enumerate((
                (f"{comp}_sd_peak", UM, "µm", "peak SD (µm)"),
                (f"{comp}_sd_peak_time", 100, "%", "time of peak SD (% of movement)"))):
            a = ax[row, col]
            err = None
            if f"{k}_ci_low" in s:
                err = np.abs([s[k] - s[f"{k}_ci_low"], s[f"{k}_ci_high"] - s[k]]) * scale
            a.errorbar(x, s[k] * scale, yerr=err, fmt="o", color="k", mfc="none", ms=5,
                       capsize=2, label=f"{s.trials.iloc[0]} repetitions (95 % CI)")
            a.plot(x, s[f"{k}_exact"] * scale, "-", color="tab:blue", label="exact")
            a.set_ylabel(ylabel)
            what = "peak SD" if col == 0 else "peak SD time"
            a.set_title(f"({'abcd'[2 * row + col]}) {comp} {what}\n"
                        f"{_change_text(exp, k, scale, unit)}", fontsize=8)
        ax[row, 0].legend(fontsize=7)
    for a in ax.ravel():
        a.set_xlabel(_axis_label(exp.shown))
    return fig


#: Figure builders of each experiment (by its name in
#: :data:`minvar.grasp_experiments.EXPERIMENTS`), keyed by file stem.
EXPERIMENT_FIGURES: dict[str, dict[str, Callable[[GraspExperiment], Figure]]] = {
    "viapoint-height": {"fig4_2_viapoint_height_paths": viapoint_height_paths_figure,
                        "fig4_3_viapoint_height_accuracy": accuracy_figure},
    "viapoint-time": {"fig4_4_viapoint_time_paths": paths_figure,
                      "fig4_5_viapoint_time_accuracy": accuracy_figure},
    "viapoint-distance": {"fig4_7_viapoint_distance_paths": paths_figure,
                          "fig4_8_viapoint_distance_mga": mga_figure},
    "object-size": {"fig4_9_object_size_paths": paths_figure,
                    "fig4_10_object_size_mga": mga_figure},
    "movement-time": {"fig4_11_movement_time_sd": sd_time_figure,
                      "fig4_12_movement_time_peaks": sd_peaks_figure},
    "variability-size": {"fig4_13_variability_size_sd": sd_time_figure,
                         "fig4_14_variability_size_peaks": sd_peaks_figure},
    "variability-distance": {"fig4_15_variability_distance_sd": sd_time_figure,
                             "fig4_16_variability_distance_peaks": sd_peaks_figure},
}


def experiment_figures(exp: GraspExperiment) -> dict[str, Figure]:
    """Every figure of one chapter-4 experiment, keyed by file stem.

    Parameters
    ----------
    exp : GraspExperiment
        A finished experiment from :mod:`minvar.grasp_experiments`; its
        ``name`` selects the figures (:data:`EXPERIMENT_FIGURES`).

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        E.g. ``{"fig4_9_object_size_paths": ..., "fig4_10_object_size_mga": ...}``.

    Raises
    ------
    ValueError
        If ``exp.name`` is not one of the thesis's experiments.
    """
    builders = EXPERIMENT_FIGURES.get(exp.name)
    if builders is None:
        raise ValueError(f"experiment_figures: exp.name: unknown experiment {exp.name!r}; "
                         f"expected one of {', '.join(EXPERIMENT_FIGURES)}")
    return {stem: build(exp) for stem, build in builders.items()}

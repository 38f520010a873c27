"""Figures of the grasping chapter (thesis Figs. 4.1-4.16).

Every function returns a :class:`matplotlib.figure.Figure` built with
:func:`minvar.figures.new_figure` (no pyplot state). Positions are drawn in
cm in the world frame (origin at the object centre, +y toward the object),
standard deviations in micrometres: at the thesis's 1 % execution noise they
are tens of micrometres.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from .figures import new_figure
from .grasp import GraspPlan, GraspResult, GraspTask, plan_grasp

if TYPE_CHECKING:  # pragma: no cover
    from .grasp_experiments import GraspExperiment

__all__ = [
    "setup_figure",
    "grasp_figure",
    "paths_figure",
    "viapoint_height_paths_figure",
    "accuracy_figure",
    "mga_figure",
    "sd_time_figure",
    "sd_peaks_figure",
]

CM, UM = 100.0, 1e6

#: How each swept parameter is displayed: (label, scale, unit).
_DISPLAY = {
    "object_size": ("object size", 100.0, "cm"),
    "distance": ("transport distance", 100.0, "cm"),
    "duration": ("movement time", 1000.0, "ms"),
    "viapoint_offset": ("via-point distance from object", 100.0, "cm"),
    "viapoint_height": ("via-point height", 100.0, "cm"),
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


def _draw_object(ax, task: GraspTask) -> None:
    r = task.object_size / 2 * CM
    if r > 0:
        ax.add_patch(Circle((0, 0), r, fc="0.9", ec="0.4", lw=0.8, zorder=0))
    ax.plot(*(np.array([task.finger_target, task.thumb_target]).T * CM), "k.", ms=6)


def _draw_posture(ax, plan: GraspPlan, q_arm, q_finger, q_thumb, style: dict) -> None:
    """Arm and digits as line segments for one set of joint angles (cm)."""
    arm = plan.arm.chain
    wrist = arm.forward(q_arm)
    pts = [np.asarray(arm.base), arm.elbow(q_arm), wrist]
    ax.plot(*(np.array(pts).T * CM), **style)
    style = {k: v for k, v in style.items() if k != "label"}  # one legend entry
    for cp, q in ((plan.finger, q_finger), (plan.thumb, q_thumb)):
        digit = [wrist, wrist + cp.chain.elbow(q), wrist + cp.chain.forward(q)]
        ax.plot(*(np.array(digit).T * CM), **style)


def setup_figure(task: GraspTask | None = None, *, plan: GraspPlan | None = None) -> Figure:
    """The arm, hand and object at the start and at the goal (thesis Fig. 4.1).

    Parameters
    ----------
    task : GraspTask, optional
        The grasp (default: the thesis's); ignored if ``plan`` is given.
    plan : GraspPlan, optional
        A plan of the grasp (saves planning).
    """
    plan = plan_grasp(task or GraspTask()) if plan is None else plan
    task = plan.task
    fig, ax = new_figure(1, 2, size=(10, 5))
    a = ax[0, 0]
    _draw_posture(a, plan, plan.arm.q_start, plan.finger.q_start, plan.thumb.q_start,
                  dict(color="0.5", marker="o", ms=3, lw=1.5, label="start"))
    _draw_posture(a, plan, plan.arm.q_goal, plan.finger.q_goal, plan.thumb.q_goal,
                  dict(color="k", marker="o", ms=3, lw=1.5, label="goal"))
    _draw_object(a, task)
    a.plot(*np.asarray(task.shoulder) * CM, "ks", ms=6)
    a.annotate("shoulder", np.asarray(task.shoulder) * CM, textcoords="offset points",
               xytext=(5, -10), fontsize=8)
    a.set_title(f"(a) arm and gripper; object {task.object_size * CM:g} cm, "
                f"{task.distance * CM:g} cm away", fontsize=9)
    b = ax[0, 1]
    _draw_posture(b, plan, plan.arm.q_goal, plan.finger.q_goal, plan.thumb.q_goal,
                  dict(color="k", marker="o", ms=3, lw=1.5))
    _draw_object(b, task)
    wt = np.asarray(task.wrist_target)
    for via, mk in ((plan.finger_via, "s"), (plan.thumb_via, "D")):
        if len(via):
            b.plot(*((via + wt).T * CM), mk, mfc="none", mec="tab:red", ms=7)
    r = task.object_size / 2 + 0.04
    b.set_xlim(-r * CM, r * CM)
    b.set_ylim((wt[1] - 0.02) * CM, 0.03 * CM)
    b.set_title("(b) at the goal: digit targets (dots), via-points (red)", fontsize=9)
    a.set_aspect("equal", adjustable="datalim")
    b.set_aspect("equal", adjustable="box")
    for x in (a, b):
        x.set_xlabel("x (cm)")
        x.set_ylabel("y (cm)")
    a.legend(fontsize=8, loc="lower left")
    return fig


def grasp_figure(result: GraspResult, *, shown: int = 20, title: str | None = None) -> Figure:
    """Repetitions of one grasp (thesis Fig. 4.6 and more).

    Panels: (a) ``shown`` wrist, finger (dotted) and thumb (dashed) paths;
    (b) mean speed profiles; (c) grip aperture; (d) wrist and aperture SD.

    Parameters
    ----------
    result : GraspResult
        Repetitions of one grasp.
    shown : int
        How many individual repetitions to draw in (a) and (c).
    title : str, optional
        Figure title.
    """
    task = result.task
    k = min(shown, result.trials)
    fig, ax = new_figure(2, 2, size=(10, 8))
    a = ax[0, 0]
    for name, ls, c in (("wrist", "-", "0.4"), ("finger", ":", "tab:green"),
                        ("thumb", "--", "tab:red")):
        p = getattr(result, name)[:k] * CM
        a.plot(p[..., 0].T, p[..., 1].T, ls=ls, color=c, lw=0.7, alpha=0.7)
        a.plot([], [], ls=ls, color=c, label=name)
    _draw_object(a, task)
    a.set_aspect("equal", adjustable="datalim")
    a.set_xlabel("x (cm)")
    a.set_ylabel("y (cm)")
    a.set_title(f"(a) paths ({k} of {result.trials})")
    a.legend(fontsize=8)
    rt = result.relative_time * 100
    b = ax[0, 1]
    b.plot(rt, result.wrist_speed.mean(0), "-", color="0.4", label="wrist")
    b.plot(rt, result.finger_speed.mean(0), ":", color="tab:green", label="finger")
    b.plot(rt, result.thumb_speed.mean(0), "--", color="tab:red", label="thumb")
    b.set_xlabel("time (% of movement)")
    b.set_ylabel("speed (m/s)")
    b.set_title("(b) mean speed")
    b.legend(fontsize=8)
    c = ax[1, 0]
    c.plot(rt, result.aperture[:k].T * CM, color="tab:blue", lw=0.6, alpha=0.6)
    mga_t = result.mga_time.mean() * 100
    c.axvline(mga_t, color="k", ls=":", lw=0.8)
    c.set_xlabel("time (% of movement)")
    c.set_ylabel("grip aperture (cm)")
    c.set_title(f"(c) aperture; mean MGA {result.mga.mean() * CM:.2f} cm at {mga_t:.0f} %")
    d = ax[1, 1]
    d.plot(rt, result.wrist_sd * UM, "-", color="0.3", label="wrist")
    d.plot(rt, result.aperture_sd * UM, "-", color="tab:blue", label="aperture")
    d.set_xlabel("time (% of movement)")
    d.set_ylabel("SD (µm)")
    d.set_title("(d) variability")
    d.legend(fontsize=8)
    for v in task.via_schedule:
        for x in (b, c, d):
            x.axvline(v.fraction * 100, color="tab:red", lw=0.6, ls="--", alpha=0.5)
    if title:
        fig.suptitle(title)
    return fig


def _mean_paths(ax, exp: GraspExperiment, idx: list[int]) -> None:
    label, scale, unit = _display(exp.parameter)
    cols = _colours(len(idx))
    for c, i in zip(cols, idx):
        cur = exp.curves[exp.curves.setting == i]
        v = exp.values[i]
        ax.plot(cur.finger_x * CM, cur.finger_y * CM, ":", color=c, lw=1.4)
        ax.plot(cur.thumb_x * CM, cur.thumb_y * CM, "--", color=c, lw=1.4,
                label=f"{v * scale:g} {unit}")
    # the objects drawn: each one shown if size is swept, else the base object
    sizes = exp.values[idx] if exp.parameter == "object_size" else [exp.base.object_size]
    for s in sizes:
        if s > 0:
            ax.add_patch(Circle((0, 0), s / 2 * CM, fc="none", ec="0.6", lw=0.6))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    ax.legend(fontsize=7, title=label, title_fontsize=7)


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

    Panels: (a) the hand at its goal, the target line and each setting's
    via-points (hand frame at the wrist target); (b) mean digit paths.

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
                  dict(color="k", marker="o", ms=3, lw=1.2))
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
    a.legend(fontsize=7, title="via-point line", title_fontsize=7)
    a.set_title("(a) via-points relative to the target line", fontsize=9)
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
    label, scale, unit = _display(exp.parameter)
    x = exp.values * scale
    fig, ax = new_figure(2, 2, size=(10, 8))
    tr = exp.trials
    span = np.ptp(x) if len(x) > 1 else 1.0
    jitter = np.random.default_rng(0).uniform(-0.01, 0.01, len(tr)) * span  # display only
    for j, digit in enumerate(("finger", "thumb")):
        a = ax[0, j]
        a.plot(tr[exp.parameter] * scale + jitter, tr[f"{digit}_distance"] * UM, "x", ms=2,
               alpha=0.3, color="tab:blue")
        a.plot(x, exp.summary[f"{digit}_distance_mean"] * UM, "k-", lw=1.5, label="mean")
        a.set_ylabel("end-point distance from target (µm)")
        a.set_title(f"({'ab'[j]}) {digit} end-point distance", fontsize=9)
        a.legend(fontsize=8)
        b = ax[1, j]
        for axis, mk, c in (("x", "o", "tab:orange"), ("y", "s", "tab:purple")):
            b.plot(x, exp.summary[f"{digit}_sd_{axis}"] * UM, mk, color=c, mfc="none",
                   label=f"{axis} ({exp.summary.trials.iloc[0]} repetitions)")
            b.plot(x, exp.summary[f"{digit}_sd_{axis}_exact"] * UM, "-", color=c,
                   label=f"{axis} exact")
        b.set_ylabel("end-point SD (µm)")
        b.set_title(f"({'cd'[j]}) {digit} end-point SD", fontsize=9)
        b.legend(fontsize=7)
    for a in ax.ravel():
        a.set_xlabel(_axis_label(exp.parameter))
    return fig


def mga_figure(exp: GraspExperiment) -> Figure:
    """Maximum grip aperture and its timing per setting (thesis Figs. 4.8, 4.10).

    Panels: (a) mean MGA with its regression line and equation; (b) mean
    relative time of the MGA.

    Parameters
    ----------
    exp : GraspExperiment
        A sweep from :mod:`minvar.grasp_experiments` with MGA statistics.
    """
    _, scale, _ = _display(exp.parameter)
    x = exp.values * scale
    s = exp.summary
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    a = ax[0, 0]
    a.errorbar(x, s.mga_mean * CM, yerr=s.mga_sd * CM, fmt="o", color="k", ms=4, capsize=2)
    slope = exp.stats.get("mga_slope")
    if slope is not None:
        icpt = exp.stats["mga_intercept"]
        xs = np.array([exp.values.min(), exp.values.max()])
        a.plot(xs * scale, (slope * xs + icpt) * CM, "-", color="tab:blue")
        a.text(0.04, 0.92, f"MGA = {slope:.2f} x + {icpt * CM:.2f} cm",
               transform=a.transAxes, fontsize=9)
    a.set_ylabel("maximum grip aperture (cm)")
    a.set_title("(a) maximum grip aperture", fontsize=9)
    b = ax[0, 1]
    b.errorbar(x, s.mga_time_mean * 100, yerr=s.mga_time_sd * 100, fmt="o-", color="k",
               ms=4, capsize=2)
    b.axhspan(60, 80, color="0.9", zorder=0, label="60-80 % (human studies)")
    b.set_ylabel("time of MGA (% of movement)")
    b.set_title("(b) relative time of the maximum", fontsize=9)
    b.legend(fontsize=8)
    for a in ax.ravel():
        a.set_xlabel(_axis_label(exp.parameter))
    return fig


def sd_time_figure(exp: GraspExperiment) -> Figure:
    """Wrist and aperture SD over normalised time per setting (thesis Figs. 4.11, 4.13, 4.15).

    Parameters
    ----------
    exp : GraspExperiment
        A variability sweep from :mod:`minvar.grasp_experiments`.
    """
    label, scale, unit = _display(exp.parameter)
    fig, ax = new_figure(1, 2, size=(11, 4.4))
    for c, (i, v) in zip(_colours(len(exp.values)), enumerate(exp.values)):
        cur = exp.curves[exp.curves.setting == i]
        rt = cur.relative_time * 100
        ax[0, 0].plot(rt, cur.wrist_sd * UM, color=c, label=f"{v * scale:g} {unit}")
        ax[0, 1].plot(rt, cur.aperture_sd * UM, color=c)
    ax[0, 0].set_title("(a) wrist position SD", fontsize=9)
    ax[0, 1].set_title("(b) grip aperture SD", fontsize=9)
    for a in ax.ravel():
        a.set_xlabel("time (% of movement)")
        a.set_ylabel("SD (µm)")
    ax[0, 0].legend(fontsize=7, title=label, title_fontsize=7)
    return fig


def sd_peaks_figure(exp: GraspExperiment) -> Figure:
    """Peak SD and its relative time per setting (thesis Figs. 4.12, 4.14, 4.16).

    Panels: (a) wrist peak SD, (b) its time, (c) aperture peak SD, (d) its
    time; markers from the repetitions, lines exact; one-way ANOVA p-values
    (per-repetition peak deviations) in the titles.

    Parameters
    ----------
    exp : GraspExperiment
        A variability sweep from :mod:`minvar.grasp_experiments`.
    """
    _, scale, _ = _display(exp.parameter)
    x = exp.values * scale
    s = exp.summary
    fig, ax = new_figure(2, 2, size=(10, 8))
    for row, comp in enumerate(("wrist", "aperture")):
        p = exp.stats.get(f"{comp}_anova_p", float("nan"))
        pt = exp.stats.get(f"{comp}_time_anova_p", float("nan"))
        a, b = ax[row, 0], ax[row, 1]
        a.plot(x, s[f"{comp}_sd_peak"] * UM, "o", color="k", mfc="none", label="repetitions")
        a.plot(x, s[f"{comp}_sd_peak_exact"] * UM, "-", color="tab:blue", label="exact")
        a.set_ylabel("peak SD (µm)")
        a.set_title(f"({'ac'[row]}) {comp} peak SD; ANOVA p = {p:.2g}", fontsize=9)
        b.plot(x, s[f"{comp}_sd_peak_time"] * 100, "o", color="k", mfc="none",
               label="repetitions")
        b.plot(x, s[f"{comp}_sd_peak_time_exact"] * 100, "-", color="tab:blue", label="exact")
        b.set_ylabel("time of peak SD (% of movement)")
        b.set_title(f"({'bd'[row]}) {comp} peak SD time; ANOVA p = {pt:.2g}", fontsize=9)
        a.legend(fontsize=8)
    for a in ax.ravel():
        a.set_xlabel(_axis_label(exp.parameter))
    return fig

"""Figures of single grasps (thesis Figs. 4.1 and 4.6).

Every function returns a :class:`matplotlib.figure.Figure` built with
:func:`~minvar.plotting.new_figure` (no pyplot state). Positions are drawn in
cm in the world frame (origin at the object centre, +y toward the object; see
docs/coordinates.md), standard deviations in micrometres: at the thesis's 1 %
execution noise they are tens of micrometres. The sweeps' figures are in
:mod:`minvar.plotting.grasp_experiments`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from ..grasp import GraspTask, plan_grasp
from .canvas import new_figure

if TYPE_CHECKING:  # pragma: no cover - results are duck-typed at run time
    from ..grasp import GraspPlan, GraspResult

__all__ = ["setup_figure", "grasp_figure"]

#: Display scales: positions in cm, standard deviations in micrometres.
CM, UM = 100.0, 1e6


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

    Panel (a): the arm and gripper at the start (grey: the digits touching,
    ``tip_start`` ahead of the wrist) and at the goal (black), the line of the
    digit targets, the distance to the object r (grip midpoint to object
    centre) and the wrist's travel. Panel (b): near the object, the hand at
    the goal, its closed starting digits drawn at the wrist target (the frame
    the grip is planned in: they start below the target line), the digit
    targets (dots) and via-points (red).

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
    a.axhline(0, color="k", lw=0.5, ls=":")
    a.plot(*np.asarray(task.shoulder) * CM, "ks", ms=6)
    a.annotate("shoulder", np.asarray(task.shoulder) * CM, textcoords="offset points",
               xytext=(5, -10), fontsize=8)
    grip = np.asarray(task.wrist_start) + (0.0, task.tip_start)
    a.annotate("", xy=(0, 0), xytext=grip * CM,
               arrowprops=dict(arrowstyle="<->", color="tab:blue", lw=0.8))
    a.annotate(f"r = {np.hypot(*grip) * CM:.0f} cm", grip * CM / 2, textcoords="offset points",
               xytext=(-55, 0), fontsize=8, color="tab:blue")
    a.set_title(f"(a) object {task.object_size * CM:g} cm; the wrist travels "
                f"{task.transport_distance * CM:g} cm", fontsize=9)
    b = ax[0, 1]
    _draw_posture(b, plan, plan.arm.q_goal, plan.finger.q_goal, plan.thumb.q_goal,
                  dict(color="k", marker="o", ms=3, lw=1.5, label="goal"))
    _draw_posture(b, plan, plan.arm.q_goal, plan.finger.q_start, plan.thumb.q_start,
                  dict(color="0.5", marker="o", ms=3, lw=1.2, ls="--",
                       label="closed start posture, hand frame at the wrist target"))
    _draw_object(b, task)
    b.axhline(0, color="k", lw=0.5, ls=":")
    wt = np.asarray(task.wrist_target)
    for via, mk in ((plan.finger_via, "s"), (plan.thumb_via, "D")):
        if len(via):
            b.plot(*((via + wt).T * CM), mk, mfc="none", mec="tab:red", ms=7)
    r = task.object_size / 2 + 0.04
    b.set_xlim(-r * CM, r * CM)
    b.set_ylim((wt[1] - 0.02) * CM, 0.03 * CM)
    b.set_title(f"(b) at the goal: targets (dots), via-points (red); g = "
                f"{np.hypot(*np.subtract(task.finger_target, task.thumb_target)) * CM:g} cm",
                fontsize=9)
    b.legend(fontsize=7, loc="lower left")
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

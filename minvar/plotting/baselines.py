"""Figures of the thesis's chapter 2 comparison models (Figs. 2.5-2.8).

Minimum jerk, minimum n-th derivative and minimum angle jerk movements
(:mod:`minvar.baselines`). Every function takes movements already computed,
so the caller decides their number and sampling, and returns a
:class:`matplotlib.figure.Figure` made by :func:`~minvar.plotting.new_figure`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from ..analysis import peak_to_mean_speed
from ..baselines import peak_to_mean_ratio
from .canvas import new_figure, path_axes, time_axes

if TYPE_CHECKING:  # pragma: no cover - results are duck-typed at run time
    from ..baselines import ArmTrajectory, SmoothTrajectory

__all__ = [
    "minimum_jerk_figure",
    "derivative_order_figure",
    "angle_jerk_joint_figure",
    "angle_jerk_hand_figure",
]

#: Human peak/mean velocity ratio quoted by the thesis (section 2.2.3).
HUMAN_PEAK_TO_MEAN = 1.875


def minimum_jerk_figure(movements: Sequence[SmoothTrajectory]) -> Figure:
    """Hand paths and speed profiles of minimum jerk movements (thesis Fig. 2.5).

    Parameters
    ----------
    movements : sequence of SmoothTrajectory
        E.g. ten movements between nearby points (:func:`minvar.baselines.minimum_jerk`).
    """
    fig, ax = new_figure(1, 2, size=(10, 4))
    for m in movements:
        ax[0, 0].plot(*m.position.T, lw=1)
        ax[0, 1].plot(m.time, m.speed, lw=1)
    path_axes(ax[0, 0], "(a) hand paths")
    time_axes(ax[0, 1], "(b) tangential speed")
    fig.suptitle(f"Minimum jerk: {len(movements)} movements")
    return fig


def derivative_order_figure(movements: Mapping[int, SmoothTrajectory]) -> Figure:
    """Minimum n-th derivative movements and their peak/mean velocity ratio (Fig. 2.6).

    Panels: (a) x(t), (b) x velocity, (c) ratio r against n: each movement's
    sampled ratio (dots) on the closed form (line), the human value 1.875
    dashed.

    Parameters
    ----------
    movements : mapping of int to SmoothTrajectory
        Movements along x by derivative order n (2 acceleration, 3 jerk, ...),
        e.g. ``minimum_derivative(n, (0, 0), (0.2, 0), 1.0, dt=0.001)``
        (:func:`minvar.baselines.minimum_derivative`; thesis: 20 cm in 1 s).
    """
    fig, ax = new_figure(1, 3, size=(13, 3.8))
    ratios = []
    for n, m in movements.items():
        ax[0, 0].plot(m.time, m.position[:, 0] * 100, label=f"n = {n}")
        ax[0, 1].plot(m.time, m.velocity[:, 0] * 100, label=f"n = {n}")
        ratios.append(peak_to_mean_speed(m.speed, m.time))
    ax[0, 0].legend(fontsize=8)
    time_axes(ax[0, 0], "(a) x trajectory", "x (cm)")
    time_axes(ax[0, 1], "(b) x velocity", "velocity (cm/s)")
    fine = np.arange(1, max(movements) + 1)
    ax[0, 2].plot(fine, [peak_to_mean_ratio(int(n)) for n in fine], "k-", lw=0.8)
    ax[0, 2].plot(list(movements), ratios, "ko")
    ax[0, 2].axhline(HUMAN_PEAK_TO_MEAN, color="tab:red", ls="--", label="humans, r = 1.875")
    ax[0, 2].set_xlabel("derivative order n")
    ax[0, 2].set_ylabel("peak / mean velocity r")
    ax[0, 2].set_title("(c) r against n")
    ax[0, 2].legend(fontsize=8)
    return fig


def angle_jerk_joint_figure(movements: Sequence[ArmTrajectory]) -> Figure:
    """Joint angles, velocities and accelerations of minimum angle jerk movements (Fig. 2.7).

    Parameters
    ----------
    movements : sequence of ArmTrajectory
        E.g. ten movements (:func:`minvar.baselines.minimum_angle_jerk`).
    """
    fig, ax = new_figure(1, 3, size=(13, 3.8))
    for m in movements:
        j = m.joints
        for a, values in zip(ax[0], (j.position, j.velocity, j.acceleration)):
            a.plot(j.time, np.degrees(values[:, 0]), "tab:blue", lw=0.8)
            a.plot(j.time, np.degrees(values[:, 1]), "tab:orange", lw=0.8)
    ax[0, 0].plot([], [], "tab:blue", label="shoulder")
    ax[0, 0].plot([], [], "tab:orange", label="elbow")
    ax[0, 0].legend(fontsize=8)
    time_axes(ax[0, 0], "(a) joint angles", "angle (deg)")
    time_axes(ax[0, 1], "(b) joint velocities", "velocity (deg/s)")
    time_axes(ax[0, 2], "(c) joint accelerations", "acceleration (deg/s$^2$)")
    fig.suptitle(f"Minimum angle jerk: {len(movements)} movements")
    return fig


def angle_jerk_hand_figure(
    movement: ArmTrajectory, straight: SmoothTrajectory | None = None
) -> Figure:
    """Hand path and speed of a minimum angle jerk movement (Fig. 2.8).

    Parameters
    ----------
    movement : ArmTrajectory
        The movement; the arm is drawn at its start and end.
    straight : SmoothTrajectory, optional
        The minimum (Cartesian) jerk movement between the same points, dashed,
        to show the curvature.
    """
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    hand = movement.hand
    ax[0, 0].plot(*hand.position.T, "k-", lw=1.5, label="minimum angle jerk")
    if straight is not None:
        ax[0, 0].plot(*straight.position.T, "k--", lw=0.8, label="minimum jerk")
        ax[0, 1].plot(straight.time, straight.speed, "k--", lw=0.8, label="minimum jerk")
    chain = movement.chain
    for q, style in ((movement.joints.position[0], "o-"), (movement.joints.position[-1], "o:")):
        arm = np.array([chain.base, chain.elbow(q), chain.forward(q)])
        ax[0, 0].plot(*arm.T, style, color="0.6", lw=1, ms=3)
    ax[0, 0].legend(fontsize=8)
    path_axes(ax[0, 0], "(a) hand path")
    ax[0, 1].plot(hand.time, hand.speed, "k-", lw=1.5, label="minimum angle jerk")
    ax[0, 1].legend(fontsize=8)
    time_axes(ax[0, 1], "(b) hand speed")
    return fig

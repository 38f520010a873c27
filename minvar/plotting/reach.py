"""Figures of reaching movements (thesis Figs. 3.4-3.7).

Each function takes a result already computed (:class:`~minvar.reach.ReachResult`,
:class:`~minvar.analysis.SpeedAccuracy`) and returns a
:class:`matplotlib.figure.Figure` made by :func:`~minvar.plotting.new_figure`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from .canvas import new_figure

if TYPE_CHECKING:  # pragma: no cover - results are duck-typed at run time
    from ..analysis import SpeedAccuracy
    from ..reach import ReachResult

__all__ = ["reach_figure", "speed_accuracy_figure"]


def reach_figure(result: ReachResult, *, shown: int = 50, title: str | None = None) -> Figure:
    """Paths and speed profiles of repeated reaches (thesis Figs. 3.4, 3.6).

    Panels: (a) ``shown`` individual paths with start, goal and via-points,
    (b) their speed profiles, (c) the mean path, (d) the mean speed profile.

    Parameters
    ----------
    result : ReachResult
        Repetitions of one movement.
    shown : int
        How many individual repetitions to draw in (a) and (b).
    title : str, optional
        Figure title.
    """
    fig, ax = new_figure(2, 2, size=(9, 7.5))
    task = result.task
    k = min(shown, result.trials)
    pos, speed, t = result.position[:k], result.speed[:k], result.time
    for a in (ax[0, 0], ax[1, 0]):
        a.plot(*task.start, "ko", ms=5, label="start")
        a.plot(*task.goal, "k*", ms=10, label="goal")
        for v in task.via_points:
            a.plot(*v.position, "s", mfc="none", mec="tab:red", ms=8, label="via-point")
        a.set_xlabel("x (m)")
        a.set_ylabel("y (m)")
        a.set_aspect("equal", adjustable="datalim")
    ax[0, 0].plot(pos[..., 0].T, pos[..., 1].T, lw=0.6, alpha=0.6)
    ax[0, 0].set_title(f"(a) {k} repetitions")
    ax[0, 1].plot(t, speed.T, lw=0.6, alpha=0.6)
    ax[0, 1].set_title("(b) speed profiles")
    ax[1, 0].plot(*result.mean_position.T, "k-", lw=1.5)
    ax[1, 0].set_title(f"(c) mean path of {result.trials}")
    ax[1, 1].plot(t, result.mean_speed, "k-", lw=1.5)
    ax[1, 1].set_title(f"(d) mean speed of {result.trials}")
    for a in (ax[0, 1], ax[1, 1]):
        a.set_xlabel("time (s)")
        a.set_ylabel("speed (m/s)")
        for v in task.via_points:
            a.axvline(v.time_s(task.duration), color="tab:red", lw=0.8, ls=":")
    handles, labels = ax[1, 0].get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax[1, 0].legend(unique.values(), unique.keys(), fontsize=8, loc="best")
    if title:
        fig.suptitle(title)
    return fig


def speed_accuracy_figure(sweep: SpeedAccuracy, *, title: str | None = None) -> Figure:
    """End-point spread against movement time (thesis Figs. 3.5, 3.7).

    Panels: (a) end-point SD in x, y and total; (b) each repetition's distance
    from the goal (crosses) and the mean distance (line).

    Parameters
    ----------
    sweep : SpeedAccuracy
        Result of :func:`minvar.analysis.speed_accuracy`.
    title : str, optional
        Figure title.
    """
    fig, ax = new_figure(1, 2, size=(10, 4))
    s = sweep.summary
    ms = s["duration"] * 1000
    ax[0, 0].plot(ms, s["sd_x"] * 1000, "o-", label="x")
    ax[0, 0].plot(ms, s["sd_y"] * 1000, "s-", label="y")
    ax[0, 0].plot(ms, s["sd_total"] * 1000, "k^-", label="total")
    ax[0, 0].set_xlabel("movement time (ms)")
    ax[0, 0].set_ylabel("end-point SD (mm)")
    ax[0, 0].set_title("(a) end-point standard deviation")
    ax[0, 0].legend(fontsize=8)
    tr = sweep.trials
    jitter = np.random.default_rng(0).uniform(-8, 8, len(tr))  # display only
    ax[0, 1].plot(tr["duration"] * 1000 + jitter, tr["distance"] * 1000, "x", ms=3, alpha=0.4)
    ax[0, 1].plot(ms, s["distance_mean"] * 1000, "k-", lw=1.5, label="mean")
    ax[0, 1].set_xlabel("movement time (ms)")
    ax[0, 1].set_ylabel("distance from goal (mm)")
    ax[0, 1].set_title("(b) end-point distance from goal")
    ax[0, 1].legend(fontsize=8)
    if title:
        fig.suptitle(title)
    return fig

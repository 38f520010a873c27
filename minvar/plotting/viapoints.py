"""Figures of via-point movements: thesis chapter 3 (Figs. 3.2-3.3, 3.8-3.9) and appendix A.

Via-point timing, merging movements, the letter 'a' (chapter 3) and the
via-point criteria, spatio-temporal curvature and generalisation of appendix A
(Figs. A.1-A.3). The point-to-point and 's' figures (3.4-3.7) are in
:mod:`minvar.plotting.reach`. Every function takes results already computed,
so the caller decides trials and seeds, and returns a
:class:`matplotlib.figure.Figure` made by :func:`~minvar.plotting.new_figure`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from ..viapoints import CRITERIA, spatiotemporal_curvature
from .canvas import new_figure, path_axes, time_axes

if TYPE_CHECKING:  # pragma: no cover - results are duck-typed at run time
    import pandas as pd
    from numpy.typing import ArrayLike

    from ..reach import ReachResult
    from ..viapoints import CriteriaComparison

__all__ = [
    "viapoint_timing_figure",
    "merging_figure",
    "letter_figure",
    "letter_durations_figure",
    "criteria_figure",
    "curvature_figure",
    "generalisation_figure",
]


def viapoint_timing_figure(
    paths: Mapping[str, tuple[np.ndarray, np.ndarray]],
    timing: pd.DataFrame,
    via_point: ArrayLike | None = None,
) -> Figure:
    """Effect of a via-point's timing (thesis Fig. 3.2).

    Parameters
    ----------
    paths : mapping of label -> (time, position)
        Panel (a): e.g. via-point at 25 %, at 75 % and no via-point.
    timing : pandas.DataFrame
        Panel (b): :func:`minvar.viapoints.viapoint_timing` output.
    via_point : (2,) array_like, optional
        Via-point position to mark in (a), m.
    """
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    for (label, (_, p)), style in zip(paths.items(), (":", "--", "-", "-.")):
        ax[0, 0].plot(*p.T, style, lw=1.5, label=label)
    if via_point is not None:
        ax[0, 0].plot(*via_point, "s", mfc="none", mec="tab:red", ms=8, label="via-point")
    ax[0, 0].legend(fontsize=8)
    path_axes(ax[0, 0], "(a) expected paths")
    ms = timing["via_time"] * 1000
    ax[0, 1].plot(ms, timing["msd"], "ko-", ms=3)
    ref = timing.loc[timing["shift"].abs().idxmin(), "via_time"] * 1000
    ax[0, 1].axvspan(ref - 100, ref + 100, color="0.9", label="within 100 ms")
    ax[0, 1].set_xlabel("via-point time (ms)")
    ax[0, 1].set_ylabel("MSD from reference (rad$^2$, eq. A.2)")
    ax[0, 1].set_title(f"(b) reference via-point at {ref:.0f} ms")
    ax[0, 1].legend(fontsize=8)
    return fig


def merging_figure(first: ReachResult, second: ReachResult, merged: ReachResult) -> Figure:
    """Two movements A->B, B->C and their merger A->C through B (thesis Fig. 3.3).

    Parameters
    ----------
    first, second : ReachResult
        Movements A->B and B->C; the second is drawn after the first ends.
    merged : ReachResult
        Movement A->C with a via-point at B.
    """
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    offset = first.task.duration
    for r, label, style, t0 in (
        (first, "1: A to B", "--", 0.0),
        (second, "2: B to C", ":", offset),
        (merged, "3: A to C via B", "-", 0.0),
    ):
        ax[0, 0].plot(*r.mean_position.T, style, lw=1.5, label=label)
        ax[0, 1].plot(r.time + t0, r.mean_speed, style, lw=1.5, label=label)
    for name, p in zip("ABC", (first.task.start, first.task.goal, second.task.goal)):
        ax[0, 0].annotate(name, p, textcoords="offset points", xytext=(4, 4))
        ax[0, 0].plot(*p, "ko", ms=4)
    ax[0, 0].legend(fontsize=8)
    path_axes(ax[0, 0], f"(a) mean paths of {merged.trials}")
    ax[0, 1].legend(fontsize=8)
    time_axes(ax[0, 1], "(b) mean speed")
    return fig


def _mark_vias(ax_path, ax_speed, task) -> None:
    for i, v in enumerate(task.via_points, 1):
        ax_path.plot(*v.position, "s", mfc="none", mec="tab:red", ms=7)
        ax_path.annotate(str(i), v.position, textcoords="offset points", xytext=(4, 3),
                         fontsize=7, color="tab:red")
        ax_speed.axvline(v.time_s(task.duration), color="tab:red", lw=0.6, ls=":")
    ax_path.plot(*task.start, "ko", ms=4)
    ax_path.plot(*task.goal, "k*", ms=8)


def letter_figure(result: ReachResult) -> Figure:
    """The letter 'a' drawn through via-points (thesis Fig. 3.8).

    Panels: (a) one movement's path (and the mean path, grey) with the
    via-points numbered; (b) its speed profile with the via-point times dotted.

    Parameters
    ----------
    result : ReachResult
        Repetitions of the 'a' (:func:`minvar.viapoints.letter_a`).
    """
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    ax[0, 0].plot(*result.mean_position.T, color="0.7", lw=3, label=f"mean of {result.trials}")
    ax[0, 0].plot(*result.position[0].T, "k-", lw=1.2, label="one movement")
    ax[0, 1].plot(result.time, result.mean_speed, color="0.7", lw=3)
    ax[0, 1].plot(result.time, result.speed[0], "k-", lw=1.2)
    _mark_vias(ax[0, 0], ax[0, 1], result.task)
    ax[0, 0].legend(fontsize=8)
    path_axes(ax[0, 0], "(a) hand path")
    time_axes(ax[0, 1], "(b) speed")
    return fig


def letter_durations_figure(results: Sequence[ReachResult]) -> Figure:
    """The same via-point movement at several movement times (thesis Fig. 3.9).

    Parameters
    ----------
    results : sequence of ReachResult
        One per movement time; one movement of each is drawn.
    """
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    for r in results:
        d = r.task.duration
        line, = ax[0, 0].plot(*r.position[0].T, lw=1.2, label=f"{d * 1000:.0f} ms")
        ax[0, 1].plot(r.time / d, r.speed[0], lw=1.2, color=line.get_color())
    ax[0, 0].legend(fontsize=8)
    path_axes(ax[0, 0], "(a) hand paths")
    time_axes(ax[0, 1], "(b) speed")
    ax[0, 1].set_xlabel("time / movement time")
    return fig


def criteria_figure(comparison: CriteriaComparison) -> Figure:
    """Via-point criteria compared (thesis Fig. A.1).

    Panels: (a) mean-square difference of each replay against the number of
    points it stores, one marker per criterion and trajectory; (b) mean
    MSD x number of points per criterion (lower is better).

    Parameters
    ----------
    comparison : CriteriaComparison
        :func:`minvar.viapoints.compare_criteria` output.
    """
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    t = comparison.table
    markers = dict(zip(CRITERIA, "os^"))
    for c in t["criterion"].unique():
        rows = t[t["criterion"] == c]
        ax[0, 0].plot(rows["n_points"], rows["msd_per_sample"], markers.get(c, "x"),
                      mfc="none", label=c)
    ax[0, 0].set_yscale("log")
    ax[0, 0].set_xlabel("number of points (via-points + start + goal)")
    ax[0, 0].set_ylabel("MSD per sample (rad$^2$)")
    ax[0, 0].set_title(f"(a) {t['trajectory'].nunique()} trajectories")
    ax[0, 0].legend(fontsize=8)
    s = comparison.summary
    ax[0, 1].bar(s["criterion"], s["score"], color="0.6")
    ax[0, 1].set_ylabel("MSD per sample x number of points")
    ax[0, 1].set_title("(b) mean over trajectories (lower is better)")
    return fig


def curvature_figure(
    time: ArrayLike,
    position: ArrayLike,
    indices: Sequence[int],
    events: dict[str, float] | None = None,
) -> Figure:
    """A trajectory with via-points at its curvature extrema (thesis Fig. A.2).

    Panels: (a) path with the via-points; (b) x(t) and the spatio-temporal
    curvature (eq. A.1 in m and s, dotted) with the extrema marked, and
    vertical lines at ``events``.

    Parameters
    ----------
    time : (S,) array_like
        Sample times, s.
    position : (S, 2) array_like
        Path, m.
    indices : sequence of int
        Samples chosen as via-points.
    events : dict of str to float, optional
        Named moments to mark in (b), s (e.g. the movement's onset, its peak
        speed, the start of the post-movement period).
    """
    time = np.asarray(time, dtype=float)
    position = np.asarray(position, dtype=float)
    idx = np.asarray(indices, dtype=int)
    kappa = spatiotemporal_curvature(position, time)
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    ax[0, 0].plot(*position.T, "k-", lw=1.2)
    ends = [0, len(position) - 1]
    ax[0, 0].plot(*position[ends].T, "ko", ms=5, label="start, goal")
    ax[0, 0].plot(*position[idx].T, "s", mfc="none", mec="tab:red", ms=8, label="via-points")
    ax[0, 0].legend(fontsize=8)
    path_axes(ax[0, 0], "(a) path and curvature via-points")
    ax[0, 1].plot(time, position[:, 0], "k-", lw=1.2)
    ax[0, 1].plot(time[idx], position[idx, 0], "s", mfc="none", mec="tab:red", ms=8)
    time_axes(ax[0, 1], "(b) x and curvature", "x (m)")
    twin = ax[0, 1].twinx()
    twin.plot(time, kappa, ":", color="tab:blue")
    twin.plot(time[idx], kappa[idx], "o", color="tab:blue", ms=4)
    twin.set_ylabel("spatio-temporal curvature (eq. A.1, m and s)", color="tab:blue")
    for k, (name, when) in enumerate((events or {}).items()):
        ax[0, 1].axvline(when, color="0.5", lw=0.8, ls="--")
        ax[0, 1].annotate(name, (when, 0.02 + 0.07 * k), xycoords=("data", "axes fraction"),
                          fontsize=7, color="0.3", xytext=(3, 0), textcoords="offset points")
    return fig


def generalisation_figure(
    original: ReachResult, retimed: ReachResult, scaled: ReachResult
) -> Figure:
    """Temporal and spatial generalisation of a via-point movement (thesis Fig. A.3).

    Parameters
    ----------
    original : ReachResult
        The movement as represented (dotted in both panels).
    retimed : ReachResult
        The same representation at another movement time (eq. A.3), panel (a).
    scaled : ReachResult
        The representation scaled about its start (eqs. A.4-A.5), panel (b).
    """
    fig, ax = new_figure(1, 2, size=(10, 4.2))
    d0, d1 = original.task.duration, retimed.task.duration
    for a in ax[0]:
        a.plot(*original.position[0].T, "k:", lw=1.5, label=f"original, {d0 * 1000:.0f} ms")
    ax[0, 0].plot(*retimed.position[0].T, "k-", lw=1.2, label=f"re-timed, {d1 * 1000:.0f} ms")
    t0, t1 = original.task, scaled.task
    alpha = np.linalg.norm(np.subtract(t1.goal, t1.start)) / np.linalg.norm(
        np.subtract(t0.goal, t0.start)
    )
    ax[0, 1].plot(*scaled.position[0].T, "k-", lw=1.2, label=f"scaled by {alpha:.2g}")
    for a, title in zip(ax[0], ("(a) temporal generalisation", "(b) spatial generalisation")):
        a.legend(fontsize=8)
        path_axes(a, title)
    return fig

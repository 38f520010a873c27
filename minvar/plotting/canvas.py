"""The blank figure every plotting function starts from, and common axis labels.

Figures are built with :class:`matplotlib.figure.Figure`, never through
pyplot: pyplot keeps global state (the current figure, a registry of open
figures), which leaks memory in long runs and breaks figures made in worker
processes. The caller saves a figure with ``fig.savefig(path)``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

__all__ = ["new_figure", "path_axes", "time_axes"]


def new_figure(
    rows: int, cols: int, *, size: tuple[float, float] | None = None
) -> tuple[Figure, np.ndarray]:
    """A figure and its axes grid, independent of pyplot.

    Parameters
    ----------
    rows, cols : int
        Grid of axes.
    size : (width, height), optional
        Figure size in inches (default: 4 x 3.4 per panel).

    Returns
    -------
    fig : matplotlib.figure.Figure
        The figure, with constrained layout.
    axes : (rows, cols) array of matplotlib.axes.Axes
        Always two-dimensional, even for a single panel.
    """
    fig = Figure(figsize=size or (4.0 * cols, 3.4 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    return fig, axes


def path_axes(ax: Axes, title: str) -> None:
    """Label an axes showing a path in the plane: x and y in m, equal aspect.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    title : str
        Its title.
    """
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(title)


def time_axes(ax: Axes, title: str, ylabel: str = "speed (m/s)") -> None:
    """Label an axes showing a quantity over time in s.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    title : str
        Its title.
    ylabel : str
        The quantity and its unit.
    """
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)

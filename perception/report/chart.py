"""A figure as data, drawn by Pillow in milliseconds or by matplotlib.

A :class:`Chart` is a row of :class:`Panel` s holding :class:`Line` s,
:class:`Band` s (a filled range under the lines) and :class:`ErrorBars`
(:mod:`perception.report.chart_spec`). The report's figures are built once
as a chart (one idea in one place) and drawn two ways: :func:`render_png`
draws it with Pillow (:mod:`perception.report.chart_png`), in a few tens of
milliseconds and without matplotlib (which takes about 0.6 s to import and a
second or more to lay out and draw a report's figures: most of ``hammer-mv
recognize``'s time on a short clip, and serial time at the end of every
batch); :func:`to_matplotlib` gives the same figure as a matplotlib
``Figure``, for a user who wants to restyle it or save it in another format.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from perception.report.chart_png import PanelLayout, layout, nice_ticks, render_png
from perception.report.chart_spec import (
    HLINE_COLOUR,
    HLINE_WIDTH,
    LEGEND_PT,
    Band,
    Chart,
    ErrorBars,
    Legend,
    Line,
    Panel,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["Band", "Chart", "ErrorBars", "Legend", "Line", "Panel", "PanelLayout", "layout",
           "nice_ticks", "render_png", "to_matplotlib"]


def to_matplotlib(chart: Chart) -> Figure:
    """The chart as a matplotlib figure (matplotlib is imported here, not before).

    Parameters
    ----------
    chart : Chart
        The figure.
    """
    from minvar.plotting import new_figure

    def text(s: str | None) -> str | None:
        # a ``$`` in a clip name is text, not mathtext (``$\\x$`` would fail to draw)
        return None if s is None else s.replace("$", r"\$")

    fig, ax = new_figure(1, len(chart.panels), size=chart.size)
    handles = {}
    for a, panel in zip(ax[0], chart.panels):
        for band in panel.bands:  # a collection: under the lines whatever the order
            a.fill_between(band.x, band.lower, band.upper, color=band.colour, alpha=band.alpha,
                           lw=0)
        for line in panel.lines:
            (h,) = a.plot(line.x, line.y, line.style, color=line.colour, lw=line.width,
                          label=text(line.label) or "_nolegend_")
            if line.label:
                handles.setdefault(text(line.label), h)
        for bars in panel.errorbars:
            a.errorbar(bars.x, bars.y, yerr=bars.err, fmt="none", ecolor=bars.colour,
                       elinewidth=bars.width, capsize=bars.cap, capthick=bars.width)
        for y in panel.hlines:
            a.axhline(y, color=HLINE_COLOUR, lw=HLINE_WIDTH, zorder=1.5)
        if panel.equal_aspect:
            a.set_aspect("equal", adjustable="datalim")
        a.set_title(text(panel.title))
        a.set_xlabel(text(panel.xlabel))
        a.set_ylabel(text(panel.ylabel))
        if panel.legend is not None and any(ln.label for ln in panel.lines):
            a.legend(loc=panel.legend.location, ncol=panel.legend.columns,
                     title=text(panel.legend.title), fontsize=LEGEND_PT, title_fontsize=LEGEND_PT)
    if chart.legend is not None and handles:
        fig.legend(list(handles.values()), list(handles), loc="outside lower center",
                   ncol=chart.legend.columns, title=text(chart.legend.title), fontsize=LEGEND_PT,
                   title_fontsize=LEGEND_PT, frameon=False)
    if chart.title:
        fig.suptitle(text(chart.title))
    return fig

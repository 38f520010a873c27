"""A figure as data: a :class:`Chart` is a row of :class:`Panel` s of lines, bands and bars.

What is drawn, not how: :mod:`perception.report.chart_png` draws a chart
with Pillow, :func:`perception.report.chart.to_matplotlib` with matplotlib.
Colours, line styles and font sizes are matplotlib's defaults, so the two
look alike. Every array is checked and stored as a flat float array when a
part is made; a non-finite value is a gap (nothing is drawn there). Every
text (a title, a label: often a clip's name) is stored as it can be drawn:
bytes that were not UTF-8 and control characters escaped
(:func:`~perception.io.names.printable`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from perception.io.names import printable

__all__ = ["Band", "Chart", "ErrorBars", "Legend", "Line", "Panel"]

#: Line styles: solid, dashed, dotted.
STYLES = ("-", "--", ":")
#: Where a panel's legend may sit: a corner, or ``best``, the corner it hides the
#: fewest points in (the first of these in a tie, as matplotlib's ``best``).
LOCATIONS = ("upper right", "upper left", "lower left", "lower right", "best")
#: matplotlib's tab10 cycle: the colours ``C0`` … ``C9``.
TAB10 = {"C0": "#1f77b4", "C1": "#ff7f0e", "C2": "#2ca02c", "C3": "#d62728", "C4": "#9467bd",
         "C5": "#8c564b", "C6": "#e377c2", "C7": "#7f7f7f", "C8": "#bcbd22", "C9": "#17becf"}
#: matplotlib's single-letter colours.
BASE_COLOURS = {"b": (0, 0, 255), "g": (0, 128, 0), "r": (255, 0, 0), "c": (0, 191, 191),
                "m": (191, 0, 191), "y": (191, 191, 0), "k": (0, 0, 0), "w": (255, 255, 255)}
#: Colour and width (points) of a panel's horizontal reference lines.
HLINE_COLOUR, HLINE_WIDTH = "0.7", 0.6
#: Font sizes, points: titles, axis labels and ticks, legends (matplotlib's defaults).
TITLE_PT, LABEL_PT, LEGEND_PT = 12.0, 10.0, 9.0


def rgb(colour: str) -> tuple[int, int, int]:
    """``C0``-``C9``, a matplotlib letter, ``#rrggbb`` or a grey level ``"0.7"`` as RGB."""
    c = TAB10.get(colour, colour)
    if c in BASE_COLOURS:
        return BASE_COLOURS[c]
    if len(c) == 7 and c.startswith("#"):
        try:
            return tuple(int(c[i:i + 2], 16) for i in (1, 3, 5))
        except ValueError:
            pass
    else:
        try:
            grey = float(c)
        except ValueError:
            grey = -1.0
        if 0.0 <= grey <= 1.0:
            return (round(grey * 255),) * 3
    raise ValueError(f"unknown colour {colour!r}: use C0-C9, one of "
                     f"{''.join(BASE_COLOURS)}, #rrggbb or a grey level '0'-'1'")


@dataclasses.dataclass(frozen=True, eq=False)
class Line:
    """A line through points ``(x[i], y[i])``; a non-finite value breaks it.

    Attributes
    ----------
    x, y : (N,) array
        Data coordinates.
    colour : str
        ``C0``-``C9`` (matplotlib's tab10), a matplotlib letter (``k``, ``r``,
        …), ``#rrggbb`` or a grey level such as ``"0.7"``.
    width : float
        Line width, points.
    style : str
        ``-`` solid, ``--`` dashed, ``:`` dotted.
    label : str or None
        Legend entry (None or empty: not in the legend).
    """

    x: np.ndarray
    y: np.ndarray
    colour: str = "C0"
    width: float = 1.5
    style: str = "-"
    label: str | None = None

    def __post_init__(self):
        _store_arrays(self, "x", "y")
        _store_texts(self, "label")
        if self.style not in STYLES:
            raise ValueError(f"unknown line style {self.style!r}: use one of {STYLES}")
        rgb(self.colour)


@dataclasses.dataclass(frozen=True, eq=False)
class Band:
    """A filled region between two curves, under the panel's lines (a range, a ± SD).

    It is filled between ``lower[i]`` and ``upper[i]`` along ``x``; a
    non-finite value breaks it, as it does a line.

    Attributes
    ----------
    x, lower, upper : (N,) array
        Data coordinates.
    colour : str
        As a :class:`Line`'s.
    alpha : float
        Opacity, 0-1: what is under the band shows through.
    """

    x: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    colour: str = "C0"
    alpha: float = 0.2

    def __post_init__(self):
        _store_arrays(self, "x", "lower", "upper")
        rgb(self.colour)
        if not 0.0 <= self.alpha <= 1.0:
            raise ValueError(f"alpha must be within 0-1, not {self.alpha!r}")


@dataclasses.dataclass(frozen=True, eq=False)
class ErrorBars:
    """Vertical bars from ``y[i] - err[i]`` to ``y[i] + err[i]``, capped at both ends.

    A bar with a non-finite ``x``, ``y`` or ``err`` is left out.

    Attributes
    ----------
    x, y, err : (N,) array
        Data coordinates; ``err`` is not negative.
    colour : str
        As a :class:`Line`'s.
    width : float
        Line width of the bars and caps, points.
    cap : float
        Half a cap's length, points (matplotlib's ``capsize``; 0: no caps).
    """

    x: np.ndarray
    y: np.ndarray
    err: np.ndarray
    colour: str = "C0"
    width: float = 1.0
    cap: float = 3.0

    def __post_init__(self):
        _store_arrays(self, "x", "y", "err")
        rgb(self.colour)
        if np.any(self.err < 0):
            raise ValueError("err must not be negative")
        if not (self.width > 0 and self.cap >= 0):
            raise ValueError(f"width must be > 0 and cap >= 0, not {self.width!r}, {self.cap!r}")


def _store_texts(part, *names: str) -> None:
    """Store a frozen part's text fields ``names`` as they can be drawn (None kept)."""
    for name in names:
        value = getattr(part, name)
        if value is not None:
            object.__setattr__(part, name, printable(str(value)))


def _store_arrays(part, *names: str) -> None:
    """Store a frozen part's fields ``names`` as flat float arrays of one length."""
    arrays = [np.asarray(getattr(part, name), dtype=float).ravel() for name in names]
    if len({a.size for a in arrays}) > 1:
        sizes = ", ".join(str(a.size) for a in arrays)
        raise ValueError(f"{', '.join(names[:-1])} and {names[-1]} differ in length ({sizes})")
    for name, a in zip(names, arrays):
        object.__setattr__(part, name, a)


@dataclasses.dataclass(frozen=True)
class Legend:
    """Where and how a legend is laid out.

    Attributes
    ----------
    location : str
        A panel's legend: the corner it sits in, or ``best`` (see
        :data:`LOCATIONS`). A chart's legend is always below its panels.
    columns : int
        Entries fill the columns top to bottom, left to right.
    title : str or None
        Shown above the entries.
    """

    location: str = "upper left"
    columns: int = 1
    title: str | None = None

    def __post_init__(self):
        _store_texts(self, "title")
        if self.location not in LOCATIONS:
            raise ValueError(f"unknown legend location {self.location!r}: use one of "
                             f"{LOCATIONS}")
        if self.columns < 1:
            raise ValueError("a legend needs at least one column")


@dataclasses.dataclass(frozen=True, eq=False)
class Panel:
    """One set of axes.

    Attributes
    ----------
    title, xlabel, ylabel : str
        Its title and axis labels.
    lines : tuple of Line
        Drawn in order (the last on top).
    hlines : tuple of float
        Thin grey horizontal lines across the panel at these ``y``, over
        the bands and under the lines (and inside its limits).
    equal_aspect : bool
        One unit is as long in ``x`` as in ``y`` (the limits widen to fit).
    legend : Legend or None
        A legend of the labelled lines inside the panel.
    bands : tuple of Band
        Filled under everything else, in order.
    errorbars : tuple of ErrorBars
        Drawn over the lines, in order.
    """

    title: str = ""
    xlabel: str = ""
    ylabel: str = ""
    lines: tuple[Line, ...] = ()
    hlines: tuple[float, ...] = ()
    equal_aspect: bool = False
    legend: Legend | None = None
    bands: tuple[Band, ...] = ()
    errorbars: tuple[ErrorBars, ...] = ()

    def __post_init__(self):
        _store_texts(self, "title", "xlabel", "ylabel")
        for name, kind in (("lines", Line), ("bands", Band), ("errorbars", ErrorBars)):
            parts = tuple(getattr(self, name))
            if not all(isinstance(p, kind) for p in parts):
                raise ValueError(f"{name} must hold only {kind.__name__}s")
            object.__setattr__(self, name, parts)
        object.__setattr__(self, "hlines", tuple(float(y) for y in self.hlines))

    def points(self) -> tuple[np.ndarray, np.ndarray]:
        """Every point drawn (``x``, ``y``): the lines', the bands' edges and the bars' ends.

        The panel's limits hold them all (and its ``hlines``); the legend's
        ``best`` corner hides the fewest of them.
        """
        xs, ys = [], []
        for line in self.lines:
            ok = np.isfinite(line.x) & np.isfinite(line.y)
            xs.append(line.x[ok])
            ys.append(line.y[ok])
        for band in self.bands:
            ok = np.isfinite(band.x) & np.isfinite(band.lower) & np.isfinite(band.upper)
            xs += [band.x[ok]] * 2
            ys += [band.lower[ok], band.upper[ok]]
        for bars in self.errorbars:
            ok = np.isfinite(bars.x) & np.isfinite(bars.y) & np.isfinite(bars.err)
            xs += [bars.x[ok]] * 2
            ys += [bars.y[ok] - bars.err[ok], bars.y[ok] + bars.err[ok]]
        return np.concatenate(xs or [np.zeros(0)]), np.concatenate(ys or [np.zeros(0)])


@dataclasses.dataclass(frozen=True, eq=False)
class Chart:
    """A figure: panels side by side, a title, and a legend below them.

    Attributes
    ----------
    panels : tuple of Panel
        Left to right.
    title : str
        Above the panels.
    size : (width, height)
        Inches (the PNG is ``size * dpi`` pixels).
    legend : Legend or None
        A legend below the panels of every panel's labelled lines, one
        entry per label (its ``location`` is not used).
    """

    panels: tuple[Panel, ...]
    title: str = ""
    size: tuple[float, float] = (12.0, 5.0)
    legend: Legend | None = None

    def __post_init__(self):
        _store_texts(self, "title")
        object.__setattr__(self, "panels", tuple(self.panels))
        if not self.panels:
            raise ValueError("a chart needs at least one panel")
        if len(self.size) != 2 or not all(v > 0 for v in self.size):
            raise ValueError(f"size must be (width, height) in inches, not {self.size!r}")

    def legend_lines(self) -> list[Line]:
        """The lines of the chart's legend: the first line of each label, in order."""
        seen: dict[str, Line] = {}
        for panel in self.panels:
            for line in panel.lines:
                if line.label:
                    seen.setdefault(line.label, line)
        return list(seen.values())



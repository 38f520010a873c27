"""A figure as data, drawn by Pillow in milliseconds or by matplotlib.

A :class:`Chart` is a row of :class:`Panel` s holding :class:`Line` s. The
report's per-clip figures are built once as a chart (one idea in one place)
and drawn two ways: :func:`render_png` draws it with Pillow, in a few tens of
milliseconds and without matplotlib (which takes about 0.6 s to import and
1.5 s to lay out and draw the two figures: most of ``hammer-mv recognize``'s
time on a short clip); :func:`to_matplotlib` gives the same figure as a
matplotlib ``Figure``, for a user who wants to restyle it or save it in
another format.

The Pillow drawing follows matplotlib's default style: tab10 colours,
DejaVu Sans (matplotlib's own font file, read without importing matplotlib;
Pillow's default font if it is missing), ticks at 1-2-5 steps, 5 % margins,
dash patterns scaled by the line width. Lines are drawn at twice the size
and reduced, so they come out anti-aliased; text (anti-aliased by FreeType)
is drawn on the reduced image. A character the font lacks (a clip name in
another script) is drawn as a box, without a warning.
"""

from __future__ import annotations

import dataclasses
import functools
import io
import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from PIL import Image, ImageDraw, ImageFont

__all__ = ["Chart", "Legend", "Line", "Panel", "PanelLayout", "layout", "nice_ticks",
           "render_png", "to_matplotlib"]

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
#: matplotlib's dash patterns (on, off), in line widths.
_DASHES = {"--": (3.7, 1.6), ":": (1.0, 1.65)}
#: Supersampling: drawn at this multiple of the output size, then reduced.
_SCALE = 2


def _rgb(colour: str) -> tuple[int, int, int]:
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
        x = np.asarray(self.x, dtype=float).ravel()
        y = np.asarray(self.y, dtype=float).ravel()
        if x.shape != y.shape:
            raise ValueError(f"x and y differ in length ({x.size} and {y.size})")
        if self.style not in STYLES:
            raise ValueError(f"unknown line style {self.style!r}: use one of {STYLES}")
        _rgb(self.colour)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)


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
        Thin grey horizontal lines across the panel at these ``y``, under
        the lines (and inside its limits).
    equal_aspect : bool
        One unit is as long in ``x`` as in ``y`` (the limits widen to fit).
    legend : Legend or None
        A legend of the labelled lines inside the panel.
    """

    title: str = ""
    xlabel: str = ""
    ylabel: str = ""
    lines: tuple[Line, ...] = ()
    hlines: tuple[float, ...] = ()
    equal_aspect: bool = False
    legend: Legend | None = None

    def __post_init__(self):
        object.__setattr__(self, "lines", tuple(self.lines))
        object.__setattr__(self, "hlines", tuple(float(y) for y in self.hlines))


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


# -- ticks and limits ------------------------------------------------------------
def _step(lo: float, hi: float, most: int) -> float:
    """The smallest 1-2-5 step that splits ``[lo, hi]`` into at most ``most`` intervals."""
    raw = (hi - lo) / max(int(most), 1)
    if not raw > 0 or not math.isfinite(raw):
        return 1.0
    mag = 10.0 ** math.floor(math.log10(raw))
    return next(m * mag for m in (1, 2, 5, 10) if m * mag >= raw * (1 - 1e-9))


def nice_ticks(lo: float, hi: float, most: int = 9) -> np.ndarray:
    """Ticks at every multiple of a 1-2-5 step (1, 2 or 5 × 10^k) within ``[lo, hi]``.

    Parameters
    ----------
    lo, hi : float
        The axis limits.
    most : int
        At most this many intervals of the step fit between ``lo`` and ``hi``
        (fewer steps where it leaves less than two ticks).
    """
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
        return np.zeros(0)
    step = _step(lo, hi, most)
    for _ in range(6):
        first, last = math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9)
        if last > first:
            break
        mag = 10.0 ** math.floor(math.log10(step) + 1e-9)
        step = {1: 0.5, 2: 1.0, 5: 2.0}.get(round(step / mag), 0.5) * mag  # the next smaller
    return np.arange(first, last + 1) * step


def _limits(values: list[np.ndarray]) -> tuple[float, float]:
    """The finite values' range with 5 % margins (0-1 if none; widened if one value)."""
    finite = [v[np.isfinite(v)] for v in values]
    finite = [v for v in finite if v.size]
    if not finite:
        return 0.0, 1.0
    lo, hi = min(float(v.min()) for v in finite), max(float(v.max()) for v in finite)
    if hi - lo <= 1e-12 * max(1.0, abs(lo)):
        half = 0.05 * abs(lo) or 0.05
        return lo - half, hi + half
    pad = 0.05 * (hi - lo)
    return lo - pad, hi + pad


def _tick_labels(ticks: np.ndarray, minus: str) -> list[str]:
    """Tick values with as many decimals as the step needs (no ``-0``)."""
    step = ticks[1] - ticks[0] if len(ticks) > 1 else 1.0
    decimals = max(0, -math.floor(math.log10(step) + 1e-9))
    out = []
    for v in ticks:
        s = f"{round(float(v), decimals) + 0.0:.{decimals}f}"
        out.append(s.replace("-", minus))
    return out


# -- layout ----------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class PanelLayout:
    """Where a panel's axes are drawn in the PNG, and their limits and ticks.

    Attributes
    ----------
    box : (left, top, right, bottom)
        The axes' frame, PNG pixels (pixel centres).
    xlim, ylim : (float, float)
        Data limits at the frame's edges.
    xticks, yticks : array
        Tick positions, data units.
    """

    box: tuple[float, float, float, float]
    xlim: tuple[float, float]
    ylim: tuple[float, float]
    xticks: np.ndarray
    yticks: np.ndarray

    def pixel(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """PNG pixel (column, row) of data point(s) ``(x, y)``."""
        left, top, right, bottom = self.box
        (x0, x1), (y0, y1) = self.xlim, self.ylim
        col = left + (np.asarray(x, dtype=float) - x0) / (x1 - x0) * (right - left)
        row = bottom - (np.asarray(y, dtype=float) - y0) / (y1 - y0) * (bottom - top)
        return col, row


@functools.cache
def _font_file() -> str | None:
    """matplotlib's DejaVu Sans, found without importing matplotlib (None if absent)."""
    import importlib.util
    from pathlib import Path

    try:
        spec = importlib.util.find_spec("matplotlib")
    except (ImportError, ValueError):
        return None
    for folder in (spec.submodule_search_locations or []) if spec else []:
        path = Path(folder) / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
        if path.is_file():
            return str(path)
    return None


@functools.cache
def _font(px: int) -> ImageFont.FreeTypeFont:
    from PIL import ImageFont

    path = _font_file()
    if path is not None:
        try:
            return ImageFont.truetype(path, px)
        except OSError:
            pass
    return ImageFont.load_default(size=px)


def _minus() -> str:
    """U+2212 where the font has it (DejaVu Sans), else a hyphen."""
    return "\u2212" if _font_file() else "-"


class _Fonts:
    """Fonts and lengths at one resolution (``ppp`` pixels per point)."""

    def __init__(self, ppp: float):
        self.ppp = ppp

    def font(self, pt: float) -> ImageFont.FreeTypeFont:
        # a whole number of pixels once reduced: text is drawn after the reduction
        return _font(_SCALE * max(1, round(pt * self.ppp / _SCALE)))

    def fit(self, text: str, pt: float, width: float) -> tuple[ImageFont.FreeTypeFont, str]:
        """``text`` in a font of ``pt`` points, smaller (down to 7 pt) if it is wider than
        ``width``, and cut short with an ellipsis if even that is too wide."""
        font = self.font(pt)
        length = font.getlength(text)
        if length > width > 0:
            font = self.font(max(7.0, pt * width / length))
            while len(text) > 1 and font.getlength(text) > width:
                keep = max(1, int(len(text) * width / font.getlength(text)) - 1)
                text = text[:keep].rstrip() + "\u2026"
        return font, text

    def height(self, font) -> int:
        ascent, descent = font.getmetrics()
        return ascent + descent

    def pt(self, points: float) -> float:
        return points * self.ppp


#: Gaps, points: around the figure, between panels, title to axes, tick length,
#: tick to label, label to tick labels.
_PAD, _WSPACE, _TITLE_PAD, _TICK, _TICK_PAD, _LABEL_PAD = 4.0, 14.0, 6.0, 3.5, 3.5, 4.0


@dataclasses.dataclass(frozen=True)
class _Box:
    """A panel's cell and its axes' frame (whole drawing pixels)."""

    cell: tuple[float, float, float, float]
    frame: PanelLayout


class _LegendBlock:
    """A legend's layout: its entries in columns, its size and spacing (drawing pixels)."""

    def __init__(self, lines: list[Line], legend: Legend, fonts: _Fonts):
        self.legend = legend
        self.font = fonts.font(LEGEND_PT)
        em = fonts.pt(LEGEND_PT)
        self.em, self.row = em, fonts.height(self.font)
        n = len(lines)
        cols = min(legend.columns, max(n, 1))
        rows, large = divmod(n, cols)  # matplotlib: the first `large` columns one longer
        sizes = [rows + 1] * large + [rows] * (cols - large)
        self.columns, start = [], 0
        for size in sizes:
            if size:
                self.columns.append(lines[start:start + size])
                start += size
        self.handle, self.handle_pad, self.col_gap, self.row_gap, self.border = (
            2.0 * em, 0.8 * em, 2.0 * em, 0.5 * em, 0.4 * em)
        self.widths = [self.handle + self.handle_pad
                       + max(self.font.getlength(ln.label or "") for ln in col)
                       for col in self.columns]
        entries_w = sum(self.widths) + self.col_gap * max(len(self.widths) - 1, 0)
        title_w = self.font.getlength(legend.title) if legend.title else 0.0
        self.title_h = self.row + self.row_gap if legend.title else 0.0
        nrows = max((len(c) for c in self.columns), default=0)
        self.width = max(entries_w, title_w) + 2 * self.border
        self.height = (2 * self.border + self.title_h + nrows * self.row
                       + max(nrows - 1, 0) * self.row_gap)


def _panel_box(panel: Panel, cell: tuple[float, float, float, float],
               fonts: _Fonts) -> _Box:
    """The axes of a panel in its cell, with limits and ticks fitted to the axes' size."""
    left, top, right, bottom = cell
    label = fonts.font(LABEL_PT)
    label_h = fonts.height(label)
    a_top = top + (fonts.height(fonts.fit(panel.title, TITLE_PT, right - left)[0])
                   + fonts.pt(_TITLE_PAD) if panel.title else fonts.pt(_PAD))
    a_bottom = bottom - (fonts.pt(_TICK + _TICK_PAD) + label_h
                         + (fonts.pt(_LABEL_PAD) + label_h if panel.xlabel else 0.0))
    drawn = [np.isfinite(ln.x) & np.isfinite(ln.y) for ln in panel.lines]  # points drawn
    xlim0 = _limits([ln.x[ok] for ln, ok in zip(panel.lines, drawn)])
    ylim0 = _limits([ln.y[ok] for ln, ok in zip(panel.lines, drawn)]
                    + [np.asarray(panel.hlines, dtype=float)])
    minus = _minus()
    ylabel_w = label_h + fonts.pt(_LABEL_PAD) if panel.ylabel else 0.0
    font_px = fonts.pt(LABEL_PT)

    def fit(a_left: float, a_right: float) -> _Box:
        axes = (round(a_left), round(a_top), round(a_right), round(a_bottom))
        w, h = max(axes[2] - axes[0], 1), max(axes[3] - axes[1], 1)
        xlim, ylim = xlim0, ylim0
        if panel.equal_aspect:
            per_px = max((xlim[1] - xlim[0]) / w, (ylim[1] - ylim[0]) / h)
            cx, cy = sum(xlim) / 2, sum(ylim) / 2
            xlim = (cx - per_px * w / 2, cx + per_px * w / 2)
            ylim = (cy - per_px * h / 2, cy + per_px * h / 2)
        xticks = nice_ticks(*xlim, most=max(2, min(9, int(w / (3 * font_px)))))
        yticks = nice_ticks(*ylim, most=max(2, min(9, int(h / (2 * font_px)))))
        return _Box(cell, PanelLayout(axes, xlim, ylim, xticks, yticks))

    # y tick labels set the left edge, the x ticks' overhang the right; the
    # ticks follow the box (and with an equal aspect, the limits): two passes
    box = fit(left + ylabel_w + fonts.pt(_TICK + _TICK_PAD), right - fonts.pt(_PAD))
    for _ in range(2):
        ywidth = max((label.getlength(s) for s in _tick_labels(box.frame.yticks, minus)),
                     default=0.0)
        xlast = _tick_labels(box.frame.xticks, minus)[-1] if len(box.frame.xticks) else ""
        box = fit(left + ylabel_w + ywidth + fonts.pt(_TICK + _TICK_PAD),
                  right - max(fonts.pt(_PAD), label.getlength(xlast) / 2))
    return box


def _layout(chart: Chart, width: int, height: int,
            fonts: _Fonts) -> tuple[list[_Box], float, _LegendBlock | None]:
    """The panels' boxes, where the panels start (below the title) and the legend block."""
    pad = fonts.pt(_PAD)
    top = pad
    if chart.title:
        top += fonts.height(fonts.fit(chart.title, TITLE_PT, width - 2 * pad)[0]) + pad
    bottom = height - pad
    block = None
    if chart.legend is not None and chart.legend_lines():
        block = _LegendBlock(chart.legend_lines(), chart.legend, fonts)
        bottom -= block.height + pad
    n = max(len(chart.panels), 1)
    gap = fonts.pt(_WSPACE)
    cell_w = (width - 2 * pad - (n - 1) * gap) / n
    boxes = []
    for k, panel in enumerate(chart.panels):
        left = pad + k * (cell_w + gap)
        boxes.append(_panel_box(panel, (left, top, left + cell_w, bottom), fonts))
    return boxes, bottom, block


def _pixels(chart: Chart, dpi: float) -> tuple[int, int]:
    return max(1, round(chart.size[0] * dpi)), max(1, round(chart.size[1] * dpi))


def layout(chart: Chart, dpi: float = 120) -> list[PanelLayout]:
    """Where :func:`render_png` puts each panel's axes, and their limits and ticks.

    Parameters
    ----------
    chart : Chart
        The figure.
    dpi : float
        Pixels per inch of the PNG.
    """
    width, height = _pixels(chart, dpi)
    boxes, _, _ = _layout(chart, width * _SCALE, height * _SCALE, _Fonts(dpi * _SCALE / 72))

    def png(v: float) -> float:  # a drawing pixel centre to the PNG's
        return (v + 0.5) / _SCALE - 0.5

    return [dataclasses.replace(b.frame, box=tuple(png(v) for v in b.frame.box))
            for b in boxes]


# -- drawing ---------------------------------------------------------------------
def _runs(x: np.ndarray, y: np.ndarray):
    """The finite stretches of a line, as (K, 2) arrays of at least two points."""
    ok = np.isfinite(x) & np.isfinite(y)
    if not ok.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.view(np.int8), [0]])))
    for start, stop in zip(edges[::2], edges[1::2]):
        if stop - start >= 2:
            yield np.column_stack([x[start:stop], y[start:stop]])


def _dash_segments(pts: np.ndarray, on: float, off: float) -> list[list]:
    """The pieces of polyline ``pts`` (pixels) drawn with dashes ``on``, gaps ``off``."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    total = s[-1]
    if not total > 0:
        return []
    starts = np.arange(0.0, total, on + off)
    ends = np.minimum(starts + on, total)
    a = np.column_stack([np.interp(starts, s, pts[:, 0]), np.interp(starts, s, pts[:, 1])])
    b = np.column_stack([np.interp(ends, s, pts[:, 0]), np.interp(ends, s, pts[:, 1])])
    first = np.searchsorted(s, starts, side="right").tolist()
    last = np.searchsorted(s, ends, side="left").tolist()
    vertices = [tuple(v) for v in pts.tolist()]
    return [[tuple(p), *vertices[i:j], tuple(q)]
            for p, q, i, j in zip(a.tolist(), b.tolist(), first, last)]


def _stroke(draw: ImageDraw.ImageDraw, pts: np.ndarray, line: Line, fonts: _Fonts) -> None:
    """Draw polyline ``pts`` (drawing pixels) in ``line``'s colour, width and style."""
    colour, width = _rgb(line.colour), max(1, round(fonts.pt(line.width)))
    if line.style == "-":
        pieces = [[tuple(v) for v in np.asarray(pts, dtype=float).tolist()]]
    else:
        on, off = _DASHES[line.style]
        unit = fonts.pt(max(line.width, 0.5))
        pieces = _dash_segments(np.asarray(pts, dtype=float), on * unit, off * unit)
    for xy in pieces:
        if len(xy) > 2:
            draw.line(xy, fill=colour, width=width, joint="curve")
        elif len(xy) == 2:
            draw.line(xy, fill=colour, width=width)


class _Painter:
    """Lines drawn at :data:`_SCALE` times the size; text kept for after the reduction.

    FreeType anti-aliases text by itself, so text is drawn on the reduced
    image (a quarter of the pixels to fill) at the place the layout gave it.
    """

    def __init__(self, width: int, height: int, dpi: float):
        from PIL import Image, ImageDraw

        self.fonts = _Fonts(dpi * _SCALE / 72)
        self.canvas = Image.new("RGB", (width * _SCALE, height * _SCALE), "white")
        self.draw = ImageDraw.Draw(self.canvas)
        self.texts: list[tuple[float, float, str, int, str]] = []

    def text(self, x: float, y: float, text: str, font, anchor: str) -> None:
        """``text`` at ``(x, y)`` (drawing pixels); anchor ``up`` turns it to read upwards,
        its top at ``x``, centred on ``y``."""
        self.texts.append((x, y, text, font.size, anchor))

    def line(self, pts, line: Line) -> None:
        _stroke(self.draw, pts, line, self.fonts)

    def finish(self) -> Image.Image:
        from PIL import ImageDraw

        image = self.canvas.reduce(_SCALE)
        draw = ImageDraw.Draw(image)
        for x, y, text, size, anchor in self.texts:
            font = _font(size // _SCALE)
            x, y = (x + 0.5) / _SCALE - 0.5, (y + 0.5) / _SCALE - 0.5
            if anchor == "up":
                _draw_upwards(image, text, font, x, y)
            else:
                draw.text((x, y), text, fill="black", font=font, anchor=anchor)
        return image


def _draw_upwards(image: Image.Image, text: str, font, left: float, centre_y: float) -> None:
    """``text`` turned a quarter left (read upwards), its top at ``left``."""
    from PIL import Image, ImageDraw

    ascent, descent = font.getmetrics()
    strip = Image.new("L", (max(1, math.ceil(font.getlength(text))) + 2, ascent + descent))
    ImageDraw.Draw(strip).text((1, 0), text, fill=255, font=font, anchor="la")
    turned = strip.rotate(90, expand=True)
    image.paste((0, 0, 0), (round(left), round(centre_y - turned.height / 2)), turned)


def _draw_lines(paint: _Painter, box: _Box, panel: Panel) -> None:
    """The panel's hlines and lines, clipped to its axes."""
    frame = box.frame
    left, top, right, bottom = frame.box

    def pixels(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.column_stack(frame.pixel(x, y))

    for y in panel.hlines:
        if math.isfinite(y):
            hline = Line(frame.xlim, [y, y], HLINE_COLOUR, HLINE_WIDTH)
            paint.line(pixels(hline.x, hline.y), hline)
    for line in panel.lines:
        for run in _runs(line.x, line.y):
            paint.line(pixels(run[:, 0], run[:, 1]), line)
    # every point lies inside the limits: only a line's width can stray
    # outside the frame, into this band, which is cleared (the clipping)
    widths = [ln.width for ln in panel.lines] + [HLINE_WIDTH]
    band = math.ceil(paint.fonts.pt(max(widths)) / 2) + 1
    for rect in ((left - band, top - band, left - 1, bottom + band),
                 (right + 1, top - band, right + band, bottom + band),
                 (left, top - band, right, top - 1), (left, bottom + 1, right, bottom + band)):
        paint.draw.rectangle(rect, fill="white")


def _draw_legend(paint: _Painter, block: _LegendBlock, left: float, top: float,
                 frame: bool) -> None:
    from PIL import Image

    box = (round(left), round(top), round(left + block.width), round(top + block.height))
    if frame:  # matplotlib's: white at 80 %, a light grey edge, rounded corners
        region = paint.canvas.crop(box)
        paint.canvas.paste(Image.blend(region, Image.new("RGB", region.size, "white"), 0.8),
                           box[:2])
        paint.draw.rounded_rectangle(box, radius=round(0.2 * block.em), outline=_rgb("0.8"),
                                     width=max(1, round(paint.fonts.pt(0.8))))
    y = top + block.border
    if block.legend.title:
        paint.text(left + block.width / 2, y, block.legend.title, block.font, "ma")
        y += block.title_h
    x = left + block.border
    for col, col_w in zip(block.columns, block.widths):
        for k, line in enumerate(col):
            mid = y + k * (block.row + block.row_gap) + block.row / 2
            paint.line([(x, mid), (x + block.handle, mid)], line)
            paint.text(x + block.handle + block.handle_pad, mid, line.label or "", block.font,
                       "lm")
        x += col_w + block.col_gap


def _legend_corner(block: _LegendBlock, box: _Box, panel: Panel) -> tuple[float, float]:
    """Top left of a panel's legend (drawing pixels), half a line in from its corner."""
    left, top, right, bottom = box.frame.box
    pad = 0.5 * block.em
    corners = {}
    for where in LOCATIONS[:4]:
        vertical, horizontal = where.split()
        corners[where] = (left + pad if horizontal == "left" else right - pad - block.width,
                          top + pad if vertical == "upper" else bottom - pad - block.height)
    if panel.legend.location != "best":
        return corners[panel.legend.location]
    x, y = box.frame.pixel(np.concatenate([ln.x for ln in panel.lines] or [np.zeros(0)]),
                       np.concatenate([ln.y for ln in panel.lines] or [np.zeros(0)]))

    def hidden(corner: tuple[float, float]) -> int:
        cx, cy = corner
        return int(np.sum((x >= cx) & (x <= cx + block.width)
                          & (y >= cy) & (y <= cy + block.height)))

    return min(corners.values(), key=hidden)  # min keeps the first of equals


def _draw_panel(paint: _Painter, box: _Box, panel: Panel) -> None:
    fonts, draw = paint.fonts, paint.draw
    _draw_lines(paint, box, panel)
    frame = box.frame
    left, top, right, bottom = frame.box
    if panel.legend is not None and (labelled := [ln for ln in panel.lines if ln.label]):
        block = _LegendBlock(labelled, panel.legend, fonts)
        lx, ly = _legend_corner(block, box, panel)
        _draw_legend(paint, block, lx, ly, frame=True)
    thin = max(1, round(fonts.pt(0.8)))
    draw.rectangle((left, top, right, bottom), outline="black", width=thin)
    label = fonts.font(LABEL_PT)
    tick, gap = fonts.pt(_TICK), fonts.pt(_TICK + _TICK_PAD)
    cols, _ = frame.pixel(frame.xticks, np.zeros(len(frame.xticks)))
    for col, text in zip(cols, _tick_labels(frame.xticks, _minus())):
        draw.line([(col, bottom), (col, bottom + tick)], fill="black", width=thin)
        paint.text(col, bottom + gap, text, label, "ma")
    _, rows = frame.pixel(np.zeros(len(frame.yticks)), frame.yticks)
    for row, text in zip(rows, _tick_labels(frame.yticks, _minus())):
        draw.line([(left - tick, row), (left, row)], fill="black", width=thin)
        paint.text(left - gap, row, text, label, "rm")
    cell_left, cell_top, cell_right, cell_bottom = box.cell
    centre = (left + right) / 2
    if panel.title:
        font, title = fonts.fit(panel.title, TITLE_PT, cell_right - cell_left)
        half = font.getlength(title) / 2
        centre_t = min(max(centre, cell_left + half), cell_right - half)
        paint.text(centre_t, top - fonts.pt(_TITLE_PAD), title, font, "md")
    if panel.xlabel:
        font, xlabel = fonts.fit(panel.xlabel, LABEL_PT, cell_right - cell_left)
        paint.text(centre, cell_bottom, xlabel, font, "md")
    if panel.ylabel:
        font, ylabel = fonts.fit(panel.ylabel, LABEL_PT, bottom - top)
        paint.text(cell_left, (top + bottom) / 2, ylabel, font, "up")


def _render(chart: Chart, dpi: float) -> Image.Image:
    width, height = _pixels(chart, dpi)
    paint = _Painter(width, height, dpi)
    big_w, big_h = paint.canvas.size
    fonts = paint.fonts
    boxes, panels_bottom, block = _layout(chart, big_w, big_h, fonts)
    pad = fonts.pt(_PAD)
    if chart.title:
        font, title = fonts.fit(chart.title, TITLE_PT, big_w - 2 * pad)
        paint.text(big_w / 2, pad, title, font, "ma")
    for box, panel in zip(boxes, chart.panels):
        _draw_panel(paint, box, panel)
    if block is not None:
        _draw_legend(paint, block, (big_w - block.width) / 2, panels_bottom + pad, frame=False)
    return paint.finish()


def render_png(chart: Chart, *, dpi: float = 120) -> bytes:
    """The chart drawn with Pillow, as PNG bytes (``chart.size * dpi`` pixels).

    Parameters
    ----------
    chart : Chart
        The figure.
    dpi : float
        Pixels per inch.
    """
    from PIL import Image

    buf = io.BytesIO()
    # 256 colours (white, a few line colours and their anti-aliased blends) look
    # the same, and encode in half the time to half the bytes
    image = _render(chart, dpi).quantize(256, method=Image.Quantize.FASTOCTREE)
    image.save(buf, format="PNG", compress_level=2)
    return buf.getvalue()


def to_matplotlib(chart: Chart) -> Figure:
    """The chart as a matplotlib figure (matplotlib is imported here, not before).

    Parameters
    ----------
    chart : Chart
        The figure.
    """
    from minvar.plotting import new_figure

    fig, ax = new_figure(1, len(chart.panels), size=chart.size)
    handles = {}
    for a, panel in zip(ax[0], chart.panels):
        for line in panel.lines:
            (h,) = a.plot(line.x, line.y, line.style, color=line.colour, lw=line.width,
                          label=line.label or "_nolegend_")
            if line.label:
                handles.setdefault(line.label, h)
        for y in panel.hlines:
            a.axhline(y, color=HLINE_COLOUR, lw=HLINE_WIDTH, zorder=1.5)
        if panel.equal_aspect:
            a.set_aspect("equal", adjustable="datalim")
        a.set_title(panel.title)
        a.set_xlabel(panel.xlabel)
        a.set_ylabel(panel.ylabel)
        if panel.legend is not None and any(ln.label for ln in panel.lines):
            a.legend(loc=panel.legend.location, ncol=panel.legend.columns,
                     title=panel.legend.title, fontsize=LEGEND_PT, title_fontsize=LEGEND_PT)
    if chart.legend is not None and handles:
        fig.legend(list(handles.values()), list(handles), loc="outside lower center",
                   ncol=chart.legend.columns, title=chart.legend.title, fontsize=LEGEND_PT,
                   title_fontsize=LEGEND_PT, frameon=False)
    if chart.title:
        fig.suptitle(chart.title)
    return fig

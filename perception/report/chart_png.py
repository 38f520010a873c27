"""A :class:`~perception.report.chart_spec.Chart` drawn by Pillow, in milliseconds.

:func:`render_png` draws a chart without matplotlib (which takes about
0.6 s to import and a second or more to lay out and draw a report's
figures). The drawing follows matplotlib's default style: tab10 colours,
DejaVu Sans (matplotlib's own font file, read without importing matplotlib;
Pillow's default font if it is missing), ticks at 1-2-5 steps, 5 % margins,
dash patterns scaled by the line width. Lines, bands and error bars are
drawn at twice the size and reduced, so they come out anti-aliased; a band
is blended over what is under it at its alpha. Text (anti-aliased by
FreeType) is drawn on the reduced image. A character the font lacks (a clip
name in another script) is drawn as a box, without a warning.
"""

from __future__ import annotations

import dataclasses
import functools
import io
import math
from typing import TYPE_CHECKING

import numpy as np

from perception.report.chart_spec import (
    HLINE_COLOUR,
    HLINE_WIDTH,
    LABEL_PT,
    LEGEND_PT,
    LOCATIONS,
    TITLE_PT,
    Band,
    Chart,
    ErrorBars,
    Legend,
    Line,
    Panel,
    rgb,
)

if TYPE_CHECKING:
    from PIL import Image, ImageDraw, ImageFont

__all__ = ["PanelLayout", "layout", "nice_ticks", "render_png"]

#: matplotlib's dash patterns (on, off), in line widths.
_DASHES = {"--": (3.7, 1.6), ":": (1.0, 1.65)}
#: Supersampling: drawn at this multiple of the output size, then reduced.
_SCALE = 2
#: Height of the strips a band is blended in, drawing pixels.
_STRIP = 32


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
            return _safe_font_class()(path, px)
        except OSError:
            pass
    return ImageFont.load_default(size=px)


#: What Pillow raises where it cannot lay out a text (``raqm_layout() failed`` is a
#: RuntimeError; a character it cannot encode, a UnicodeError).
_LAYOUT_ERRORS = (OSError, RuntimeError, ValueError)


def _escaped(text: str) -> str:
    """``text`` in ASCII, every other character as a backslash escape."""
    return text.encode("ascii", "backslashreplace").decode("ascii")


@functools.cache
def _safe_font_class() -> type:
    """A FreeType font whose text always lays out.

    Complex layout (libraqm: right-to-left and combining scripts) fails on
    some texts and builds (``RuntimeError: raqm_layout() failed``): such a
    text is laid out again without it (``Layout.BASIC``: each character's
    glyph in order), and, should that fail too, drawn escaped in ASCII. A
    figure never fails for a clip's name.
    """
    from PIL import ImageFont

    class SafeFont(ImageFont.FreeTypeFont):
        _basic: ImageFont.FreeTypeFont | None = None

        def _fallback(self) -> ImageFont.FreeTypeFont:
            if self._basic is None:
                self._basic = ImageFont.FreeTypeFont(self.path, self.size, self.index,
                                                     self.encoding,
                                                     layout_engine=ImageFont.Layout.BASIC)
            return self._basic

        def _safe(self, method: str, text, *args, **kwargs):
            try:
                return getattr(super(), method)(text, *args, **kwargs)
            except _LAYOUT_ERRORS:
                pass
            basic = getattr(self._fallback(), method)
            try:
                return basic(text, *args, **kwargs)
            except _LAYOUT_ERRORS:
                if not isinstance(text, str):
                    raise
                return basic(_escaped(text), *args, **kwargs)

        def getlength(self, text, *args, **kwargs):
            return self._safe("getlength", text, *args, **kwargs)

        def getbbox(self, text, *args, **kwargs):
            return self._safe("getbbox", text, *args, **kwargs)

        def getmask(self, text, *args, **kwargs):
            return self._safe("getmask", text, *args, **kwargs)

        def getmask2(self, text, *args, **kwargs):
            return self._safe("getmask2", text, *args, **kwargs)

    return SafeFont


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
    x, y = panel.points()
    xlim0 = _limits([x])
    ylim0 = _limits([y, np.asarray(panel.hlines, dtype=float)])
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
def _runs(*columns: np.ndarray):
    """The stretches where every column is finite, as (K, len(columns)) arrays, K >= 2."""
    ok = np.logical_and.reduce([np.isfinite(c) for c in columns])
    if not ok.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.view(np.int8), [0]])))
    for start, stop in zip(edges[::2], edges[1::2]):
        if stop - start >= 2:
            yield np.column_stack([c[start:stop] for c in columns])


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
    colour, width = rgb(line.colour), max(1, round(fonts.pt(line.width)))
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
    """Lines, bands and bars drawn at :data:`_SCALE` times the size; text kept for after
    the reduction.

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


def _fill_band(paint: _Painter, frame: PanelLayout, band: Band) -> None:
    """Fill ``band`` on a mask of the axes, blended over what is drawn at its alpha."""
    from PIL import Image, ImageDraw

    left, top, right, bottom = (int(v) for v in frame.box)
    mask = Image.new("L", (right - left + 1, bottom - top + 1), 0)
    draw, drawn = ImageDraw.Draw(mask), False
    level = round(255 * band.alpha)
    for run in _runs(band.x, band.lower, band.upper):
        cols, lower = frame.pixel(run[:, 0], run[:, 1])
        _, upper = frame.pixel(run[:, 0], run[:, 2])
        outline = np.column_stack([np.concatenate([cols, cols[::-1]]),
                                   np.concatenate([upper, lower[::-1]])]) - (left, top)
        draw.polygon([tuple(v) for v in outline.tolist()], fill=level)
        drawn = True
    if not (drawn and level):
        return
    # blended strip by strip, each over its filled part only: a band is mostly
    # thin, and a blend costs the same for every pixel of its box, filled or not
    colour = rgb(band.colour)
    for y in range(0, mask.height, _STRIP):
        strip = mask.crop((0, y, mask.width, min(y + _STRIP, mask.height)))
        if (box := strip.getbbox()) is not None:
            x0, y0, x1, y1 = box
            paint.canvas.paste(colour, (left + x0, top + y + y0, left + x1, top + y + y1),
                               strip.crop(box))


def _crisp(centre: float, width: int) -> tuple[int, int]:
    """The drawing pixels (first, last) of a stroke ``width`` PNG pixels wide, centred
    on drawing pixel ``centre`` and snapped to whole PNG pixels (a sharp 1-2 px bar)."""
    first = round((centre + 0.5) / _SCALE - 0.5 - (width - 1) / 2)
    return first * _SCALE, (first + width) * _SCALE - 1


def _draw_errorbars(paint: _Painter, frame: PanelLayout, bars: ErrorBars) -> None:
    """Each bar from ``y - err`` to ``y + err``, a cap across each end, on whole pixels
    (as matplotlib snaps them)."""
    ok = np.isfinite(bars.x) & np.isfinite(bars.y) & np.isfinite(bars.err)
    cols, low = frame.pixel(bars.x[ok], bars.y[ok] - bars.err[ok])
    _, high = frame.pixel(bars.x[ok], bars.y[ok] + bars.err[ok])
    colour = rgb(bars.colour)
    width = max(1, round(paint.fonts.pt(bars.width) / _SCALE))  # PNG pixels
    half = paint.fonts.pt(bars.cap)
    for col, a, b in zip(cols.tolist(), low.tolist(), high.tolist()):
        x0, x1 = _crisp(col, width)
        (top, _), (_, bottom) = _crisp(b, width), _crisp(a, width)
        paint.draw.rectangle((x0, top, x1, bottom), fill=colour)
        if half > 0:
            centre = (x0 + x1 + 1) / 2
            c0 = round((centre - half) / _SCALE) * _SCALE
            c1 = round((centre + half) / _SCALE) * _SCALE - 1
            for row in (a, b):
                r0, r1 = _crisp(row, width)
                paint.draw.rectangle((c0, r0, c1, r1), fill=colour)


def _draw_data(paint: _Painter, box: _Box, panel: Panel) -> None:
    """The panel's bands, hlines, lines and error bars, in that order, clipped to its axes."""
    frame = box.frame
    left, top, right, bottom = frame.box

    def pixels(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.column_stack(frame.pixel(x, y))

    for band in panel.bands:
        _fill_band(paint, frame, band)
    for y in panel.hlines:
        if math.isfinite(y):
            hline = Line(frame.xlim, [y, y], HLINE_COLOUR, HLINE_WIDTH)
            paint.line(pixels(hline.x, hline.y), hline)
    for line in panel.lines:
        for run in _runs(line.x, line.y):
            paint.line(pixels(run[:, 0], run[:, 1]), line)
    for bars in panel.errorbars:
        _draw_errorbars(paint, frame, bars)
    # every point lies inside the limits: only a line's width or a cap can
    # stray outside the frame, into this band, which is cleared (the clipping)
    stray = ([ln.width / 2 for ln in panel.lines] + [HLINE_WIDTH / 2]
             + [max(b.width / 2, b.cap) for b in panel.errorbars])
    band = math.ceil(paint.fonts.pt(max(stray))) + 1
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
        paint.draw.rounded_rectangle(box, radius=round(0.2 * block.em), outline=rgb("0.8"),
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
    x, y = box.frame.pixel(*panel.points())

    def hidden(corner: tuple[float, float]) -> int:
        cx, cy = corner
        return int(np.sum((x >= cx) & (x <= cx + block.width)
                          & (y >= cy) & (y <= cy + block.height)))

    return min(corners.values(), key=hidden)  # min keeps the first of equals


def _draw_panel(paint: _Painter, box: _Box, panel: Panel) -> None:
    fonts, draw = paint.fonts, paint.draw
    _draw_data(paint, box, panel)
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


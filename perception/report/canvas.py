"""The figures' Agg canvas: strings rendered once per process, figures kept per kind.

What a report's per-clip figures cost is drawing, not data; measured on
motion-capture trials (tools/bench_mocap.py), and removed here:

* **Text.** matplotlib 3.11 lays out and renders every string glyph by glyph
  on every draw (about 1 ms a string), and looks up its font's heights at
  every measure; a clip's three figures draw some 130 strings, most of them
  the same in every clip (tick labels, axis labels, legend entries).
  :func:`new_canvas` gives a figure an Agg canvas whose renderer keeps each
  string's rendered coverage mask (as matplotlib up to 3.10 drew a string:
  whole, at a pixel position) and stamps it again in the string's colour and
  angle, and keeps each font's heights per size.
* **PNG.** Pillow's encoder tries five filters on every row; :func:`png_bytes`
  filters each row of an opaque figure one way (``Sub``, which suits flat
  backgrounds), as RGB, and deflates it at zlib level 1: half the time, for
  files of about the same size.
* **Building.** A new figure builds its axes, and its first draw builds every
  tick (a third of a figure's cost). :func:`kept_figure` keeps one figure per
  kind and layout per thread: the next clip's figure is the same ``Figure``
  with the previous clip's lines, patches, texts and legends removed and its
  limits reset, its ticks and tick labels reused.

A kept figure is valid until the next :func:`kept_figure` of its kind in that
thread: it is for drawing and saving at once (the clip and batch reports),
never for figures handed to a caller (``Recognition.plot()`` gets new ones).
matplotlib is imported on the first call, not with this module.
"""

from __future__ import annotations

import io
import math
import struct
import threading
import zlib
from collections import OrderedDict
from collections.abc import Callable, Hashable
from functools import cache
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["keep_layouts", "kept_figure", "new_canvas", "png_bytes", "png_encoder",
           "quicker_legend"]

#: Rendered strings kept per process (a few kB each; a batch uses a few hundred).
TEXT_CACHE_SIZE = 4096
#: Figures kept per thread: one per kind and layout (a repertoire's legend rows, ...).
KEPT_FIGURES = 8

_MASKS: OrderedDict[tuple, tuple[np.ndarray, float, float, float]] = OrderedDict()
#: Width, height and descent of each string, px, as measured (as many as masks).
_EXTENTS: OrderedDict[tuple, tuple[float, float, float]] = OrderedDict()
_MASKS_LOCK = threading.Lock()
#: Ascent, descent and line gap of each font and size, px (a few entries).
_HEIGHTS: dict[tuple, tuple] = {}
#: Each string's layout on the report's canvas (``Text._get_layout``), by what it depends on.
_LAYOUTS: OrderedDict[tuple, tuple] = OrderedDict()
_KEPT = threading.local()


def _font_key(prop) -> tuple:
    """What picks a font and its size (a ``FontProperties`` is mutable: not the key), with
    the fonts a generic family (``sans-serif``) stands for now."""
    from matplotlib import rcParams

    families = tuple(prop.get_family())
    return (families, tuple(tuple(rcParams[f"font.{f}"]) for f in families
                            if f"font.{f}" in rcParams),
            prop.get_style(), prop.get_variant(), prop.get_weight(), prop.get_stretch(),
            prop.get_size_in_points(), prop.get_file(), prop.get_math_fontfamily())


@cache
def _canvas_class() -> type:
    """``FigureCanvasAgg`` whose renderer draws strings from :data:`_MASKS` (built once)."""
    from matplotlib import rcParams
    from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg, get_hinting_flag
    from matplotlib.font_manager import fontManager, get_font
    from matplotlib.ft2font import FT2Font

    if not hasattr(FT2Font, "draw_glyphs_to_bitmap"):  # a matplotlib without whole strings
        return FigureCanvasAgg

    class _Renderer(RendererAgg):
        #: its strings' measures are the kept ones (:func:`_kept_layout` may keep layouts)
        keeps_layouts = True

        def _get_font_height_metrics(self, prop) -> tuple:
            """A font's ascent, descent and line gap at this size, px, as ``Text`` finds them
            (its ``OS/2`` or ``hhea`` table), once per font and size rather than at
            every measure of every string (``Text._get_layout`` asks its renderer first)."""
            key = (*_font_key(prop), self.dpi)
            with _MASKS_LOCK:
                hit = _HEIGHTS.get(key)
            if hit is None:
                font = get_font(fontManager._find_fonts_by_props(prop))
                hit = (None, None, None)  # no table: Text measures "lp" itself
                for table_name, gap, ascent, descent in (
                        ("OS/2", "sTypoLineGap", "sTypoAscender", "sTypoDescender"),
                        ("hhea", "lineGap", "ascent", "descent")):
                    table = font.get_sfnt_table(table_name)
                    if table is not None:
                        scale = (prop.get_size_in_points() * self.dpi / 72
                                 / font.get_sfnt_table("head")["unitsPerEm"])
                        hit = (table[ascent] * scale, -table[descent] * scale,
                               table[gap] * scale)
                        break
                with _MASKS_LOCK:
                    _HEIGHTS[key] = hit
            return hit

        def _text_key(self, s: str, prop) -> tuple:
            """What a string's layout depends on: the string, its font and size, the dpi
            and the hinting and kerning settings."""
            return (s, *_font_key(prop), self.dpi, rcParams["text.hinting"],
                    rcParams["text.hinting_factor"], rcParams["text.kerning_factor"])

        def _mask(self, s: str, prop, antialiased: bool) -> tuple:
            """The string's coverage mask and offsets, rendered at the origin, unrotated."""
            key = (*self._text_key(s, prop), bool(antialiased))
            with _MASKS_LOCK:
                hit = _MASKS.get(key)
                if hit is not None:
                    _MASKS.move_to_end(key)
                    return hit
            font = self._prepare_font(prop)
            font.set_text(s, 0, flags=get_hinting_flag())
            return self._keep_mask(key, font, antialiased)

        @staticmethod
        def _keep_mask(key: tuple, font, antialiased: bool) -> tuple:
            """The mask of the string ``font`` holds laid out (``set_text``), kept as ``key``."""
            font.draw_glyphs_to_bitmap(antialiased=bool(antialiased))
            xo, yo = font.get_bitmap_offset()
            hit = (np.array(font.get_image(), dtype=np.uint8), xo / 64.0, yo / 64.0,
                   font.get_descent() / 64.0)
            with _MASKS_LOCK:
                _MASKS[key] = hit
                while len(_MASKS) > TEXT_CACHE_SIZE:
                    _MASKS.popitem(last=False)
            return hit

        def get_text_width_height_descent(self, s, prop, ismath):
            """A string's extent, px, as ``RendererAgg`` measures it, kept per process (a
            tick label measured once, not once per figure); the string laid out to be
            measured is rendered then too (it is about to be drawn), so that each string
            is laid out once (``set_text``: about half a millisecond) rather than twice."""
            if ismath:  # mathtext and TeX: matplotlib's own
                return super().get_text_width_height_descent(s, prop, ismath)
            key = self._text_key(s, prop)
            with _MASKS_LOCK:
                hit = _EXTENTS.get(key)
            if hit is not None:
                return hit
            font = self._prepare_font(prop)
            font.set_text(s, 0.0, flags=get_hinting_flag())
            w, h = font.get_width_height()  # as RendererAgg measures: unrotated, subpixels
            hit = (w / 64.0, h / 64.0, font.get_descent() / 64.0)
            antialiased = bool(rcParams["text.antialiased"])  # a Text's default
            if (*key, antialiased) not in _MASKS:
                self._keep_mask((*key, antialiased), font, antialiased)
            with _MASKS_LOCK:
                _EXTENTS[key] = hit
                while len(_EXTENTS) > TEXT_CACHE_SIZE:
                    _EXTENTS.popitem(last=False)
            return hit

        def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
            # OpenType features and languages need the glyph-by-glyph layout
            special = mtext is not None and any(
                getattr(mtext, name, lambda: None)() for name in ("get_fontfeatures",
                                                                   "get_language"))
            if ismath or special:
                return super().draw_text(gc, x, y, s, prop, angle, ismath, mtext)
            mask, xo, yo, descent = self._mask(s, prop, gc.get_antialiased())
            if not mask.size:  # an empty string, or only spaces
                return None
            rad = math.radians(angle)  # the descent turns with the text
            self._renderer.draw_text_image(mask, round(x + xo + descent * math.sin(rad)),
                                           round(y + yo + descent * math.cos(rad)) + 1,
                                           angle, gc)
            return None

    class _Canvas(FigureCanvasAgg):
        def get_renderer(self):
            w, h = self.get_width_height(physical=True)
            key = w, h, self.figure.dpi
            if self._lastKey != key:  # as FigureCanvasAgg's, with the renderer above
                self.renderer = _Renderer(w, h, self.figure.dpi)
                self._lastKey = key
            return self.renderer

    return _Canvas


def new_canvas(fig: Figure) -> None:
    """Give ``fig`` the report's Agg canvas (strings rendered once per process).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure not shown through pyplot.
    """
    _canvas_class()(fig)


def _clear(fig: Figure, axes) -> None:
    """Take the last clip off a kept figure: its artists, legends, limits and aspect."""
    for ax in axes:
        for artist in (*ax.lines, *ax.patches, *ax.texts, *ax.collections, *ax.images):
            artist.remove()
        if ax.legend_ is not None:
            ax.legend_.remove()
        ax.set_aspect("auto")
        ax.set_xlim(0.0, 1.0)  # a new axes' limits, should nothing be drawn on it
        ax.set_ylim(0.0, 1.0)
        ax.relim()  # no artists: null data limits, as a new axes has
        ax.set_autoscale_on(True)
    for legend in tuple(fig.legends):
        legend.remove()


def kept_figure(key: Hashable, build: Callable[[], tuple[Figure, object]], *,
                clear: bool = True) -> tuple[Figure, object]:
    """This thread's figure for ``key``, emptied, or a new one from ``build()``.

    Parameters
    ----------
    key : hashable
        The figure's kind and everything its layout depends on (size,
        panels, legend rows): figures of one key differ only in what is
        drawn on them.
    build : callable
        Returns ``(fig, drawn)`` for a key not yet kept: ``drawn`` the axes
        drawn on, or the artists a caller updates.
    clear : bool
        Take the last use's artists, legends and limits off (default);
        without, the figure is returned as it was left, for a caller that
        updates every artist it drew (``set_data``).

    Returns
    -------
    fig : matplotlib.figure.Figure
        Valid until the next call with this key in this thread.
    drawn : object
        As ``build`` returned it.
    """
    kept = getattr(_KEPT, "figures", None)
    if kept is None:
        kept = _KEPT.figures = OrderedDict()
    if key in kept:
        kept.move_to_end(key)
        fig, axes = kept[key]
        if clear:
            _clear(fig, fig.axes)
        return fig, axes
    fig, axes = kept[key] = build()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            _quicker_axis(axis)
    for legend in (*fig.legends, *(ax.legend_ for ax in fig.axes if ax.legend_ is not None)):
        quicker_legend(legend)  # a legend kept with its figure (clear=False)
    keep_layouts(_texts(fig))
    while len(kept) > KEPT_FIGURES:
        kept.popitem(last=False)
    return fig, axes


def _texts(fig) -> list:
    """The texts of ``fig``: its own, its axes' (titles, axis labels, the ticks made),
    its legends'."""
    from matplotlib.text import Text

    return fig.findobj(lambda a: isinstance(a, Text))


def _quicker_axis(axis) -> None:
    """Let ``axis`` make its further major ticks as copies of its first, and update
    and measure its ticks once a draw.

    matplotlib builds each tick an axis draws (a ``Tick``: two tick lines, a
    grid line and two labels, each set up from the rcParams), then copies
    the first tick's properties onto it (``Axis._copy_tick_props``): 1.5 ms
    a tick (2-core machine), and a process's first three report figures
    build 113. A copy of the first tick, its parts copied and their mutable
    state their own, is the same tick in 0.12 ms. And an axis's draw updates
    its ticks (locator, formatter, positions, labels) and measures their
    labels, then does both again to place its label below them
    (``_get_tick_boxes_siblings``): the second time, within that draw, gets
    the first's ticks and boxes. Only for an axis whose class draws and
    makes ticks as ``Axis`` does, and only on this axis (attributes of the
    instance: other figures keep matplotlib's own).
    """
    from matplotlib.axis import Axis

    cls = type(axis)
    if any(getattr(cls, name, None) is not getattr(Axis, name, None) or not hasattr(Axis, name)
           for name in ("get_major_ticks", "draw", "_update_ticks", "_get_ticklabel_bboxes",
                        "_copy_tick_props")):
        return
    drawing: dict = {}  # while this axis draws: its ticks, and their boxes for a renderer

    def get_major_ticks(numticks=None):
        if numticks is None:
            numticks = len(axis.get_majorticklocs())
        ticks = axis.majorTicks  # the first made by matplotlib, as always
        while len(ticks) < numticks:
            ticks.append(_copy_tick(ticks[0]))
        return ticks[:numticks]

    def draw(renderer):
        drawing.clear()
        drawing["on"] = True
        try:
            return cls.draw(axis, renderer)
        finally:
            drawing.clear()

    def _update_ticks():
        if not drawing:
            return cls._update_ticks(axis)
        if "ticks" not in drawing:
            drawing["ticks"] = cls._update_ticks(axis)
        return drawing["ticks"]

    def _get_ticklabel_bboxes(ticks, renderer=None):
        if not drawing or ticks is not drawing.get("ticks"):
            return cls._get_ticklabel_bboxes(axis, ticks, renderer)
        if drawing.get("renderer") is not renderer or "boxes" not in drawing:
            drawing["boxes"] = cls._get_ticklabel_bboxes(axis, ticks, renderer)
            drawing["renderer"] = renderer
        return drawing["boxes"]

    for fn in (get_major_ticks, draw, _update_ticks, _get_ticklabel_bboxes):
        fn.__doc__ = getattr(Axis, fn.__name__).__doc__
        setattr(axis, fn.__name__, fn)


def quicker_legend(legend) -> None:
    """Let ``legend`` lay out its boxes once a draw, and find its best place once.

    A legend's draw measures its box (every entry's text and handle, packed
    in columns), then draws each box of the tree, and each box lays out its
    own subtree again to place its children: a 16-entry legend lays out each
    entry five times, a fifth of a clip's figures. Within one draw nothing
    moves a box's size, so each box's layout (``get_bbox``,
    ``_get_bbox_and_child_offsets``) is kept for the rest of that draw, and so
    is the best location (``loc="best"``, asked for by the measure and by the
    draw). Outside a draw the legend measures afresh. Only for a legend whose
    class draws and places as ``Legend`` does, on this legend's boxes only
    (attributes of the instances).

    Parameters
    ----------
    legend : matplotlib.legend.Legend
        A legend of a figure drawn on the report's canvas.
    """
    from matplotlib.legend import Legend
    from matplotlib.offsetbox import OffsetBox

    cls = type(legend)
    if any(getattr(cls, name, None) is not getattr(Legend, name, None) or not hasattr(Legend, name)
           for name in ("draw", "_find_best_position", "_findoffset")):
        return
    drawing: dict = {}  # while the legend draws: (method, box, arguments) -> result

    def kept(box, name: str):
        method = getattr(type(box), name)

        def during_draw(*args, **kwargs):
            if not drawing or kwargs:
                return method(box, *args, **kwargs)
            key = (name, id(box), *args)  # a renderer by identity, sizes by value
            if key not in drawing:
                drawing[key] = method(box, *args)
            return drawing[key]

        during_draw.__doc__ = method.__doc__
        return during_draw

    boxes, seen = [legend._legend_box], set()
    while boxes:
        box = boxes.pop()
        if id(box) in seen or not isinstance(box, OffsetBox):
            continue
        seen.add(id(box))
        for name in ("get_bbox", "_get_bbox_and_child_offsets"):
            setattr(box, name, kept(box, name))
        boxes.extend(box.get_children())

    def draw(renderer):
        drawing.clear()
        drawing["on"] = True  # never a key of a result
        try:
            return cls.draw(legend, renderer)
        finally:
            drawing.clear()

    draw.__doc__ = Legend.draw.__doc__
    legend.draw = draw
    keep_layouts((*legend.get_texts(), legend.get_title()))
    legend._find_best_position = kept(legend, "_find_best_position")


def keep_layouts(texts) -> None:
    """Let each of ``texts`` take its layout from the process's kept ones when drawn on
    the report's canvas.

    A string's layout (``Text._get_layout``: its lines' extents, the box
    rotated and aligned) is about a tenth of a millisecond of Python, asked
    for when the text is measured and again when it is drawn; a clip's three
    figures lay out some 250 strings, most of them the same in every clip
    (tick labels, axis labels, legend entries). The layout depends only on
    the string, its font and size, the dpi, the hinting and kerning
    settings, the line spacing, alignments and rotation: on the report's
    renderer (whose measures are kept by the same things) it is kept by
    them. A text that may be mathtext or TeX, or wraps, on any other renderer
    (SVG, PDF), is laid out by matplotlib as always.

    Parameters
    ----------
    texts : iterable of matplotlib.text.Text
        Texts of a figure on the report's canvas.
    """
    from matplotlib.text import Text

    if not callable(getattr(Text, "_get_layout", None)):
        return
    for text in texts:
        if type(text)._get_layout is Text._get_layout and "_get_layout" not in vars(text):
            text._get_layout = _kept_layout(text)


def _kept_layout(text):
    """``text._get_layout``, kept per process for what it depends on (:func:`keep_layouts`)."""
    from matplotlib import rcParams

    def _get_layout(renderer):
        s = text._text
        if (not getattr(renderer, "keeps_layouts", False) or "$" in s or text._usetex
                or text._wrap):
            return type(text)._get_layout(text, renderer)
        key = (s, *_font_key(text._fontproperties), text.figure.dpi,
               renderer.dpi, rcParams["text.hinting"], rcParams["text.hinting_factor"],
               rcParams["text.kerning_factor"], text._linespacing, text._multialignment,
               text._horizontalalignment, text._verticalalignment, text.get_rotation(),
               text._rotation_mode)
        with _MASKS_LOCK:
            hit = _LAYOUTS.get(key)
            if hit is not None:  # a tick label outlives the clips' titles
                _LAYOUTS.move_to_end(key)
        if hit is None:
            hit = type(text)._get_layout(text, renderer)
            with _MASKS_LOCK:
                _LAYOUTS[key] = hit
                while len(_LAYOUTS) > TEXT_CACHE_SIZE:
                    _LAYOUTS.popitem(last=False)
        box, lines, corner = hit
        return box.frozen(), list(lines), corner  # the caller's own box and list

    _get_layout.kept_layout = True  # a copy of the text (a copied tick) gets its own
    _get_layout.__doc__ = "The text's layout (Text._get_layout), kept (canvas.keep_layouts)."
    return _get_layout


#: The parts of a ``Tick`` (``Tick.get_children``).
_TICK_PARTS = ("tick1line", "tick2line", "gridline", "label1", "label2")


def _copy_tick(tick):
    """A copy of ``tick`` whose parts and mutable state are its own."""
    copiers = _state_copiers()
    new = _copied(tick, copiers)
    for name in _TICK_PARTS:
        setattr(new, name, _copied(getattr(tick, name), copiers))
    return new


def _copied(artist, copiers: dict):
    """A copy of ``artist``: its attributes, each mutable one (:func:`_state_copiers`)
    copied; transforms, clip boxes, markers and callbacks to the axes shared, as
    ``Artist.update_from`` shares them (``copy.copy`` would drop the last)."""
    new = object.__new__(type(artist))
    state = new.__dict__
    for name, value in vars(artist).items():
        copier = copiers.get(type(value))
        state[name] = value if copier is None else copier(value)
    if getattr(state.get("_get_layout"), "kept_layout", False):  # bound to the copy
        state["_get_layout"] = _kept_layout(new)
    return new


@cache
def _state_copiers() -> dict:
    """How each mutable kind of attribute a tick's artists hold is copied: callback
    registries new (nothing is connected to a tick's parts), lists, arrays, font
    properties and sticky edges (a named pair of lists) copied."""
    from matplotlib import artist
    from matplotlib.cbook import CallbackRegistry
    from matplotlib.font_manager import FontProperties

    copiers = {CallbackRegistry: lambda _: CallbackRegistry(signals=["pchanged"]),
               list: list, np.ndarray: np.copy, FontProperties: FontProperties.copy}
    pair = getattr(artist, "_XYPair", None)
    if pair is not None:
        copiers[pair] = lambda v: pair(list(v.x), list(v.y))
    return copiers


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def png_bytes(fig: Figure, dpi: int) -> bytes:
    """``fig`` drawn at ``dpi``, as the bytes of a PNG file.

    An opaque figure (every pixel's alpha 255, as the report's are) is
    written as 8-bit RGB, each row ``Sub``-filtered, at zlib level 1, with
    its resolution (``pHYs``) and ``Software`` as matplotlib writes them; a
    figure with any transparency goes through matplotlib and Pillow (RGBA).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : int
        Dots per inch.
    """
    return png_encoder(fig, dpi)()


def png_encoder(fig: Figure, dpi: int) -> Callable[[], bytes]:
    """``fig`` drawn at ``dpi`` now, and what encodes it as :func:`png_bytes` does.

    The drawing is matplotlib's (this thread only); the encoding of an
    opaque figure is NumPy's and zlib's on the pixels drawn, which any thread
    may call while this one draws the next figure (both let other threads
    run). A figure with transparency is encoded at once (through
    matplotlib), and what is returned gives its bytes.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : int
        Dots per inch.
    """
    import matplotlib

    raw = io.BytesIO()
    fig.savefig(raw, format="rgba", dpi=dpi)  # drawn as savefig draws (dpi, face colour)
    width = int(fig.get_figwidth() * dpi)
    rgba = np.frombuffer(raw.getbuffer(), dtype=np.uint8).reshape(-1, width, 4)
    # each pixel a little-endian word: opaque where its top byte (alpha) is 255
    if not (rgba.view("<u4") >= 0xFF000000).all():  # transparency: kept, as RGBA
        out = io.BytesIO()
        fig.savefig(out, format="png", dpi=dpi, pil_kwargs={"compress_level": 1})
        return out.getvalue
    from PIL import Image  # matplotlib's own dependency, loaded with it

    software = f"Matplotlib version{matplotlib.__version__}, https://matplotlib.org/"
    return lambda: _png_of(rgba, dpi, software, Image.frombuffer)


def _png_of(rgba: np.ndarray, dpi: int, software: str, image: Callable) -> bytes:
    """The PNG file of opaque (H, W, 4) pixels: RGB, ``Sub`` filter, zlib level 1, with
    ``software`` (its ``Software``); ``image``: Pillow's ``Image.frombuffer``. Imports
    nothing (called in a thread while another may import)."""
    height, width = rgba.shape[:2]
    # the RGB bytes packed by Pillow (a C loop over the pixels): 2.5 times as fast as
    # gathering them by index with NumPy, itself a third of copying the strided view
    rgb = np.frombuffer(image("RGBA", (width, height), rgba, "raw", "RGBA", 0, 1).tobytes(
        "raw", "RGB"), dtype=np.uint8).reshape(height, width * 3)
    rows = np.empty((height, width * 3 + 1), dtype=np.uint8)
    rows[:, 0] = 1  # Sub: each byte less the one a pixel before it (mod 256)
    rows[:, 1:4] = rgb[:, :3]
    np.subtract(rgb[:, 3:], rgb[:, :-3], out=rows[:, 4:])
    per_metre = int(dpi / 0.0254 + 0.5)
    return b"".join([
        b"\x89PNG\r\n\x1a\n",
        _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)),
        _chunk(b"pHYs", struct.pack(">IIB", per_metre, per_metre, 1)),
        _chunk(b"tEXt", b"Software\0" + software.encode("latin-1")),
        _chunk(b"IDAT", zlib.compress(rows, 1)),
        _chunk(b"IEND", b""),
    ])

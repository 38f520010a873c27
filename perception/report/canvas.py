"""The figures' Agg canvas: strings rendered once per process, figures kept per kind.

Two costs dominate a report's per-clip figures, and neither is the data:

* **Text.** matplotlib 3.11 lays out and renders every string glyph by glyph
  on every draw (about 1 ms a string); a clip's three figures draw some 130
  strings, most of them the same in every clip (tick labels, axis labels,
  legend entries). :func:`new_canvas` gives a figure an Agg canvas whose
  renderer keeps each string's rendered coverage mask (as matplotlib up to
  3.10 drew a string: whole, at a pixel position) and stamps it again in the
  string's colour and angle, so a string is rendered once per process.
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

import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from functools import cache
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
    from matplotlib.figure import Figure

__all__ = ["kept_figure", "new_canvas"]

#: Rendered strings kept per process (a few kB each; a batch uses a few hundred).
TEXT_CACHE_SIZE = 4096
#: Figures kept per thread: one per kind and layout (a repertoire's legend rows, ...).
KEPT_FIGURES = 8

_MASKS: OrderedDict[tuple, tuple[np.ndarray, float, float, float]] = OrderedDict()
_MASKS_LOCK = threading.Lock()
_KEPT = threading.local()


@cache
def _canvas_class() -> type:
    """``FigureCanvasAgg`` whose renderer draws strings from :data:`_MASKS` (built once)."""
    import numpy as np
    from matplotlib import rcParams
    from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg, get_hinting_flag
    from matplotlib.ft2font import FT2Font

    if not hasattr(FT2Font, "draw_glyphs_to_bitmap"):  # a matplotlib without whole strings
        return FigureCanvasAgg

    class _Renderer(RendererAgg):
        def _mask(self, s: str, prop, antialiased: bool) -> tuple:
            """The string's coverage mask and offsets, rendered at the origin, unrotated."""
            key = (s, tuple(prop.get_family()), prop.get_style(), prop.get_variant(),
                   prop.get_weight(), prop.get_stretch(), prop.get_size_in_points(),
                   prop.get_file(), self.dpi, bool(antialiased), rcParams["text.hinting"],
                   rcParams["text.hinting_factor"], rcParams["text.kerning_factor"])
            with _MASKS_LOCK:
                hit = _MASKS.get(key)
                if hit is not None:
                    _MASKS.move_to_end(key)
                    return hit
            font = self._prepare_font(prop)
            font.set_text(s, 0, flags=get_hinting_flag())
            font.draw_glyphs_to_bitmap(antialiased=bool(antialiased))
            xo, yo = font.get_bitmap_offset()
            hit = (np.array(font.get_image(), dtype=np.uint8), xo / 64.0, yo / 64.0,
                   font.get_descent() / 64.0)
            with _MASKS_LOCK:
                _MASKS[key] = hit
                while len(_MASKS) > TEXT_CACHE_SIZE:
                    _MASKS.popitem(last=False)
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
    while len(kept) > KEPT_FIGURES:
        kept.popitem(last=False)
    return fig, axes

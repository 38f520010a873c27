"""A recognize with figures: each string laid out once (issue 45 item 4). Nothing here is
timed (tools/bench_speed.py is)."""

from __future__ import annotations

import numpy as np

from perception.report import canvas


def _figure(texts: list[str]):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3, 2), dpi=100)
    canvas.new_canvas(fig)
    ax = fig.subplots()
    ax.plot(np.arange(5.0), np.arange(5.0) ** 2, label="a line")
    for i, text in enumerate(texts):
        ax.text(0.1, 0.2 * i, text, fontsize=8 + 2 * i, rotation=30 * i)
    ax.set_xlabel("time (s)")
    ax.legend()
    return fig


def test_the_canvas_measures_a_string_as_agg_measures_it():
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.font_manager import FontProperties

    canvas._EXTENTS.clear()  # the first call measures, whatever ran before in this process
    fig = _figure([])
    ours = fig.canvas.get_renderer()
    agg = RendererAgg(300, 200, 100)
    for size in (7, 10.5, 14):
        prop = FontProperties(size=size)
        for s in ("0.5", "time (s)", "Wg jy", "−1.0"):
            expected = agg.get_text_width_height_descent(s, prop, False)
            assert ours.get_text_width_height_descent(s, prop, False) == expected  # laid out
            assert ours.get_text_width_height_descent(s, prop, False) == expected  # kept


def test_a_string_laid_out_once_draws_as_one_laid_out_twice():
    texts = ["grip aperture", "0.25 s", "peak 0.8 m/s"]
    canvas._MASKS.clear()
    canvas._EXTENTS.clear()
    once = canvas.png_bytes(_figure(texts), 100)  # each mask made where it was measured
    canvas._MASKS.clear()  # the extents kept: each mask made where it is drawn
    twice = canvas.png_bytes(_figure(texts), 100)
    assert once == twice
    assert canvas.png_bytes(_figure(texts), 100) == once  # and from the caches

"""perception.report.chart: one figure spec, drawn by Pillow (no matplotlib) or by matplotlib."""

import io
import math
import os
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from perception.report.chart import (
    Band,
    Chart,
    ErrorBars,
    Legend,
    Line,
    Panel,
    layout,
    nice_ticks,
    render_png,
    to_matplotlib,
)

ROOT = Path(__file__).resolve().parents[1]


def _pixels(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def _mask(img: np.ndarray, rgb) -> np.ndarray:
    """Pixels within 60 of colour ``rgb`` in every channel."""
    return (np.abs(img - np.array(rgb)) < 60).all(axis=-1)


def _cross():
    """Red and blue verticals at x = 2 and 8, a green horizontal at y = 5, data 0-10."""
    lines = (Line([2, 2], [0, 10], "r", 1.0), Line([8, 8], [0, 10], "b", 1.0),
             Line([0, 10], [5, 5], "#00ff00", 1.0))
    return Chart((Panel("t", "x", "y", lines),), title="cross", size=(6, 4))


def test_a_line_lands_on_the_pixels_of_its_data_coordinates():
    chart = _cross()
    img = _pixels(render_png(chart, dpi=100))
    geo = layout(chart, dpi=100)[0]
    assert geo.xlim == pytest.approx((-0.5, 10.5)) and geo.ylim == pytest.approx((-0.5, 10.5))
    left, top, right, bottom = geo.box
    col_red, col_blue = geo.pixel([2, 8], [0, 0])[0]
    _, row_green = geo.pixel(0, 5)
    # the transform: 5 % margins, x right and y up
    assert col_red == pytest.approx(left + 2.5 / 11 * (right - left))
    assert row_green == pytest.approx(bottom - 5.5 / 11 * (bottom - top))
    # and the image: a row above the green line, a column between the verticals
    row = round(geo.pixel(0, 7.3)[1])
    red, blue = np.flatnonzero(_mask(img[row], (255, 0, 0))), np.flatnonzero(
        _mask(img[row], (0, 0, 255)))
    assert red.size and blue.size
    assert red.mean() == pytest.approx(col_red, abs=1.0)
    assert blue.mean() == pytest.approx(col_blue, abs=1.0)
    green = np.flatnonzero(_mask(img[:, round((col_red + col_blue) / 2)], (0, 255, 0)))
    assert green.size and green.mean() == pytest.approx(row_green, abs=1.0)
    # the frame is where the layout says, black, with white just outside
    mid = round((top + bottom) / 2)
    assert img[mid, round(left)].max() < 90 and img[mid, round(right)].max() < 90
    assert img[mid, round(right) + 4].min() > 200


def test_colours_are_matplotlibs():
    lines = tuple(Line([0, 1], [k, k], colour, 6.0)
                  for k, colour in enumerate(["C0", "C3", "g", "0.7"]))
    chart = Chart((Panel(lines=lines),), size=(4, 3))
    img, geo = _pixels(render_png(chart, dpi=100)), layout(chart, dpi=100)[0]
    for k, want in enumerate([(0x1F, 0x77, 0xB4), (0xD6, 0x27, 0x28), (0, 128, 0),
                              (178, 178, 178)]):
        col, row = geo.pixel(0.5, k)
        np.testing.assert_allclose(img[round(float(row)), round(float(col))], want, atol=12)


def test_a_chart_refuses_what_it_cannot_draw():
    for make, match in ((lambda: Line([0], [0], "C10"), "colour"),
                        (lambda: Line([0], [0], "purple"), "colour"),
                        (lambda: Line([0], [0], style="-."), "style"),
                        (lambda: Line([0, 1], [0]), "length"),
                        (lambda: Legend("centre"), "location"),
                        (lambda: Legend(columns=0), "column"),
                        (lambda: Chart(()), "panel"),
                        (lambda: Chart((Panel(),), size=(0, 3)), "size"),
                        (lambda: Band([0, 1], [0, 1], [1]), "length"),
                        (lambda: Band([0], [0], [1], alpha=1.5), "alpha"),
                        (lambda: Band([0], [0], [1], "nope"), "colour"),
                        (lambda: ErrorBars([0, 1], [0, 1], [1, -1]), "negative"),
                        (lambda: ErrorBars([0], [0], [1], cap=-1), "cap"),
                        (lambda: Panel(lines=(Band([0], [0], [1]),)), "Line")):
        with pytest.raises(ValueError, match=match):
            make()


@pytest.mark.parametrize("size, dpi", [((12, 5), 120), ((7.5, 3.2), 100), ((3, 3), 72)])
def test_the_png_has_the_requested_size(size, dpi):
    chart = Chart((Panel("a", lines=(Line([0, 1], [0, 1]),)), Panel("b")), "t", size=size)
    png = render_png(chart, dpi=dpi)
    assert png.startswith(b"\x89PNG")
    assert Image.open(io.BytesIO(png)).size == (round(size[0] * dpi), round(size[1] * dpi))


def _is_125(step: float) -> bool:
    mantissa = step / 10 ** math.floor(math.log10(step))
    return any(math.isclose(mantissa, m) for m in (1, 2, 5))


@pytest.mark.parametrize("lo, hi", [(0, 1), (-3.7, 123.4), (0.03, 0.9), (-0.26, 0.06),
                                    (1e-5, 3.3e-5), (-1000.5, -999.2), (-150, 310)])
def test_ticks_step_1_2_5_and_cover_the_range(lo, hi):
    for most in (3, 5, 9):
        ticks = nice_ticks(lo, hi, most)
        step = ticks[1] - ticks[0]
        assert _is_125(step), step
        np.testing.assert_allclose(np.diff(ticks), step)
        assert lo - 1e-12 <= ticks[0] < lo + step and hi - step < ticks[-1] <= hi + 1e-12
        assert len(ticks) - 1 <= most


def test_a_panels_limits_hold_its_data_and_its_ticks_span_them():
    x = np.linspace(-3.7, 123.4, 50)
    y = np.sin(x) * 40 + 17
    chart = Chart((Panel(lines=(Line(x, y),), hlines=(0.0,)),))
    geo = layout(chart)[0]
    assert geo.ylim[0] < 0  # the hline is inside too
    for ticks, lim, data in ((geo.xticks, geo.xlim, x), (geo.yticks, geo.ylim, y)):
        step = ticks[1] - ticks[0]
        assert _is_125(step) and len(ticks) >= 3
        assert lim[0] < data.min() and data.max() < lim[1]
        assert lim[0] <= ticks[0] < lim[0] + step and lim[1] - step < ticks[-1] <= lim[1]


def test_equal_aspect_gives_one_unit_the_same_pixels_both_ways():
    circle = np.linspace(0, 2 * np.pi, 60)
    chart = Chart((Panel(lines=(Line(np.cos(circle), 0.3 * np.sin(circle)),),
                         equal_aspect=True),), size=(8, 4))
    geo = layout(chart)[0]
    left, top, right, bottom = geo.box
    per_x = (geo.xlim[1] - geo.xlim[0]) / (right - left)
    per_y = (geo.ylim[1] - geo.ylim[0]) / (bottom - top)
    assert per_x == pytest.approx(per_y, rel=1e-9)
    assert geo.xlim[0] < -1 and geo.xlim[1] > 1 and geo.ylim[0] < -0.3 and geo.ylim[1] > 0.3


def test_non_finite_values_break_a_line():
    x = np.linspace(0, 10, 101)
    y = np.full_like(x, 5.0)
    y[40:61] = np.nan
    y[80] = np.inf
    lines = (Line(x, y, "r", 2.0), Line([np.nan, np.nan], [np.nan, 1.0], "b", label="none"),
             Line([], [], "k"))
    chart = Chart((Panel(lines=lines, legend=Legend()),), size=(6, 4))
    img, geo = _pixels(render_png(chart, dpi=100)), layout(chart, dpi=100)[0]
    row = round(float(geo.pixel(0, 5)[1]))
    for x_data, drawn in ((2.0, True), (5.0, False), (7.0, True)):
        col = round(float(geo.pixel(x_data, 5)[0]))
        assert _mask(img[row - 1:row + 2, col], (255, 0, 0)).any() == drawn, x_data
    # nothing to draw at all is drawn as empty axes
    empty = render_png(Chart((Panel(lines=(Line([np.nan], [np.nan]),)),)))
    assert Image.open(io.BytesIO(empty)).size == (1440, 600)


def test_names_in_other_scripts_draw_without_warnings():
    name = "日本語-🙂-é-Ωμέγα"
    chart = Chart((Panel(name, name, name, (Line([0, 1], [0, 1], label=name),),
                         legend=Legend("best", title=name)),),
                  title=f"{name}: verdict", legend=Legend(title=name, columns=3))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        png = render_png(chart)
    assert Image.open(io.BytesIO(png)).size == (1440, 600)


@pytest.mark.parametrize("repeat", [5, 30])
def test_a_long_title_is_shrunk_or_cut_to_fit(repeat):
    title = "a very long clip name " * repeat  # shrunk; too long even at 7 pt: cut
    img = _pixels(render_png(Chart((Panel(),), title=title, size=(6, 3)), dpi=100))
    ink = np.flatnonzero((img[:30] < 128).all(axis=2).any(axis=0))
    assert ink.size and ink[0] >= 2 and ink[-1] <= 597  # not cut at the edges
    assert ink[-1] - ink[0] > 400  # and still across most of the figure


def test_a_legend_samples_its_lines_in_the_corner_with_room():
    diagonal = np.linspace(0, 1, 200)
    lines = (Line(diagonal, diagonal, "k", 1.0),  # fills the lower left and upper right
             Line([np.nan, np.nan], [0, 1], "m", 3.0, "--", "sample"))
    for location, corner in (("best", "upper left"), ("lower right", "lower right")):
        chart = Chart((Panel(lines=lines, legend=Legend(location)),), size=(6, 4))
        img, geo = _pixels(render_png(chart, dpi=100)), layout(chart, dpi=100)[0]
        left, top, right, bottom = (round(v) for v in geo.box)
        magenta = np.argwhere(_mask(img, (191, 0, 191)))
        assert magenta.size, location  # only the legend's sample is magenta
        rows, cols = magenta[:, 0], magenta[:, 1]
        upper = rows.max() < (top + bottom) / 2
        lefts = cols.max() < (left + right) / 2
        assert (upper, lefts) == (corner.startswith("upper"), corner.endswith("left"))


def test_to_matplotlib_draws_the_same_axes_and_lines():
    from matplotlib.figure import Figure

    chart = Chart(
        (Panel("a", "x", "y", (Line([0, 1], [0, 1], "C1", 2.6, "--", "one"),
                               Line([0, 1], [1, 0], "0.45", 1.2, ":", "two"),
                               Line([0, 1], [2, 2], "k")), hlines=(0.0,), equal_aspect=True,
               legend=Legend("lower left", columns=2)),
         Panel("b", lines=(Line([0, 1], [0, 1], label="one"),))),
        title="t", legend=Legend(title="shared", columns=2))
    fig = to_matplotlib(chart)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    a, b = fig.axes
    assert [len(ax.lines) for ax in (a, b)] == [4, 1]  # three lines and the hline; one
    assert a.get_title() == "a" and a.get_xlabel() == "x" and a.get_ylabel() == "y"
    assert a.lines[0].get_linestyle() == "--" and a.lines[0].get_linewidth() == 2.6
    assert a.get_aspect() == 1.0 and a.get_legend() is not None and b.get_legend() is None
    assert [t.get_text() for t in a.get_legend().get_texts()] == ["one", "two"]
    (shared,) = fig.legends
    assert [t.get_text() for t in shared.get_texts()] == ["one", "two"]  # one per label
    assert fig.get_suptitle() == "t"


def _blend(under, colour, alpha):
    return (1 - alpha) * np.asarray(under, dtype=float) + alpha * np.asarray(colour, dtype=float)


def test_a_band_fills_between_its_curves_blended_over_what_is_under_it():
    x = np.linspace(0, 10, 101)
    low, high = np.full_like(x, 2.0), np.full_like(x, 6.0)
    low[45:56] = np.nan  # a gap: nothing filled there
    bands = (Band(x, low, high, "b", 0.3),  # blue 2-6, then red 4-8 over it
             Band([0, 10], [4, 4], [8, 8], "r", 0.5))
    chart = Chart((Panel(lines=(Line([9, 9], [0, 10], "k", 1.0),), bands=bands),),
                  size=(6, 4))
    img, geo = _pixels(render_png(chart, dpi=100)), layout(chart, dpi=100)[0]
    col = round(float(geo.pixel(2, 0)[0]))
    blue = _blend((255, 255, 255), (0, 0, 255), 0.3)
    for y, want in ((1, (255, 255, 255)), (3, blue), (5, _blend(blue, (255, 0, 0), 0.5)),
                    (7, _blend((255, 255, 255), (255, 0, 0), 0.5)), (9, (255, 255, 255))):
        row = round(float(geo.pixel(0, y)[1]))
        np.testing.assert_allclose(img[row, col], want, atol=12, err_msg=f"y = {y}")
    # each colour spans the rows between its curves' pixels
    _, (row_2, row_4, row_6, row_8) = geo.pixel([0] * 4, [2, 4, 6, 8])
    for colour, (lo, hi) in ((blue, (row_4, row_2)), (_blend(blue, (255, 0, 0), 0.5),
                                                      (row_6, row_4)),
                             (_blend((255, 255, 255), (255, 0, 0), 0.5), (row_8, row_6))):
        rows = np.flatnonzero(np.abs(img[:, col] - colour).max(axis=1) < 12)
        assert rows.min() == pytest.approx(lo, abs=1.5) and rows.max() == pytest.approx(
            hi, abs=1.5)
    # the line is drawn over the bands, opaque; the gap leaves white
    row, col_line = (round(float(v)) for v in geo.pixel(9, 3)[::-1])
    assert img[row, col_line].max() < 90
    gap = round(float(geo.pixel(5, 0)[0]))
    np.testing.assert_allclose(img[round(float(geo.pixel(0, 3)[1])), gap], (255, 255, 255),
                               atol=12)


def test_error_bars_reach_y_plus_and_minus_err_with_caps_across_their_ends():
    bars = ErrorBars([2, 5, 3.5], [5, 5, 5], [2, 1, np.nan], "r", width=1.0, cap=3.0)
    chart = Chart((Panel(errorbars=(bars,)),), size=(6, 4))
    img, geo = _pixels(render_png(chart, dpi=100)), layout(chart, dpi=100)[0]
    assert geo.ylim == pytest.approx((3 - 0.2, 7 + 0.2))  # the limits hold the bars' ends
    red = _mask(img, (255, 0, 0))
    for x, err in ((2, 2), (5, 1)):
        col = round(float(geo.pixel(x, 0)[0]))
        rows = np.flatnonzero(red[:, col])
        _, (top, bottom) = geo.pixel([x, x], [5 + err, 5 - err])
        assert rows.min() == pytest.approx(top, abs=1.5)
        assert rows.max() == pytest.approx(bottom, abs=1.5)
        for cap_row in (rows.min(), rows.max()):  # a cap: 2 x 3 pt across, centred on the bar
            cols = np.flatnonzero(red[cap_row])
            cols = cols[np.abs(cols - col) < 20]
            assert cols.max() - cols.min() + 1 == pytest.approx(6 / 72 * 100, abs=1.5)
            assert (cols.min() + cols.max()) / 2 == pytest.approx(col, abs=1)
        mid = round(float(geo.pixel(x, 5)[1]))  # between the caps: just the bar
        assert np.flatnonzero(red[mid, col - 10:col + 11]).size <= 2
    # a bar with a non-finite err is left out
    assert not red[:, round(float(geo.pixel(3.5, 0)[0]))].any()


def test_to_matplotlib_fills_bands_and_draws_error_bars():
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_rgba

    chart = Chart((Panel("a", lines=(Line([0, 1], [0, 1], "C1", label="one"),),
                         bands=(Band([0, 1], [-1, 0], [1, 2], "C2", 0.25),),
                         errorbars=(ErrorBars([0, 1], [0, 1], [0.5, 0.2], "C3", 1.5, 4.0),)),))
    (a,) = to_matplotlib(chart).axes
    (fill,) = [c for c in a.collections if isinstance(c, PolyCollection)]
    assert fill.get_alpha() == 0.25
    np.testing.assert_allclose(fill.get_facecolor()[0], to_rgba("C2", 0.25))
    (bars,) = a.containers
    assert bars.has_yerr and not bars.has_xerr and bars.lines[0] is None  # fmt="none"
    caps, (segments,) = bars.lines[1], bars.lines[2]
    assert len(caps) == 2 and all(cap in a.lines for cap in caps)
    assert caps[0].get_markersize() == 8.0  # 2 x capsize
    np.testing.assert_allclose(segments.get_segments()[0], [[0, -0.5], [0, 0.5]])
    assert segments.get_linewidth()[0] == 1.5
    np.testing.assert_allclose(segments.get_color()[0], to_rgba("C3"))
    assert a.get_ylim()[0] <= -1 and a.get_ylim()[1] >= 2  # the band is in the limits


# -- the report's per-clip charts ------------------------------------------------
@pytest.fixture(scope="module")
def rec():
    from _demos import default_repertoire, demo_tracks

    from perception.pipeline import recognize_clip

    return recognize_clip(demo_tracks("normal", 0)[0], default_repertoire(), clip="c")


def test_the_clip_charts_carry_the_figures_content(rec):
    from perception.report import confidence_chart, confidence_figure, paths_chart, paths_figure

    conf = confidence_chart(rec)
    assert conf.title.startswith("c: verdict ") and rec.winner in conf.title
    assert [len(p.lines) for p in conf.panels] == [len(rec.names)] * 2
    for panel in conf.panels:
        assert panel.hlines == (0.0,)
        for line, name, kind in zip(panel.lines, rec.names, rec.kinds):
            assert line.label == name
            assert line.width == (2.6 if name == rec.winner else 1.2)
            assert line.style == ("--" if kind == "reach" else "-")
    np.testing.assert_allclose(conf.panels[0].lines[0].y, rec.confidence[0] * 100)
    paths = paths_chart(rec)
    left, right = paths.panels
    assert left.equal_aspect and rec.reference_model in left.title
    circle = left.lines[-1]
    assert circle.label == "object" and circle.colour == "y"
    np.testing.assert_allclose(np.hypot(circle.x, circle.y), rec.observation.object_diameter / 2)
    assert [ln.style for ln in right.lines] == ["-", "--", ":"]
    for chart, fig in ((conf, confidence_figure(rec)), (paths, paths_figure(rec))):
        assert [len(a.lines) for a in fig.axes] == [len(p.lines) + len(p.hlines)
                                                    for p in chart.panels]
        assert fig.get_suptitle() == chart.title


def test_the_clip_report_draws_its_figures_without_matplotlib(rec, tmp_path):
    saved = tmp_path / "rec.pickle"
    saved.write_bytes(pickle.dumps(rec))
    code = ("import pickle, sys\nfrom pathlib import Path\n"
            "from perception.report.clip import write_clip_report\n"
            f"rec = pickle.loads(Path({str(saved)!r}).read_bytes())\n"
            f"paths = write_clip_report(rec, Path({str(tmp_path)!r}))\n"
            "print('matplotlib' in sys.modules)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT),
                                                        os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=env)
    assert out.stdout.split() == ["False"], out.stdout
    assert out.stderr == ""
    for name, size in (("c.confidence.png", (1440, 600)), ("c.paths.png", (1440, 660))):
        assert Image.open(tmp_path / name).size == size


# -- the batch report's charts ---------------------------------------------------
def _summaries():
    """Five scored clips of three conditions (two of them spare), in memory."""
    from perception.report import ClipSummary

    rng = np.random.default_rng(3)
    out = []
    for k, cond in enumerate(["normal", "normal", "delayed", "odd", "odd"]):
        time = np.linspace(0, 1 + 0.1 * k, 30)
        conf = np.vstack([np.sin(time + k), time * (k + 1)]) * 0.1
        out.append(ClipSummary(f"{cond}-{k}", time, ["m", "r"], ["grasp", "reach"], conf,
                               np.zeros(2), "m", "thesis", transport=conf / 3,
                               aperture=0.05 + 0.01 * rng.standard_normal(time.size)))
    return out, ["normal", "normal", "delayed", "odd", "odd"]


def test_the_batch_charts_carry_the_figures_content():
    from matplotlib.collections import PolyCollection

    from perception.report import (
        aperture_chart,
        aperture_figure,
        condition_chart,
        condition_figure,
        confidence_all_chart,
        confidence_all_figure,
        confidence_single_chart,
        confidence_single_figure,
    )
    from perception.report.conditions import aperture_profiles, condition_profiles
    from perception.report.figures import condition_colour

    recs, conds = _summaries()
    colours = {c: condition_colour(c, conds) for c in conds}
    assert colours == {"normal": "C0", "delayed": "C1", "odd": "C4"}
    # Fig. 5.4d: a line and a band per condition, the model dashed black on a grey band
    prof = aperture_profiles(recs, conds)
    own = pd.DataFrame({"phase": np.linspace(0, 1, 11), "mean": 0.06, "sd": 0.005})
    ap = aperture_chart(prof, own, "m")
    (panel,) = ap.panels
    assert "Fig. 5.4d" in panel.title and panel.ylabel == "grip aperture (cm)"
    assert [ln.label for ln in panel.lines] == ["normal (n=2)", "delayed (n=1)", "odd (n=2)",
                                                "model m"]
    assert [(ln.colour, ln.style) for ln in panel.lines] == [
        ("C0", "-"), ("C1", "-"), ("C4", "-"), ("k", "--")]
    assert [(b.colour, b.alpha) for b in panel.bands] == [
        ("C0", 0.2), ("C1", 0.2), ("C4", 0.2), ("k", 0.12)]
    normal = prof[prof["condition"] == "normal"]
    np.testing.assert_allclose(panel.bands[0].upper, (normal["mean"] + normal["sd"]) * 100)
    np.testing.assert_allclose(panel.bands[0].x, normal["phase"] * 100)
    # Fig. 5.8a and b: one clip per condition, every clip; one legend entry per condition
    single = confidence_single_chart(recs[1:4], conds[1:4], "m")
    assert [ln.label for ln in single.panels[0].lines] == ["normal: normal-1",
                                                           "delayed: delayed-2", "odd: odd-3"]
    every = confidence_all_chart(recs, conds, "m").panels[0]
    assert "every clip (5; Fig. 5.8b)" == every.title and every.hlines == (0.0,)
    assert [ln.label for ln in every.lines] == ["normal", None, "delayed", "odd", None]
    assert every.ylabel == "C of m (cm, weighted)"
    np.testing.assert_allclose(every.lines[3].y, recs[3].confidence[0] * 100)
    # Fig. 5.8c: the total and its two terms, SD bars at 11 points, the legend in the first
    cp = condition_profiles(recs, conds, "m")
    cond = condition_chart(cp, "m")
    assert cond.title == "m's confidence by condition (Fig. 5.8c)"
    assert cond.size == pytest.approx((15.6, 4.8))
    assert [p.title for p in cond.panels] == ["confidence C: mean ± SD",
                                              "transport term: mean ± SD", "grip term: mean ± SD"]
    assert [p.legend is not None for p in cond.panels] == [True, False, False]
    bars = cond.panels[2].errorbars[0]
    normal = cp[cp["condition"] == "normal"]
    assert bars.colour == "C0" and bars.x.size == 11 and bars.cap == 3.0
    np.testing.assert_allclose(bars.err, normal["grip_sd"].to_numpy()[::10] * 100)
    assert cond.panels[0].lines[1].label == "delayed (n=1)"
    # the matplotlib figures draw the same charts
    figs = {"ap": aperture_figure(prof, own, "m"),
            "single": confidence_single_figure(recs[1:4], conds[1:4], "m"),
            "all": confidence_all_figure(recs, conds, "m"), "cond": condition_figure(cp, "m")}
    (a,) = figs["ap"].axes
    assert len([c for c in a.collections if isinstance(c, PolyCollection)]) == 4
    assert [t.get_text() for t in a.get_legend().get_texts()] == [
        ln.label for ln in panel.lines]
    assert [t.get_text() for t in figs["all"].axes[0].get_legend().get_texts()] == [
        "normal", "delayed", "odd"]
    assert figs["single"].axes[0].get_title() == "one clip per condition (Fig. 5.8a)"
    assert [len(ax.containers) for ax in figs["cond"].axes] == [3, 3, 3]
    assert figs["cond"].get_suptitle() == cond.title
    # and Pillow draws them at the figures' sizes
    for chart, size in ((ap, (900, 600)), (single, (900, 600)), (cond, (1872, 576))):
        assert Image.open(io.BytesIO(render_png(chart))).size == size

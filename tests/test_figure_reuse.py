"""Figures that cost little (issue 45 item 3): a clip's figures drawn on a kept figure show
that clip and nothing of the one before, and strings rendered once are drawn as before."""

from __future__ import annotations

import dataclasses
import io
import math
import threading
from pathlib import Path

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks
from PIL import Image

from perception.pipeline import recognize_clip
from perception.recordings import MocapImport, read_reaches, recognize_reach
from perception.report.canvas import kept_figure, new_canvas
from perception.report.clip import clip_outputs, write_clip_report
from perception.report.figures import confidence_figure, paths_figure
from perception.report.kinematics import kinematics_figure

OPTOTRAK = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"
DRAW = {"confidence": confidence_figure, "paths": paths_figure,
        "kinematics": kinematics_figure}


@pytest.fixture(scope="module")
def clips():
    """Video clips (two normal grasps, a delayed one), a mocap reach without a wrist, and
    the first normal clip with its onset, MGA and opening not measured."""
    rep = default_repertoire()
    normal, delayed, normal1 = (recognize_clip(demo_tracks(cond, i)[0], rep, clip=f"{cond}-{i}")
                                for cond, i in (("normal", 0), ("delayed", 0), ("normal", 1)))
    mocap = recognize_reach(read_reaches(OPTOTRAK, MocapImport(rate=85))[0], rep)[0]
    unmeasured = dataclasses.replace(normal, clip="unmeasured")
    unmeasured.__dict__["landmarks"] = (  # the cached property, replaced
        dataclasses.replace(normal.landmarks[0], onset_time=math.nan, mga=math.nan,
                            opening_time=math.nan), None)
    return {"normal": normal, "delayed": delayed, "normal1": normal1, "mocap": mocap,
            "unmeasured": unmeasured}


def _values(x) -> list:
    """Numbers comparable with ``==`` (NaN as a sentinel), to 1e-9."""
    return np.round(np.nan_to_num(np.asarray(x, dtype=float), nan=-12345.0), 9).tolist()


def _content(fig) -> dict:
    """What a figure shows: every line's data and look, patch, text, legend and limit."""
    fig.canvas.draw()  # the limits as drawn (an equal aspect adjusts them)
    shown = {"suptitle": fig.get_suptitle(),
             "legends": [([t.get_text() for t in legend.get_texts()],
                          [h.get_linewidth() for h in legend.legend_handles])
                         for legend in fig.legends]}
    for i, ax in enumerate(fig.axes):
        legend = ax.get_legend()
        shown[i] = {
            "lines": [(line.get_label(), line.get_gid(), line.get_linewidth(),
                       line.get_linestyle(), line.get_marker(), str(line.get_color()),
                       _values(line.get_xydata())) for line in ax.get_lines()],
            "patches": [(type(p).__name__, _values(p.get_extents().bounds))
                        for p in ax.patches],
            "texts": [(t.get_text(), _values(t.get_position()), t.get_gid())
                      for t in ax.texts],
            "labels": (ax.get_title(), ax.get_xlabel(), ax.get_ylabel()),
            "legend": None if legend is None else [t.get_text() for t in legend.get_texts()],
            "limits": _values([*ax.get_xlim(), *ax.get_ylim()]),
        }
    return shown


def _spans_its_data(fig) -> None:
    """Each panel's limits hold its curves and fit them (within margins) in x or y: limits
    found for this figure's data, not left from another's."""
    fig.canvas.draw()
    for ax in fig.axes:
        xy = np.concatenate([line.get_xydata() for line in ax.get_lines()
                             if line.get_transform() == ax.transData])
        xy = xy[np.isfinite(xy).all(axis=1)]
        fits = []
        for k, (lo, hi) in enumerate((ax.get_xlim(), ax.get_ylim())):
            assert lo <= xy[:, k].min() and xy[:, k].max() <= hi
            fits.append(np.ptp(xy[:, k]) >= 0.8 * (hi - lo))
        assert any(fits)


@pytest.mark.parametrize("kind, first, second, same", [
    ("confidence", "normal", "delayed", True),
    ("confidence", "delayed", "normal", True),
    ("paths", "normal", "normal1", True),  # the same reference model
    ("paths", "normal1", "normal", True),
    ("paths", "normal", "delayed", False),  # another model: a figure of its own
    # a wrist not recorded, then one tracked: a figure of its own (one line fewer)
    ("paths", "mocap", "normal", False),
    ("paths", "normal", "mocap", False),
    # kept per the marks drawn (which landmarks were measured) and the transport's point
    ("kinematics", "normal", "normal1", True),
    ("kinematics", "normal", "unmeasured", False),  # every landmark, then some not measured
    ("kinematics", "unmeasured", "delayed", False),
    ("kinematics", "mocap", "normal", False),  # the grip midpoint's speed, then the wrist's
])
def test_a_kept_figure_shows_the_second_clip_and_nothing_of_the_first(clips, kind, first,
                                                                      second, same):
    draw = DRAW[kind]
    a, b = clips[first], clips[second]
    if kind == "paths":  # kept per reference model and wrist
        assert (a.reference_model == b.reference_model) == same or "mocap" in (first, second)
    kept_a = draw(a, reuse=True)
    kept_b = draw(b, reuse=True)
    assert (kept_b is kept_a) == same  # the same Figure, drawn again
    _spans_its_data(kept_b)
    assert _content(kept_b) == _content(draw(b))  # as a new figure of B shows B
    assert _content(kept_b) != _content(draw(a))
    assert b.clip in kept_b.get_suptitle() and a.clip not in kept_b.get_suptitle()


def test_the_confidence_lines_hold_the_second_clips_values(clips):
    a, b = clips["normal"], clips["delayed"]
    confidence_figure(a, reuse=True)
    fig = confidence_figure(b, reuse=True)
    conf, ll = fig.axes
    for ax, values in ((conf, b.confidence * 100), (ll, b.log_likelihood)):
        lines = ax.get_lines()
        assert len(lines) == len(b.names) + 1  # a line per model and y = 0, none left over
        for line, name, want in zip(lines, b.names, values):
            np.testing.assert_array_equal(line.get_xdata(), b.time)
            np.testing.assert_array_equal(line.get_ydata(), want)
            assert line.get_linewidth() == (2.6 if name == b.winner else 1.2)
        # the panel spans B's curves (limits found again, not the last clip's)
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert x0 <= b.time.min() and x1 >= b.time.max()
        assert y0 <= np.nanmin(values) and y1 >= np.nanmax(values)
    (legend,) = fig.legends
    widths = [h.get_linewidth() for h in legend.legend_handles]
    assert widths == [2.6 if name == b.winner else 1.2 for name in b.names]


def test_the_no_wrist_note_leaves_with_its_reach(clips):
    fig = paths_figure(clips["mocap"], reuse=True)
    assert [t for t in fig.axes[0].texts if t.get_gid() == "no-wrist"]
    fig = paths_figure(clips["normal"], reuse=True)
    assert not [t for t in fig.axes[0].texts if t.get_gid() == "no-wrist"]
    assert "wrist observed" in [line.get_label() for line in fig.axes[0].get_lines()]


def test_figures_handed_to_a_caller_are_never_kept(clips):
    rec = clips["normal"]
    for kind, draw in DRAW.items():
        kept = draw(rec, reuse=True)
        mine, again = draw(rec), draw(rec)
        assert mine is not again and kept not in (mine, again), kind
        assert rec.plot(kind) is not kept


def test_a_thread_keeps_its_own_figures():
    def build():
        from matplotlib.figure import Figure

        fig = Figure()
        new_canvas(fig)
        return fig, [fig.add_subplot()]

    here, _ = kept_figure(("test", "thread"), build)
    there = []
    worker = threading.Thread(target=lambda: there.append(kept_figure(("test", "thread"),
                                                                      build)[0]))
    worker.start()
    worker.join()
    assert there[0] is not here
    assert kept_figure(("test", "thread"), build)[0] is here


def test_the_clip_report_writes_each_clips_own_figures(clips, tmp_path):
    for name in ("normal", "delayed"):
        write_clip_report(clips[name], tmp_path)
    for name in ("normal", "delayed"):
        files = clip_outputs(tmp_path, clips[name].clip)
        for key, kind in (("confidence_png", "confidence"), ("paths_png", "paths"),
                          ("kinematics_png", "kinematics")):
            saved = np.asarray(Image.open(files[key]).convert("RGB"), dtype=int)
            buf = io.BytesIO()
            DRAW[kind](clips[name]).savefig(buf, format="png", dpi=120)
            fresh = np.asarray(Image.open(buf).convert("RGB"), dtype=int)
            assert saved.shape == fresh.shape
            # the same figure: the curves pixel for pixel, text within a pixel's antialiasing
            assert (np.abs(saved - fresh).sum(axis=2) > 100).mean() < 0.01, (name, kind)


def _ink(fig) -> np.ndarray:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return np.asarray(Image.open(buf).convert("RGB"), dtype=int)


def test_a_string_rendered_once_is_drawn_in_each_colour_and_angle_it_is_given():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    def figure(canvas):
        fig = Figure(figsize=(3, 2))
        canvas(fig)
        fig.text(0.1, 0.7, "grasp-1.0s", color="red", fontsize=14)
        fig.text(0.1, 0.3, "grasp-1.0s", color="blue", fontsize=14)  # the same string
        fig.text(0.9, 0.5, "grasp-1.0s", color="green", fontsize=14, rotation=90,
                 ha="center", va="center")
        return fig

    cached, plain = _ink(figure(new_canvas)), _ink(figure(FigureCanvasAgg))
    for channel, rows, cols in ((0, slice(0, 100), slice(0, 200)),  # red above
                                (2, slice(100, 200), slice(0, 200)),  # blue below
                                (1, slice(0, 200), slice(230, 300))):  # green, upright
        others = [c for c in range(3) if c != channel]
        inked = ((cached[rows, cols, channel] > 100)
                 & (cached[rows, cols][..., others] < 80).all(axis=-1))
        assert inked.sum() > 50, channel
    # the same text where matplotlib draws it, within a pixel
    for img in (cached, plain):
        assert img.shape == cached.shape
    ys, xs = np.nonzero((cached < 250).any(axis=2))
    yp, xp = np.nonzero((plain < 250).any(axis=2))
    for got, want in ((ys.min(), yp.min()), (ys.max(), yp.max()), (xs.min(), xp.min()),
                      (xs.max(), xp.max())):
        assert abs(int(got) - int(want)) <= 2


def test_a_figure_written_as_png_holds_the_pixels_matplotlib_draws():
    from matplotlib.figure import Figure

    from perception.report.canvas import png_bytes

    fig = Figure(figsize=(3, 2))
    new_canvas(fig)
    ax = fig.add_subplot()
    ax.plot([0, 1, 2], [0, 1, 0.5], color="C3")
    ax.set_title("a clip")
    raw = io.BytesIO()
    fig.savefig(raw, format="rgba", dpi=90)
    drawn = np.frombuffer(raw.getvalue(), dtype=np.uint8).reshape(180, 270, 4)
    png = Image.open(io.BytesIO(png_bytes(fig, 90)))
    assert png.format == "PNG" and png.mode == "RGB" and png.size == (270, 180)
    assert png.info["dpi"] == pytest.approx((90, 90), abs=0.01)
    assert png.info["Software"].startswith("Matplotlib")
    np.testing.assert_array_equal(np.asarray(png), drawn[..., :3])  # lossless, every pixel
    # a figure with transparency keeps it (RGBA, through matplotlib's own writer)
    fig.patch.set_alpha(0.0)
    see_through = Image.open(io.BytesIO(png_bytes(fig, 90)))
    assert see_through.mode == "RGBA" and np.asarray(see_through)[0, 0, 3] == 0


def test_texts_are_measured_and_placed_as_on_matplotlibs_own_canvas(clips):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    for kind, draw in DRAW.items():
        ours, plain = draw(clips["mocap"]), draw(clips["mocap"])
        FigureCanvasAgg(plain)
        boxes = []
        for fig in (ours, plain):
            fig.canvas.draw()
            renderer = fig.canvas.get_renderer()
            texts = [fig._suptitle, *(t for ax in fig.axes for t in (
                ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts,
                *ax.get_xticklabels(), *ax.get_yticklabels()))]
            boxes.append([_values(t.get_window_extent(renderer).bounds) for t in texts])
        assert boxes[0] == boxes[1], kind


def _ticked(keep: str | None):
    """Two panels with curves, on a kept figure (``keep``: its key) or a new one, drawn."""
    from perception.report.figures import _figure

    def build():
        return _figure((8, 4), 2, titled=True)

    fig, axes = kept_figure(("test ticks", keep), build) if keep else build()
    t = np.linspace(0.0, 2.3, 60)
    axes[0].plot(t, 1e3 * np.sin(t))
    axes[1].plot(t, 0.01 * np.cos(3 * t))
    axes[1].tick_params(axis="y", labelsize=7, colors="C3")  # after the first tick
    fig.canvas.draw()
    return fig, axes


def test_ticks_copied_from_the_first_draw_as_matplotlibs_own():
    from perception.report.canvas import png_bytes

    kept, kept_axes = _ticked(keep="copied")
    new, new_axes = _ticked(keep=None)
    for a, b in zip(kept_axes, new_axes):
        for axis_a, axis_b in ((a.xaxis, b.xaxis), (a.yaxis, b.yaxis)):
            assert "get_major_ticks" in vars(axis_a) and "get_major_ticks" not in vars(axis_b)
            ticks_a, ticks_b = axis_a.get_major_ticks(), axis_b.get_major_ticks()
            assert len(ticks_a) == len(ticks_b) > 3
            for ta, tb in zip(ticks_a, ticks_b):
                assert ta.get_loc() == tb.get_loc()
                for part_a, part_b in zip(ta.get_children(), tb.get_children()):
                    assert part_a is not part_b
                    assert type(part_a) is type(part_b)
                    assert part_a.get_visible() == part_b.get_visible()
                for text_a, text_b in ((ta.label1, tb.label1), (ta.label2, tb.label2)):
                    assert text_a.get_text() == text_b.get_text()
                    assert text_a.get_fontsize() == text_b.get_fontsize()
                    assert text_a.get_color() == text_b.get_color()
    assert png_bytes(kept, 100) == png_bytes(new, 100)  # every pixel


def test_a_copied_tick_is_a_tick_of_its_own():
    fig, (ax, _) = _ticked(keep="own")
    first, second, third = ax.yaxis.get_major_ticks()[:3]
    for a, b in ((first, second), (second, third)):
        for part_a, part_b in zip(a.get_children(), b.get_children()):
            assert part_a is not part_b
            assert part_a._callbacks is not part_b._callbacks
        assert a.label1.get_fontproperties() is not b.label1.get_fontproperties()
    second.label1.set_fontsize(20)
    second.tick1line.set_markersize(9)
    second.tick1line.set_xdata([0.5])
    assert first.label1.get_fontsize() == third.label1.get_fontsize() != 20
    assert first.tick1line.get_markersize() == third.tick1line.get_markersize() != 9
    ax.tick_params(axis="y", length=6, labelcolor="C2")  # reaches every tick, copied or not
    for tick in ax.yaxis.get_major_ticks():
        assert tick.tick1line.get_markersize() == 6
        assert tick.label1.get_color() == "C2"


def test_a_kept_axis_updates_its_ticks_afresh_at_each_draw_and_outside_one():
    from perception.report.canvas import png_bytes

    kept, kept_axes = _ticked(keep="afresh")
    new, new_axes = _ticked(keep=None)
    for axes in (kept_axes, new_axes):  # after a draw: other limits, the ticks asked for
        axes[0].set_xlim(-5.0, 17.0)
        axes[1].set_ylim(-0.5, 0.25)
    assert ([t.get_text() for t in kept_axes[0].get_xticklabels()]
            == [t.get_text() for t in new_axes[0].get_xticklabels()])
    assert "−5" in [t.get_text() for t in kept_axes[0].get_xticklabels()]  # a minus sign
    assert png_bytes(kept, 100) == png_bytes(new, 100)  # and drawn again, every pixel
    labels = [t.get_text() for t in kept_axes[1].get_yticklabels()]
    assert labels == [t.get_text() for t in new_axes[1].get_yticklabels()]
    assert "−0.4" in labels  # the new limits' ticks (matplotlib's minus sign)


def _legends(fig_keep: str | None, labels: list[str]):
    """A figure with a legend placed at its best (in a panel) and a titled two-column one
    below the panels, on a kept figure (``fig_keep``: its key) or a new one."""
    from perception.report.figures import _figure, _legend

    def build():
        fig, axes = _figure((8, 4), 2, titled=True, legend_rows=3)
        return fig, axes

    fig, axes = kept_figure(("test legends", fig_keep), build) if fig_keep else build()
    t = np.linspace(0.0, 1.0, 40)
    # colours given, as the report's figures give them (a kept axes' colour cycle goes on)
    lines = [axes[0].plot(t, (k + 1) * t ** (k + 1), color=f"C{k}", label=label)[0]
             for k, label in enumerate(labels)]
    axes[1].plot(t, np.cos(6 * t), color="k")
    _legend(axes[0], lines)  # loc="best": found from the curves
    _legend(fig, lines, "lower center", ncols=2, title="the models", frameon=False)
    return fig, axes


def test_a_legend_laid_out_once_a_draw_is_matplotlibs_own():
    from perception.report.canvas import png_bytes, quicker_legend

    labels = ["grasp-0.5s", "grasp-1.0s", "reach-0.8s"]
    kept, axes = _legends("once", labels)
    for legend in (*kept.legends, axes[0].get_legend()):
        quicker_legend(legend)
        assert "draw" in vars(legend) and "get_bbox" in vars(legend._legend_box)
    new, _ = _legends(None, labels)
    assert png_bytes(kept, 100) == png_bytes(new, 100)  # every pixel
    # outside a draw a legend measures afresh: a longer entry, a wider box
    (legend,) = kept.legends
    renderer = kept.canvas.get_renderer()
    before = legend.get_window_extent(renderer).width
    legend.get_texts()[0].set_text("a much longer model name than before")
    assert legend.get_window_extent(renderer).width > before
    # and a kept figure drawn again with other entries, its new legends laid out once a
    # draw too, shows them as a new one does
    kept, axes = _legends("once", ["one", "two (a longer name)", "three", "four"])
    for legend in (*kept.legends, axes[0].get_legend()):
        quicker_legend(legend)
        assert "draw" in vars(legend)
    new, _ = _legends(None, ["one", "two (a longer name)", "three", "four"])
    assert png_bytes(kept, 100) == png_bytes(new, 100)


def test_a_kept_layout_follows_everything_a_texts_layout_depends_on():
    from matplotlib.figure import Figure
    from matplotlib.text import Text

    from perception.report import canvas
    from perception.report.canvas import keep_layouts

    fig = Figure(figsize=(3, 2))
    new_canvas(fig)
    kept, plain = fig.text(0.5, 0.5, "grasp-1.0s"), fig.text(0.5, 0.5, "grasp-1.0s")
    keep_layouts([kept])
    assert "_get_layout" in vars(kept) and "_get_layout" not in vars(plain)
    renderer = fig.canvas.get_renderer()
    assert renderer.keeps_layouts  # the report's renderer: layouts are kept
    canvas._LAYOUTS.clear()
    kept._get_layout(renderer)
    assert len(canvas._LAYOUTS) == 1  # laid out once, kept
    (key,) = canvas._LAYOUTS
    canvas._LAYOUTS[key] = (canvas._LAYOUTS[key][0], ["marker"], canvas._LAYOUTS[key][2])
    assert kept._get_layout(renderer)[1] == ["marker"]  # and taken from there
    canvas._LAYOUTS.clear()
    changes = [("text", "two\nlines"), ("fontsize", 14), ("rotation", 30),
               ("ha", "right"), ("va", "top"), ("linespacing", 2.0),
               ("multialignment", "center"), ("rotation_mode", "anchor"),
               ("fontweight", "bold"), ("fontfamily", "monospace"), ("text", "pay $5")]
    seen = set()
    for name, value in changes:
        for text in (kept, plain):
            text.set(**{name: value})
        box, lines, corner = kept._get_layout(renderer)
        want_box, want_lines, want_corner = Text._get_layout(plain, renderer)
        assert (box.bounds, lines, corner) == (want_box.bounds, want_lines, want_corner), name
        seen.add(repr((box.bounds, lines, corner)))
        box.x0 = -1e6  # the caller's own box: the next layout is not moved
        assert kept._get_layout(renderer)[0].bounds == want_box.bounds
    assert len(seen) == len(changes)  # each change moved the layout: each was followed
    # on another renderer (a vector format), matplotlib's own layout
    for fmt in ("svg", "pdf"):
        fig.savefig(io.BytesIO(), format=fmt)


def test_a_kinematics_figure_moved_to_another_trial_is_drawn_as_a_new_one(clips):
    from perception.report.canvas import png_bytes

    mocap = [recognize_reach(r, default_repertoire())[0]
             for r in read_reaches(OPTOTRAK, MocapImport(rate=85))[1:3]]
    trials = [clips[n] for n in ("normal", "normal1", "delayed", "unmeasured", "mocap",
                                 "normal")] + mocap
    figures = []
    for rec in trials:
        kept = kinematics_figure(rec, reuse=True)
        figures.append(kept)
        assert png_bytes(kept, 80) == png_bytes(kinematics_figure(rec), 80), rec.clip
        assert rec.clip in kept.get_suptitle()
    # the same marks measured: the same figure, its artists moved (not drawn afresh)
    assert figures[1] is figures[0] and figures[5] is figures[0]
    assert figures[3] is not figures[0]  # onset, MGA and opening not measured: its own

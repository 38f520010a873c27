"""perception.report.figures: the report's matplotlib figures, read back from their axes."""

import io
import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]


def _xy(line) -> tuple[np.ndarray, np.ndarray]:
    xy = line.get_xydata()
    return xy[:, 0], xy[:, 1]


def _legend_texts(legend) -> list[str]:
    return [t.get_text() for t in legend.get_texts()]


# -- one clip ---------------------------------------------------------------------
@pytest.fixture(scope="module")
def rec():
    from _demos import default_repertoire, demo_tracks

    from perception.pipeline import recognize_clip

    return recognize_clip(demo_tracks("normal", 0)[0], default_repertoire(), clip="c")


def test_the_confidence_figure_draws_every_models_confidence_and_likelihood(rec):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from perception.report import confidence_figure

    fig = confidence_figure(rec)
    # an Agg canvas (the report's, which renders each string once), never pyplot's
    assert isinstance(fig, Figure) and isinstance(fig.canvas, FigureCanvasAgg)
    assert fig.get_suptitle().startswith("c: verdict ") and rec.winner in fig.get_suptitle()
    conf, ll = fig.axes
    assert conf.get_ylabel() == "C (cm, weighted)" and ll.get_ylabel() == "log-likelihood"
    for ax, values in ((conf, rec.confidence * 100), (ll, rec.log_likelihood)):
        lines = ax.get_lines()
        assert len(lines) == len(rec.names) + 1  # a line per model, and y = 0
        for line, name, kind, want in zip(lines, rec.names, rec.kinds, values):
            x, y = _xy(line)
            np.testing.assert_allclose(x, rec.time)
            np.testing.assert_allclose(y, want)
            assert line.get_label() == name
            assert line.get_linewidth() == (2.6 if name == rec.winner else 1.2)
            assert line.get_linestyle() == ("--" if kind == "reach" else "-")
        np.testing.assert_allclose(_xy(lines[-1])[1], 0.0)  # the zero line
    # one legend below both panels, an entry per model
    (legend,) = fig.legends
    assert _legend_texts(legend) == list(rec.names)
    assert legend.get_title().get_text().startswith("grasp models solid, reach dashed")
    # the legend and the panels' labels fit in the figure, and do not overlap
    renderer = fig.canvas.get_renderer()
    box = legend.get_window_extent(renderer)
    assert box.y0 >= 0 and box.x0 >= 0 and box.x1 <= fig.bbox.x1
    assert box.y1 < min(ax.get_tightbbox(renderer).y0 for ax in fig.axes)
    assert all(ax.get_tightbbox(renderer).x0 >= 0 for ax in fig.axes)


def test_the_paths_figure_draws_the_demonstration_against_the_models_own(rec):
    from perception.report import paths_figure

    fig = paths_figure(rec)
    left, right = fig.axes
    model = rec.reference_model
    assert model in left.get_title() and left.get_aspect() == 1.0
    lines = left.get_lines()
    assert [ln.get_label() for ln in lines] == [
        "finger observed", f"finger, {model}", "thumb observed", f"thumb, {model}",
        "wrist observed", f"wrist, {model}", "object"]
    # the movement as it was scored, at the repertoire's scale where the model's own is
    np.testing.assert_allclose(lines[0].get_xydata(), rec.scored_movement.finger)
    np.testing.assert_allclose(lines[3].get_xydata(), rec.nominal(model)["thumb"])
    x, y = _xy(lines[-1])
    np.testing.assert_allclose(np.hypot(x, y), rec.scored_movement.object_diameter / 2)
    assert _legend_texts(left.get_legend()) == [ln.get_label() for ln in lines]
    grip = right.get_lines()
    assert [ln.get_linestyle() for ln in grip] == ["-", "--", ":"]
    np.testing.assert_allclose(_xy(grip[0])[1], rec.scored_movement.g * 100)
    i = rec.names.index(model)
    np.testing.assert_allclose(_xy(grip[2])[1], rec.predicted_g[i] * 100)
    # another model on request
    other = next(n for n, k in zip(rec.names, rec.kinds) if k == "grasp" and n != model)
    assert other in paths_figure(rec, other).axes[0].get_title()


def test_a_recognition_plots_itself(rec):
    fig = rec.plot()
    assert [ax.get_title() for ax in fig.axes] == [
        "thesis rule: confidence C (eqs. 5.6-5.8)", "likelihood rule: cumulative log-likelihood"]
    assert "paths" in rec.plot("paths").axes[0].get_title()
    with pytest.raises(ValueError, match="kind must be one of"):
        rec.plot("speed")
    png = io.BytesIO()
    fig.savefig(png, format="png", dpi=50)
    assert Image.open(png).size == (600, 250)


@pytest.mark.filterwarnings("ignore:Glyph .* missing from:UserWarning")
@pytest.mark.parametrize("name", ["حركة", "握る", "cost $\\x$ and $y", "a\nb",
                                  os.fsdecode(b"clip\xff")])
def test_any_clip_name_is_drawn_as_it_is(rec, name):
    """A ``$`` is text, not mathtext (``$\\x$`` would fail to draw); bytes that were not
    UTF-8 and control characters are escaped; other scripts draw (boxes where the font
    lacks a glyph)."""
    import dataclasses

    from perception.io.names import printable
    from perception.report import confidence_figure

    fig = confidence_figure(dataclasses.replace(rec, clip=name))
    title = fig.texts[0]
    assert title.get_text().startswith(f"{printable(name)}: ")
    fig.savefig(io.BytesIO(), format="png")  # draws without an error


def test_writing_a_clip_report_draws_its_two_figures(rec, tmp_path):
    """In a fresh process: the figures are whole PNGs at 120 dpi; ``import perception``
    and ``write_clip_report(figures=False)`` never import matplotlib."""
    saved = tmp_path / "rec.pickle"
    saved.write_bytes(pickle.dumps(rec))
    code = ("import pickle, sys\nfrom pathlib import Path\nimport perception\n"
            "from perception.report.clip import write_clip_report\n"
            f"rec = pickle.loads(Path({str(saved)!r}).read_bytes())\n"
            f"write_clip_report(rec, Path({str(tmp_path / 'none')!r}), figures=False)\n"
            "print('matplotlib' in sys.modules)\n"
            f"write_clip_report(rec, Path({str(tmp_path)!r}))\n"
            "print('matplotlib' in sys.modules, 'matplotlib.pyplot' in sys.modules)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT),
                                                        os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=env)
    assert out.stdout.split() == ["False", "True", "False"], out.stdout
    assert out.stderr == ""
    for name, size in (("c.confidence.png", (1440, 600)), ("c.paths.png", (1440, 660))):
        with Image.open(tmp_path / name) as png:
            assert (png.format, png.size) == ("PNG", size)
    assert not [p for p in tmp_path.iterdir() if ".part" in p.name]
    assert not list((tmp_path / "none").glob("*.png"))


def test_figure_files_are_the_files_write_figure_writes(rec, tmp_path):
    from perception.report.figures import (
        FigureFiles,
        confidence_figure,
        paths_figure,
        write_figure,
    )

    figs = {"conf": confidence_figure(rec), "paths": paths_figure(rec)}
    see_through = paths_figure(rec)
    see_through.patch.set_alpha(0.0)  # encoded at once, through matplotlib (RGBA)
    figs["clear"] = see_through
    with FigureFiles("png", 90) as files:
        written = [files.write(fig, tmp_path / f"{name}.x") for name, fig in figs.items()]
        # a PNG is written once the next figure is drawn; the last when the block ends
        assert [p.name for p in written] == ["conf.x.png", "paths.x.png", "clear.x.png"]
        assert (tmp_path / "conf.x.png").exists()
    for name, fig in figs.items():
        want = write_figure(fig, tmp_path / f"{name}.want", "png", 90).read_bytes()
        assert (tmp_path / f"{name}.x.png").read_bytes() == want, name
    with Image.open(tmp_path / "clear.x.png") as png:
        assert png.mode == "RGBA"
    with FigureFiles("svg", 90) as files:
        svg = files.write(figs["conf"], tmp_path / "conf")
    assert svg.read_bytes().lstrip().startswith(b"<?xml")
    with pytest.raises(ValueError, match="figure format"):
        FigureFiles("jpg", 90)
    with pytest.raises(ValueError, match="dpi"):
        FigureFiles("png", 0)


def test_figure_files_raise_an_encoding_error_and_write_nothing_after_one(rec, tmp_path,
                                                                        monkeypatch):
    from perception.report import canvas
    from perception.report.figures import FigureFiles, confidence_figure

    def broken(*args):
        raise MemoryError("no room to encode")

    monkeypatch.setattr(canvas, "_png_of", broken)
    files = FigureFiles("png", 50)
    files.write(confidence_figure(rec), tmp_path / "a")
    with pytest.raises(MemoryError, match="no room"):
        files.close()  # raised in the caller's thread
    assert not list(tmp_path.iterdir())
    with pytest.raises(RuntimeError, match="drawing failed"), FigureFiles("png", 50) as files:
        files.write(confidence_figure(rec), tmp_path / "b")
        raise RuntimeError("drawing failed")
    assert not list(tmp_path.iterdir())  # the pending figure is not written after an error


# -- a batch ----------------------------------------------------------------------
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


def test_conditions_keep_their_colours():
    from perception.report.figures import condition_colour

    conds = ["normal", "odd", "delayed", "other", "odd"]
    assert [condition_colour(c, conds) for c in conds] == ["C0", "C4", "C1", "C5", "C4"]


def test_the_aperture_figure_draws_each_conditions_mean_over_its_sd_band():
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_rgba

    from perception.report import aperture_figure
    from perception.report.conditions import aperture_profiles

    recs, conds = _summaries()
    prof = aperture_profiles(recs, conds)
    own = pd.DataFrame({"phase": np.linspace(0, 1, 11), "mean": 0.06, "sd": 0.005})
    (ax,) = aperture_figure(prof, own, "m").axes
    # the thesis's figure number (5.4d) is in report.html's caption, not the title
    assert ax.get_title() == "grip aperture, mean ± SD"
    assert ax.get_ylabel() == "grip aperture (cm)"
    lines = ax.get_lines()
    assert _legend_texts(ax.get_legend()) == ["normal (n=2)", "delayed (n=1)", "odd (n=2)",
                                              "model m"]
    assert [(ln.get_color(), ln.get_linestyle()) for ln in lines] == [
        ("C0", "-"), ("C1", "-"), ("C4", "-"), ("k", "--")]
    normal = prof[prof["condition"] == "normal"]
    x, y = _xy(lines[0])
    np.testing.assert_allclose(x, normal["phase"] * 100)
    np.testing.assert_allclose(y, normal["mean"] * 100)
    bands = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert [b.get_alpha() for b in bands] == [0.2, 0.2, 0.2, 0.12]
    np.testing.assert_allclose(bands[3].get_facecolor()[0], to_rgba("k", 0.12))
    # the band spans mean ± SD: its outline reaches both
    top = bands[0].get_paths()[0].vertices[:, 1]
    np.testing.assert_allclose(top.max(), ((normal["mean"] + normal["sd"]) * 100).max())
    np.testing.assert_allclose(top.min(), ((normal["mean"] - normal["sd"]) * 100).min())
    assert ax.get_ylim()[1] >= top.max()  # the band is inside the limits


def test_the_confidence_figures_of_a_batch_draw_one_clip_per_condition_and_every_clip():
    from matplotlib.colors import to_rgba

    from perception.report import confidence_all_figure, confidence_single_figure

    recs, conds = _summaries()
    (single,) = confidence_single_figure(recs[1:4], conds[1:4], "m").axes
    assert single.get_title() == "one clip per condition"
    assert _legend_texts(single.get_legend()) == ["normal: normal-1", "delayed: delayed-2",
                                                  "odd: odd-3"]
    (every,) = confidence_all_figure(recs, conds, "m").axes
    assert every.get_title() == "every clip (5)"
    assert every.get_ylabel() == "C of m (cm, weighted)"
    assert _legend_texts(every.get_legend()) == ["normal", "delayed", "odd"]  # once each
    (clips,) = every.collections  # a line a clip, in the clips' order
    assert len(every.get_lines()) == 1  # y = 0
    segments = clips.get_segments()
    assert len(segments) == 5
    np.testing.assert_allclose(clips.get_colors(), [to_rgba(c) for c in
                                                    ("C0", "C0", "C1", "C4", "C4")])
    np.testing.assert_allclose(segments[3][:, 0], recs[3].time)
    np.testing.assert_allclose(segments[3][:, 1], recs[3].confidence[0] * 100)
    lo, hi = every.get_ylim()  # every line inside the limits
    assert lo <= min(s[:, 1].min() for s in segments) and hi >= max(s[:, 1].max()
                                                                   for s in segments)
    # a name matplotlib would leave out of a legend (a leading "_") is in it
    hidden = ["_odd" if c == "odd" else c for c in conds]
    (every,) = confidence_all_figure(recs, hidden, "m").axes
    assert _legend_texts(every.get_legend()) == ["normal", "delayed", "_odd"]


def test_the_condition_figure_draws_mean_and_sd_bars_of_the_total_and_its_terms():
    from perception.report import condition_figure
    from perception.report.conditions import condition_profiles

    recs, conds = _summaries()
    prof = condition_profiles(recs, conds, "m")
    fig = condition_figure(prof, "m")
    assert fig.get_suptitle() == "m's confidence by condition"
    assert tuple(fig.get_size_inches()) == pytest.approx((15.6, 4.8))
    assert [ax.get_title() for ax in fig.axes] == [
        "confidence C: mean ± SD", "transport term: mean ± SD", "grip term: mean ± SD"]
    assert [ax.get_legend() is not None for ax in fig.axes] == [True, False, False]
    assert _legend_texts(fig.axes[0].get_legend())[1] == "delayed (n=1)"
    grip = fig.axes[2]
    assert len(grip.containers) == 3  # SD bars per condition
    normal = prof[prof["condition"] == "normal"]
    np.testing.assert_allclose(_xy(grip.get_lines()[0])[1], normal["grip_mean"] * 100)
    bars = grip.containers[0]
    (segments,) = bars.lines[2]
    ends = np.array(segments.get_segments())  # (11, 2 ends, x y)
    assert len(ends) == 11
    at = np.round(np.linspace(0, len(normal) - 1, 11)).astype(int)
    mean, sd = normal["grip_mean"].to_numpy()[at], normal["grip_sd"].to_numpy()[at]
    np.testing.assert_allclose(ends[:, 1, 1] - ends[:, 0, 1], 2 * sd * 100)
    np.testing.assert_allclose(ends[:, :, 1].mean(axis=1), mean * 100)
    # without the terms, one panel
    one = prof[["condition", "phase", "mean", "sd", "n"]]
    assert len(condition_figure(one, "m").axes) == 1

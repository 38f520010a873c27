"""A recognize with figures: matplotlib imported while the clip is scored, each string
laid out once (issue 45 item 4). Nothing here is timed (tools/bench_speed.py is)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

import hammer_mv.cli.recognize as recognize
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


@pytest.fixture
def figure_thread():
    def joined():
        for thread in threading.enumerate():
            if thread.name == recognize.FIGURE_THREAD:
                thread.join(60)
        return [t for t in threading.enumerate() if t.name == recognize.FIGURE_THREAD]
    return joined


def test_the_figure_imports_run_in_a_thread_that_fails_silently(monkeypatch, capsys,
                                                                 figure_thread):
    monkeypatch.setattr(recognize, "FIGURE_MODULES", ("json", "no_such_module_of_hammer_mv"))
    recognize._import_figures_meanwhile()
    assert figure_thread() == []
    assert capsys.readouterr().err == ""  # said again where the figures are drawn


def test_no_figure_thread_once_the_figure_modules_are_imported(monkeypatch):
    monkeypatch.setattr(recognize, "FIGURE_MODULES", ("json",))
    started = []
    monkeypatch.setattr(threading.Thread, "start", lambda self: started.append(self))
    recognize._import_figures_meanwhile()
    assert started == []


def test_recognize_with_figures_imports_them_meanwhile_and_draws_them(tmp_path):
    import subprocess
    import sys

    from perception.synthetic.demos import demo_tracks

    tracks = demo_tracks("normal", 0)[0].save(tmp_path / "clip.tracks.h5")
    code = ("import sys, threading\n"
            "import hammer_mv.cli.recognize as r\n"
            "started = []\n"
            "start = threading.Thread.start\n"
            "def spy(self):\n"
            "    started.append(self.name)\n"
            "    start(self)\n"
            "threading.Thread.start = spy\n"
            "from hammer_mv.cli import main\n"
            f"main(['recognize', {str(tracks)!r}, '-o', {str(tmp_path / 'out')!r}, "
            "'--quiet'])\n"
            "print(r.FIGURE_THREAD in started)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split()[-1:] == ["True"]
    assert sorted(p.name for p in (tmp_path / "out").glob("*.png")) == [
        "clip.confidence.png", "clip.kinematics.png", "clip.paths.png"]

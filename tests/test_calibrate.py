"""Calibrate a setup once (colour models, marker sizes) and track with --setup."""

import subprocess
import sys

import cv2
import numpy as np
import pytest
from _cli import hammer_here
from _clips import errors, render

from perception.errors import InputError
from perception.synthetic.scene import Distractor, Scene
from perception.tracking.setup import TrackingSetup, calibrate, load_setup, write_setup


def hammer(*args):
    """``hammer-mv *args`` as a subprocess: for what the process shows (exit status 2 in one
    line); the lines and files of a command are tested in-process (:func:`hammer_here`)."""
    return subprocess.run([sys.executable, "-m", "hammer_mv", *map(str, args)],
                          capture_output=True, text=True)


def _frames(video, n=5):
    cap = cv2.VideoCapture(str(video))
    return [cap.read()[1] for _ in range(n)]


def test_calibration_learns_the_markers_sizes_and_colours(tmp_path):
    clip, cam = render(tmp_path, n=8, width=640, height=480, angle=0.0,
                       scene=Scene.reach_to_grasp(8, 30, onset=1.0), marker_diameter=0.012)
    setup = calibrate(_frames(clip.video), source="clip")
    p = setup.params
    assert p.marker_diameter == pytest.approx(0.012, rel=0.12)  # the rendered discs
    assert p.band_size[0] == pytest.approx(0.07, rel=0.12)
    assert p.band_size[1] == pytest.approx(0.025, rel=0.2)
    for m in setup.markers:  # the learned gate still takes the marker's own colour
        assert m.matches(m.bgr), m.name
    # round trip through the file
    path = write_setup(tmp_path / "setup.toml", setup)
    back = load_setup(path)
    assert back.markers.to_dict() == setup.markers.to_dict()
    assert back.params.band_size == pytest.approx(setup.params.band_size, abs=1e-6)
    assert back.params.marker_diameter == pytest.approx(p.marker_diameter, abs=1e-6)
    assert back.source == "clip" and back.frames == 5


def test_setup_file_refuses_unknown_tables_and_keys_naming_the_nearest(tmp_path):
    bad = tmp_path / "bad.toml"
    for text, hint in [("[sizs]\n", "'sizes'"), ("[sizes]\nmarker_diameterr = 0.01\n",
                                                  "'marker_diameter'"),
                       ("[markers.thumb]\nsat_mn = 100\n", "'sat_min'"),
                       ("[markers.thum]\nsat_min = 100\n", "'thumb'"),
                       ("[tracker]\nsize_tolerence = 2\n", "'size_tolerance'")]:
        bad.write_text(text)
        with pytest.raises(InputError, match=f"did you mean {hint}"):
            load_setup(bad)
    bad.write_text("[sizes]\nmarker_diameter = -1\n")
    with pytest.raises(InputError, match="marker_diameter"):
        load_setup(bad)
    with pytest.raises(InputError, match="not found"):
        load_setup(tmp_path / "none.toml")
    assert TrackingSetup().to_dict()["sizes"]["object_diameter"] == 0.1


def test_calibrate_then_track_with_setup_round_trip(tmp_path, capsys):
    """A session: calibrate on one clip, track another clip of the setup with --setup."""
    scene = Scene.reach_to_grasp(30, 30, onset=0.3, duration=0.6)
    one, _ = render(tmp_path, "one.mp4", n=30, width=480, height=360, scene=scene, hand=True,
                    noise_sd=3.0)
    two, _ = render(tmp_path, "two.mp4", n=30, width=480, height=360, scene=scene, hand=True,
                    noise_sd=3.0, seed=5, angle=-10.0)
    setup = tmp_path / "setup.toml"
    proc = hammer_here(capsys, "calibrate", one.video, "-o", setup)
    assert proc.returncode == 0, proc.stderr
    assert "marker diameter" in proc.stdout and setup.exists()
    out = tmp_path / "two.tracks.h5"
    proc = hammer_here(capsys, "track", two.video, "-o", out, "--setup", setup)
    assert proc.returncode == 0, proc.stderr
    from perception.io.tracks import Tracks

    tracks, truth = Tracks.load(out), Tracks.load(two.truth)
    err = errors(tracks, truth)
    assert np.median(err[:, :3]) < 1.0 and np.isfinite(err).all()
    # the setup's colours are the ones used
    assert load_setup(setup).markers.to_json() == tracks.tracker["colour_models"]
    bad = tmp_path / "bad.toml"
    bad.write_text("[sizes]\nband_sise = [0.07, 0.025]\n")
    proc = hammer("track", two.video, "-o", tmp_path / "x.h5", "--setup", bad)
    assert proc.returncode == 2 and "did you mean 'band_size'" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and not (tmp_path / "x.h5").exists()


def test_calibrate_refuses_an_ambiguous_marker_and_a_roi_settles_it(tmp_path, capsys):
    scene = Scene.reach_to_grasp(8, 30, onset=1.0)
    twin = scene.thumb[0] + (0.026, 0.0)
    clip, _ = render(tmp_path, n=8, width=320, height=240, angle=0.0, scene=scene,
                     distractors=(Distractor("thumb", tuple(twin)),))
    out = tmp_path / "setup.toml"
    proc = hammer_here(capsys, "calibrate", clip.video, "-o", out)
    assert proc.returncode == 2 and "thumb" in proc.stderr and "--roi thumb" in proc.stderr
    assert not out.exists()
    from perception.io.tracks import Tracks

    truth = Tracks.load(clip.truth)
    x, y = truth.position[0, truth.index("thumb")]
    proc = hammer_here(capsys, "calibrate", clip.video, "-o", out, "--roi", "thumb", int(x) - 8,
                       int(y) - 8, 16, 16)
    assert proc.returncode == 0, proc.stderr
    assert out.exists()

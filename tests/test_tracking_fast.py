"""Fast grasps filmed with motion blur: both digits kept, never confidently wrong.

A 0.5 s grasp at 30 frames/s moves a digit marker 20-35 px a frame; with a
1/30 s shutter it is a streak whose colour is a mix of the marker's and the
skin's or table's (``perception.tracking.blur``). Ground truth is the
renderer's (the marker's centre at the middle of the exposure).
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import cv2
import h5py
import numpy as np
import pytest

from perception.io.tracks import Tracks
from perception.synthetic.render import render_clip
from perception.synthetic.scene import Occlusion, Scene
from perception.tracking.blur import StreakGate, blur_gate, streak_mass
from perception.tracking.markers import default_markers
from perception.tracking.measurement import streak_centre
from perception.tracking.video_tracks import track_video

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import evaluate_fast_tracking as fast  # noqa: E402


def _track(clip, tmp_path: Path, name: str):
    scene = Scene(wrist=clip.paths["wrist"], finger=clip.paths["finger"],
                  thumb=clip.paths["thumb"], object_diameter=clip.object_size)
    res = render_clip(scene, clip.camera, clip.style, tmp_path / f"{name}.mp4", seed=7)
    tracks = Tracks.load(track_video(res.video, tmp_path / f"{name}.tracks.h5"))
    with h5py.File(res.truth, "r") as f:
        visible = f["truth/visible"][()]
    return tracks, Tracks.load(res.truth), visible


@pytest.mark.parametrize("k", [12, 6])
def test_a_blurred_half_second_grasp_keeps_both_digits(tmp_path, k):
    # Clips of the fast population whose finger the colour gate alone lost
    # for 40-70 % of the movement (the streak's hue left the finger's range).
    clip = fast.population_clip(k, 30.0, 1 / 30, (0.5, 0.5))
    tracks, truth, visible = _track(clip, tmp_path, "fast")
    s = fast.score(tracks, truth, slice(clip.onset, clip.end), visible=visible)
    assert s["both"] >= 0.9, s
    assert max(s["wrong"].values()) == 0.0, s


def test_a_digit_hidden_while_fast_is_reported_lost_not_placed(tmp_path):
    clip = fast.population_clip(12, 30.0, 1 / 30, (0.5, 0.5))
    hidden = range(clip.onset + 4, clip.onset + 8)  # the fastest frames
    style = dataclasses.replace(clip.style, occlusions=(
        Occlusion(marker="finger", start=hidden.start, stop=hidden.stop),))
    tracks, truth, visible = _track(dataclasses.replace(clip, style=style), tmp_path, "hidden")
    j = tracks.markers.index("finger")
    assert not visible[hidden.start:hidden.stop, truth.markers.index("finger")].any()
    sure = tracks.likelihood[hidden.start:hidden.stop, j] >= 0.5
    assert not sure.any(), tracks.position[hidden.start:hidden.stop, j]
    s = fast.score(tracks, truth, slice(clip.onset, clip.end), visible=visible)
    assert max(s["wrong"].values()) == 0.0, s
    # and found again once shown
    err = np.linalg.norm(tracks.position[hidden.stop + 2:clip.end, j]
                         - truth.position[hidden.stop + 2:clip.end, j], axis=-1)
    assert np.nanmax(err) <= 5.0, err


def test_an_ordinary_grasp_is_tracked_as_precisely_as_before(tmp_path):
    # 1.2 s at 30 frames/s with a 1/60 s shutter: the digits move at most
    # about a marker's width a frame, and every frame is within 1.5 px.
    clip = fast.population_clip(0, 30.0, 1 / 60, (1.2, 1.2))
    tracks, truth, visible = _track(clip, tmp_path, "slow")
    s = fast.score(tracks, truth, slice(clip.onset, clip.end), tolerance=1.5,
                   visible=visible)
    assert s["both"] == 1.0, s


def test_the_centre_of_a_streak_is_its_middle_whatever_clings_to_one_side():
    mask = np.zeros((40, 80), np.uint8)
    cv2.line(mask, (20, 20), (60, 20), 255, 9)  # a streak centred on (40, 20)
    mask[24:30, 20:40] = 255  # a skirt of colour along its trailing half
    x, y = streak_centre(mask, (1.0, 0.0))
    assert abs(x - 40.0) <= 1.0 and abs(y - 20.0) <= 1.0
    mo = cv2.moments(mask, True)
    assert mo["m10"] / mo["m00"] < 39.0  # the centroid leans toward the skirt


def test_the_blur_gate_is_as_loose_as_the_scene_allows():
    thumb = default_markers()["thumb"]
    rest = np.full((120, 160, 3), (140, 160, 178), np.uint8)  # the table
    cv2.circle(rest, (40, 60), 6, thumb.bgr, -1)
    box, mass = (33, 53, 15, 15), float(np.pi * 36)
    hsv = cv2.cvtColor(rest, cv2.COLOR_BGR2HSV)
    loose = blur_gate(thumb, hsv, box, mass, 0.3)
    assert loose is not None and loose.sat_min < thumb.sat_min
    assert loose.hue != thumb.hue  # widened in hue too
    # an orange thing (a red marker's hue mixed with skin) far away: the hue stays
    cv2.circle(rest, (130, 60), 8, (60, 110, 220), -1)
    tight = blur_gate(thumb, cv2.cvtColor(rest, cv2.COLOR_BGR2HSV), box, mass, 0.3)
    assert tight is not None and tight.hue == thumb.hue


def test_a_streak_gate_takes_a_washed_out_streak_and_not_the_skin():
    finger = default_markers()["finger"]
    skin = np.full((40, 40, 3), (120, 150, 215), np.float32)
    marker = np.array(finger.bgr, np.float32)
    region = skin.copy()
    region[18:22, 5:35] = 0.35 * marker + 0.65 * skin[0, 0]  # a third green, the rest skin
    region = region.astype(np.uint8)
    gate = StreakGate(tuple(map(float, finger.bgr)), finger)
    mask = gate.backproject_bgr(region)
    assert mask[18:22, 5:35].all()
    assert not mask[:16].any() and not mask[24:].any()
    assert not finger.backproject(cv2.cvtColor(region, cv2.COLOR_BGR2HSV)).any()


def test_a_streak_may_hold_up_to_a_full_exposure_of_colour():
    ref = np.pi * 25
    assert streak_mass(ref, 0.0) == ref
    assert streak_mass(ref, 20.0) == pytest.approx(ref + 10.0 * 20.0)

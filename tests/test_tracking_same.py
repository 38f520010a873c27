"""The tracker's faster paths give the tracks of the plain ones, bit for bit (issue 45 item 5).

Tracking was made cheaper without changing a value: crops are converted to
HSV as one contiguous row (:func:`perception.tracking.markers.to_hsv`;
OpenCV converts a row's last pixels one at a time, five times slower) and
the blur gate's rival test labels only the box of the gate's pixels. Each
is checked against the plain call it replaces, and whole clips (a fast
blurred grasp, whose digits are measured as streaks and re-acquired, and a
realistic one over a photograph) are tracked both ways.
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from perception.io.tracks import Tracks
from perception.synthetic.realistic import render_realistic_set
from perception.synthetic.render import render_clip
from perception.synthetic.scene import Scene
from perception.tracking import blur, measurement, reacquisition, tracker
from perception.tracking.markers import to_hsv
from perception.tracking.video_tracks import track_video

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

import evaluate_fast_tracking as fast  # noqa: E402


def _plain_hsv(bgr: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)


class _WholeBox:
    """``cv2`` as the blur gate sees it, whose ``boundingRect`` is the whole mask."""

    def __getattr__(self, name):
        return getattr(cv2, name)

    @staticmethod
    def boundingRect(mask):  # noqa: N802 (OpenCV's name)
        return 0, 0, mask.shape[1], mask.shape[0]


def test_to_hsv_is_opencvs_conversion_for_every_colour():
    # every 8-bit colour, in rows of 31 (a width OpenCV converts one pixel
    # at a time) against to_hsv's single row (its vector path)
    codes = np.arange(1 << 24, dtype=np.uint32)
    for part in np.array_split(codes, 16):
        bgr = np.stack([part >> 16, (part >> 8) & 255, part & 255], axis=-1).astype(np.uint8)
        rows = bgr[: len(bgr) // 31 * 31].reshape(-1, 31, 3)
        assert np.array_equal(to_hsv(rows), _plain_hsv(rows))


@pytest.mark.parametrize("width", [*range(1, 70), 95, 127, 128, 129, 640])
def test_to_hsv_of_a_crop_is_the_crops_own_conversion(width):
    rng = np.random.default_rng(width)
    frame = rng.integers(0, 256, (48, 700, 3), dtype=np.uint8)
    x0 = int(rng.integers(0, 700 - width + 1))
    crop = frame[5:40, x0:x0 + width]
    got = to_hsv(crop)
    assert got.shape == crop.shape and got.dtype == np.uint8
    assert np.array_equal(got, _plain_hsv(crop))


def _fast_clip(d: Path) -> Path:
    clip = fast.population_clip(1, 30.0, 1 / 30, fast.FAST_DURATION)  # re-acquires a digit
    scene = Scene(wrist=clip.paths["wrist"], finger=clip.paths["finger"],
                  thumb=clip.paths["thumb"], object_diameter=clip.object_size)
    res = render_clip(scene, clip.camera, clip.style, d / "fast.mp4", seed=fast.FAST_SEED + 1)
    return res.video


def _realistic_clip(d: Path) -> Path:
    (clip,) = render_realistic_set(d, backgrounds=("coffee",), conditions=("normal",),
                                   sleeve=False)
    return clip.realistic.video


@pytest.mark.parametrize("render", [_fast_clip, _realistic_clip], ids=["fast", "realistic"])
def test_tracks_are_those_of_the_plain_path(tmp_path, monkeypatch, render):
    video = render(tmp_path)
    streaks = []
    smear = measurement._streak

    def counted(*args, **kwargs):
        streaks.append(1)
        return smear(*args, **kwargs)

    monkeypatch.setattr(measurement, "_streak", counted)
    now = Tracks.load(track_video(video, tmp_path / "now.tracks.h5"))
    for module in (measurement, blur, tracker, reacquisition):
        monkeypatch.setattr(module, "to_hsv", _plain_hsv)
    monkeypatch.setattr(blur, "cv2", _WholeBox())
    plain = Tracks.load(track_video(video, tmp_path / "plain.tracks.h5"))
    assert np.array_equal(now.position, plain.position, equal_nan=True)
    assert np.array_equal(now.likelihood, plain.likelihood)
    assert np.array_equal(now.status, plain.status)
    # the clip exercises the paths: re-acquisition, and the fast one's streaks
    assert (now.status == 1).any()
    assert streaks or render is _realistic_clip

"""Streaming tracking: Tracker.feed/flush give track_frames' rows, a bounded amount per call."""

import cv2
import numpy as np
import pytest
from _clips import HARD, render

from perception.io.video import FrameSource
from perception.synthetic.scene import Distractor, Scene
from perception.tracking import candidates
from perception.tracking.markers import default_markers
from perception.tracking.params import TrackerParams
from perception.tracking.tracker import Tracker
from perception.tracking.video_tracks import track_frames


class _Rows:
    """A TracksWriter stand-in keeping the rows appended."""

    def __init__(self):
        self.rows = []

    def append(self, *row):
        self.rows.append(row)


def _same(a, b):
    """Rows (index, time, position, likelihood, status[, frame]) equal to the byte."""
    assert len(a) == len(b)
    for ra, rb in zip(a, b):
        assert ra[:2] == rb[:2]
        for x, y in zip(ra[2:5], rb[2:5]):
            assert x.dtype == y.dtype and x.tobytes() == y.tobytes()


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    """A hard 640x480 clip with a distractor of the finger's colour crossing it."""
    n = 45
    scene = Scene.reach_to_grasp(n, 30, onset=0.2, duration=1.0)
    mid = scene.finger[n // 2]
    d = Distractor("finger", start=(mid[0] - 0.15, mid[1] + 0.02),
                   end=(mid[0] + 0.15, mid[1] + 0.02), frames=(5, n))
    clip, _ = render(tmp_path_factory.mktemp("feed"), n=n, scene=scene, distractors=(d,),
                     **HARD)
    with FrameSource(clip.video) as src:
        return list(src)


def _stream(frames, tracker, counts=None):
    """Feed every frame, then flush; ``counts`` gets the frames each call tracked."""
    calls, real = [], tracker.update
    tracker.update = lambda *a: calls.append(1) or real(*a)
    rows = []
    for index, time_s, frame in frames:
        got = tracker.feed(frame, time_s, index)
        if counts is not None:
            counts.append(len(calls))
        assert len(got) == len(calls)
        calls.clear()
        rows += got
    rows += tracker.flush()
    return rows


@pytest.mark.parametrize("init", [5, 2, 1])
def test_feed_and_flush_give_track_frames_rows_exactly(frames, init):
    params = TrackerParams(init_frames=init)
    offline = _Rows()
    track_frames(iter(frames), offline, Tracker(params=params))
    counts = []
    rows = _stream(frames, Tracker(params=params), counts)
    _same(rows, offline.rows)
    assert [r[0] for r in rows] == [f[0] for f in frames]
    assert all(r[5] is f[2] for r, f in zip(rows, frames))  # each row with its own frame
    # nothing until the look-ahead is in, then the first frame alone (first detection),
    # then catch_up (2) frames a call until the queue is down to the new frame, then one
    assert Tracker.catch_up == 2
    assert counts == [0] * (init - 1) + [1] + [2] * (init - 1) + [1] * (len(frames) - 2 * init + 1)


@pytest.mark.parametrize("n", [1, 2, 4])
def test_flush_tracks_a_stream_shorter_than_the_look_ahead(frames, n):
    offline = _Rows()
    track_frames(iter(frames[:n]), offline, Tracker())
    tracker = Tracker()
    assert all(tracker.feed(f, t, i) == [] for i, t, f in frames[:n])
    rows = tracker.flush()
    _same(rows, offline.rows)
    assert len(rows) == n and tracker.flush() == []
    assert not tracker.never_found


def test_candidates_are_labelled_in_the_colours_box_as_in_the_whole_frame(frames, monkeypatch):
    """describe labels blobs within their bounding box only: the candidates are the same."""
    hsv = [cv2.cvtColor(f, cv2.COLOR_BGR2HSV) for _, _, f in frames[::11]]
    # odd places, touching the frame's edge, and a frame with nothing of the colour
    hsv.append(np.zeros_like(hsv[0]))
    rng = np.random.default_rng(0)
    for k in range(3):
        noisy = hsv[0].copy()
        noisy[rng.random(noisy.shape[:2]) < 0.002 * (k + 1)] = (0, 220, 200)
        noisy[:7, -5 - k:] = (0, 220, 200)
        hsv.append(noisy)

    def every(markers):
        return [repr(candidates.describe(h, m, 2, roi, later))
                for h in hsv for m in markers for roi in (None, (31, 17, 301, 203))
                for later in (None, hsv[1])]

    markers = list(default_markers())
    cropped = every(markers)
    monkeypatch.setattr(cv2, "boundingRect", lambda m: (0, 0, m.shape[1], m.shape[0]))
    assert every(markers) == cropped
    assert any("Candidate" in c for c in cropped)

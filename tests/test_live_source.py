"""`perception.io.video.open_source`: bounded read-ahead, files, refusals, Ctrl-C, closing.

A camera is :class:`FastCamera`, put in the place of ``cv2.VideoCapture(<int>)``:
it serves frames as fast as it is read, so a consumer always falls behind.

No test asserts how fast anything happens: each waits for an event, with :data:`HANG`
only as the bound of a bug, so that a slow or busy machine passes them all.
"""

from __future__ import annotations

import _thread
import threading
import time

import cv2
import numpy as np
import pytest

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io.video import FrameSource, open_source, write_video

#: Seconds after which a wait is taken to hang: a bound for a bug, not a speed.
HANG = 600


class FastCamera:
    """``n`` numbered 8 x 8 frames (None: endless), served at once; ``opening`` holds the
    open until it is set (``open_started``, ``open_returned``: where the open is)."""

    def __init__(self, n: int | None = 200, opening: threading.Event | None = None):
        self.n, self.served, self.opening = n, 0, opening
        self.ended, self.released = threading.Event(), threading.Event()
        self.open_started, self.open_returned = threading.Event(), threading.Event()

    def __call__(self, target, *args):  # cv2.VideoCapture(target, api, params)
        self.target = target
        self.open_started.set()
        if self.opening is not None:
            self.opening.wait(HANG)  # a driver, or FFmpeg, slow to open
        self.open_returned.set()
        return self

    def isOpened(self) -> bool:  # noqa: N802 - cv2's API
        return True

    def get(self, prop) -> float:
        return 30.0 if prop == cv2.CAP_PROP_FPS else 0.0

    def read(self):
        if self.n is not None and self.served >= self.n:
            self.ended.set()
            return False, None
        self.served += 1
        return True, np.full((8, 8, 3), (self.served - 1) % 256, np.uint8)

    def release(self) -> None:
        self.released.set()


def test_a_live_source_holds_at_most_read_ahead_frames_and_drops_the_oldest(camera):
    cam = camera(FastCamera(200))
    with open_source("0", read_ahead=4) as src:
        assert src.kind == "camera" and src.fps == 30.0 and cam.target == 0
        assert cam.ended.wait(HANG)  # the consumer took nothing while 200 frames came
        got = list(src)
    # the newest 4 waited; the 196 older were dropped and counted, not held
    assert [i for i, _, _ in got] == [196, 197, 198, 199]
    assert [int(f[0, 0, 0]) for _, _, f in got] == [196, 197, 198, 199]
    assert src.dropped == 196 and cam.released.is_set()
    assert src.attrs() == {"source": "0", "fps": 30.0}


def test_a_file_read_as_a_stream_drops_its_oldest_frames_and_keeps_its_own_times(tmp_path):
    path = tmp_path / "clip.mkv"
    n = 40
    write_video([np.full((48, 64, 3), 5 * k, np.uint8) for k in range(n)], path, 25)
    expected = list(FrameSource(path))
    with open_source(f"file://{path}", read_ahead=3) as src:
        assert src.kind == "stream" and src.fps == 25.0
        deadline = time.monotonic() + HANG  # the reader's pace is the machine's: wait for it
        while src.dropped < n - 3 and time.monotonic() < deadline:
            time.sleep(0.01)
        got = list(src)
    assert src.dropped == n - 3 and [i for i, _, _ in got] == [n - 3, n - 2, n - 1]
    for (i, t, frame) in got:  # the stream's own time stamps, not an index over a rate
        assert t == pytest.approx(expected[i][1]) and np.array_equal(frame, expected[i][2])


def test_a_file_read_as_fast_as_possible_drops_nothing_and_is_frame_source(tmp_path):
    path = tmp_path / "clip.mkv"
    write_video([np.full((48, 64, 3), 3 * k, np.uint8) for k in range(60)], path, 30)
    expected = FrameSource(path)
    frames = list(expected)
    with open_source(str(path), read_ahead=2) as src:
        assert src.kind == "file" and src.fps == 30.0
        got = []
        for item in src:
            time.sleep(0.002)  # slower than the decoder: its reader waits, drops nothing
            got.append(item)
    assert src.dropped == 0 and len(got) == len(frames) == 60
    assert [(i, t) for i, t, _ in got] == [(i, t) for i, t, _ in frames]
    assert all(np.array_equal(a[2], b[2]) for a, b in zip(got, frames, strict=True))
    assert src.attrs() == expected.attrs()


def test_a_consumer_that_fails_stops_and_releases_a_source_still_sending(camera):
    cam = camera(FastCamera(None))  # endless
    with pytest.raises(RuntimeError, match="the consumer broke"), open_source("0") as src:
        for i, _, _ in src:
            if i == 5:
                raise RuntimeError("the consumer broke")
    # closed on the error's way out: no reader left inside read() at exit
    assert cam.released.wait(HANG)
    src._ahead._thread.join(HANG)
    assert src._ahead._thread.is_alive() is False
    served = cam.served
    time.sleep(0.1)
    assert cam.served == served


def test_ctrl_c_while_a_stream_opens_is_delivered_at_once(camera):
    opening = threading.Event()
    cam = camera(FastCamera(10, opening=opening))

    def interrupt_once_opening():  # Ctrl-C while the open is under way, however slow
        if cam.open_started.wait(HANG):
            _thread.interrupt_main()

    threading.Thread(target=interrupt_once_opening, daemon=True).start()
    try:
        with pytest.raises(KeyboardInterrupt):
            open_source("udp://127.0.0.1:9")
        # delivered while the open still waits (it returns only once `opening` is set):
        # not after it, however long the machine takes
        assert cam.open_started.is_set() and not cam.open_returned.is_set()
    finally:
        opening.set()


@pytest.mark.parametrize(("source", "kwargs", "words"), [
    ("3000000000", {}, "below 2**31"),
    ("0", {"stall_timeout": 1e7}, "stall_timeout"),  # the library names the field; watch
    ("0", {"stall_timeout": float("inf")}, "stall_timeout"),  # gives its flag (below)
])
def test_out_of_range_cameras_and_stall_timeouts_are_input_errors(camera, source, kwargs,
                                                                  words):
    cam = camera(FastCamera(10))
    with pytest.raises(InputError, match=r"\A[^\n]*\Z") as err:
        open_source(source, **kwargs)
    assert words in str(err.value) and not hasattr(cam, "target")  # nothing opened


@pytest.mark.parametrize(("source", "options", "words"), [
    ("3000000000", [], "below 2**31"),
    ("0", ["--stall-timeout", "3000000"], "--stall-timeout"),
    ("nope.mp4", [], "no such file (nor a camera index or stream URL)"),
])
def test_watch_refuses_them_in_one_line(camera, tmp_path, capsys, source, options, words):
    cam = camera(FastCamera(10))
    rc = main(["watch", source, "-o", str(tmp_path / "out"), *options])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and words in err, err
    assert not hasattr(cam, "target")

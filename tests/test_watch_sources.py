"""`hammer-mv watch` from a camera (a fake one serving a rendered clip) and `--labelled-video`.

There is no camera on CI: ``cv2.VideoCapture`` of a camera index is replaced,
in this process, by :class:`FakeCamera`, which serves a rendered clip's
frames and then stops delivering (its ``read`` blocks, as a driver's may),
so that only ``--stall-timeout`` can end the run.
"""

from __future__ import annotations

import json
import threading
import time

import cv2
import numpy as np
import pytest
from _demos import default_repertoire
from _reports import assert_json_close

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io import capture as live
from perception.online import OnlineRecognizer
from perception.synthetic.demos import render_demo_clip

FPS = 30.0
N = 75
WARMUP = 0.3  # s from opening a camera to its first frame: the first frame's time, not 0
STALL = 0.5  # s


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    """A rendered clip, its frames, its repertoire and `recognize`'s report of it."""
    d = tmp_path_factory.mktemp("watch_sources")
    video = render_demo_clip(d, "clip.mp4", n=N, fps=FPS)[0].video
    rep = default_repertoire().save(d / "rep.h5")  # built for 30 frames/s
    assert main(["recognize", str(video), "-o", str(d / "offline"), "--no-figures",
                 "--repertoire", str(rep)]) == 0
    cap = cv2.VideoCapture(str(video))
    frames = []
    while (got := cap.read())[0]:
        frames.append(got[1])
    cap.release()
    assert len(frames) == N
    offline = json.loads((d / "offline" / "clip.recognition.json").read_text())
    return video, rep, offline, frames


class FakeCamera:
    """A camera that serves ``frames`` on its own clock, then blocks in ``read``.

    Frame k comes ``warmup + k / fps`` s after the camera opened by
    :meth:`monotonic`, the clock the live source reads in the real one's place (on
    the real one the times, and the verdict with them, would depend on how
    busy the machine is); the frames themselves come at once. After the last
    one ``read`` blocks until ``unblock`` is set, as a stalled driver's may.
    """

    OPENED_AT = 1000.0

    def __init__(self, frames, fps: float, warmup: float, opened: bool = True):
        self.frames, self.fps, self.warmup, self.opened = frames, fps, warmup, opened
        self.now = self.OPENED_AT
        self.served, self.last_served = 0, None
        self.unblock, self.released = threading.Event(), threading.Event()

    def monotonic(self) -> float:
        return self.now

    def isOpened(self) -> bool:  # noqa: N802 - cv2's API
        return self.opened

    def get(self, prop) -> float:
        return self.fps if prop == cv2.CAP_PROP_FPS else 0.0

    def read(self):
        k = self.served
        if k >= len(self.frames):  # stalled: no frame, no error, no return
            self.unblock.wait()
            return False, None
        self.now = self.OPENED_AT + self.warmup + k / self.fps
        self.served, self.last_served = k + 1, time.monotonic()
        return True, self.frames[k].copy()

    def release(self) -> None:
        self.released.set()


class _CameraClock:
    """The ``time`` module as the live source sees it: ``monotonic`` is the camera's clock."""

    def __init__(self, cam: FakeCamera):
        self.monotonic = cam.monotonic

    def __getattr__(self, name):
        return getattr(time, name)


@pytest.fixture
def camera(monkeypatch):
    """``install(camera)``: ``cv2.VideoCapture(<int>)`` opens ``camera``; files open as ever.

    Returns the list of the camera indices opened.
    """
    real, opened, cams = cv2.VideoCapture, [], []

    def install(cam: FakeCamera) -> list:
        def capture(target, *args):
            if isinstance(target, int):
                opened.append(target)
                return cam
            return real(target, *args)

        cams.append(cam)
        monkeypatch.setattr(cv2, "VideoCapture", capture)
        monkeypatch.setattr(live, "time", _CameraClock(cam))
        monkeypatch.setattr(live, "READ_AHEAD", 2 * N)  # it serves its frames at once: keep all
        return opened

    yield install
    for cam in cams:  # let a reader thread still blocked in read() end
        cam.unblock.set()


def _close(a, b):
    return assert_json_close(a, b, rel=1e-6, abs_=1e-9)


#: Seconds after which a run is taken to hang: a bound for a bug, far above any slow or busy
#: machine's time (no test here asserts how fast anything is)
HANG = 600


def _main_within(argv, seconds: float = HANG) -> int:
    """``main(argv)``, failing the test rather than hanging if it has not returned in time."""
    result = []
    worker = threading.Thread(target=lambda: result.append(main(argv)), daemon=True)
    worker.start()
    worker.join(seconds)
    assert not worker.is_alive(), f"hammer-mv {' '.join(argv)} still running after {seconds} s"
    return result[0]


def test_a_camera_is_recognised_on_its_own_clock_until_it_stalls(clip, camera, tmp_path,
                                                                 capsys, monkeypatch):
    _, rep, offline, frames = clip
    cam = FakeCamera(frames, FPS, WARMUP)
    opened = camera(cam)
    waits = []  # each wait of the watch for its next frame: (timeout, whether it got one)
    real_next = live.ReadAhead.next

    def next_(self, timeout=None):
        item = real_next(self, timeout)
        waits.append((timeout, item is not None))
        return item

    monkeypatch.setattr(live.ReadAhead, "next", next_)
    rc = _main_within(["watch", "3", "-o", str(tmp_path), "--no-figures", "--repertoire",
                       str(rep), "--live", "--stall-timeout", str(STALL)])
    returned = time.monotonic()
    out = capsys.readouterr().out
    assert rc == 0 and opened == [3]
    # ended by the stall timeout, after the last frame and not before: the camera, still
    # blocked in read(), sent nothing for --stall-timeout (and the grace for a stuck read);
    # the watch's last wait was that one, and it got nothing (no wall-time bound: a busy
    # machine judges the frames more slowly, which changes nothing here)
    assert cam.served == N and not cam.unblock.is_set()
    assert returned - cam.last_served >= STALL + live.STALL_GRACE
    assert waits[-1] == (STALL + live.STALL_GRACE, False)
    assert sum(got for _, got in waits) == N + 1  # the header's frame rate, then every frame
    online = json.loads((tmp_path / "camera3.recognition.json").read_text())
    assert online["clip"] == "camera3" and online["input"] == "3"
    info = online["online"]
    assert info["source"] == "camera" and info["frames"] == N and not info["interrupted"]
    assert info["dropped_frames"] == 0
    for key in ("verdict", "verdict_detail", "winner"):
        assert online[key] == offline[key], key
    # the times are the clock's when each frame came: the first after the warm-up (index /
    # fps would start at 0, the stream's time stamps are absent), then the camera's pace
    times = np.array([float(line.split()[0]) for line in out.splitlines() if " s  " in line])
    assert len(times) == N and np.all(np.diff(times) > 0)
    assert times == pytest.approx(WARMUP + np.arange(N) / FPS, abs=1e-3)  # printed to 1 ms
    assert f"camera3: {offline['verdict']}" in out
    # and the report is `recognize`'s, to the rounding of times 0.3 s later; its clock's
    # origin the camera's, the warm-up later than the file's
    assert online.pop("time_origin") == pytest.approx(offline["time_origin"] + WARMUP)
    expected = {k: v for k, v in offline.items()
                if k not in ("clip", "input", "fingerprint", "time_origin")}
    _close({k: v for k, v in online.items() if k not in ("clip", "input", "online")}, expected)
    cam.unblock.set()  # the driver returns at last: the reader stops and lets the camera go
    assert cam.released.wait(HANG)


def test_a_camera_that_cannot_be_opened_is_one_line(clip, camera, tmp_path, capsys):
    _, rep, _, frames = clip
    opened = camera(FakeCamera(frames, FPS, 0.0, opened=False))
    rc = _main_within(["watch", "7", "-o", str(tmp_path / "out"), "--repertoire", str(rep)])
    err = capsys.readouterr().err
    assert rc == 2 and opened == [7]
    assert err.count("\n") == 1 and "cannot open the camera" in err and "7" in err
    assert not (tmp_path / "out" / "camera7.recognition.json").exists()


@pytest.mark.parametrize("stall", ["0", "-1", "nan"])
def test_a_stall_timeout_that_is_not_positive_is_one_line(clip, camera, tmp_path, capsys,
                                                         stall):
    _, rep, _, frames = clip
    opened = camera(FakeCamera(frames, FPS, 0.0))
    rc = _main_within(["watch", "0", "-o", str(tmp_path), "--repertoire", str(rep),
                       f"--stall-timeout={stall}"])
    err = capsys.readouterr().err
    assert rc == 2 and opened == []  # refused before the camera is opened
    assert err.count("\n") == 1 and "--stall-timeout" in err


def _read_video(path):
    cap = cv2.VideoCapture(str(path))
    frames = []
    while (got := cap.read())[0]:
        frames.append(got[1].astype(float))
    cap.release()
    return frames


def _leftovers(folder):
    """Temporary files of an atomic write (``.<stem>.<owner>.<random>.part<suffix>``)."""
    return sorted(p.name for p in folder.iterdir() if ".part" in p.name)


def test_the_labelled_video_has_every_frame_with_the_bars_drawn(clip, tmp_path, capsys):
    video, rep, offline, frames = clip
    out = tmp_path / "labelled" / "clip.labelled.mp4"
    assert main(["watch", str(video), "-o", str(tmp_path / "r"), "--no-figures",
                 "--repertoire", str(rep), "--as-fast-as-possible", "--quiet",
                 "--labelled-video", str(out)]) == 0
    labelled = _read_video(out)
    assert len(labelled) == N and labelled[0].shape == frames[0].shape
    assert _leftovers(out.parent) == []
    # the share of pixels changed outright where the bars and their names are drawn (a
    # row per model, above the verdict at the bottom left), and beside them, on the
    # right, where nothing is drawn and mp4v's re-encoding alone changes them a little
    rows = slice(-(14 * len(offline["models"]) + 25), -28)
    for k in (0, N // 2, N - 1):
        changed = np.abs(labelled[k][rows] - frames[k][rows]).max(axis=2) > 60
        bars, plain = changed[:, :260].mean(), changed[:, -120:].mean()
        assert bars > 0.03 and plain < 0.001, (k, bars, plain)


def test_a_run_that_fails_leaves_no_labelled_video(clip, tmp_path, monkeypatch, capsys):
    video, rep, _, _ = clip
    update = OnlineRecognizer.update

    def failing(self, frame, t, index=None):
        if index == 30:  # after 30 frames have gone to the video
            raise InputError("the source broke", "clip.mp4")
        return update(self, frame, t, index)

    monkeypatch.setattr(OnlineRecognizer, "update", failing)
    out = tmp_path / "labelled" / "clip.labelled.mp4"
    rc = main(["watch", str(video), "-o", str(tmp_path / "r"), "--no-figures", "--repertoire",
               str(rep), "--as-fast-as-possible", "--labelled-video", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "the source broke" in err
    assert not out.exists() and _leftovers(out.parent) == []


def test_an_unwritable_labelled_video_is_one_line(clip, tmp_path, capsys):
    video, rep, _, _ = clip
    out = tmp_path / "a-file" / "clip.labelled.mp4"  # its folder is a file
    (tmp_path / "a-file").write_text("not a folder")
    rc = main(["watch", str(video), "-o", str(tmp_path / "r"), "--no-figures", "--repertoire",
               str(rep), "--as-fast-as-possible", "--labelled-video", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and str(out) in err
    assert not (tmp_path / "r" / "clip.recognition.json").exists()


@pytest.mark.parametrize("which", ["video", "repertoire"])
def test_a_labelled_video_in_place_of_an_input_is_refused(clip, tmp_path, capsys, which):
    video, rep, _, _ = clip
    target = {"video": video, "repertoire": rep}[which]
    before = target.read_bytes()
    rc = main(["watch", str(video), "-o", str(tmp_path / "r"), "--no-figures", "--repertoire",
               str(rep), "--as-fast-as-possible", "--labelled-video", str(target)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "also an input" in err
    assert target.read_bytes() == before

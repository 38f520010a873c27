"""`hammer-mv watch` and its operator (issue 33, item 3): signals, full disks, bad outputs.

* SIGINT, SIGTERM and SIGHUP end a watch with the report of what was seen, marked
  interrupted, and exit status 128 + the signal's number; a second one while the
  report is written does not lose it; one during a frame waits for the frame;
* a labelled video that cannot be written costs only itself (exit status 2);
* ``-o`` and ``--labelled-video`` are checked before the source opens, and no
  output may be the source, however the source is named;
* a watch that fails stops its source's reader, releases it and leaves no video.

Loopback only: files, and a fake stream in this process. Each subprocess is bounded
by a timeout, each watch in this process by its source (a file, or a fake that fails).
"""

from __future__ import annotations

import _thread
import errno
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

import cv2
import pytest
from _demos import default_repertoire
from test_live_source import FastCamera

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io import video as video_io
from perception.online import OnlineRecognizer
from perception.report import clip as clip_report
from perception.synthetic.demos import render_demo_clip
from perception.tracking import overlay

N = 75  # frames, at 30 frames/s: a paced watch runs 2.5 s


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    """A rendered 640 x 480 clip and its repertoire."""
    d = tmp_path_factory.mktemp("watch_faults")
    video = render_demo_clip(d, "clip.mp4", n=N)[0].video
    return video, default_repertoire().save(d / "rep.h5")


def _watch(clip, out, *options):
    video, rep = clip
    return ["watch", str(video), "-o", str(out), "--repertoire", str(rep), *map(str, options)]


def _leftovers(*folders):
    """Temporary files of atomic writes (``.<stem>.<owner>.<random>.part<suffix>``)."""
    return sorted(p.name for f in folders if f.exists() for p in f.iterdir() if ".part" in p.name)


def _one_line(err: str) -> None:
    assert err.count("\n") == 1 and "Traceback" not in err, err


# -- signals (a subprocess, paced at the clip's frame rate) ------------------------------
#: `hammer-mv` whose video files, once the frame at ``AFTER`` s is given, wait for ever (as a
#: camera with nothing more to send does): a signal sent then ends the watch at that frame,
#: however slowly a busy machine judges the frames (the file would otherwise end first)
_WAITING_AFTER = """
import sys, time
from perception.io import video
frames = video.FrameSource._frames
def waiting(self):
    for item in frames(self):
        yield item
        if item[1] >= AFTER:
            while True:
                time.sleep(0.05)
video.FrameSource._frames = waiting
from hammer_mv.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _signalled(argv, signals, *, after=1.0, gap=0.2, limit=600):
    """Run ``hammer-mv argv`` with --live; once the frame at ``after`` s is judged (the file
    then waits), send ``signals`` ``gap`` s apart; return (exit status, stdout, stderr).
    ``limit``: a hang (the watchdog), not a speed."""
    proc = subprocess.Popen([sys.executable, "-c", _WAITING_AFTER.replace("AFTER", str(after)),
                             *argv, "--live"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    watchdog = threading.Timer(limit, proc.kill)
    watchdog.start()
    try:
        lines = []
        for line in proc.stdout:  # a line per frame: "   1.033 s  ..."
            lines.append(line)
            if " s  " in line and float(line.split()[0]) >= after:
                break
        for k, sig in enumerate(signals):
            time.sleep(gap if k else 0)
            proc.send_signal(sig)
        out, err = proc.communicate(timeout=limit)
        return proc.returncode, "".join(lines) + out, err
    finally:
        watchdog.cancel()
        proc.kill()


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGTERM, 143), (signal.SIGHUP, 129),
                                             (signal.SIGINT, 130)])
def test_a_signal_ends_the_watch_with_the_report_of_what_was_seen(clip, tmp_path, sig, status):
    out, labelled = tmp_path / "r", tmp_path / "lv" / "clip.labelled.mp4"
    rc, stdout, err = _signalled(_watch(clip, out, "--no-figures", "--labelled-video", labelled),
                                 [sig])
    assert rc == status, err
    report = json.loads((out / "clip.recognition.json").read_text())
    info = report["online"]
    assert info["interrupted"] and info["signal"] == sig.name
    # every frame up to the one at 1 s, the source waiting after it: judged and no more
    assert info["frames"] == sum(" s  " in line for line in stdout.splitlines()) == 31
    assert info["labelled_video_error"] is None and labelled.exists()
    assert _leftovers(out, labelled.parent) == []
    assert stdout.splitlines()[-1].startswith(f"clip: {report['verdict']}")


def test_more_signals_while_the_report_is_written_do_not_lose_it(clip, tmp_path, monkeypatch):
    # the first Ctrl-C while a frame is drawn, three more while the report is written
    draw, write, calls = overlay.Labeller.draw, clip_report.write_clip_report, []

    def drawing(self, *args):
        calls.append(1)
        if len(calls) == 40:
            _thread.interrupt_main()
        return draw(self, *args)

    def writing(*args, **kwargs):
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGINT):
            _thread.interrupt_main(sig)
            time.sleep(0.02)  # delivered here, not after
        return write(*args, **kwargs)

    monkeypatch.setattr(overlay.Labeller, "draw", drawing)
    monkeypatch.setattr(clip_report, "write_clip_report", writing)
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    labelled = tmp_path / "lv" / "clip.labelled.mp4"
    rc = main(_watch(clip, tmp_path / "r", "--no-figures", "--as-fast-as-possible",
                     "--quiet", "--labelled-video", labelled))
    assert rc == 130
    info = json.loads((tmp_path / "r" / "clip.recognition.json").read_text())["online"]
    assert info["interrupted"] and info["signal"] == "SIGINT" and info["frames"] < N
    assert labelled.exists() and _leftovers(tmp_path / "r", labelled.parent) == []
    # the watch's handlers are gone with it
    assert {s: signal.getsignal(s) for s in before} == before


def test_ctrl_c_during_the_first_drawn_frame_ends_the_watch_cleanly(clip, tmp_path,
                                                                    monkeypatch, capsys):
    labeller = overlay.Labeller.__init__

    def first(self, *args, **kwargs):  # the writer is open, no frame written yet
        _thread.interrupt_main()
        labeller(self, *args, **kwargs)

    monkeypatch.setattr(overlay.Labeller, "__init__", first)
    labelled = tmp_path / "lv" / "clip.labelled.mp4"
    rc = main(_watch(clip, tmp_path / "r", "--no-figures", "--as-fast-as-possible",
                     "--quiet", "--labelled-video", labelled))
    err = capsys.readouterr().err
    # too few frames for a report: said in one line, nothing left behind
    assert rc == 130 and "interrupted" in err and "clip too short" in err
    _one_line(err)
    assert not labelled.exists() and _leftovers(tmp_path / "r", labelled.parent) == []


# -- the labelled video ------------------------------------------------------------------
@pytest.mark.parametrize("where", ["write", "finish"])
def test_a_labelled_video_that_cannot_be_written_costs_only_itself(clip, tmp_path, monkeypatch,
                                                                   capsys, where):
    if where == "write":  # its writer raising midway: a full disk
        write = video_io.VideoWriter.write

        def full(self, frame):
            if self.n_written == 10:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            write(self, frame)

        monkeypatch.setattr(video_io.VideoWriter, "write", full)
    else:  # OpenCV reports no write errors: a full disk shows as an incomplete file
        monkeypatch.setattr(video_io, "_readable", lambda path, n: False)
    labelled = tmp_path / "lv" / "clip.labelled.mp4"
    rc = main(_watch(clip, tmp_path / "r", "--no-figures", "--as-fast-as-possible", "--quiet",
                     "--labelled-video", labelled))
    err = capsys.readouterr().err
    assert rc == 2 and "labelled video" in err
    _one_line(err)
    info = json.loads((tmp_path / "r" / "clip.recognition.json").read_text())["online"]
    assert info["frames"] == N and not info["interrupted"]
    words = "No space left" if where == "write" else "incomplete"
    assert words in info["labelled_video_error"] and words in err
    assert not labelled.exists() and _leftovers(labelled.parent) == []


def test_a_watch_that_fails_after_its_frames_leaves_no_labelled_video(clip, tmp_path, capsys):
    # 3 frames at rest: the recognition fails once the file has ended
    short = tmp_path / "short.mp4"
    cap, frames = cv2.VideoCapture(str(clip[0])), []
    while len(frames) < 3 and (got := cap.read())[0]:
        frames.append(got[1])
    cap.release()
    video_io.write_video(frames, short, 30)
    labelled = tmp_path / "lv" / "short.labelled.mp4"
    rc = main(["watch", str(short), "-o", str(tmp_path / "r"), "--repertoire", str(clip[1]),
               "--as-fast-as-possible", "--labelled-video", str(labelled)])
    err = capsys.readouterr().err
    assert rc == 2 and "too short" in err
    _one_line(err)
    assert not labelled.exists() and _leftovers(labelled.parent) == []


# -- outputs checked before the source opens ---------------------------------------------
@pytest.mark.parametrize(("output", "options", "words"), [
    ("a-file/out", [], "--output"),
    ("out", ["--labelled-video", "{tmp}/a-file/l.mp4"], "a-file/l.mp4"),
    ("out", ["--labelled-video", "{tmp}/l.txt"], "unknown video extension"),
])
def test_outputs_that_cannot_be_written_are_refused_before_the_source_opens(
        camera, tmp_path, capsys, output, options, words):
    (tmp_path / "a-file").write_text("a file, not a folder")
    cam = camera(FastCamera(None))
    rc = main(["watch", "0", "-o", str(tmp_path / output),
               *(o.format(tmp=tmp_path) for o in options)])
    err = capsys.readouterr().err
    assert rc == 2 and words in err
    _one_line(err)
    assert not hasattr(cam, "target")  # the camera never opened


def _spellings(tmp_path):
    """(source, output) pairs naming one file: URLs, relative, ./, a link."""
    real = tmp_path / "c.mp4"
    (tmp_path / "link.mp4").symlink_to(real)
    return [(f"file://{real}", str(real)), ("c.mp4", str(real)), (str(real), "./c.mp4"),
            ("link.mp4", "c.mp4"), ("file:c.mp4", "c.mp4"), (f"file://{real}", "link.mp4")]


@pytest.mark.parametrize("k", range(6))
def test_the_labelled_video_never_overwrites_the_source(clip, tmp_path, monkeypatch, capsys, k):
    shutil.copy(clip[0], tmp_path / "c.mp4")
    before = (tmp_path / "c.mp4").read_bytes()
    source, output = _spellings(tmp_path)[k]
    monkeypatch.chdir(tmp_path)
    rc = main(["watch", source, "-o", "r", "--repertoire", str(clip[1]), "--quiet",
               "--as-fast-as-possible", "--labelled-video", output])
    err = capsys.readouterr().err
    assert rc == 2 and "also an input" in err, err
    _one_line(err)
    assert (tmp_path / "c.mp4").read_bytes() == before and not (tmp_path / "r").exists()


def test_the_report_never_overwrites_the_source(clip, tmp_path, capsys):
    source = tmp_path / "x.recognition.json"  # a video, whatever its name
    shutil.copy(clip[0], source)
    rc = main(["watch", str(source), "-o", str(tmp_path), "--clip", "x", "--repertoire",
               str(clip[1]), "--as-fast-as-possible", "--no-figures"])
    err = capsys.readouterr().err
    assert rc == 2 and "also an input" in err
    _one_line(err)
    assert source.read_bytes() == clip[0].read_bytes()


# -- a source still sending --------------------------------------------------------------
def test_a_watch_that_fails_while_a_stream_sends_stops_and_releases_it(camera, tmp_path,
                                                                      monkeypatch, capsys):
    cam = camera(FastCamera(None))  # an endless stream

    def failing(self, frame, t, index=None):
        if index >= 5:
            raise InputError("the stream broke", "udp://127.0.0.1:9")
        return update(self, frame, t, index)

    update = OnlineRecognizer.update
    monkeypatch.setattr(OnlineRecognizer, "update", failing)
    threads = set(threading.enumerate())
    labelled = tmp_path / "l.mp4"
    rc = main(["watch", "udp://127.0.0.1:9", "-o", str(tmp_path / "r"),
               "--labelled-video", str(labelled)])
    err = capsys.readouterr().err
    assert rc == 2 and "the stream broke" in err
    _one_line(err)
    # stopped and let go before the exit: no reader left, nothing read after
    assert cam.released.is_set() and set(threading.enumerate()) <= threads
    served = cam.served
    time.sleep(0.1)
    assert cam.served == served
    assert not labelled.exists() and _leftovers(tmp_path) == []

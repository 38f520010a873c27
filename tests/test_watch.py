"""`hammer-mv watch` on a video file and on a local UDP stream: recognize's outputs."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from _cli import hammer_here, main_here
from _demos import default_repertoire
from _reports import assert_json_close

from perception.synthetic.demos import render_demo_clip


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    """A rendered 640 x 480 clip, its repertoire and `recognize`'s report of it."""
    d = tmp_path_factory.mktemp("watch")
    video = render_demo_clip(d, "clip.mp4", n=75)[0].video
    rep = default_repertoire().save(d / "rep.h5")
    assert main_here("recognize", video, "-o", d / "offline", "--no-figures", "--repertoire",
                     rep) == 0
    return video, rep, json.loads((d / "offline" / "clip.recognition.json").read_text()), d


def _hammer(*args, **kw):
    """``hammer-mv *args`` as a subprocess: for what the process shows (exit status 2 in one
    line); the lines and files of a command are tested in-process (:func:`hammer_here`)."""
    return subprocess.run([sys.executable, "-m", "hammer_mv", *map(str, args)],
                          capture_output=True, text=True, **kw)


# floats to 1e-9 relative: a stream's time base rounds differently
def _close(a, b):
    return assert_json_close(a, b, rel=1e-9, abs_=1e-12)


def test_watch_a_file_writes_what_recognize_writes(clip, tmp_path, capsys):
    video, rep, offline, d = clip
    proc = hammer_here(capsys, "watch", video, "-o", tmp_path, "--no-figures", "--repertoire",
                       rep, "--live", "--as-fast-as-possible")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert sum(" s  " in line for line in lines) == 75  # one per frame
    online = json.loads((tmp_path / "clip.recognition.json").read_text())
    info = online.pop("online")
    assert online == offline  # identical, key for key, bit for bit
    assert info["frames"] == 75 and info["dropped_frames"] == 0 and not info["interrupted"]
    assert info["signal"] is None and info["labelled_video_error"] is None
    assert 0 < info["decision_fraction"] <= 1 and info["decision_time"] > 0
    assert (tmp_path / "clip.confidence.csv").read_bytes() == \
        (d / "offline" / "clip.confidence.csv").read_bytes()


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _udp_bound(port: int) -> bool:
    """Whether a socket of this machine is bound to UDP ``port`` (Linux's /proc/net/udp)."""
    table = Path("/proc/net/udp")
    return any(line.split()[1].endswith(f":{port:04X}")
               for line in table.read_text().splitlines()[1:] if line.strip())


def _wait_until_listening(port: int, watch: subprocess.Popen, limit: float = 600) -> None:
    """Wait until ``watch`` has bound ``port``: however long the machine takes to start it,
    not a guessed number of seconds (``limit``: a hang, not a slow machine)."""
    if not Path("/proc/net/udp").exists():  # no table to read: a generous pause instead
        time.sleep(10)
        return
    deadline = time.monotonic() + limit
    while not _udp_bound(port):
        assert watch.poll() is None, watch.communicate()[1]
        assert time.monotonic() < deadline, f"watch never listened on UDP {port}"
        time.sleep(0.05)


#: `hammer-mv watch` with a read-ahead that holds the whole clip: a stream's reader drops
#: the oldest frame when the consumer falls behind, which a busy machine's does; here every
#: frame sent waits for it, so what it judges does not depend on the machine's speed (the
#: dropping itself is tested in test_live_source.py, deterministically)
_WATCH_HOLDING_EVERY_FRAME = ("import sys; from perception.io import capture; "
                              "capture.READ_AHEAD = 100_000; from hammer_mv.cli import main; "
                              "sys.exit(main(sys.argv[1:]))")


def test_watch_a_udp_stream_fed_by_ffmpeg(clip, tmp_path):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    video, rep, offline, _ = clip
    port = _free_port()
    watch = subprocess.Popen([sys.executable, "-c", _WATCH_HOLDING_EVERY_FRAME, "watch",
                              f"udp://127.0.0.1:{port}", "-o", str(tmp_path), "--clip", "clip",
                              "--no-figures", "--repertoire", str(rep), "--stall-timeout", "5"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_until_listening(port, watch)  # the receiver listens before the first packet is sent
    # the file's own frames, re-muxed (not re-encoded); its decoder header with every keyframe
    subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-loglevel", "error", "-re", "-i",
                    str(video), "-c", "copy", "-bsf:v", "dump_extra", "-f", "mpegts",
                    f"udp://127.0.0.1:{port}?pkt_size=1316"], check=True, timeout=600)
    out, err = watch.communicate(timeout=600)
    assert watch.returncode == 0, err
    online = json.loads((tmp_path / "clip.recognition.json").read_text())
    info = online.pop("online")
    # every frame sent is accounted for: judged, or counted as dropped
    assert info["frames"] + info["dropped_frames"] == 75, info
    assert info["read_ahead_dropped"] == 0  # the reader held every frame, however slow
    final = out.splitlines()[-1]  # the report's line: the clip, its verdict, every frame
    assert final.startswith(f"clip: {online['verdict']}") and "(75 frames, 0 dropped)" in final
    assert info["source"] == "stream" and info["frames"] == 75 and info["dropped_frames"] == 0
    assert online.pop("input") == f"udp://127.0.0.1:{port}"
    expected = {k: v for k, v in offline.items() if k not in ("input", "fingerprint")}
    _close(online, expected)


def test_watch_refuses_a_missing_source_in_one_line(tmp_path):
    proc = _hammer("watch", tmp_path / "nope.mp4", "-o", tmp_path / "out")
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "nope.mp4" in proc.stderr

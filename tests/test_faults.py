"""Every fault kind holds its promise: one line on stderr, exit 2, inputs untouched.

A table of hostile or careless command lines, one row per case, grouped by
kind (data loss, disk full, outside names, malformed HDF5, unknown TOML,
unbounded sizes, truncated video). Every row is checked the
same way (:func:`test_fault`): exit status 2, exactly one line on stderr (no
traceback, no warning, no FFmpeg chatter), every input byte-identical, no
file under the output's final name and nothing new outside the output
folder. A new command gets the same checks by adding rows.
"""

from __future__ import annotations

import hashlib
import os
import resource
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from _faults import one_line

from perception.io.atomic import owner_tag
from perception.io.tracks import Tracks
from perception.io.video import write_video
from perception.synthetic.demos import render_demo_clip
from perception.tracking.video_tracks import track_video

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A short clip (mp4 and avi), its tracks, and a truncated and a mislabelled video."""
    d = tmp_path_factory.mktemp("inputs")
    clip, _ = render_demo_clip(d, "a.mp4", n=45)
    track_video(clip.video, d / "a.tracks.h5")
    avi, _ = render_demo_clip(d, "b.avi", n=45)
    data = Path(avi.video).read_bytes()
    (d / "cut.avi").write_bytes(data[: len(data) // 2])
    (d / "b.avi").unlink()
    import cv2

    cap = cv2.VideoCapture(str(clip.video))
    frames = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(frame)
    cap.release()
    write_video(frames, d / "fast.mp4", 2000.0)
    from perception.recognition.planning import default_specs
    from perception.recognition.repertoire import Repertoire

    Repertoire.build(default_specs([1.0])).save(d / "rep.h5")
    return d


def _case(name, argv, message, output="out", files=None, limit=None):
    """One command line run in a fresh copy of the inputs.

    ``argv`` follows ``hammer-mv`` ("{d}": the folder, "{video}": the video
    the tracks name); ``message`` is a piece of the one stderr line; ``output``
    (relative to the folder) must not exist afterwards; ``files`` are made
    first (name: text, or a function of the path); ``limit`` is a disk that
    fills after this many bytes per file.
    """
    return pytest.param(argv, message, output, files or {}, limit, id=name)


def _broken(source, change):
    """A copy of the HDF5 file ``source`` with one object broken by ``change(h5py.File)``."""
    def make(path):
        shutil.copy(path.parent / source, path)
        with h5py.File(path, "a") as fh:
            change(fh)
    return make


def _soft_link(fh):
    fh.move("tracks/position", "tracks/position_data")
    fh["tracks/position"] = h5py.SoftLink("/tracks/position_data")


def _external_link(fh):
    del fh["tracks/position"]
    fh["tracks/position"] = h5py.ExternalLink("elsewhere.h5", "/x")


def _compound(fh):
    pos = fh["tracks/position"][()]
    del fh["tracks/position"]
    fh["tracks/position"] = np.zeros(pos.shape[:-1], dtype=[("x", "f8"), ("y", "f8")])


def _array_attr(fh):
    fh["video"].attrs["fps_nominal"] = np.array([30.0, 25.0])


def _zero_dt(fh):
    for name in fh["models"]:
        fh["models"][name].attrs["dt"] = 0.0


INFO = "tracks info {d}/bad.tracks.h5"  # a tracks file with one object broken
REC = "recognize {d}/a.tracks.h5 --repertoire {d}/bad.h5 -o {d}/out"
BUILD = "repertoire build {d}/rep.toml -o {d}/out/r.h5"
SYNTH = "synth {d}/r.toml -o {d}/out"
ONE = "[conditions]\nnormal = 1\n"
CASES = [
    # -- data loss: an output that is an input, or not a regular file
    _case("track -o its own video", "track {d}/a.mp4 -o {d}/a.mp4", "is also an input", None),
    _case("track --labelled-video its own video",
          "track {d}/a.mp4 -o {d}/out/t.h5 --labelled-video {d}/a.mp4", "is also an input",
          "out/t.h5"),
    _case("tracks export over its input",
          "tracks export {d}/a.tracks.h5 -o {d}/a.tracks.h5 --format csv", "is also an input",
          None),
    _case("tracks render over its video", "tracks render {d}/a.tracks.h5 {d}/a.mp4 -o {d}/a.mp4",
          "is also an input", None),
    _case("tracks render over the video its tracks name",
          "tracks render {d}/a.tracks.h5 -o {video}", "is also an input", None),
    _case("repertoire build over its config", "repertoire build {d}/rep.toml -o {d}/rep.toml",
          "is also an input", None, {"rep.toml": "durations = [1.0]\n"}),
    _case("track -o a FIFO", "track {d}/a.mp4 -o {d}/fifo", "not a regular file",
          files={"fifo": os.mkfifo}),
    _case("track -o a folder", "track {d}/a.mp4 -o {d}/dir", "is a folder",
          files={"dir": Path.mkdir}),
    # -- disk full (a file-size limit stands in for a full disk)
    _case("disk full: track", "track {d}/a.mp4 -o {d}/out/t.h5", "cannot write", "out/t.h5",
          limit=20_000),
    _case("disk full: tracks export", "tracks export {d}/a.tracks.h5 -o {d}/out/t.csv --format csv",
          "cannot write", "out/t.csv", limit=2_000),
    _case("disk full: repertoire build", "repertoire build --durations 1.0 -o {d}/out/r.h5",
          "cannot write", "out/r.h5", limit=20_000),
    _case("disk full: synth", SYNTH, "cannot write", "out/normal-01.mp4", {"r.toml": ONE},
          limit=20_000),
    _case("disk full: labelled video", "tracks render {d}/a.tracks.h5 {d}/a.mp4 -o {d}/out/l.mp4",
          "cannot write", "out/l.mp4", limit=20_000),
    # -- names from the outside world
    _case("manifest row escaping -o", "batch {d}/m.csv -o {d}/out", "row 3",
          "escape.recognition.json", {"m.csv": "clip,video\nok,a.mp4\n../escape,a.mp4\n"}),
    _case("duplicate manifest rows", "batch {d}/m.csv -o {d}/out", "appears twice (rows 2 and 3)",
          "out/summary.csv", {"m.csv": "clip,video\nx,a.mp4\nx,a.mp4\n"}),
    # -- malformed HDF5
    *[_case(f"tracks: {name}", INFO, "bad.tracks.h5",
            files={"bad.tracks.h5": _broken("a.tracks.h5", change)})
      for name, change in [("soft link", _soft_link), ("external link", _external_link),
                           ("compound dtype", _compound), ("array-valued attribute", _array_attr)]],
    _case("tracks: not HDF5", "tracks export {d}/bad.tracks.h5 -o {d}/out/x.csv --format csv",
          "not an HDF5 file", "out/x.csv", {"bad.tracks.h5": "hello"}),
    _case("repertoire: dt = 0", REC + " --no-figures", "bad.h5", "out/a.recognition.json",
          {"bad.h5": _broken("rep.h5", _zero_dt)}),
    _case("repertoire: not HDF5", REC, "not an HDF5 file", "out/a.recognition.json",
          {"bad.h5": "x"}),
    # -- unknown TOML tables and keys
    _case("recipe: misspelt table", SYNTH, "did you mean 'scene'",
          files={"r.toml": ONE + "[scence]\nduration = 1.0\n"}),
    _case("recipe: misspelt scene key", SYNTH, "did you mean 'rest_before'",
          files={"r.toml": ONE + "[scene]\nrest_befor = 0.3\n"}),
    _case("repertoire config: [[models]]", BUILD, "did you mean 'model'", "out/r.h5",
          {"rep.toml": "[[models]]\nname = 'x'\n"}),
    _case("repertoire config: unknown top-level key", BUILD, "did you mean 'durations'",
          "out/r.h5", {"rep.toml": "duration = [1.0]\n"}),
    _case("pose config: misspelt key",
          "recognize {d}/a.tracks.h5 -o {d}/out --pose-config {d}/pose.toml",
          "did you mean 'pcutoff'", files={"pose.toml": "pcutof = 0.5\n"}),
    # -- unbounded sizes
    *[_case(f"recipe: {name}", SYNTH, message, files={"r.toml": text}) for name, text, message in [
        ("a billion frames/s", ONE + "[render]\nfps = 1e9\n", "frame rate"),
        ("a day of rest", ONE + "[scene]\nrest_before = 1e5\n", "rest_before"),
        ("a huge frame", ONE + "[render]\nwidth = 100000\n", "width and height"),
        ("a million clips", "[conditions]\nnormal = 1000000\n", "at most")]],
    # -- truncated and mislabelled videos: one policy in every command
    _case("track: truncated video", "track {d}/cut.avi -o {d}/out/t.h5", "truncated", "out/t.h5"),
    _case("recognize: truncated video", "recognize {d}/cut.avi -o {d}/out", "truncated",
          "out/cut.recognition.json"),
    _case("track: 2000 frames/s header", "track {d}/fast.mp4 -o {d}/out/t.h5", "--fps",
          "out/t.h5"),
    _case("track: --fps 1e9", "track {d}/a.mp4 --fps 1e9 -o {d}/out/t.h5", "--fps", "out/t.h5"),
]


def _tree(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.is_fifo()}


def _limit(nbytes):
    def preexec():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write fails with EFBIG instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return preexec


@pytest.mark.parametrize("argv, message, output, files, limit", CASES)
def test_fault(argv, message, output, files, limit, inputs, tmp_path):
    d = tmp_path / "w"
    shutil.copytree(inputs, d)
    for name, make in files.items():
        (d / name).write_text(make) if isinstance(make, str) else make(d / name)
    video = Tracks.load(d / "a.tracks.h5").video["path"] if "{video}" in argv else None
    argv = [a.format(d=d, video=video) for a in argv.split()]
    before = _tree(d)
    env = {**os.environ, "PYTHONWARNINGS": "default"}  # warnings must be silenced by us
    proc = subprocess.run([sys.executable, "-m", "hammer_mv", *argv], capture_output=True,
                          text=True, timeout=300, cwd=d, env=env,
                          preexec_fn=_limit(limit) if limit else None)
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-2000:])
    one_line(proc.stderr, message)
    after = _tree(d)
    for path, digest in before.items():
        if path.startswith(".") or "/." in path:
            continue  # stale temporaries may be (and should be) cleaned up
        assert after.get(path) == digest, f"input {path} changed or vanished"
    assert output is None or not (d / output).exists(), f"{output} written"
    outside = [p for p in set(after) - set(before) if not p.startswith("out/")]
    assert outside == [], f"new files outside the output folder: {outside}"
    leftovers = [p for p in after if ".part" in p]
    assert leftovers == [], f"temporary files left behind: {leftovers}"


def test_a_rerun_removes_what_a_killed_writer_left(tmp_path):
    """Temporary files and folders of ended writers go; a live writer's stay."""
    from perception.io.atomic import remove_stale, write_text

    host = owner_tag().split("p")[0]
    dead = tmp_path / f".clip.{host}p999999.x1.part.json"
    live = tmp_path / f".clip.{owner_tag()}.x2.part.json"
    other_host = tmp_path / ".clip.hffffffp999999.x3.part.json"
    for p in (dead, live, other_host):
        p.write_text("{")
    write_text(tmp_path / "clip.json", "{}")
    assert not dead.exists() and live.exists() and other_host.exists()
    folder = tmp_path / f".repertoire-{host}p999999-abc"
    folder.mkdir()
    (folder / "repertoire.h5").write_bytes(b"x")
    assert remove_stale(tmp_path, ".repertoire-h*p*") == 1 and not folder.exists()

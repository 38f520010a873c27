"""Every fault kind holds its promise: one line on stderr, exit 2, inputs untouched.

A table of hostile or careless command lines, one row per case, grouped by
kind (data loss, disk full, outside names, malformed HDF5, unknown TOML,
unbounded sizes, truncated video). Every row is checked the
same way (:func:`_check`): exit status 2, exactly one line on stderr (no
traceback, no warning, no FFmpeg chatter), every input byte-identical, no
file under the output's final name and nothing new outside the output
folder. A new command gets the same checks by adding rows.
"""

from __future__ import annotations

import hashlib
import os
import resource
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pytest

from perception.io.atomic import owner_tag
from perception.io.tracks import Tracks
from perception.io.video import write_video
from perception.synthetic.demos import render_demo_clip
from perception.tracking.tracker import track_video

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


@dataclass
class Case:
    """One command line run in a fresh copy of the inputs.

    ``prepare(folder)`` makes whatever else the case needs and returns the
    arguments after ``hammer-mv``; ``output`` is the path (relative to the
    folder) that must not exist afterwards; ``message`` a piece of the one
    stderr line.
    """

    prepare: object
    message: str
    output: str | None = "out"
    limit_bytes: int | None = None  # a disk that fills after this many bytes per file


def _broken(source: str, name: str, change, argv):
    """A copy ``name`` of the HDF5 file ``source`` with one object broken by
    ``change(h5py.File)``; the command line ``argv`` ("{bad}" and "{d}" filled in)."""
    def prepare(d: Path) -> list[str]:
        bad = d / name
        bad.write_bytes((d / source).read_bytes())
        with h5py.File(bad, "a") as fh:
            change(fh)
        return [a.format(bad=bad, d=d) for a in argv]
    return prepare


def _h5_variant(change):
    """A tracks file with one object broken, read by ``tracks info``."""
    return _broken("a.tracks.h5", "bad.tracks.h5", change, ["tracks", "info", "{bad}"])


def _soft_link(fh):
    fh.move("tracks/position", "tracks/position_data")
    fh["tracks/position"] = h5py.SoftLink("/tracks/position_data")


def _external_link(fh):
    del fh["tracks/position"]
    fh["tracks/position"] = h5py.ExternalLink("elsewhere.h5", "/x")


def _compound(fh):
    pos = fh["tracks/position"][()]
    del fh["tracks/position"]
    rec = np.zeros(pos.shape[:-1], dtype=[("x", "f8"), ("y", "f8")])
    fh["tracks/position"] = rec


def _array_attr(fh):
    fh["video"].attrs["fps_nominal"] = np.array([30.0, 25.0])


def _repertoire_variant(change):
    """A repertoire file with one object broken, used to recognise."""
    return _broken("rep.h5", "bad.h5", change,
                   ["recognize", "{d}/a.tracks.h5", "--repertoire", "{bad}", "-o", "{d}/out",
                    "--no-figures"])


def _zero_dt(fh):
    for name in fh["models"]:
        fh["models"][name].attrs["dt"] = 0.0


def _write(name: str, text: str, args):
    def prepare(d: Path) -> list[str]:
        (d / name).write_text(text)
        return [a.replace("{d}", str(d)) for a in args]
    return prepare


CASES = {
    # -- data loss: an output that is an input, or not a regular file
    "track -o its own video": Case(lambda d: ["track", str(d / "a.mp4"), "-o",
                                              str(d / "a.mp4")], "is also an input", None),
    "track --labelled-video its own video": Case(
        lambda d: ["track", str(d / "a.mp4"), "-o", str(d / "out/t.h5"), "--labelled-video",
                   str(d / "a.mp4")], "is also an input", "out/t.h5"),
    "tracks export over its input": Case(
        lambda d: ["tracks", "export", str(d / "a.tracks.h5"), "-o", str(d / "a.tracks.h5"),
                   "--format", "csv"], "is also an input", None),
    "tracks render over its video": Case(
        lambda d: ["tracks", "render", str(d / "a.tracks.h5"), str(d / "a.mp4"), "-o",
                   str(d / "a.mp4")], "is also an input", None),
    "tracks render over the video its tracks name": Case(
        lambda d: ["tracks", "render", str(d / "a.tracks.h5"), "-o",
                   Tracks.load(d / "a.tracks.h5").video["path"]],
        "is also an input", None),
    "repertoire build over its config": Case(
        _write("rep.toml", "durations = [1.0]\n",
               ["repertoire", "build", "{d}/rep.toml", "-o", "{d}/rep.toml"]),
        "is also an input", None),
    "track -o a FIFO": Case(lambda d: (os.mkfifo(d / "fifo"), ["track", str(d / "a.mp4"), "-o",
                                                               str(d / "fifo")])[1],
                            "not a regular file", "out"),
    "track -o a folder": Case(lambda d: ((d / "dir").mkdir(), ["track", str(d / "a.mp4"), "-o",
                                                               str(d / "dir")])[1],
                              "is a folder", "out"),
    # -- disk full (a file-size limit stands in for a full disk)
    "disk full: track": Case(lambda d: ["track", str(d / "a.mp4"), "-o", str(d / "out/t.h5")],
                             "cannot write", "out/t.h5", limit_bytes=20_000),
    "disk full: tracks export": Case(
        lambda d: ["tracks", "export", str(d / "a.tracks.h5"), "-o", str(d / "out/t.csv"),
                   "--format", "csv"], "cannot write", "out/t.csv", limit_bytes=2_000),
    "disk full: repertoire build": Case(
        lambda d: ["repertoire", "build", "--durations", "1.0", "-o", str(d / "out/r.h5")],
        "cannot write", "out/r.h5", limit_bytes=20_000),
    "disk full: synth": Case(
        _write("r.toml", "[conditions]\nnormal = 1\n", ["synth", "{d}/r.toml", "-o", "{d}/out"]),
        "cannot write", "out/normal-01.mp4", limit_bytes=20_000),
    "disk full: labelled video": Case(
        lambda d: ["tracks", "render", str(d / "a.tracks.h5"), str(d / "a.mp4"), "-o",
                   str(d / "out/l.mp4")], "cannot write", "out/l.mp4", limit_bytes=20_000),
    # -- names from the outside world
    "manifest row escaping -o": Case(
        _write("m.csv", "clip,video\nok,a.mp4\n../escape,a.mp4\n",
               ["batch", "{d}/m.csv", "-o", "{d}/out"]), "row 3", "escape.recognition.json"),
    "duplicate manifest rows": Case(
        _write("m.csv", "clip,video\nx,a.mp4\nx,a.mp4\n", ["batch", "{d}/m.csv", "-o", "{d}/out"]),
        "appears twice (rows 2 and 3)", "out/summary.csv"),
    # -- malformed HDF5
    "tracks: soft link": Case(_h5_variant(_soft_link), "bad.tracks.h5"),
    "tracks: external link": Case(_h5_variant(_external_link), "bad.tracks.h5"),
    "tracks: compound dtype": Case(_h5_variant(_compound), "bad.tracks.h5"),
    "tracks: array-valued attribute": Case(_h5_variant(_array_attr), "bad.tracks.h5"),
    "tracks: not HDF5": Case(_write("bad.tracks.h5", "hello", ["tracks", "export",
                                                              "{d}/bad.tracks.h5", "-o",
                                                              "{d}/out/x.csv", "--format",
                                                              "csv"]),
                             "not an HDF5 file", "out/x.csv"),
    "repertoire: dt = 0": Case(_repertoire_variant(_zero_dt), "bad.h5",
                               "out/a.recognition.json"),
    "repertoire: not HDF5": Case(
        _write("bad.h5", "x", ["recognize", "{d}/a.tracks.h5", "--repertoire", "{d}/bad.h5",
                               "-o", "{d}/out"]), "not an HDF5 file", "out/a.recognition.json"),
    # -- unknown TOML tables and keys
    "recipe: misspelt table": Case(
        _write("r.toml", "[conditions]\nnormal = 1\n[scence]\nduration = 1.0\n",
               ["synth", "{d}/r.toml", "-o", "{d}/out"]), "did you mean 'scene'"),
    "recipe: misspelt scene key": Case(
        _write("r.toml", "[conditions]\nnormal = 1\n[scene]\nrest_befor = 0.3\n",
               ["synth", "{d}/r.toml", "-o", "{d}/out"]), "did you mean 'rest_before'"),
    "repertoire config: [[models]]": Case(
        _write("rep.toml", "[[models]]\nname = 'x'\n",
               ["repertoire", "build", "{d}/rep.toml", "-o", "{d}/out/r.h5"]),
        "did you mean 'model'", "out/r.h5"),
    "repertoire config: unknown top-level key": Case(
        _write("rep.toml", "duration = [1.0]\n",
               ["repertoire", "build", "{d}/rep.toml", "-o", "{d}/out/r.h5"]),
        "did you mean 'durations'", "out/r.h5"),
    "pose config: misspelt key": Case(
        _write("pose.toml", "pcutof = 0.5\n", ["recognize", "{d}/a.tracks.h5", "-o", "{d}/out",
                                               "--pose-config", "{d}/pose.toml"]),
        "did you mean 'pcutoff'"),
    # -- unbounded sizes
    "recipe: a billion frames/s": Case(
        _write("r.toml", "[conditions]\nnormal = 1\n[render]\nfps = 1e9\n",
               ["synth", "{d}/r.toml", "-o", "{d}/out"]), "frame rate"),
    "recipe: a day of rest": Case(
        _write("r.toml", "[conditions]\nnormal = 1\n[scene]\nrest_before = 1e5\n",
               ["synth", "{d}/r.toml", "-o", "{d}/out"]), "rest_before"),
    "recipe: a huge frame": Case(
        _write("r.toml", "[conditions]\nnormal = 1\n[render]\nwidth = 100000\n",
               ["synth", "{d}/r.toml", "-o", "{d}/out"]), "width and height"),
    "recipe: a million clips": Case(
        _write("r.toml", "[conditions]\nnormal = 1000000\n",
               ["synth", "{d}/r.toml", "-o", "{d}/out"]), "at most"),
    # -- truncated and mislabelled videos: one policy in every command
    "track: truncated video": Case(lambda d: ["track", str(d / "cut.avi"), "-o",
                                              str(d / "out/t.h5")], "truncated", "out/t.h5"),
    "recognize: truncated video": Case(lambda d: ["recognize", str(d / "cut.avi"), "-o",
                                                  str(d / "out")], "truncated",
                                       "out/cut.recognition.json"),
    "track: 2000 frames/s header": Case(lambda d: ["track", str(d / "fast.mp4"), "-o",
                                                   str(d / "out/t.h5")], "--fps", "out/t.h5"),
    "track: --fps 1e9": Case(lambda d: ["track", str(d / "a.mp4"), "--fps", "1e9", "-o",
                                        str(d / "out/t.h5")], "--fps", "out/t.h5"),
}


def _tree(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.is_fifo()}


def _limit(nbytes):
    def preexec():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write fails with EFBIG instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return preexec


@pytest.mark.parametrize("name", list(CASES))
def test_fault(name, inputs, tmp_path):
    case = CASES[name]
    d = tmp_path / "w"
    d.mkdir()
    for p in inputs.iterdir():
        (d / p.name).write_bytes(p.read_bytes())
    argv = case.prepare(d)
    before = _tree(d)
    env = {**os.environ, "PYTHONWARNINGS": "default"}  # warnings must be silenced by us
    proc = subprocess.run([sys.executable, "-m", "hammer_mv", *argv], capture_output=True,
                          text=True, timeout=300, cwd=d, env=env,
                          preexec_fn=_limit(case.limit_bytes) if case.limit_bytes else None)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-2000:])
    assert len(lines) == 1, proc.stderr[-2000:]
    assert case.message in lines[0], lines[0]
    after = _tree(d)
    for path, digest in before.items():
        if path.startswith(".") or "/." in path:
            continue  # stale temporaries may be (and should be) cleaned up
        assert after.get(path) == digest, f"input {path} changed or vanished"
    assert case.output is None or not (d / case.output).exists(), f"{case.output} written"
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

"""Files that lie: sizes, values and kinds of file are checked before they are believed.

Each test builds a small file that claims something absurd (a billion rows,
a position of 1e20 px, gains x 1e200, a header of 0 frames/s) or is not a
file at all (a FIFO), and checks that reading it ends in one
:class:`~perception.errors.InputError` naming the file and the field, fast
and without allocating what the file claims.
"""

from __future__ import annotations

import errno
import os
import pickle
import shutil
import struct
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import cv2
import h5py
import numpy as np
import pytest

from perception.errors import InputError
from perception.io import atomic
from perception.io.exports import export_tracks, status_path_for
from perception.io.pose import PoseImport, read_pose, write_dlc
from perception.io.repertoire import read_repertoire
from perception.io.tracks import Tracks
from perception.io.video import FrameSource, sha256_file, write_video

MARKERS = ("thumb", "finger", "wrist", "object")


def _tracks(n=20, markers=MARKERS, frame0=0, **video):
    rng = np.random.default_rng(0)
    m = len(markers)
    return Tracks(frame=np.arange(frame0, frame0 + n), time=np.arange(frame0, frame0 + n) / 30,
                  markers=markers, position=rng.uniform(10, 90, (n, m, 2)),
                  likelihood=np.ones((n, m)), status=np.zeros((n, m)),
                  video={"width": 96, "height": 64, "fps_nominal": 30.0, **video})


def _frames(n, w=96, h=64):
    for i in range(n):
        yield np.full((h, w, 3), 10 * i % 250, np.uint8)


# -- sizes claimed, refused before anything is read --------------------------------------
def test_tracks_claiming_half_a_billion_rows_is_refused_at_once(tmp_path):
    path = tmp_path / "huge.tracks.h5"
    _tracks().save(path)
    n = 500_000_000
    with h5py.File(path, "a") as fh:
        g = fh["tracks"]
        for name, tail, dtype in (("frame", (), "i8"), ("time", (), "f8"),
                                  ("position", (4, 2), "f8"), ("likelihood", (4,), "f4"),
                                  ("status", (4,), "i1")):
            del g[name]
            g.create_dataset(name, shape=(n, *tail), chunks=(1024, *tail), dtype=dtype)
    start = time.perf_counter()
    with pytest.raises(InputError) as err:
        Tracks.load(path)
    assert time.perf_counter() - start < 2.0
    assert str(path) in str(err.value)
    assert err.value.field and err.value.field.startswith("/tracks/")
    assert "claims" in err.value.problem


def test_sleap_file_claiming_two_billion_frames_is_refused_at_once(tmp_path):
    path = tmp_path / "huge.h5"
    with h5py.File(path, "w") as fh:
        fh.create_dataset("tracks", shape=(1, 2, 4, 2_000_000_000), chunks=(1, 2, 4, 4096),
                          dtype="f4")
        fh["node_names"] = np.array([m.encode() for m in MARKERS])
        fh["track_names"] = np.array([b"a"])
    from perception.io.pose import _movement

    _movement()  # importing movement takes seconds: not what is timed
    start = time.perf_counter()
    with pytest.raises(InputError) as err:
        read_pose(path, PoseImport(fps=30))
    assert time.perf_counter() - start < 2.0
    assert err.value.path == str(path) and err.value.field == "/tracks"


def test_video_of_16000_px_frames_is_refused_before_decoding(tmp_path, monkeypatch):
    path = tmp_path / "clip.avi"
    write_video(_frames(5), path, 30)
    real = cv2.VideoCapture

    class Huge:
        def __init__(self, *args):
            self._cap = real(*args)

        def get(self, prop):
            if prop in (cv2.CAP_PROP_FRAME_WIDTH, cv2.CAP_PROP_FRAME_HEIGHT):
                return 16000.0
            return self._cap.get(prop)

        def read(self):
            raise AssertionError("decoded a frame of a video it should have refused")

        def __getattr__(self, name):
            return getattr(self._cap, name)

    monkeypatch.setattr(cv2, "VideoCapture", Huge)
    with pytest.raises(InputError, match="16000 x 16000") as err:
        FrameSource(path, hash=False)
    assert err.value.path == str(path) and err.value.field == "frame size"


# -- values: positions, attributes ----------------------------------------------------------
def test_position_of_1e20_px_is_refused(tmp_path):
    t = _tracks()
    position = t.position.copy()
    position[3, 1] = (1e20, 5.0)
    path = t.replace(position=position).save(tmp_path / "far.tracks.h5")
    with pytest.raises(InputError, match="far outside the frame") as err:
        Tracks.load(path)
    assert err.value.field == "/tracks/position" and err.value.path == str(path)
    assert "finger" in err.value.problem


def test_infinite_position_is_refused_and_nan_is_lost(tmp_path):
    t = _tracks()
    position = t.position.copy()
    position[2, 0] = np.nan
    assert Tracks.load(t.replace(position=position).save(tmp_path / "ok.tracks.h5")).n_frames
    position[4, 0] = (np.inf, 1.0)
    path = t.replace(position=position).save(tmp_path / "inf.tracks.h5")
    with pytest.raises(InputError, match="infinite"):
        Tracks.load(path)


@pytest.mark.parametrize("value", [["thumb", "finger"], "[1, 2, 3]", "{not json",
                                   '{"thumb": {"bgr": [1, 2]}}'])
def test_colour_models_of_the_wrong_kind_are_refused(tmp_path, value):
    path = _tracks().replace(tracker={"colour_models": "{}"}).save(tmp_path / "c.tracks.h5")
    with h5py.File(path, "a") as fh:
        fh["tracker"].attrs["colour_models"] = value
    with pytest.raises(InputError) as err:
        Tracks.load(path)
    assert err.value.field == "/tracker.colour_models" and err.value.path == str(path)


def test_pose_tracks_and_options_pickle(tmp_path):
    t = _tracks()
    back = pickle.loads(pickle.dumps(t))
    assert back.markers == t.markers and dict(back.video) == dict(t.video)
    np.testing.assert_array_equal(back.position, t.position)
    options = PoseImport(keypoints={"thumb": "Thumb"}, fps=30.0, individual="a")
    again = pickle.loads(pickle.dumps(options))
    assert again == options and dict(again.keypoints) == {"thumb": "Thumb"}
    csv = write_dlc(t, tmp_path / "dlc.csv")
    pose = read_pose(csv, PoseImport(fps=30.0))
    assert pickle.loads(pickle.dumps(pose)).n_frames == t.n_frames


# -- repertoires ------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def repertoire_file(tmp_path_factory):
    from perception.recognition.models import ModelSpec
    from perception.recognition.repertoire import Repertoire

    rep = Repertoire.build([ModelSpec("g", "grasp", {"duration": 0.5})])
    return rep.save(tmp_path_factory.mktemp("rep") / "rep.h5")


def _scale(key, factor):
    def change(g):
        g[f"arm/{key}"][...] = g[f"arm/{key}"][()] * factor
    return change


def _substeps(value):
    def change(g):
        g.attrs["substeps"] = value
    return change


@pytest.mark.parametrize("change, field", [
    (_scale("L", 1e200), "/models/g/arm/L"),
    (_scale("K", 1e200), "/models/g/arm/K"),
    (_scale("P", -1.0), "/models/g/arm/P"),
    (_scale("P", 0.0), "/models/g/arm/P"),
    (_substeps(0), "/models/g.substeps"),
    (_substeps(-3), "/models/g.substeps"),
])
def test_repertoire_values_no_plan_has_are_refused(tmp_path, repertoire_file, change, field):
    path = tmp_path / "bad.h5"
    shutil.copy(repertoire_file, path)
    with h5py.File(path, "a") as fh:
        change(fh["models/g"])
    with pytest.raises(InputError) as err:
        read_repertoire(path)
    assert err.value.field == field and err.value.path == str(path)


def test_repertoire_good_file_still_reads(repertoire_file):
    _, models = read_repertoire(repertoire_file)
    assert [m.name for m in models] == ["g"] and models[0].substeps >= 1


def test_engine_refuses_a_model_that_predicts_nothing_finite():
    from types import SimpleNamespace

    from perception.recognition.engine import _refuse_broken_models, _refuse_non_finite

    models = [SimpleNamespace(name="good"), SimpleNamespace(name="huge")]
    observable = np.array([False, True, True, True])
    valid = np.array([[False, True, True, True], [False, False, False, False]])
    with pytest.raises(InputError, match="huge predicts no finite hand position"):
        _refuse_broken_models(models, observable, valid)
    _refuse_broken_models(models, observable, valid[[0, 0]])  # both fine
    with pytest.raises(InputError, match="log-likelihood of model huge"):
        _refuse_non_finite(models, {"log-likelihood": np.array([[0.0, 1.0], [0.0, np.nan]])})


# -- frame rates in headers -------------------------------------------------------------------
def _avi_with_rate(path: Path, rate: int, usec: int) -> Path:
    write_video(_frames(10), path, 30)
    data = bytearray(path.read_bytes())
    i = data.find(b"strh")
    assert data[i + 8:i + 12] == b"vids"
    data[i + 32:i + 36] = struct.pack("<I", rate)
    j = data.find(b"avih")
    data[j + 8:j + 12] = struct.pack("<I", usec)
    path.write_bytes(bytes(data))
    return path


def test_header_of_0_frames_per_second_is_refused_not_read_as_25(tmp_path):
    path = _avi_with_rate(tmp_path / "zero.avi", 0, 0)
    with pytest.raises(InputError, match="no frame rate.*--fps") as err:
        FrameSource(path, hash=False)
    assert err.value.field == "frame rate" and err.value.path == str(path)
    times = [t for _, t, _ in FrameSource(path, hash=False, fps=30.0)]
    np.testing.assert_allclose(times, np.arange(10) / 30.0)


def test_header_of_1000_frames_per_second_is_refused(tmp_path):
    path = tmp_path / "ms.mp4"
    write_video(_frames(10), path, 1000.0)
    with pytest.raises(InputError, match="claims 1000 frames/s.*--fps") as err:
        FrameSource(path, hash=False)
    assert err.value.field == "frame rate"
    assert FrameSource(path, hash=False, fps=500.0).header.fps_nominal == 1000.0


# -- exports: bounded, and whole or not at all ---------------------------------------------
@pytest.mark.parametrize("fmt, name", [("dlc", "x.h5"), ("dlc", "x.csv"), ("csv", "x.csv"),
                                       ("trackpy", "x.csv"), ("movement", "x.nc")])
def test_export_onto_a_full_disk_leaves_nothing(tmp_path, monkeypatch, fmt, name):
    out = tmp_path / "out"
    out.mkdir()

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(atomic.os, "fsync", full)
    with pytest.raises(OSError) as err:
        export_tracks(_tracks(), out / name, fmt)
    assert err.value.errno == errno.ENOSPC
    assert sorted(os.listdir(out)) == []


def test_dlc_export_whose_status_file_fails_leaves_no_table(tmp_path, monkeypatch):
    real = atomic.write_bytes

    def fail_status(path, data):
        if str(path).endswith(".status.csv"):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(path, data)

    monkeypatch.setattr(atomic, "write_bytes", fail_status)
    with pytest.raises(OSError):
        export_tracks(_tracks(), tmp_path / "x.csv", "dlc")
    assert not (tmp_path / "x.csv").exists()
    assert not status_path_for(tmp_path / "x.csv").exists()


def test_export_of_2000_markers_is_one_line(tmp_path):
    markers = tuple(f"m{i}" for i in range(2000))
    with pytest.raises(InputError, match="2000 markers") as err:
        export_tracks(_tracks(n=3, markers=markers), tmp_path / "x.h5", "dlc")
    assert err.value.field == "markers"
    assert os.listdir(tmp_path) == []


# -- render: the tracked video, found beside the tracks ---------------------------------------
def test_render_refuses_a_video_other_than_the_tracked_one(tmp_path, monkeypatch):
    from perception.tracking.overlay import render_labelled

    folder = tmp_path / "clips"
    folder.mkdir()
    video = folder / "clip.avi"
    write_video(_frames(8), video, 30)
    tracks = _tracks(n=8, path="clip.avi", sha256=sha256_file(video))
    saved = Tracks.load(tracks.save(folder / "clip.tracks.h5"))
    monkeypatch.chdir(tmp_path)  # the stored path is relative to the tracks, not to here
    out = render_labelled(saved, None, tmp_path / "labelled.avi")
    assert out.exists()
    other = tmp_path / "other.avi"
    write_video(_frames(8, w=96), other, 25)
    (tmp_path / "labelled.avi").unlink()
    with pytest.raises(InputError, match="not the tracked video") as err:
        render_labelled(saved, other, tmp_path / "labelled.avi")
    assert err.value.path == str(other)
    shutil.copy(other, video)  # another video at the stored path
    with pytest.raises(InputError, match="not the tracked video"):
        render_labelled(saved, None, tmp_path / "labelled.avi")
    assert not (tmp_path / "labelled.avi").exists()


# -- pose files ------------------------------------------------------------------------------
def test_two_markers_on_one_keypoint_are_refused():
    with pytest.raises(InputError, match="thumb and finger both map to keypoint 'finger'") as e:
        PoseImport(keypoints={"thumb": "finger"})
    assert e.value.field == "--keypoints"
    with pytest.raises(InputError) as e:
        PoseImport(keypoints={"thumb": "tip", "finger": "tip"})
    assert e.value.field == "--keypoints"
    swapped = PoseImport(keypoints={"thumb": "finger", "finger": "index"})
    assert swapped.keypoint("thumb") == "finger"


@pytest.mark.parametrize("name", ["dlc.csv", "dlc.h5"])
def test_deeplabcut_frame_numbers_are_kept(tmp_path, name):
    t = _tracks(n=12, frame0=42150)
    path = write_dlc(t, tmp_path / name)
    back = read_pose(path, PoseImport(fps=30.0))
    np.testing.assert_array_equal(back.frame, np.arange(42150, 42162))
    np.testing.assert_allclose(back.time, back.frame / 30.0)
    np.testing.assert_allclose(back.position, t.position)


def test_reading_a_pose_file_writes_nothing_under_home_and_prints_nothing(tmp_path):
    csv = write_dlc(_tracks(), tmp_path / "dlc.csv")
    home = tmp_path / "home"
    home.mkdir()
    home.chmod(0o500)  # read-only: movement's default log could not be made
    code = textwrap.dedent(f"""
        import warnings
        warnings.simplefilter("default")
        from perception.io.pose import PoseImport, read_pose
        t = read_pose({str(csv)!r}, PoseImport(fps=30.0))
        print(t.n_frames)
    """)
    env = {**os.environ, "HOME": str(home), "PYTHONWARNINGS": "default"}
    try:
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                              text=True, timeout=120, cwd=tmp_path)
    finally:
        home.chmod(0o700)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "20"
    assert list(home.iterdir()) == []
    assert "movement" not in done.stderr and "deprecated" not in done.stderr, done.stderr


# -- not files at all --------------------------------------------------------------------------
def _raises_within(seconds, fn, *args):
    outcome = {}

    def run():
        try:
            fn(*args)
        except BaseException as exc:  # noqa: BLE001 - handed to the test
            outcome["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        # unblock the reader so the test process can end, then fail
        with open(args[0], "wb"):
            pass
        pytest.fail(f"{fn.__name__} blocked on a FIFO")
    return outcome.get("error")


@pytest.mark.parametrize("reader, name", [
    (Tracks.load, "fifo.tracks.h5"),
    (read_repertoire, "fifo.h5"),
    (lambda p: read_pose(p, PoseImport(fps=30)), "fifo.csv"),
    (lambda p: FrameSource(p, hash=False), "fifo.mp4"),
])
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_is_refused_within_a_second(tmp_path, reader, name):
    path = tmp_path / name
    os.mkfifo(path)
    error = _raises_within(1.0, reader, path)
    assert isinstance(error, InputError), error
    assert "not a regular file" in str(error) and str(path) in str(error)


def test_pose_position_of_1e20_px_is_refused(tmp_path):
    t = _tracks()
    position = t.position.copy()
    position[5, 2] = (3.0, 1e20)
    path = write_dlc(t.replace(position=position), tmp_path / "far.csv")
    with pytest.raises(InputError, match="'wrist' at row 5") as err:
        read_pose(path, PoseImport(fps=30.0))
    assert err.value.field == "position" and err.value.path == str(path)

"""Files that lie: sizes, values and kinds of file are checked before they are believed.

Each case builds a small file that claims something absurd (a billion rows, a
position of 1e20 px, gains x 1e200, a header of 0 frames/s) or is not a file
at all (a FIFO); reading it must end, fast and without allocating what the
file claims, in one :class:`~perception.errors.InputError` naming the file
and the field.
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
import tracemalloc

import cv2
import h5py
import numpy as np
import pytest
from _faults import error_within, refused

from perception.errors import InputError
from perception.io import atomic
from perception.io.exports import export_tracks, status_path_for, write_dlc
from perception.io.pose import PoseImport, _movement, read_pose
from perception.io.repertoire import read_repertoire
from perception.io.tracks import Tracks
from perception.io.video import FrameSource, sha256_file, write_video
from perception.synthetic.recipes import load_recipe
from perception.tracking.markers import load_markers
from perception.tracking.setup import load_setup

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


def _read_pose(path):
    return read_pose(path, PoseImport(fps=30))


def _read_video(path):
    return FrameSource(path, hash=False)


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A good tracks file (with colour models) and repertoire file to break."""
    from perception.recognition.models import ModelSpec
    from perception.recognition.repertoire import Repertoire

    folder = tmp_path_factory.mktemp("good")
    rep = Repertoire.build([ModelSpec("g", "grasp", {"duration": 0.5})])
    return {"rep.h5": rep.save(folder / "rep.h5"),
            "t.tracks.h5": _tracks(tracker={"colour_models": "{}"}).save(folder / "t.tracks.h5")}


# A change breaks one object of an open HDF5 file.
def _set(key, index, value):
    def change(fh):
        fh[key][index] = value
    return change


def _attr(key, name, value):
    def change(fh):
        fh[key].attrs[name] = value
    return change


def _scale(key, factor):
    def change(fh):
        fh[key][...] = fh[key][()] * factor
    return change


def _claim(fh):  # half a billion rows
    for name, tail, dtype in (("frame", (), "i8"), ("time", (), "f8"), ("position", (4, 2), "f8"),
                              ("likelihood", (4,), "f4"), ("status", (4,), "i1")):
        del fh["tracks"][name]
        fh["tracks"].create_dataset(name, shape=(500_000_000, *tail), chunks=(1024, *tail),
                                    dtype=dtype)


# A maker writes a file into ``folder`` and returns its path.
def _sleap(folder):  # two billion frames
    with h5py.File(folder / "huge.h5", "w") as fh:
        fh.create_dataset("tracks", shape=(1, 2, 4, 2_000_000_000), chunks=(1, 2, 4, 4096),
                          dtype="f4")
        fh["node_names"] = np.array([m.encode() for m in MARKERS])
        fh["track_names"] = np.array([b"a"])
    return folder / "huge.h5"


def _dlc_far(folder):
    t = _tracks()
    position = t.position.copy()
    position[5, 2] = (3.0, 1e20)
    return write_dlc(t.replace(position=position), folder / "far.csv")


def _avi_at_0(folder):
    path = folder / "zero.avi"
    write_video(_frames(10), path, 30)
    data = bytearray(path.read_bytes())
    i = data.find(b"strh")
    assert data[i + 8:i + 12] == b"vids"
    data[i + 32:i + 36] = struct.pack("<I", 0)  # rate
    j = data.find(b"avih")
    data[j + 8:j + 12] = struct.pack("<I", 0)  # microseconds per frame
    path.write_bytes(bytes(data))
    return path


def _mp4_at_1000(folder):
    write_video(_frames(10), folder / "ms.mp4", 1000.0)
    return folder / "ms.mp4"


def _case(name, make, read, field, match=None):
    """``make``: a maker, or (good file, change); ``field``: "/x/" is any field under /x/."""
    return pytest.param(make, read, field, match, id=name)


TRACKS, REP = "t.tracks.h5", "rep.h5"
FILES = [
    # -- sizes claimed, refused before anything is read
    _case("tracks claiming half a billion rows", (TRACKS, _claim), Tracks.load, "/tracks/",
          "claims"),
    _case("SLEAP file claiming two billion frames", _sleap, _read_pose, "/tracks", "claims"),
    # -- values: positions, attributes
    _case("position of 1e20 px", (TRACKS, _set("tracks/position", (3, 1), (1e20, 5.0))),
          Tracks.load, "/tracks/position", r"(?s)^(?=.*finger).*far outside the frame"),
    _case("infinite position", (TRACKS, _set("tracks/position", (4, 0), (np.inf, 1.0))),
          Tracks.load, "/tracks/position", "infinite"),
    _case("pose position of 1e20 px", _dlc_far, _read_pose, "position", "'wrist' at row 5"),
    *[_case(f"colour models {value!r}", (TRACKS, _attr("tracker", "colour_models", value)),
            Tracks.load, "/tracker.colour_models")
      for value in [["thumb", "finger"], "[1, 2, 3]", "{not json", '{"thumb": {"bgr": [1, 2]}}']],
    # -- repertoire values no plan has
    *[_case(f"repertoire {name}", (REP, change), read_repertoire, field)
      for name, change, field in [
          ("L x 1e200", _scale("models/g/arm/L", 1e200), "/models/g/arm/L"),
          ("K x 1e200", _scale("models/g/arm/K", 1e200), "/models/g/arm/K"),
          ("P x -1", _scale("models/g/arm/P", -1.0), "/models/g/arm/P"),
          ("P x 0", _scale("models/g/arm/P", 0.0), "/models/g/arm/P"),
          ("substeps 0", _attr("models/g", "substeps", 0), "/models/g.substeps"),
          ("substeps -3", _attr("models/g", "substeps", -3), "/models/g.substeps")]],
    # -- frame rates in headers
    _case("header of 0 frames/s, not read as 25", _avi_at_0, _read_video, "frame rate",
          "no frame rate.*`fps`"),
    _case("header of 1000 frames/s", _mp4_at_1000, _read_video, "frame rate",
          "claims 1000 frames/s.*`fps`"),
]


@pytest.mark.parametrize("make, read, field, match", FILES)
def test_a_file_that_lies_is_refused_naming_file_and_field(make, read, field, match, tmp_path,
                                                           good):
    if callable(make):
        path = make(tmp_path)
    else:
        path = shutil.copy(good[make[0]], tmp_path)
        with h5py.File(path, "a") as fh:
            make[1](fh)
    if read is _read_pose:
        _movement()  # importing movement allocates: not what is measured
    # refused before the claimed sizes are read: measured by what is allocated, not by the
    # time it takes (which depends on the machine and its load); reading what the files
    # claim would take gigabytes
    tracemalloc.start()
    try:
        error = refused(read, path, path=path, match=match)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64e6, peak
    assert error.field == field or field.endswith("/") and error.field.startswith(field), error


def test_good_files_still_read(tmp_path, good):
    _, models = read_repertoire(good[REP])
    assert [m.name for m in models] == ["g"] and models[0].substeps >= 1
    path = shutil.copy(good[TRACKS], tmp_path)
    with h5py.File(path, "a") as fh:
        fh["tracks/position"][2, 0] = np.nan  # a NaN position is a lost marker
    assert Tracks.load(path).n_frames
    # a header refused is read with the frame rate given
    times = [t for _, t, _ in FrameSource(_avi_at_0(tmp_path), hash=False, fps=30.0)]
    np.testing.assert_allclose(times, np.arange(10) / 30.0)
    assert FrameSource(_mp4_at_1000(tmp_path), hash=False, fps=500.0).header.fps_nominal == 1000.0


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
    assert e.value.location == ("PoseImport", "keypoints")  # the CLI's --keypoints
    with pytest.raises(InputError) as e:
        PoseImport(keypoints={"thumb": "tip", "finger": "tip"})
    assert e.value.location == ("PoseImport", "keypoints")
    swapped = PoseImport(keypoints={"thumb": "finger", "finger": "index"})
    assert swapped.keypoint("thumb") == "finger"


@pytest.mark.parametrize("name", ["dlc.csv", "dlc.h5"])
def test_deeplabcut_frame_numbers_are_kept(tmp_path, name):
    t = _tracks(n=12, frame0=42150)
    path = write_dlc(t, tmp_path / name)
    # random positions read as spikes by the cleaning: read the points as written
    back = read_pose(path, PoseImport(fps=30.0, cleaning=None))
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


# -- not files at all
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
@pytest.mark.parametrize("read, name", [
    (load_setup, "setup.toml"), (load_markers, "colours.toml"), (load_markers, "colours.json"),
    (load_recipe, "recipe.toml"), (Tracks.load, "fifo.tracks.h5"), (read_repertoire, "fifo.h5"),
    (_read_pose, "fifo.csv"), (_read_video, "fifo.mp4"),
], ids=lambda v: v if isinstance(v, str) else None)
def test_a_fifo_is_refused_before_it_is_opened(tmp_path, read, name):
    path = tmp_path / name
    os.mkfifo(path)
    error = error_within(read, path)
    assert isinstance(error, InputError), error
    assert "not a regular file" in str(error) and str(path) in str(error)

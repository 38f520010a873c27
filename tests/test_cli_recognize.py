"""`hammer-mv recognize` on tracks files: bad inputs are one line and exit 2."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _cli import hammer_here
from _demos import default_repertoire, demo_tracks


@pytest.fixture(scope="module")
def repfile(tmp_path_factory):
    return default_repertoire().save(tmp_path_factory.mktemp("rep") / "rep.h5")


def _recognize(path, out, repfile, *extra):
    """``hammer-mv recognize`` as a subprocess: for what the process shows (exit status 2 in
    one line); the lines and files of a run are tested in-process (:func:`_recognize_here`)."""
    return subprocess.run([sys.executable, "-m", "hammer_mv", "recognize", str(path), "-o",
                           str(out), "--repertoire", str(repfile), *extra],
                          capture_output=True, text=True)


def _recognize_here(capsys, path, out, repfile, *extra):
    return hammer_here(capsys, "recognize", path, "-o", out, "--repertoire", repfile, *extra)


def _save(tracks, path):
    tracks.save(path)
    return path


def test_tracks_file_is_recognised(tmp_path, repfile, capsys):
    path = _save(demo_tracks("normal", 0)[0], tmp_path / "n.tracks.h5")
    proc = _recognize_here(capsys, path, tmp_path / "out", repfile)
    assert proc.returncode == 0, proc.stderr
    assert "winner grasp-" in proc.stdout
    assert (tmp_path / "out" / "n.recognition.json").exists()


@pytest.mark.parametrize("marker, message", [("finger", "marker 'finger' is never seen"),
                                             ("object", "object is never seen")])
def test_marker_missing_for_the_whole_clip(tmp_path, repfile, marker, message):
    tracks = demo_tracks("normal", 0)[0]
    pos = tracks.position.copy()
    pos[:, tracks.markers.index(marker)] = np.nan
    path = _save(tracks.replace(position=pos), tmp_path / "m.tracks.h5")
    proc = _recognize(path, tmp_path / "out", repfile)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and message in proc.stderr and "m.tracks.h5" in proc.stderr
    assert not (tmp_path / "out" / "m.recognition.json").exists()


def test_clip_too_short(tmp_path, repfile):
    t = demo_tracks("normal", 0)[0]
    short = t.replace(frame=t.frame[:6], time=t.time[:6], position=t.position[:6],
                      likelihood=t.likelihood[:6], status=t.status[:6])
    proc = _recognize(_save(short, tmp_path / "s.tracks.h5"), tmp_path / "out", repfile)
    assert proc.returncode == 2 and "too short" in proc.stderr


def test_corrupt_repertoire(tmp_path):
    path = _save(demo_tracks("normal", 0)[0], tmp_path / "n.tracks.h5")
    bad = tmp_path / "rep.h5"
    bad.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    proc = _recognize(path, tmp_path / "out", bad)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "rep.h5" in proc.stderr


@pytest.mark.parametrize("extra, message", [(["--rule", "vote"], "invalid choice"),
                                            (["--filter-gain", "3"], "--filter-gain: "),
                                            (["--object-diameter", "-1"],
                                             "--object-diameter: ")])
def test_bad_options(tmp_path, repfile, extra, message):
    path = _save(demo_tracks("normal", 0)[0], tmp_path / "n.tracks.h5")
    proc = _recognize(path, tmp_path / "out", repfile, *extra)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and message in proc.stderr


@pytest.mark.parametrize("kind", ["tracks", "mocap"])
def test_recognize_of_a_file_that_is_not_video_never_loads_opencv(tmp_path, kind):
    # OpenCV (0.2 s of start-up) was imported by every recognize, to turn its thread pool
    # off, also for inputs that are never tracked. (A pose file still loads it: movement's
    # readers import sleap_io, which imports cv2.)
    import subprocess
    import sys
    from pathlib import Path

    from perception.synthetic.demos import demo_tracks

    extra = []
    if kind == "tracks":
        path = demo_tracks("normal")[0].save(tmp_path / "clip.tracks.h5")
    else:
        path = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"
        extra = ["--rate", "85", "--markers", "thumb=thumb", "finger=index"]
    res = subprocess.run([sys.executable, "-X", "importtime", "-m", "hammer_mv", "recognize",
                          str(path), "-o", str(tmp_path / "out"), "--no-figures", "--quiet",
                          *extra], capture_output=True, text=True, timeout=300)
    assert res.returncode in (0, 1), res.stderr[-2000:]
    imported = [line.rsplit("|", 1)[-1].strip() for line in res.stderr.splitlines()
                if line.startswith("import time:")]
    assert imported and "cv2" not in imported


def test_flags_another_kind_of_input_reads_are_said_not_read(tmp_path, repfile, capsys):
    """--rate and --markers are read from a motion-capture recording, --keypoints from a pose
    file: given for a tracks file they were dropped without a word."""
    path = _save(demo_tracks("normal", 0)[0], tmp_path / "n.tracks.h5")
    proc = _recognize_here(capsys, path, tmp_path / "out", repfile, "--no-figures", "--rate",
                           "85", "--markers", "thumb=x", "finger=y", "--keypoints", "thumb=a",
                           "finger=b")
    assert proc.returncode == 0, proc.stderr
    warned = [line for line in proc.stderr.splitlines() if "not read" in line]
    assert warned == ["hammer-mv recognize: warning: --markers, --rate (options of a "
                      "motion-capture recording); --keypoints (options of a pose file) not "
                      "read: the input is a tracks file"]
    # a recording's own flags are read; a pose file's are not
    table = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"
    proc = _recognize_here(capsys, table, tmp_path / "rec", repfile, "--no-figures", "--rate",
                           "85", "--markers", "thumb=thumb", "finger=index", "--pcutoff", "0.5")
    assert "--pcutoff (options of a pose file) not read: the input is a motion-capture " \
           "recording" in proc.stderr
    assert "--rate" not in proc.stderr
    # nothing said where every flag given is read
    proc = _recognize_here(capsys, path, tmp_path / "out2", repfile, "--no-figures")
    assert "not read" not in proc.stderr

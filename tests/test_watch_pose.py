"""`watch` from a pose file: its keypoints fed row by row score as `recognize` on the file."""

from __future__ import annotations

import filecmp
import json
import subprocess
import sys

import pytest
from _cli import hammer_here
from _demos import default_repertoire, demo_tracks

from perception.io.exports import export_tracks


@pytest.fixture(scope="module")
def pose(tmp_path_factory):
    d = tmp_path_factory.mktemp("pose")
    tracks = demo_tracks("delayed", 2)[0]
    path = d / "trial.tracks.h5"
    tracks.save(path)
    dlc = d / "trialDLC_resnet50_labJan1shuffle1_1000.h5"
    export_tracks(tracks, dlc, "dlc")
    rep = default_repertoire().save(d / "rep.h5")
    return dlc, rep, tracks.object_diameter_px()


def _cli(*args):
    """``hammer-mv *args`` as a subprocess: for what the process shows (exit status 2 in one
    line); the lines and files of a command are tested in-process (:func:`hammer_here`)."""
    return subprocess.run([sys.executable, "-m", "hammer_mv", *map(str, args)],
                          capture_output=True, text=True, timeout=300)


def test_a_pose_file_watched_is_the_pose_file_recognised(pose, tmp_path, capsys):
    dlc, rep, diameter = pose
    opts = ["--fps", "30", "--object-diameter-px", diameter, "--repertoire", rep, "--no-figures"]
    a = hammer_here(capsys, "recognize", dlc, "-o", tmp_path / "a", *opts)
    b = hammer_here(capsys, "watch", dlc, "-o", tmp_path / "b", "--as-fast-as-possible", "--live",
                    *opts)
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    name = "trial.recognition.json"  # a DeepLabCut file is named after its video
    off = json.loads((tmp_path / "a" / name).read_text())
    on = json.loads((tmp_path / "b" / name).read_text())
    online = on.pop("online")
    assert on == off and online["source"] == "pose" and online["agrees"]
    assert filecmp.cmp(tmp_path / "a" / "trial.confidence.csv",
                       tmp_path / "b" / "trial.confidence.csv", shallow=False)
    # the live lines tell a provisional verdict (?) from the settled one (capitals)
    lines = [line.rstrip() for line in b.stdout.splitlines() if " s  moving " in line]
    first = next((k for k, line in enumerate(lines) if "SETTLED" in line), len(lines))
    # before the decision every verdict is provisional (?), from it on the settled one
    assert first > 0 and all("?" in line and "SETTLED" not in line for line in lines[:first])
    assert all("SETTLED" in line for line in lines[first:])
    assert online["settled_early"] == (first < len(lines))


def test_a_pose_file_has_no_frames_to_label(pose, tmp_path):
    dlc, rep, diameter = pose
    res = _cli("watch", dlc, "-o", tmp_path / "o", "--fps", "30", "--object-diameter-px",
               diameter, "--repertoire", rep, "--labelled-video", tmp_path / "v.mp4")
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1
    assert "--labelled-video" in res.stderr and not (tmp_path / "v.mp4").exists()


def test_a_pose_file_lacking_a_keypoint_is_one_line_and_status_2(pose, tmp_path):
    import dataclasses

    _, rep, diameter = pose
    tracks = demo_tracks("delayed", 2)[0]
    keep = [tracks.markers.index(m) for m in ("thumb", "wrist", "object")]
    dlc = tmp_path / "trialDLC_resnet50_labJan1shuffle1_1000.h5"
    export_tracks(dataclasses.replace(tracks, markers=tuple(tracks.markers[k] for k in keep),
                                      position=tracks.position[:, keep],
                                      likelihood=tracks.likelihood[:, keep],
                                      status=tracks.status[:, keep]), dlc, "dlc")
    res = _cli("watch", dlc, "-o", tmp_path / "o", "--fps", "30", "--object-diameter-px",
               diameter, "--repertoire", rep, "--as-fast-as-possible")
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1, res.stderr
    assert "keypoint 'finger'" in res.stderr and "Traceback" not in res.stderr
    assert not (tmp_path / "o" / "trial.recognition.json").exists()

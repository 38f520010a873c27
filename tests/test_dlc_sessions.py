"""DeepLabCut and SLEAP output folders as those tools write them (issue 34, item 1).

A trial is the video; what DeepLabCut writes beside it (``<video>DLC_<scorer>.h5``,
``.csv``, ``_filtered.h5``, ``_meta.pickle``, ``_labeled.mp4``) and SLEAP's
``.analysis.h5`` are that trial's pose files, counted once, timed at the video's
frame rate. Names from DeepLabCut's ``auxiliaryfunctions`` and ``filtering``
and SLEAP's ``sleap/io/convert.py`` (docs/pose-files.md).
"""

import json
import shutil

import numpy as np
import pandas as pd
import pytest
from _demos import default_repertoire

from perception.batch import run_batch
from perception.discovery import find_clips
from perception.errors import InputError
from perception.io.exports import write_dlc
from perception.io.pose import PoseImport, pose_output, read_pose, video_beside
from perception.observation import ObserveParams, observe
from perception.pipeline import RecognitionSettings, clip_name
from perception.synthetic.demos import demo_tracks, render_demo_clip

movement = pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")

FPS = 25.0  # not 30: the rate can only have come from the videos
SCORER = "DLC_resnet50_xShuffle1_1000"
SETTINGS = RecognitionSettings(pose=PoseImport(object_diameter_px=80.0))


def _sleap_analysis(tracks, path):
    from movement.io import load_poses, save_poses

    pos = np.transpose(tracks.position, (0, 2, 1))[..., None]
    ds = load_poses.from_numpy(pos, tracks.likelihood[..., None].astype(float),
                               individual_names=["hand"], keypoint_names=list(tracks.markers))
    save_poses.to_sleap_analysis_file(ds, path)


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """Three trials: two analysed by DeepLabCut (one filtered), one exported from SLEAP."""
    out = tmp_path_factory.mktemp("dlc")
    for k, (stem, cond) in enumerate([("trial01", "normal"), ("trial02", "delayed"),
                                      ("trial03", "normal")]):
        render_demo_clip(out, f"{stem}.mp4", n=20, fps=FPS, width=96, height=72, seed=k)
        (out / f"{stem}.truth.h5").unlink()
        tracks, _ = demo_tracks(cond, k, fps=FPS)
        if stem == "trial03":
            _sleap_analysis(tracks, out / "labels.v001.000_trial03.analysis.h5")
            (out / "trial03.mp4.predictions.slp").write_bytes(b"never opened")
            continue
        for end in (".h5", ".csv") + (("_filtered.h5",) if stem == "trial01" else ()):
            write_dlc(tracks, out / f"{stem}{SCORER}{end}", scorer=SCORER)
        (out / f"{stem}{SCORER}_meta.pickle").write_bytes(b"\x80\x04N.")
        shutil.copy(out / f"{stem}.mp4", out / f"{stem}{SCORER}_labeled.mp4")
    return out


def test_each_trial_is_one_clip_read_from_its_best_pose_file(session):
    found = find_clips(session)
    assert {i.clip: (i.kind, i.path.name) for i in found.items} == {
        "trial01": ("pose", f"trial01{SCORER}_filtered.h5"),
        "trial02": ("pose", f"trial02{SCORER}.h5"),
        "trial03": ("pose", "labels.v001.000_trial03.analysis.h5")}
    skipped = dict(found.skipped)
    for stem in ("trial01", "trial02"):
        assert "labelled video" in skipped[f"{stem}{SCORER}_labeled.mp4"]
        assert "metadata" in skipped[f"{stem}{SCORER}_meta.pickle"]
        assert skipped[f"{stem}{SCORER}.csv"].startswith(f"clip '{stem}' is read from")
    assert f"trial01{SCORER}.h5" in skipped
    assert "trial03.mp4.predictions.slp" in skipped
    assert not any(name.endswith(".mp4") and "DLC" not in name for name in skipped)


@pytest.mark.parametrize("name, expected", [
    ("trial01DLC_resnet50_reachJan1shuffle1_100000.h5", ("trial01", 1)),
    ("trial01DLC_resnet50_reachJan1shuffle1_100000.csv", ("trial01", 0)),
    ("trial01DLC_resnet50_reachJan1shuffle1_100000_filtered.h5", ("trial01", 3)),
    ("trial01DLC_resnet50_reachJan1shuffle1_100000_filtered.csv", ("trial01", 2)),
    ("trial 1DeepCut_resnet50_reachJan1shuffle1_100000.h5", ("trial 1", 1)),  # DLC < 2.1
    ("t1DLC_Resnet50_reachJan1shuffle1_snapshot_200.h5", ("t1", 1)),  # DLC 3
    ("t1DLC_HrnetW32_reachJan1shuffle5_detector_360_snapshot_110_el.h5", ("t1", 1)),
    ("t1DLC_dlcrnetms5_reachJan1shuffle1_50000_el_filtered.h5", ("t1", 3)),
    ("t1DLC_resnet50_reachJan1shuffle1_100000_meta.pickle", ("t1", "metadata")),
    ("t1DLC_resnet50_reachJan1shuffle1_100000_full.pickle", ("t1", "metadata")),
    ("t1DLC_resnet50_reachJan1shuffle1_100000_labeled.mp4", ("t1", "labelled video")),
    ("t1DLC_resnet50_reachJan1shuffle1_100000filtered_labeled.MP4", ("t1", "labelled video")),
    ("t1DLC_dlcrnetms5_reachJan1shuffle1_50000_full.mp4", ("t1", "labelled video")),
    ("t1DLC_resnet50_reachJan1shuffle1_100000_skeleton.csv", ("t1", "bone lengths")),
    ("trial03.analysis.h5", ("trial03", 1)),
    ("trial03.predictions.analysis.h5", ("trial03", 1)),
    ("trial03.mp4.predictions.analysis.h5", ("trial03", 1)),
    ("labels.v001.012_trial03.analysis.h5", ("trial03", 1)),
    ("trial03.mp4.predictions.slp", ("trial03", 0)),
    ("trial03.h5", None),
    ("session_dlc_export.h5", None),  # DeepLabCut's scorer is spelled DLC_
])
def test_deeplabcut_and_sleap_names(name, expected):
    found = pose_output(name)
    if expected is None or isinstance(expected[1], int):
        assert found == expected
    else:
        assert found[0] == expected[0] and expected[1] in found[1]
    if expected is not None and isinstance(expected[1], int):
        assert clip_name(name) == (expected[0], "pose")


def test_the_batch_runs_every_trial_at_the_videos_frame_rate(session, tmp_path):
    found = find_clips(session)
    summary = run_batch(found.items, tmp_path / "out", default_repertoire(FPS), SETTINGS,
                        quiet=True, skipped=found.skipped)
    assert sorted(summary["clip"]) == ["trial01", "trial02", "trial03"]
    assert (summary["status"] == "ok").all(), summary["error"].tolist()
    for clip in summary["clip"]:
        time = json.loads((tmp_path / "out" / f"{clip}.recognition.json").read_text())["time"]
        assert 1 / np.median(np.diff(time)) == pytest.approx(FPS)
    skipped = json.loads((tmp_path / "out" / "batch.json").read_text())["skipped"]
    assert {s["file"] for s in skipped} == {n for n, _ in found.skipped}


def test_fps_overrides_the_video_and_without_either_the_error_names_it(session, tmp_path):
    dlc = session / f"trial02{SCORER}.h5"
    assert video_beside(dlc) == session / "trial02.mp4"
    assert 1 / np.median(np.diff(read_pose(dlc, PoseImport(fps=50)).time)) == pytest.approx(50)
    alone = tmp_path / dlc.name
    shutil.copy(dlc, alone)
    with pytest.raises(InputError) as err:
        read_pose(alone)
    assert err.value.field == "fps" and "trial02.mp4" in str(err.value)
    assert "\n" not in str(err.value)
    (tmp_path / "trial02.mp4").write_bytes(b"not a video")
    with pytest.raises(InputError, match="its video trial02.mp4: not a readable video.*`fps`"):
        read_pose(alone)


def test_recognize_and_batch_commands_need_no_fps(session, tmp_path, capsys):
    from hammer_mv.cli import main

    # in this process: what the commands read and write is checked, not how a process exits
    rep = default_repertoire(FPS).save(tmp_path / "rep.h5")
    common = ["--repertoire", str(rep), "--object-diameter-px", "80", "--no-figures"]
    capsys.readouterr()
    status = main(["recognize", str(session / f"trial02{SCORER}.h5"), "-o",
                   str(tmp_path / "one"), *common])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert out.startswith("trial02: ")
    assert (tmp_path / "one" / "trial02.recognition.json").is_file()
    status = main(["batch", str(session), "-o", str(tmp_path / "many"), "--quiet", *common[:4]])
    assert status == 0, capsys.readouterr().err
    summary = pd.read_csv(tmp_path / "many" / "summary.csv")
    assert sorted(summary["clip"]) == ["trial01", "trial02", "trial03"]
    assert (summary["status"] == "ok").all()


def _error(call) -> str:
    with pytest.raises(InputError) as err:
        call()
    message = str(err.value)
    assert "\n" not in message and "--roi" not in message and "--setup" not in message
    return message


def test_a_missing_keypoint_names_keypoints(session):
    path = session / f"trial02{SCORER}.h5"
    assert "`keypoints`" in _error(lambda: read_pose(path, PoseImport(keypoints={"thumb": "x"})))


# the scale and hand messages of a pose file name its options (fields here; the command
# line gives their flags), not the tracker's --roi
def test_an_unknown_scale_names_object_diameter_px(session):
    tracks = read_pose(session / f"trial02{SCORER}.h5")
    message = _error(lambda: observe(tracks))
    assert "`object_diameter_px`" in message and "`px_per_m`" in message


def test_a_pose_file_that_is_no_hand_gets_no_colour_tracking_advice(session):
    tracks = read_pose(session / f"trial02{SCORER}.h5")
    message = _error(lambda: observe(tracks, ObserveParams(px_per_m=8000)))
    assert "`keypoints`" in message and "roi" not in message

import shutil
import subprocess
import sys

import h5py
import numpy as np
import pandas as pd
import pytest
from _cli import hammer_here
from _clips import HARD, errors, render

from perception.io.tracks import Tracks
from perception.synthetic.scene import Occlusion


def hammer(*args, cwd=None):
    """``hammer-mv *args`` as a subprocess: for what the process shows (exit status 2 in one
    line, the console of a run whose stderr is not a terminal); the lines and files of a
    command are tested in-process (:func:`hammer_here`)."""
    return subprocess.run(
        [sys.executable, "-m", "hammer_mv", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    d = tmp_path_factory.mktemp("clips")
    good, _ = render(d, "good.mp4", n=24, width=320, height=240, **HARD)
    no_thumb, _ = render(
        d, "nothumb.mp4", n=8, width=320, height=240, occlusions=(Occlusion("thumb", 0, 8),)
    )
    good_avi, _ = render(d, "good.avi", n=24, width=320, height=240, **HARD)
    return {"good": good, "nothumb": no_thumb, "avi": good_avi}


def _copy(clip, tmp_path, name=None):
    dst = tmp_path / (name or clip.video.name)
    shutil.copy(clip.video, dst)
    return dst


def test_track_writes_default_output_beside_video(clips, tmp_path):
    video = _copy(clips["good"], tmp_path)
    proc = hammer("track", video)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "good.tracks.h5"
    assert out.exists()
    assert proc.stderr == ""  # no progress bar when stderr is not a terminal
    assert "24 frames" in proc.stdout and "thumb 100 %" in proc.stdout
    tracks, truth = Tracks.load(out), Tracks.load(clips["good"].truth)
    assert np.median(errors(tracks, truth)) < 1.0
    assert tracks.video["n_frames"] == 24 and tracks.video["path"] == str(video)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.mp4", "good.tracks.h5"]


def test_track_output_option_and_quiet(clips, tmp_path):
    video = _copy(clips["good"], tmp_path)
    out = tmp_path / "sub" / "t.h5"
    proc = hammer("track", video, "-o", out, "--quiet")
    assert proc.returncode == 0 and proc.stdout == "" and proc.stderr == ""
    assert Tracks.load(out).n_frames == 24


def test_track_roi_and_colours_options(clips, tmp_path, capsys):
    video = _copy(clips["good"], tmp_path)
    truth = Tracks.load(clips["good"].truth)
    x, y = truth.position[0, 0]
    colours = tmp_path / "colours.toml"
    colours.write_text("[thumb]\nhue = [[170, 8]]\n")
    proc = hammer_here(
        capsys,
        "track",
        video,
        "--roi",
        "thumb",
        int(x) - 8,
        int(y) - 8,
        16,
        16,
        "--colours",
        colours,
        "--quiet",
    )
    assert proc.returncode == 0, proc.stderr
    tracks = Tracks.load(tmp_path / "good.tracks.h5")
    assert "170, 8" in tracks.tracker["colour_models"]
    assert "thumb" in tracks.tracker["rois"]
    assert np.median(errors(tracks, truth)[:, 0]) < 1.0


def test_truncated_avi_is_refused_in_one_line(clips, tmp_path):
    data = clips["avi"].video.read_bytes()
    video = tmp_path / "cut.avi"
    video.write_bytes(data[: len(data) * 2 // 3])
    proc = hammer("track", video, "--quiet")
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "header claims" in proc.stderr
    assert not (tmp_path / "cut.tracks.h5").exists()


def test_tracks_info(clips, tmp_path, capsys):
    video = _copy(clips["good"], tmp_path)
    hammer_here(capsys, "track", video, "--quiet")
    proc = hammer_here(capsys, "tracks", "info", tmp_path / "good.tracks.h5")
    assert proc.returncode == 0, proc.stderr
    assert "24 frames" in proc.stdout
    for name in ("thumb", "finger", "wrist", "object"):
        assert name in proc.stdout
    assert "times from container" in proc.stdout


@pytest.mark.parametrize("fmt", ["dlc", "trackpy", "csv"])
def test_tracks_export(clips, tmp_path, fmt, capsys):
    video = _copy(clips["good"], tmp_path)
    hammer_here(capsys, "track", video, "--quiet")
    tracks = Tracks.load(tmp_path / "good.tracks.h5")
    out = tmp_path / f"out.{fmt}.csv"
    proc = hammer_here(capsys, "tracks", "export", tmp_path / "good.tracks.h5", "--format", fmt,
                       "-o", out)
    assert proc.returncode == 0, proc.stderr
    if fmt == "dlc":
        df = pd.read_csv(out, header=[0, 1, 2], index_col=0)
        np.testing.assert_allclose(df[("hammer-mv", "wrist", "x")], tracks.marker("wrist")[:, 0])
    elif fmt == "trackpy":
        df = pd.read_csv(out)
        assert len(df) == int(tracks.valid.sum())  # one row per seen point; lost ones have none
        wrist = df[df.marker == "wrist"].sort_values("frame")
        seen = tracks.valid[:, tracks.index("wrist")]
        np.testing.assert_allclose(wrist.y, tracks.marker("wrist")[seen, 1])
    else:
        df = pd.read_csv(out)
        np.testing.assert_allclose(df.thumb_x, tracks.marker("thumb")[:, 0])


def test_trim_keeps_exactly_the_frames_recognition_scores(tmp_path, capsys):
    """``tracks export --trim`` and ``recognize`` use the one movement span."""
    from perception.synthetic.scene import Scene

    scene = Scene.reach_to_grasp(60, 30.0, start=(0.0, -0.30), onset=0.4, duration=1.0)
    clip, _ = render(tmp_path, "reach.mp4", n=60, width=320, height=240, scene=scene, angle=0)
    assert hammer_here(capsys, "track", clip.video, "--quiet")[0] == 0
    tracks_file = tmp_path / "reach.tracks.h5"
    out = tmp_path / "t.csv"
    status, _, err = hammer_here(capsys, "tracks", "export", tracks_file, "--format", "csv",
                                 "-o", out, "--trim", "--max-gap", "3")
    assert status == 0, err
    trimmed = pd.read_csv(out)["frame"].to_numpy()
    # the figures are not looked at here
    status, _, err = hammer_here(capsys, "recognize", tracks_file, "-o", tmp_path / "rec",
                                 "--quiet", "--no-figures")
    assert status == 0, err
    # the per-step table is the movement resampled at the repertoire's frame period (issue
    # 42): each step's nearest frame, inside the span and reaching its ends
    scored = np.unique(pd.read_csv(tmp_path / "rec" / "reach.confidence.csv")["frame"])
    assert set(scored) <= set(trimmed)
    assert scored[0] - trimmed[0] <= 1 and trimmed[-1] - scored[-1] <= 1
    # the movement: from just before the onset (frame 12) to a little after the end
    assert 8 <= trimmed[0] <= 13 and 40 <= trimmed[-1] < 59
    status, info, _ = hammer_here(capsys, "tracks", "info", tracks_file)
    assert status == 0 and f"active: frames {trimmed[0]} .. {trimmed[-1]}" in info


def test_trim_of_tracks_without_a_movement_is_refused_in_one_line(tmp_path, capsys):
    from perception.synthetic.demos import demo_tracks

    tracks, _ = demo_tracks("normal", 0)
    still = tracks.replace(position=np.broadcast_to(tracks.position[:1], tracks.position.shape))
    still.save(tmp_path / "still.tracks.h5")
    out = tmp_path / "t.csv"
    proc = hammer("tracks", "export", tmp_path / "still.tracks.h5", "--format", "csv",
                  "-o", out, "--trim")
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "--trim: no movement found" in proc.stderr
    assert not out.exists()
    info = hammer_here(capsys, "tracks", "info", tmp_path / "still.tracks.h5")
    assert "active: none (no movement found" in info.stdout


def _wrong_schema(tmp_path):
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as fh:
        fh.attrs["schema"] = "someone-else/poses"
        fh.create_dataset("x", data=[1, 2, 3])
    return path


def _wrong_version(tmp_path, clips):
    path = tmp_path / "v9.tracks.h5"
    shutil.copy(clips["good"].truth, path)
    with h5py.File(path, "a") as fh:
        fh.attrs["schema_version"] = 9
    return path


def _truncated_mp4(tmp_path, clips):
    data = clips["good"].video.read_bytes()
    path = tmp_path / "cut.mp4"
    path.write_bytes(data[: len(data) // 2])
    return path


def _bad_case(case, t, clips):
    """Arguments for one bad input; the names and problem its error line must mention."""
    if case == "missing":
        return ["track", t / "none.mp4"], "none.mp4", "no such file"
    if case == "zero-byte":
        (t / "empty.mp4").touch()
        return ["track", t / "empty.mp4"], "empty.mp4", "empty file"
    if case == "not-video":
        (t / "notes.mp4").write_text("hello\n" * 50)
        return ["track", t / "notes.mp4"], "notes.mp4", "not a readable video"
    if case == "truncated":
        return ["track", _truncated_mp4(t, clips)], "cut.mp4", "video"
    if case == "never-found":
        return ["track", _copy(clips["nothumb"], t)], "nothumb.mp4", "thumb never found"
    if case == "colours":
        (t / "c.toml").write_text("[thumb]\nhue = 5\n")
        return ["track", _copy(clips["good"], t), "--colours", t / "c.toml"], "c.toml", "thumb.hue"
    if case.startswith("roi-"):
        roi, names, problem = {
            "roi-marker": (["nose", 1, 2, 3, 4], "--roi nose", "unknown marker"),
            "roi-number": (["thumb", 1, 2, "x", 4], "--roi thumb", "integer"),
            "roi-size": (["thumb", 1, 2, 0, 4], "--roi thumb", "W, H > 0"),
            "roi-outside": (["thumb", 300, 200, 50, 50], "good.mp4", "extends past"),
            "roi-empty": (["thumb", 0, 0, 10, 10], "good.mp4", "nothing of its colour"),
        }[case]
        return ["track", _copy(clips["good"], t), "--roi", *roi], names, problem
    if case == "info-schema":
        return ["tracks", "info", _wrong_schema(t)], "other.h5", "not a hammer-mv tracks file"
    if case == "export-version":
        args = ["tracks", "export", _wrong_version(t, clips), "--format", "dlc", "-o", t / "x.csv"]
        return args, "v9.tracks.h5", "schema_version 9"
    if case == "export-not-hdf5":
        (t / "x.h5").write_text("x")
        args = ["tracks", "export", t / "x.h5", "--format", "csv", "-o", t / "x.csv"]
        return args, "x.h5", "not an HDF5 file"
    raise AssertionError(case)


BAD = [
    "missing",
    "zero-byte",
    "not-video",
    "truncated",
    "never-found",
    "colours",
    "roi-marker",
    "roi-number",
    "roi-size",
    "roi-outside",
    "roi-empty",
    "info-schema",
    "export-version",
    "export-not-hdf5",
]


@pytest.mark.parametrize("case", BAD)
def test_bad_input_exits_2_with_one_line_and_no_output(clips, tmp_path, case):
    args, names, problem = _bad_case(case, tmp_path, clips)
    before = {p.name for p in tmp_path.rglob("*")}
    proc = hammer(*args, cwd=tmp_path)
    assert proc.returncode == 2, (proc.stdout, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    assert names in lines[0] and problem in lines[0], lines[0]
    assert {p.name for p in tmp_path.rglob("*")} == before  # no output, no temporary file


def _frame_count(path):
    import cv2

    cap = cv2.VideoCapture(str(path))
    n = 0
    while cap.read()[0]:
        n += 1
    return n


def test_labelled_video_from_track_and_from_tracks_render(clips, tmp_path, capsys):
    import cv2
    import numpy as np

    video = _copy(clips["good"], tmp_path)
    labelled = tmp_path / "labelled.mp4"
    proc = hammer_here(capsys, "track", video, "--labelled-video", labelled, "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert _frame_count(labelled) == 24
    again = tmp_path / "again.mp4"
    proc = hammer_here(capsys, "tracks", "render", tmp_path / "good.tracks.h5", "-o", again)
    assert proc.returncode == 0, proc.stderr
    assert "24 frames labelled" in proc.stdout
    assert _frame_count(again) == 24
    # the drawing is there: the labelled frame differs from the video near the thumb
    from perception.io.tracks import Tracks

    t = Tracks.load(tmp_path / "good.tracks.h5")
    x, y = t.position[5, t.index("thumb")].round().astype(int)
    a, b = (cv2.VideoCapture(str(p)) for p in (video, again))
    for _ in range(6):
        fa, fb = a.read()[1], b.read()[1]
    diff = np.abs(fa.astype(int) - fb.astype(int))[y - 15:y + 15, x - 15:x + 15].sum(axis=-1)
    assert (diff > 60).sum() > 20
    proc = hammer_here(capsys, "tracks", "render", tmp_path / "good.tracks.h5",
                       tmp_path / "none.mp4", "-o", tmp_path / "x.mp4")
    assert proc.returncode == 2 and "none.mp4" in proc.stderr
    assert not (tmp_path / "x.mp4").exists()


def test_tracks_info_prints_the_quality_table(clips, tmp_path, capsys):
    video = _copy(clips["good"], tmp_path)
    assert hammer_here(capsys, "track", video, "--quiet").returncode == 0
    proc = hammer_here(capsys, "tracks", "info", tmp_path / "good.tracks.h5")
    assert proc.returncode == 0, proc.stderr
    assert "quality:" in proc.stdout and "reacquisitions" in proc.stdout
    thumb = next(line for line in proc.stdout.splitlines()[::-1] if line.startswith("thumb"))
    assert thumb.split()[1] == "100.0"  # tracked in every frame


def test_recognize_reports_tracking_quality_and_a_contact_sheet(tmp_path, capsys):
    import json

    from perception.synthetic.demos import render_demo_clip
    from perception.synthetic.scene import Scene

    scene = Scene.reach_to_grasp(45, 30, start=(0.0, -0.25), onset=0.3, duration=0.8)
    clip, _ = render_demo_clip(tmp_path, "clip.mp4", n=45, angle=0.0, hand=True, scene=scene)
    out = tmp_path / "out"
    status, _, err = hammer_here(capsys, "recognize", clip.video, "-o", out)
    assert status == 0, err
    report = json.loads((out / "clip.recognition.json").read_text())
    quality = report["tracking"]
    assert quality["frames"] == 45 and quality["contact_sheet"] == "clip.tracking.png"
    assert quality["markers"]["thumb"]["tracked"] == 1.0
    assert quality["markers"]["wrist"]["min_likelihood"] > 0.5
    import cv2

    sheet = cv2.imread(str(out / "clip.tracking.png"))
    assert sheet is not None and sheet.shape[1] == 1200


def test_contact_sheet_from_frames_kept_while_tracking_matches_a_decoded_one(tmp_path):
    import cv2

    from perception.io.frame_sample import FrameSample
    from perception.report.tracking import contact_sheet
    from perception.synthetic.demos import render_demo_clip
    from perception.synthetic.scene import Scene
    from perception.tracking.video_tracks import track_video

    scene = Scene.reach_to_grasp(45, 30, start=(0.0, -0.25), onset=0.3, duration=0.8)
    clip, _ = render_demo_clip(tmp_path, "clip.mp4", n=45, angle=0.0, hand=True, scene=scene)
    every = FrameSample(max_frames=100)  # stride 1: the very frames a decode gives
    tracks = Tracks.load(track_video(clip.video, tmp_path / "c.tracks.h5", frames=every))
    assert every.stride == 1 and sorted(every.frames) == list(range(45))
    kept = contact_sheet(tracks, None, tmp_path / "kept.png", frames=every)
    decoded = contact_sheet(tracks, None, tmp_path / "decoded.png")
    np.testing.assert_array_equal(cv2.imread(str(kept)), cv2.imread(str(decoded)))
    # deflated, not stored as OpenCV's defaults store it: the same pixels, a smaller file
    pixels = cv2.imread(str(kept))
    ok, default = cv2.imencode(".png", pixels)
    assert ok and kept.stat().st_size < 0.7 * len(default)

    few = FrameSample(max_frames=8)  # every 6th frame: the nearest stand in
    track_video(clip.video, tmp_path / "d.tracks.h5", frames=few)
    assert few.stride == 6 and sorted(few.frames) == list(range(0, 45, 6))
    assert few.nearest(17) == 18 and few.nearest(15) == 12 and few.nearest(44) == 42
    (tmp_path / "moved").mkdir()
    clip.video.rename(tmp_path / "moved" / "clip.mp4")  # the sheet can no longer decode
    assert contact_sheet(tracks, None, tmp_path / "few.png", frames=few) is not None
    assert contact_sheet(tracks, None, tmp_path / "none.png") is None


def test_a_frame_sample_that_ran_out_of_budget_does_not_stand_in():
    from perception.io.frame_sample import FrameSample

    sample = FrameSample(max_frames=4, max_bytes=10 << 20)
    sample.start(n_frames=0, frame_bytes=1 << 20)  # a header without a frame count
    for i in range(40):
        sample.offer(i, np.zeros(1))
    assert sorted(sample.frames) == [0, 1, 2, 3]
    assert sample.nearest(2) == 2 and sample.nearest(30) is None  # decode instead
    sample.start(n_frames=100, frame_bytes=4 << 20)  # 2 frames fit in 10 MiB
    assert sample.stride == 50 and sample.frames == {}
    for i in range(0, 400, 50):  # the header undercounted: the budget still holds
        sample.offer(i, np.zeros(1))
    assert sorted(sample.frames) == [0, 50]
    with pytest.raises(ValueError, match="positive budget"):
        FrameSample(max_frames=0)


def test_tracking_does_not_wait_for_the_videos_hash(tmp_path, monkeypatch):
    import threading

    from perception.io import video
    from perception.io.frame_sample import FrameSample
    from perception.synthetic.demos import render_demo_clip
    from perception.synthetic.scene import Scene
    from perception.tracking.video_tracks import track_video

    scene = Scene.reach_to_grasp(20, 30, start=(0.0, -0.25), onset=0.2, duration=0.4)
    clip, _ = render_demo_clip(tmp_path, "clip.mp4", n=20, angle=0.0, hand=True, scene=scene)
    tracked = threading.Event()
    digest = video.sha256_file(clip.video)

    def slow_sha256(path):
        assert tracked.wait(20), "the hash was waited for before the frames were tracked"
        return digest

    class LastFrame(FrameSample):
        def offer(self, index, frame):
            super().offer(index, frame)
            if index == 19:
                tracked.set()

    monkeypatch.setattr(video, "sha256_file", slow_sha256)
    out = track_video(clip.video, tmp_path / "c.tracks.h5", frames=LastFrame())
    assert Tracks.load(out).video["sha256"] == digest


def test_opencv_threads_are_set_by_the_commands_that_track_not_by_the_library(clips, tmp_path,
                                                                            monkeypatch):
    import cv2

    from hammer_mv.cli import main
    from perception.tracking.video_tracks import track_video

    calls = []
    monkeypatch.setattr(cv2, "setNumThreads", calls.append)
    track_video(clips["good"].video, tmp_path / "lib.tracks.h5")
    assert calls == []  # a library leaves process-wide state alone
    assert main(["track", str(clips["good"].video), "-o", str(tmp_path / "cli.h5"),
                 "--quiet"]) == 0
    assert calls == [1]
    calls.clear()
    assert main(["tracks", "info", str(tmp_path / "cli.h5")]) == 0
    assert calls == []  # a command that does not track leaves it too

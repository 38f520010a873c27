"""The whole pipeline on rendered video: recognize, batch, resume, failures, dask."""

import json
import shutil
import subprocess
import sys

import pandas as pd
import pytest
from _cli import hammer_here, main_here
from _demos import default_repertoire

from perception.batch import discover, run_batch
from perception.synthetic.recipes import Recipe, StimulusParams, synthesize

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    out = tmp_path_factory.mktemp("clips")
    recipe = Recipe(name="t", counts={"normal": 2, "delayed": 1, "open-close-open": 1,
                                      "reach": 1},
                    stimulus=StimulusParams(rest_before=0.3, rest_after=0.2),
                    camera_angle_deg=(-15, 15),
                    style={"hand": True, "marker_diameter": 0.012, "noise_sd": 3.0,
                           "lighting": 0.25, "blur_sigma": 0.6,
                           # same-coloured things on the table, as in datasets/gangitano.toml
                           "distractors": [{"colour": [20, 40, 200], "start": [-0.16, -0.05],
                                            "diameter": 0.05},
                                           {"colour": "finger", "start": [0.17, -0.2],
                                            "diameter": 0.015}]})
    synthesize(recipe, out, seed=2)
    return out


@pytest.fixture(scope="module")
def repfile(tmp_path_factory):
    return default_repertoire().save(tmp_path_factory.mktemp("rep") / "rep.h5")


def _main_batch(src, out, repfile, *extra):
    """``hammer-mv batch``'s exit status, run in this process: what a subprocess would
    add is its imports (4 s of CPU a run), and the tests that use this look at the
    exit status and the files written, not at the console."""
    return main_here("batch", src, "-o", out, "--repertoire", repfile, "--quiet", *extra)


def _same_reports(a, b, *, input_spelled_alike=True):
    """Two report folders hold the same summary, batch.json and per-clip JSON reports
    (``input``, the clip's path, is left out where the two batches were given it
    differently: a manifest's paths are resolved, a folder's are not)."""
    pd.testing.assert_frame_equal(pd.read_csv(a / "summary.csv"), pd.read_csv(b / "summary.csv"))
    assert json.loads((a / "batch.json").read_text()) == json.loads((b / "batch.json").read_text())
    names = sorted(p.name for p in a.glob("*.recognition.json"))
    assert names and names == sorted(p.name for p in b.glob("*.recognition.json"))
    for name in names:
        ra, rb = (json.loads((d / name).read_text()) for d in (a, b))
        if not input_spelled_alike:
            ra.pop("input"), rb.pop("input")
        assert ra == rb, name


def test_batch_jobs_1_and_2_agree_and_resume(clips, repfile, tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    assert _main_batch(clips / "manifest.csv", one, repfile) == 0
    assert _main_batch(clips, two, repfile, "--jobs", "2") == 0
    s1 = pd.read_csv(one / "summary.csv")
    assert list(s1.columns[:7]) == ["clip", "condition", "seed", "truth", "parameters",
                                    "winner", "rule"]  # the manifest's columns carried
    assert {"status", "error"} <= set(s1.columns)
    assert (s1["status"] == "ok").all()
    _same_reports(one, two, input_spelled_alike=False)
    # what the thesis reports, end to end from video
    final = s1.set_index("clip")["conf_grasp-1.0s"]
    for normal in ("normal-01", "normal-02"):
        assert final[normal] > final["delayed-01"] and final[normal] > final["open-close-open-01"]
    kinds = s1.set_index("clip")["winner"].str.split("-").str[0]
    assert kinds["reach-01"] == "reach" and (kinds[["normal-01", "normal-02"]] == "grasp").all()
    for name in ("report.html", "statistics.csv", "condition_profiles.png"):
        assert (one / name).exists(), name
    # rerun: complete, current clips are skipped
    assert _main_batch(clips / "manifest.csv", one, repfile) == 0
    assert pd.read_csv(one / "summary.csv")["reused"].all()


def test_batch_goes_on_past_bad_files(clips, repfile, tmp_path, capsys):
    src = tmp_path / "src"
    src.mkdir()
    for name in ("normal-01.mp4", "manifest.csv"):
        shutil.copy(clips / name, src / name)
    (src / "notes.txt").write_text("not a video")
    (src / "empty.mp4").write_bytes(b"")
    proc = hammer_here(capsys, "batch", src, "-o", tmp_path / "out", "--repertoire", repfile,
                       "--quiet")
    assert proc.returncode == 1 and "1 clip(s) failed" in proc.stderr
    s = pd.read_csv(tmp_path / "out" / "summary.csv").set_index("clip")
    assert s.loc["normal-01", "status"] == "ok"
    assert "notes" not in s.index  # not a clip: skipped, and listed as such
    skipped = json.loads((tmp_path / "out" / "batch.json").read_text())["skipped"]
    assert skipped == [{"file": "notes.txt", "reason": "not a video, tracks file, pose file or "
                                                      "motion-capture recording"}]
    assert s.loc["empty", "status"] == "failed" and "empty.mp4" in s.loc["empty", "error"]
    assert not list((tmp_path / "out").glob("empty.*")) and not list(
        (tmp_path / "out").glob(".*part*"))


def test_dask_scheduler_gives_the_same_results(clips, tmp_path):
    from dask.distributed import LocalCluster

    items = [i for i in discover(clips) if i.clip in ("normal-01", "reach-01")]
    rep = default_repertoire()
    local = run_batch(items, tmp_path / "local", rep, quiet=True)
    two = run_batch(items, tmp_path / "two", rep, quiet=True, jobs=2)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        remote = run_batch(items, tmp_path / "dask", rep, quiet=True,
                           scheduler=cluster.scheduler_address)
    pd.testing.assert_frame_equal(local, remote)
    pd.testing.assert_frame_equal(local, two)
    _same_reports(tmp_path / "local", tmp_path / "dask")
    _same_reports(tmp_path / "local", tmp_path / "two")


def test_recognize_writes_the_contract(clips, repfile, tmp_path):
    out = tmp_path / "r"
    assert main_here("recognize", clips / "open-close-open-01.mp4", "-o", out, "--repertoire",
                     repfile, "--quiet") == 0
    d = json.loads((out / "open-close-open-01.recognition.json").read_text())
    assert d["clip"] == "open-close-open-01" and d["rule"] == "likelihood"
    assert {"name", "kind", "final_confidence"} <= set(d["models"][0])
    assert d["winner"] in [m["name"] for m in d["models"]]
    assert all(len(v) == len(d["time"]) for v in d["confidence"].values())
    csv = pd.read_csv(out / "open-close-open-01.confidence.csv")
    assert {"time", "model", "C", "dC_r", "dC_g"} <= set(csv.columns)
    for suffix in ("confidence.png", "paths.png"):
        assert (out / f"open-close-open-01.{suffix}").stat().st_size > 5000
    # a tracks file is accepted as input too
    tracks = out / "tracks" / "open-close-open-01.tracks.h5"
    assert tracks.exists()
    assert main_here("recognize", tracks, "-o", tmp_path / "r2", "--repertoire", repfile,
                     "--quiet") == 0


@pytest.mark.parametrize("make, message", [
    (lambda d: d / "missing.mp4", "not found"),
    (lambda d: (d / "x.txt").write_text("hi") and d / "x.txt", "not a video"),
    (lambda d: (d / "z.mp4").write_bytes(b"") or d / "z.mp4", "z.mp4"),
])
def test_recognize_bad_input_exit_2(tmp_path, repfile, make, message):
    path = make(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "hammer_mv", "recognize", str(path),
                           "-o", str(tmp_path / "o"), "--repertoire", str(repfile)],
                          capture_output=True, text=True)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and message in proc.stderr
    assert not (tmp_path / "o").exists() or not any(
        p.suffix == ".json" for p in (tmp_path / "o").iterdir())


def test_parallel_batch_after_work_in_the_same_process(clips, tmp_path):
    # rendering and planning first leaves thread pools behind: workers must still run
    from perception.synthetic.recipes import StimulusParams, stimulus_paths

    stimulus_paths(StimulusParams(), 30, seed=0)
    items = [i for i in discover(clips) if i.clip in ("normal-01", "delayed-01")]
    summary = run_batch(items, tmp_path / "out", default_repertoire(), quiet=True,
                        jobs=2)
    assert (summary["status"] == "ok").all()


def test_changed_settings_or_input_are_rerun(clips, repfile, tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    shutil.copy(clips / "normal-01.mp4", src / "normal-01.mp4")
    out = tmp_path / "out"
    assert _main_batch(src, out, repfile) == 0
    assert _main_batch(src, out, repfile) == 0
    assert pd.read_csv(out / "summary.csv")["reused"].all()
    assert _main_batch(src, out, repfile, "--rule", "thesis") == 0
    assert not pd.read_csv(out / "summary.csv")["reused"].any()
    (src / "normal-01.mp4").touch()  # the same content: still current
    assert _main_batch(src, out, repfile, "--rule", "thesis") == 0
    assert pd.read_csv(out / "summary.csv")["reused"].all()
    # figures at another resolution: the clip's drawn again, none left at the old one
    from PIL import Image

    for dpi, reused in ((60, False), (60, True)):
        assert _main_batch(src, out, repfile, "--rule", "thesis", "--dpi", str(dpi)) == 0
        assert pd.read_csv(out / "summary.csv")["reused"].all() == reused
        for png in (out / f"normal-01.{key}.png" for key in ("confidence", "paths", "kinematics")):
            with Image.open(png) as im:
                assert round(im.info["dpi"][0]) == dpi, png.name
    # another video under the same name (the same size, even): made again
    shutil.copy(clips / "delayed-01.mp4", src / "normal-01.mp4")
    assert _main_batch(src, out, repfile, "--rule", "thesis") == 0
    assert not pd.read_csv(out / "summary.csv")["reused"].any()


def test_report_folder_can_be_its_own_input(clips, repfile, tmp_path):
    src = tmp_path / "both"
    src.mkdir()
    for name in ("normal-01.mp4", "reach-01.mp4"):
        shutil.copy(clips / name, src / name)
    for _ in range(2):
        assert _main_batch(src, src, repfile) == 0
    s = pd.read_csv(src / "summary.csv")
    assert list(s["clip"]) == ["normal-01", "reach-01"] and s["reused"].all()


def test_an_unexpected_error_is_recorded_and_the_batch_goes_on(clips, tmp_path):
    import dataclasses

    rep = default_repertoire()
    # A bug, not bad input: a model whose gains were cut short after it was
    # validated (ChainModel refuses such arrays when it is built).
    finger = dataclasses.replace(rep.models[0].finger)
    object.__setattr__(finger, "K", finger.K[:3])
    broken = dataclasses.replace(rep.models[0], finger=finger)
    from perception.recognition.repertoire import Repertoire

    bad_rep = Repertoire([broken, *rep.models[1:]])
    items = [i for i in discover(clips) if i.clip in ("normal-01", "reach-01")]
    summary = run_batch(items, tmp_path / "out", bad_rep, quiet=True)
    assert (summary["status"] == "failed").all()
    assert summary["error"].str.contains("unexpected IndexError").all()
    assert "IndexError" in (tmp_path / "out" / "errors.log").read_text()
    assert (tmp_path / "out" / "summary.csv").exists()
    assert (tmp_path / "out" / "report.html").exists()


def test_object_scale_from_tracking_is_within_one_percent(clips, tmp_path):
    from perception.io.tracks import Tracks
    from perception.tracking.video_tracks import track_video

    for clip in ("normal-01", "delayed-01"):
        tracked = Tracks.load(track_video(clips / f"{clip}.mp4", tmp_path / f"{clip}.tracks.h5"))
        truth = Tracks.load(clips / f"{clip}.truth.h5")
        ratio = tracked.object_diameter_px() / truth.object_diameter_px()
        assert abs(ratio - 1) < 0.01  # the colour-unmixed area: no bias from the blurred rim

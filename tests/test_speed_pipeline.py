"""Per-clip and batch speed features: lazy CLI, tracks reuse, plan cache, synth --jobs.

Start-up itself is measured, not asserted: ``tools/bench_speed.py``."""

import threading
import time

import numpy as np
import pytest
from _demos import default_repertoire

from hammer_mv.cli import COMMANDS, build_parser
from perception.recognition.models import SceneSpec
from perception.recognition.planning import default_specs
from perception.recognition.repertoire import PlanCache, Repertoire


def test_command_list_matches_the_command_modules():
    import argparse

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    helps = {a.dest: a.help for a in sub._choices_actions}
    assert helps == COMMANDS


def test_default_repertoire_plans_only_the_clips_scene():
    scene = SceneSpec(distance=0.31, object_size=0.07, tip_start=0.062)
    lazy = Repertoire.default()
    got = lazy.for_scene(scene)
    assert lazy._models is None  # the default scene was never planned
    want = Repertoire.build().for_scene(scene)
    assert [m.name for m in got] == [m.name for m in want] == lazy.names
    for a, b in zip(got, want):
        for ca, cb in zip(a.chains, b.chains):
            np.testing.assert_array_equal(ca.K, cb.K)
            np.testing.assert_array_equal(ca.P, cb.P)


def test_default_repertoire_at_the_default_scene_uses_the_default_plans():
    lazy = Repertoire.default()
    models = lazy.for_scene(SceneSpec())
    assert lazy._models is not None and models == lazy.models


def _specs():
    return default_specs((0.9,))


def test_plan_cache_plans_a_scene_once_across_workers(tmp_path):
    scene = SceneSpec(distance=0.27).quantized()
    calls = []
    results = {}

    def plan():
        calls.append(1)
        time.sleep(0.3)  # long enough for the others to find the lock
        return Repertoire.build(_specs(), scene).models

    def worker(i):
        results[i] = PlanCache(tmp_path).get(scene, _specs(), plan)

    threads = [threading.Thread(target=worker, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(calls) == 1
    for i in (1, 2):
        for a, b in zip(results[0], results[i]):
            np.testing.assert_array_equal(a.arm.L, b.arm.L)  # read back bit for bit
    assert not list(tmp_path.glob("*.lock")) and not list(tmp_path.glob(".*part*"))


def test_plan_cache_survives_a_dead_owner_and_a_corrupt_file(tmp_path):
    scene = SceneSpec(distance=0.27).quantized()
    cache = PlanCache(tmp_path, wait_s=0.2)
    key = cache.key(scene, _specs())
    (tmp_path / f"{key}.lock").write_text("")  # a worker died holding the lock
    models = cache.get(scene, _specs(), lambda: Repertoire.build(_specs(), scene).models)
    assert [m.name for m in models] == [s.name for s in _specs()]
    (tmp_path / f"{key}.lock").unlink()
    (tmp_path / f"{key}.h5").write_bytes(b"not hdf5")
    again = PlanCache(tmp_path)
    again.get(scene, _specs(), lambda: Repertoire.build(_specs(), scene).models)
    assert again.planned == 1  # planned again, and stored
    assert PlanCache(tmp_path).get(scene, _specs(), lambda: pytest.fail("not read")) is not None


def test_plan_cache_key_covers_what_changes_a_plan(tmp_path):
    cache = PlanCache(tmp_path)
    base = cache.key(SceneSpec(), _specs())
    assert cache.key(SceneSpec(distance=0.30), _specs()) != base
    assert cache.key(SceneSpec(frame_period=1 / 25), _specs()) != base
    assert cache.key(SceneSpec(), default_specs((1.0,))) != base


@pytest.mark.slow
def test_current_tracks_file_is_reused_and_a_stale_one_is_not(tmp_path, monkeypatch):
    from perception.pipeline import current_tracks, load_clip
    from perception.synthetic.demos import render_demo_clip
    from perception.tracking import video_tracks

    clip, _ = render_demo_clip(tmp_path, "a.mp4", n=30)
    other, _ = render_demo_clip(tmp_path, "b.mp4", n=30, seed=1)
    tracks = load_clip(clip.video)  # tracked: a.tracks.h5 beside the video
    assert current_tracks(clip.video, [tracks.path]) is not None
    assert current_tracks(other.video, [tracks.path]) is None  # another video's tracks

    def no_tracking(*args, **kwargs):
        raise AssertionError("tracked again")

    monkeypatch.setattr(video_tracks, "track_video", no_tracking)
    again = load_clip(clip.video)
    np.testing.assert_array_equal(again.position, tracks.position)
    monkeypatch.undo()
    roi = tmp_path / "roi.tracks.h5"
    video_tracks.track_video(clip.video, roi, rois={"object": (0, 0, 640, 480)})
    assert current_tracks(clip.video, [roi]) is None  # other tracker settings


def test_a_tracked_video_is_hashed_once_for_its_fingerprint(tmp_path, monkeypatch):
    """The tracker hashes what it decodes; the fingerprint takes that hash, and a file
    changed since is hashed again."""
    import hashlib

    from perception import pipeline
    from perception.io import files
    from perception.synthetic.demos import render_demo_clip

    clip, _ = render_demo_clip(tmp_path, "h.mp4", n=12)
    pipeline.load_clip(clip.video, tracks_out=tmp_path / "h.tracks.h5")
    read = []
    monkeypatch.setattr(files, "sha256_file", _counted(files.sha256_file, read))
    want = hashlib.sha256(clip.video.read_bytes()).hexdigest()
    assert pipeline.file_sha256(clip.video) == want
    assert pipeline.file_sha256(clip.video) == want and read == []  # not read again
    with open(clip.video, "ab") as fh:  # changed: its own hash
        fh.write(b"\0")
    assert pipeline.file_sha256(clip.video) == hashlib.sha256(
        clip.video.read_bytes()).hexdigest() != want
    assert len(read) == 1


def _counted(fn, calls):
    def counted(path):
        calls.append(path)
        return fn(path)
    return counted


def test_a_report_without_figures_removes_stale_ones(tmp_path):
    from perception.pipeline import recognize_clip
    from perception.report.clip import clip_outputs, write_clip_report
    from perception.synthetic.demos import demo_tracks

    rec = recognize_clip(demo_tracks("normal", 0)[0], default_repertoire(), clip="c")
    paths = write_clip_report(rec, tmp_path)
    assert all(p.exists() for p in paths.values())
    assert write_clip_report(rec, tmp_path, figures=False) == clip_outputs(tmp_path, "c")
    assert paths["json"].exists() and paths["csv"].exists()
    assert not paths["confidence_png"].exists() and not paths["paths_png"].exists()


@pytest.mark.slow
def test_synth_jobs_give_the_same_clips(tmp_path):
    import dataclasses

    from perception.synthetic.recipes import Recipe, StimulusParams, synthesize

    recipe = Recipe(name="t", counts={"normal": 2, "delayed": 1},
                    stimulus=StimulusParams(rest_before=0.2, rest_after=0.1),
                    style={"width": 320, "height": 240})
    one = synthesize(recipe, tmp_path / "one", seed=3)
    two = synthesize(dataclasses.replace(recipe), tmp_path / "two", seed=3, jobs=2)
    assert one.equals(two)
    for name in one["video"]:
        assert (tmp_path / "one" / name).read_bytes() == (tmp_path / "two" / name).read_bytes()


def test_models_planned_on_threads_are_the_same():
    from perception.recognition.planning import build_models

    scene = SceneSpec(distance=0.28)
    two = build_models(_specs(), scene, threads=2)
    one = build_models(_specs(), scene, threads=1)
    for a, b in zip(one, two):
        for ca, cb in zip(a.chains, b.chains):
            np.testing.assert_array_equal(ca.L, cb.L)

"""The rest of issue 46's wrong inputs: types at the boundary, markers never seen, a manifest's
clip names kept for a recording's trials.

(``watch`` of a recording: tests/test_watch_recording.py; the object-size note:
tests/test_faults_mocap_rest.py.) The recordings are written here.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest
from test_faults_mocap_rest import _table
from test_reach_finding import _simple_reach

import perception as pc
from perception.errors import InputError
from perception.observation import observe
from perception.reaches import MarkerMap, reach_tracks, trial_reaches
from perception.recordings import cached_reaches, cached_recording, prepare_reach, read_recording
from perception.report.clip import write_clip_report


def _trial():
    return _simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)])


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    path = tmp_path_factory.mktemp("t") / "trials.tsv"
    _table(_trial()).to_csv(path, sep="\t", index=False)
    return path


@pytest.fixture(scope="module")
def reach(table):
    return pc.read_reaches(table)[0]


# -- objects of the wrong type, refused on entry ------------------------------------------------
TYPE_CASES = [  # (call, what the message names)
    (lambda p, r: pc.read_reaches(p, options="fast"), "read_reaches(options=): expected "
     "MocapImport or None, got str 'fast'"),
    (lambda p, r: read_recording(p, {"rate": 100}), "read_recording(options=): expected "
     "MocapImport"),
    (lambda p, r: cached_recording(p, "fast"), "cached_recording(options=)"),
    (lambda p, r: cached_reaches(p, 3), "cached_reaches(options=)"),
    (lambda p, r: pc.recognize_reach("reach", pc.Repertoire.default()),
     "recognize_reach(reach=): expected Reach"),
    (lambda p, r: pc.recognize_reach(r, "rep.h5"), "recognize_reach(repertoire=): expected "
     "Repertoire (Repertoire.load or Repertoire.build), got str"),
    (lambda p, r: pc.recognize_reach(r, pc.Repertoire.default(), settings={}),
     "recognize_reach(settings=): expected RecognitionSettings or None, got dict"),
    (lambda p, r: pc.recognize_reach(r, pc.Repertoire.default(), options="fast"),
     "recognize_reach(options=)"),
    (lambda p, r: prepare_reach(r, options=pc.MarkerMap()), "prepare_reach(options=)"),
    (lambda p, r: reach_tracks(r, params="fast"), "reach_tracks(params=): expected ReachParams"),
    (lambda p, r: trial_reaches(_trial(), markers={"thumb": "thumb"}),
     "trial_reaches(markers=): expected MarkerMap"),
    (lambda p, r: pc.Repertoire.build(task="x"), "Repertoire.build(task=): expected Mapping"),
    (lambda p, r: pc.Repertoire.build(scene="far"), "Repertoire.build(scene=): expected "
     "SceneSpec"),
    (lambda p, r: pc.Repertoire.build(specs="grasp"), "Repertoire.build(specs=): expected "
     "ModelSpec objects, got str"),
    (lambda p, r: pc.Repertoire.build(specs=[{"name": "g"}]), "Repertoire.build(specs=[...]): "
     "expected ModelSpec, got dict"),
    (lambda p, r: pc.recognize_clip(p, "rep.h5"), "recognize_clip(repertoire=): expected "
     "Repertoire"),
    (lambda p, r: pc.recognize_clip(p, pc.Repertoire.default(), settings="fast"),
     "recognize_clip(settings=): expected RecognitionSettings or None, got str"),
    (lambda p, r: observe("tracks.h5"), "observe(tracks=): expected Tracks"),
    (lambda p, r: observe(reach_tracks(r)[0], "x"), "observe(params=): expected ObserveParams"),
    (lambda p, r: write_clip_report("x", p.parent), "write_clip_report(rec=): expected "
     "Recognition"),
    (lambda p, r: pc.track_video("clip.mp4", params="x"), "track_video(params=): expected "
     "TrackerParams"),
    (lambda p, r: pc.landmarks(p, params="x"), "landmarks(params=): expected LandmarkParams"),
    (lambda p, r: pc.landmarks(p, mocap="fast"), "landmarks(mocap=): expected MocapImport"),
]


@pytest.mark.parametrize("call, said", TYPE_CASES, ids=[s.split(":")[0] for _, s in TYPE_CASES])
def test_an_object_of_the_wrong_type_is_refused_on_entry_saying_what_was_expected(
        table, reach, call, said):
    with pytest.raises(TypeError) as err:
        call(table, reach)
    assert said in str(err.value)


# (a settings class's field of the wrong type, MocapImport(markers={...}):
# tests/test_declared_fields.py, generated)


# -- a marker never seen ------------------------------------------------------------------------
def _lost(frame: pd.DataFrame, marker: str, how: str) -> pd.DataFrame:
    frame = frame.copy()
    for ax in "xyz":
        frame[f"{marker}_{ax}"] = np.nan if how == "nan" else 0.0
    return frame


@pytest.mark.parametrize("marker, role", [("index", "finger"), ("thumb", "thumb")])
@pytest.mark.parametrize("how", ["nan", "zeros"])
@pytest.mark.parametrize("mapped", [False, True], ids=["guessed", "mapped"])
def test_a_digit_never_seen_is_refused_naming_it(tmp_path, marker, role, how, mapped):
    path = tmp_path / "trials.tsv"
    _lost(_table(_trial()), marker, how).to_csv(path, sep="\t", index=False)
    options = pc.MocapImport(markers=MarkerMap("thumb", "index")) if mapped else None
    with pytest.raises(InputError) as err:
        pc.read_reaches(path, options)
    said = err.value.problem
    assert f"marker {marker!r}" in said and "never seen" in said, said
    assert "no reach to grasp" not in said
    if role != marker:
        assert f"(the {role})" in said


def test_a_c3d_marker_whose_residual_is_always_negative_is_refused_naming_it(tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    trial = _trial()
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100]
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("thumb", "index")
    n = len(trial.time)
    points = np.ones((4, 2, n))
    points[:3, 0] = trial.markers["thumb"].T * 1000
    points[:3, 1] = trial.markers["index"].T * 1000
    c3d["data"]["points"] = points
    residuals = np.zeros((1, 2, n))
    residuals[0, 1] = -1.0  # the index never reconstructed
    c3d["data"]["meta_points"]["residuals"] = residuals
    path = tmp_path / "lost.c3d"
    c3d.write(str(path))
    with pytest.raises(InputError, match="marker 'index' \\(the finger\\) is never seen"):
        pc.read_reaches(path)


def test_a_marker_lost_in_one_trial_only_leaves_that_trial_unscored(tmp_path):
    good = _table(_trial())
    frame = pd.concat([good.assign(trial=1), _lost(good, "index", "nan").assign(trial=2)])
    path = tmp_path / "trials.tsv"
    frame[["trial", *good.columns]].to_csv(path, sep="\t", index=False)
    recording = read_recording(path)
    assert len(recording.reaches) == 1
    (u,) = recording.unscored
    assert u.status == "marker lost" and "index" in u.reason


@pytest.mark.parametrize("names, lost, role, chosen", [
    (("thumb", "index_tip", "finger"), "index_tip", "finger", "finger"),
    (("thumb_tip", "thumb_middle", "index"), "thumb_tip", "thumb", "thumb_middle"),
    (("thumb", "index", "wrist"), "wrist", "wrist", ()),
    (("thumb", "index", "object"), "object", "object", ()),
])
def test_the_guess_passes_over_a_marker_never_seen(names, lost, role, chosen):
    n = 20
    paths = {m: np.full((n, 3), np.nan) if m == lost else np.ones((n, 3)) for m in names}
    assert getattr(MarkerMap.guess(list(names)), role) in (lost, (lost,))  # by names alone
    assert getattr(MarkerMap.guess(paths), role) == chosen


def test_a_wrist_never_seen_that_nobody_mapped_is_passed_over_with_a_note():
    trial = _trial()
    trial = dataclasses.replace(trial, markers={**trial.markers,
                                                "wrist": np.full((len(trial.time), 3), np.nan)})
    reaches, unscored = trial_reaches(trial)
    assert len(reaches) == 1 and not unscored
    assert any("'wrist' is never seen: not taken as the wrist" in n for n in reaches[0].notes)


def test_a_mapped_wrist_never_seen_is_refused_naming_it(tmp_path):
    frame = _table(_trial())
    for ax in "xyz":
        frame[f"wrist_{ax}"] = np.nan
    path = tmp_path / "trials.tsv"
    frame.to_csv(path, sep="\t", index=False)
    with pytest.raises(InputError, match="marker 'wrist' is never seen"):
        pc.read_reaches(path, pc.MocapImport(markers=MarkerMap("thumb", "index",
                                                               wrist="wrist")))


# -- a manifest's clip name kept for a recording's trials -----------------------------------------
def test_a_manifests_clip_name_is_the_stem_of_each_trial_of_its_recording(tmp_path):
    from perception.discovery import expand_recordings
    from perception.pipeline import RecognitionSettings

    one = _table(_trial())
    two = _table(_simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)], seed=1))
    pd.concat([one.assign(trial=1), two.assign(trial=2)])[["trial", *one.columns]].to_csv(
        tmp_path / "P01.tsv", sep="\t", index=False)
    one.to_csv(tmp_path / "P02.tsv", sep="\t", index=False)
    pd.DataFrame({"clip": ["P01_block1", "P02_block2"], "video": ["P01.tsv", "P02.tsv"],
                  "condition": ["a", "b"]}).to_csv(tmp_path / "manifest.csv", index=False)
    items = expand_recordings(pc.discover(tmp_path / "manifest.csv"), RecognitionSettings())
    assert [i.clip for i in items] == ["P01_block1-trial1", "P01_block1-trial2", "P02_block2"]
    assert [i.condition for i in items] == ["a", "a", "b"]
    assert [i.trial for i in items] == ["P01-trial1", "P01-trial2", "P02"]

"""Bad input through the Python API (``import perception as pc``) is the documented error.

A user's mistake is an :class:`~perception.errors.InputError` (a ``ValueError``)
naming the file or the field, or a ``TypeError`` saying what was expected;
never an ``AttributeError``, a bare ``FileNotFoundError`` or a library's error
from deep inside.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import perception as pc
from perception.errors import InputError


def test_a_missing_video_is_an_input_error_naming_it(tmp_path):
    missing = tmp_path / "nope.mp4"
    for call in (lambda: pc.load_clip(missing),
                 lambda: pc.load_movements(missing)):
        with pytest.raises(InputError, match="nope.mp4: no such file"):
            call()


def test_landmarks_takes_the_object_size_in_pixels_its_error_asks_for():
    tracks, _ = pc.demo_tracks("normal", seed=0)
    bare = dataclasses.replace(tracks, tracker={})  # no apparent object size recorded
    with pytest.raises(InputError, match="object_diameter_px"):
        pc.landmarks(bare, object_diameter=0.1)
    given = pc.landmarks(bare, object_diameter=0.1, object_diameter_px=80.0)
    scaled = pc.landmarks(bare, px_per_m=800.0)
    assert given["status"].tolist() == ["complete"]
    pd.testing.assert_frame_equal(given, scaled)


@pytest.mark.parametrize("given, field", [
    (dict(frame_or_points=np.zeros((48, 64, 4), np.uint8)), "frame_or_points"),   # BGRA
    (dict(frame_or_points=np.zeros((48, 64, 3), float)), "frame_or_points"),      # not uint8
    (dict(frame_or_points=np.array([["a", "b"]] * 4)), "frame_or_points"),
    (dict(likelihood=np.ones(3)), "likelihood"),
    (dict(status=np.zeros((4, 1), np.int8)), "status"),
])
def test_a_bad_row_or_frame_given_online_is_refused_naming_the_argument(given, field):
    rec = pc.OnlineRecognizer(pc.Repertoire.default())
    args = {"frame_or_points": np.full((4, 2), 100.0), **given}
    # the tracker looks ahead over its first frames: the error must come with the first
    for k in range(6):
        with pytest.raises(InputError) as caught:
            rec.update(t=k / 30, **args)
        assert caught.value.field == field
    # and the rows refused did not count
    state = rec.update(np.full((4, 2), 100.0), 0.0)
    assert state.frame == 0


def test_the_summary_run_batch_returns_has_summary_csv_s_verdict_reasons(tmp_path):
    (tmp_path / "in").mkdir()
    for condition in ("normal", "delayed"):
        pc.demo_tracks(condition, seed=0)[0].save(tmp_path / "in" / f"{condition}.tracks.h5")
    summary = pc.run_batch(pc.discover(tmp_path / "in"), tmp_path / "out",
                           pc.Repertoire.default(), quiet=True)
    written = pd.read_csv(tmp_path / "out" / "summary.csv", keep_default_na=False)
    assert summary["verdict_reason"].tolist() == written["verdict_reason"].tolist()
    assert summary["winner_note"].fillna("").tolist() == written["winner_note"].tolist()
    assert all(summary["verdict_reason"].str.len() > 0)
    assert {"trials", "timing", "warnings"} <= set(summary.attrs)


@pytest.mark.parametrize("call, said", [
    (lambda out: pc.movement_span(None), "movement_span(tracks=): expected Tracks"),
    (lambda out: pc.movement_span("clip.tracks.h5"), "movement_span(tracks=): expected Tracks"),
    (lambda out: pc.movement_span(pc.demo_tracks("normal")[0], "fast"),
     "movement_span(params=): expected ObserveParams"),
    (lambda out: pc.observe(None), r"observe\(tracks=\): expected Tracks \(Tracks.load"),
    (lambda out: pc.run_batch("clips/", out, pc.Repertoire.default()),
     r"run_batch\(items=\): expected BatchItems, got the path 'clips/': give discover"),
    (lambda out: pc.run_batch(["a.mp4"], out, pc.Repertoire.default()),
     "run_batch(items=): expected BatchItem"),
])
def test_an_argument_of_the_wrong_type_is_a_type_error_saying_what_was_expected(
        tmp_path, call, said):
    with pytest.raises(TypeError, match=said if "\\" in said else re.escape(said)):
        call(tmp_path / "out")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("given, field", [
    (dict(fps=0), "demo_tracks.fps"), (dict(fps=-30), "demo_tracks.fps"),
    (dict(fps=math.nan), "demo_tracks.fps"), (dict(fps=5000), "demo_tracks.fps"),
    (dict(fps="30"), "demo_tracks.fps"), (dict(noise_px=-1), "demo_tracks.noise_px"),
    (dict(noise_px=math.inf), "demo_tracks.noise_px"),
])
def test_a_demonstration_at_an_impossible_rate_or_noise_is_refused(given, field):
    with pytest.raises(InputError) as caught:
        pc.demo_tracks("normal", **given)
    assert caught.value.field == field
    assert len(pc.demo_tracks("normal", fps=np.float64(25), noise_px=np.int64(0))[0].time) == 41


def test_the_mocap_import_errors_docs_mocap_md_quotes_are_the_ones_raised():
    text = (Path(__file__).resolve().parents[1] / "docs" / "mocap.md").read_text()
    quoted = " ".join(text.split())  # the quotes wrap across lines
    for rate in ("85", 0):
        with pytest.raises(InputError) as caught:
            pc.MocapImport(rate=rate)
        said = str(caught.value)
        assert said.startswith("MocapImport.rate: ")
        assert said.removeprefix("MocapImport.rate: ") in quoted, said


def test_the_online_states_docstring_names_every_verdict_a_state_takes():
    from perception.recognition.provisional import OnlineState

    doc = OnlineState.__doc__.split("verdict : ")[1].split("familiarity : ")[0]
    tracks, _ = pc.demo_tracks("delayed", seed=0)
    rec = pc.OnlineRecognizer(pc.Repertoire.default(), tracker_attrs=dict(tracks.tracker))
    seen = {(s.verdict, s.verdict_detail) for s in
            (rec.update(p, t) for p, t in zip(tracks.position, tracks.time))}
    assert {"unfamiliar", "abnormal"} <= {v for v, _ in seen}
    for verdict, detail in seen:
        assert (f"``{verdict}``" if verdict else "None") in doc, verdict
        assert detail is None or f"``{detail}``" in doc, detail


def test_every_figure_recognition_plot_draws_is_documented_and_a_new_figure():
    from matplotlib.figure import Figure

    rec = pc.recognize_clip(pc.demo_tracks("normal", seed=0)[0], pc.Repertoire.default())
    with pytest.raises(ValueError) as caught:
        rec.plot("nothing")
    kinds = re.findall(r"'(\w+)'", str(caught.value).split("not")[0])
    assert "confidence" in kinds and len(kinds) >= 3
    page = (Path(__file__).resolve().parents[1] / "docs" / "recognition.md").read_text()
    for kind in kinds:
        assert f"``{kind}``" in pc.Recognition.plot.__doc__, kind
        assert kind == "confidence" or f'`rec.plot("{kind}")`' in page, kind
        first, second = rec.plot(kind), rec.plot(kind)
        assert isinstance(first, Figure) and first is not second


@pytest.mark.parametrize("given, said", [
    (dict(observe="x"), "RecognitionSettings(observe=): expected ObserveParams, got str"),
    (dict(rules={"late_opening": 0.6}), "RecognitionSettings(rules=): expected VerdictRules"),
    (dict(hammer=None), "RecognitionSettings(hammer=): expected HammerParams, got NoneType"),
    (dict(mocap={"rate": 85}), "RecognitionSettings(mocap=): expected MocapImport or None"),
    (dict(pose="dlc"), "RecognitionSettings(pose=): expected PoseImport or None"),
    (dict(tracking="setup.toml"), "RecognitionSettings(tracking=): expected TrackingSetup"),
    (dict(fps="30"), "RecognitionSettings(fps=): expected a number (frames/s) or None, got str"),
])
def test_settings_of_the_wrong_type_are_refused_when_made(given, said):
    # they were an AttributeError where a clip first read them (observe: in observe())
    with pytest.raises(TypeError, match=re.escape(said)):
        pc.RecognitionSettings(**given)
    pc.RecognitionSettings(fps=np.float64(25), mocap=pc.MocapImport(rate=85))


def test_the_landmarks_of_tracks_say_the_rule_that_bounded_them_as_a_recordings_do():
    tracks, _ = pc.demo_tracks("normal", seed=0)
    assert pc.landmarks(tracks, px_per_m=800.0)["bound"].tolist() == ["5 % of peak speed"]
    fixed = pc.landmarks(tracks, px_per_m=800.0, params=pc.LandmarkParams(speed=0.05))
    assert fixed["bound"].tolist() == ["0.05 m/s"]

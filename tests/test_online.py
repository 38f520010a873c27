"""The online recogniser: causal pieces equal the offline ones, and its end is `recognize`'s."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from _demos import default_repertoire

from perception.errors import InputError
from perception.filtering import AlphaBeta, alpha_beta
from perception.observation import movement_span
from perception.online import OnlineRecognizer, SettleRule
from perception.pipeline import RecognitionSettings, recognize_tracks
from perception.recognition.engine import HammerParams, StepScorer, recognize
from perception.recognition.models import SceneSpec
from perception.recognition.rules import VerdictRules
from perception.synthetic.independent import draw_independent, independent_tracks


@pytest.fixture(scope="module")
def rep():
    return default_repertoire()


def _tracks(condition, seed=3, fps=30.0):
    return independent_tracks(draw_independent(condition, np.random.default_rng(seed)), seed,
                              fps=fps)[0]


def _feed(rep, tracks, **kw):
    rec = OnlineRecognizer(rep, markers=tracks.markers, tracker_attrs=dict(tracks.tracker), **kw)
    states = [rec.update(tracks.position[i], tracks.time[i]) for i in range(tracks.n_frames)]
    return rec, states


def test_alpha_beta_one_frame_at_a_time_is_the_offline_filter():

    rng = np.random.default_rng(0)
    z = rng.normal(size=(40, 3, 2))
    z[5:8, 1] = np.nan  # a gap: the filter restarts after it
    dt = rng.uniform(0.03, 0.04, 40)
    f = AlphaBeta((3, 2), 0.5, 0.15)
    online = np.stack([f(z[i], dt[i]) for i in range(40)])
    np.testing.assert_array_equal(online, alpha_beta(z, dt, 0.5, 0.15))


@pytest.mark.parametrize("params", [
    HammerParams(), HammerParams(thesis_sign="printed"), HammerParams(w_r=1.0, w_g=0.25),
    HammerParams(filter_gain=0.5, thesis_sign="printed")], ids=["default", "printed",
                                                                "weights", "gain-printed"])
def test_step_scorer_gives_the_engine_columns_frame_by_frame(rep, params):
    rec = recognize_tracks(_tracks("normal", fps=60.0), rep)
    obs = rec.observation
    models = rep.for_scene(SceneSpec.of(obs))
    offline = recognize(obs, models, params)
    scorer = StepScorer(models, params)
    for n in range(obs.n_frames):
        scorer.step(obs.time[n], obs.wrist[n], obs.finger[n], obs.thumb[n])
        np.testing.assert_array_equal(scorer.log_likelihood, offline.log_likelihood[:, n])
        np.testing.assert_array_equal(scorer.confidence, offline.confidence[:, n])
    np.testing.assert_allclose(scorer.misfit, offline.misfit, rtol=1e-12)


@pytest.mark.parametrize("condition", ["normal", "open-close-open", "reach"])
def test_the_end_of_a_stream_is_recognize(rep, condition):
    tracks = _tracks(condition)
    rec, states = _feed(rep, tracks)
    final = rec.finish()
    offline = recognize_tracks(tracks, rep, clip="stream")
    assert json.dumps(final.to_dict()) == json.dumps(offline.to_dict())
    # the onset is found causally, at the offline onset, a few frames after it
    span = movement_span(tracks)
    moving = [s for s in states if s.phase == "moving"]
    first = moving[0]
    assert first.frame - span.onset_frame <= 8
    assert first.since_onset == pytest.approx(tracks.time[first.frame] - span.onset_time)
    assert [s.phase for s in states[:9]] == ["start"] * 9  # the scene needs 10 rest rows
    assert np.all(np.diff([s.progress for s in moving]) >= 0)


def test_a_second_opening_settles_abnormal_before_the_movement_ends(rep):
    tracks = _tracks("open-close-open")
    rec, states = _feed(rep, tracks)
    d = rec.decision
    assert d is not None and d.verdict == "abnormal" and d.detail == "re-opening"
    end = movement_span(tracks).end_frame
    assert d.frame < end
    # once settled it stays: every later state carries the same decision
    assert all(s.decision == d for s in states if s.frame >= d.frame)


def test_a_settle_rule_that_cannot_be_met_leaves_the_verdict_to_the_end(rep):
    tracks = _tracks("normal")
    rec, states = _feed(rep, tracks, settle=SettleRule(margin=1e9))
    assert rec.decision is None
    assert not any(s.settled or s.decision is not None for s in states)
    # the provisional verdict at the end is the final one of the same rows: a normal grasp
    final = rec.finish()
    assert final.verdict == "normal" and final.verdict_detail is None
    assert (states[-1].verdict, states[-1].verdict_detail) == ("normal", None)
    # the margin alone held it back: one that can be met settles the same rows, normal
    reachable, _ = _feed(rep, tracks, settle=SettleRule(margin=1.0))
    assert reachable.decision is not None and reachable.decision.verdict == "normal"


def test_bad_rows_and_rules_are_input_errors(rep):
    rec = OnlineRecognizer(rep)
    with pytest.raises(InputError, match="positions"):
        rec.update(np.zeros((3, 2)), 0.0)
    with pytest.raises(InputError, match="SettleRule"):
        SettleRule(min_progress=2.0)
    with pytest.raises(InputError, match="no frames"):
        OnlineRecognizer(rep).finish()


def _replayed(rec, final):
    """The online reference pass fed the offline scene and scale, up to the offline end."""
    from perception.online import _ReferencePass

    sc, sign = rec._scene, -1.0 if final.mirrored else 1.0
    hand = 0.5 * (sc.first.rest[1] + sc.first.rest[2]) - sc.first.rest[0]
    tip = np.array([0.0, sc.ref.tip_start])
    ref = _ReferencePass(sc.models, sc.hammer, sc.scale, tip - hand * [sign, 1.0], tip,
                         final.normalisation.time_scale, sc.ref.frame_period, sign)
    for row in rec._moving:
        if row[0] <= final.observation.time[-1] + 1e-9:
            ref.feed([row])
    return ref


@pytest.mark.parametrize("condition, flip", [("normal", False), ("delayed", False),
                                             ("normal", True), ("reach", False)])
def test_the_online_reference_pass_is_the_offline_shape_pass(rep, condition, flip):
    """Fed the scene and time scale the offline pass found, the causal pass (rescaled and
    resampled frame by frame) scores exactly what the offline shape pass scores."""
    tracks = _tracks(condition, seed=5)
    if flip:  # a left hand: the finger opens on the model's -x side
        tracks = dataclasses.replace(tracks, position=tracks.position * [-1, 1] + [640, 0])
    rec, _ = _feed(rep, tracks)
    final = rec.finish()
    assert final.mirrored == flip
    ref = _replayed(rec, final)
    idx = ref.kinds["grasp" if final.shape.kinds[0] == "grasp" else "reach"]
    assert [rec._scene.names[i] for i in idx] == final.shape.names
    assert ref.scorer.frames == final.shape.time.size
    np.testing.assert_allclose(ref.scorer.log_likelihood[idx], final.shape.log_likelihood[:, -1],
                               rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ref.scorer.familiarity(final.shape.observation.dt)[idx],
                               final.shape.familiarity, rtol=1e-9)


def test_a_mirrored_scene_is_found_online_and_settles_as_offline(rep):
    """Before, the online path never looked for a mirrored scene: a left hand's normal grasp
    was abnormal (familiarity 0.001) throughout while offline said normal."""
    tracks = _tracks("normal", seed=3)
    flipped = dataclasses.replace(tracks, position=tracks.position * [-1, 1] + [640, 0])
    rec, states = _feed(rep, flipped)
    final = rec.finish()
    assert final.mirrored and final.verdict == "normal"
    assert rec._scene.guess[0] is True
    assert rec.decision is not None and rec.decision.verdict == "normal"
    assert states[-1].verdict == "normal" and states[-1].familiarity > 0.05
    plain, _ = _feed(rep, tracks)
    assert plain.decision.verdict == "normal"
    # the same movement, mirrored: the same scores once the side is read
    assert states[-1].log_likelihood == pytest.approx(plain.state.log_likelihood, rel=1e-9)


@pytest.mark.parametrize("condition", ["normal", "reach"])
def test_normal_and_reach_settle_while_the_stream_runs(rep, condition):
    tracks = _tracks(condition, seed=11)
    rec, states = _feed(rep, tracks)
    final = rec.finish()
    d = rec.decision
    assert d is not None and d.verdict == final.verdict == condition
    assert d.frame < tracks.frame[-1]
    if condition == "normal":  # once the grip has passed its maximum and the hand slows
        assert d.since_onset < final.observation.time[-1]


def test_a_stream_too_near_the_object_is_refused_as_offline(rep):
    tracks = _tracks("normal", seed=3)
    with pytest.raises(InputError) as offline:
        recognize_tracks(tracks, rep, dataclasses.replace(
            RecognitionSettings(), rules=VerdictRules(min_transport=0.5)))
    with pytest.raises(InputError) as online:
        _feed(rep, tracks, settings=dataclasses.replace(
            RecognitionSettings(), rules=VerdictRules(min_transport=0.5)))
    assert "too near" in str(offline.value) and "too near" in str(online.value)


def test_nothing_per_frame_reads_more_of_the_stream_the_longer_it_runs(rep, monkeypatch):
    """The scorer steps one frame at a time, and the evidence reads at most a window
    of the movement: what a frame costs cannot grow with the stream (timed in
    tools/bench.py, not here)."""
    import perception.online as online
    from perception.recognition.engine import StepScorer as Scorer

    tracks = _tracks("normal", seed=3)
    rec, _ = _feed(rep, tracks)
    read, scored = [], []
    monkeypatch.setattr(online, "count_peaks", lambda g, p: read.append(len(g)) or 1)
    original = Scorer.score
    monkeypatch.setattr(Scorer, "score", lambda self, t, *a: scored.append(len(t))
                        or original(self, t, *a))
    last, t0 = tracks.position[-1], float(tracks.time[-1])
    dt = float(np.median(np.diff(tracks.time)))
    for k in range(1, 400):
        rec.update(last, t0 + k * dt)
    assert max(scored) <= 2  # one frame's grid points (two at most)
    assert read and max(read) <= rec._scene.window and read[-1] == max(read)
    assert len(read) < 400  # past the window the evidence is not read again

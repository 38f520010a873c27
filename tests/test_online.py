"""The online recogniser: causal pieces equal the offline ones, and its end is `recognize`'s."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from _demos import default_repertoire

from perception.errors import InputError
from perception.filtering import AlphaBeta, alpha_beta
from perception.observation import movement_span
from perception.online import OnlineRecognizer, SettleRule
from perception.pipeline import RecognitionSettings, recognize_tracks
from perception.recognition.engine import HammerParams, StepScorer, recognize, score_clip
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


def test_a_series_resumed_from_one_filtered_before_is_the_series_filtered_whole():
    """The online recogniser observes the rows so far after every row: alpha_beta resumes
    from the longest series it filtered before that the new one begins with (bitwise the
    same), and starts over where an earlier value differs."""
    rng = np.random.default_rng(1)
    z = rng.normal(size=(60, 3, 2))
    z[10:13, 2] = np.nan
    dt = rng.uniform(0.03, 0.04, 60)
    step = AlphaBeta((3, 2), 0.5, 0.15)
    whole = np.stack([step(z[i], dt[i]) for i in range(60)])
    for n in (20, 21, 45, 60):
        np.testing.assert_array_equal(alpha_beta(z[:n], dt[:n], 0.5, 0.15), whole[:n])
    changed = z.copy()
    changed[5, 0] += 1.0  # not a continuation of anything filtered before
    step = AlphaBeta((3, 2), 0.5, 0.15)
    again = np.stack([step(changed[i], dt[i]) for i in range(60)])
    np.testing.assert_array_equal(alpha_beta(changed, dt, 0.5, 0.15), again)
    assert not np.array_equal(again, whole, equal_nan=True)


def test_scores_of_the_same_movement_are_reused_and_of_another_are_not(rep):
    obs = recognize_tracks(_tracks("normal"), rep).scored_observation
    models = rep.for_scene(SceneSpec.of(obs))
    first = score_clip(obs, models)
    assert score_clip(dataclasses.replace(obs, wrist=obs.wrist.copy()), models) is first
    moved = obs.wrist.copy()
    moved[len(moved) // 2] += 0.01
    other = score_clip(dataclasses.replace(obs, wrist=moved), models)
    assert other is not first
    assert not np.array_equal(other.log_likelihood, first.log_likelihood)
    with pytest.raises(ValueError):  # shared by every result made from them: read-only
        first.log_likelihood[0, 0] = 0.0


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
    # the onset is found causally, a few frames after it: on the rows so far (the
    # crossings the wrist has passed fit its time scale), then at the offline onset
    span = movement_span(tracks)
    moving = [s for s in states if s.phase == "moving"]
    first = moving[0]
    assert first.frame - span.onset_frame <= 9
    assert first.since_onset == pytest.approx(tracks.time[first.frame] - span.onset_time,
                                              abs=tracks.time[1] - tracks.time[0])
    last = moving[-1]
    assert last.since_onset == pytest.approx(tracks.time[last.frame] - span.onset_time)
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


def test_an_abnormal_familiarity_waits_for_the_stream_s_end(rep):
    """A movement's familiarity rises as it completes and comes to rest, so a low one is
    not conclusive early: an `abnormal` resting on familiarity settles only at the end
    (as offline), while a normal grasp under the usual threshold settles before it."""
    tracks = _tracks("normal")
    # above the grasp's familiarity (0.45), under its transport's (0.81): `abnormal`, not
    # a transport that departs
    strict = RecognitionSettings(rules=VerdictRules(familiarity_threshold=0.6))
    rec, states = _feed(rep, tracks, settings=strict, settle=SettleRule(margin=0.0))
    final = rec.finish()
    assert (final.verdict, final.verdict_rule) == ("abnormal", "familiarity")
    assert any(s.verdict == "abnormal" for s in states)  # provisional, never settled
    assert rec.decision is None
    usual, _ = _feed(rep, tracks, settle=SettleRule(margin=0.0))
    assert usual.decision is not None and usual.decision.verdict == "normal"


def test_bad_rows_and_rules_are_input_errors(rep):
    rec = OnlineRecognizer(rep)
    with pytest.raises(InputError, match="positions"):
        rec.update(np.zeros((3, 2)), 0.0)
    with pytest.raises(InputError, match="SettleRule"):
        SettleRule(min_progress=2.0)
    with pytest.raises(InputError, match="no frames"):
        OnlineRecognizer(rep).finish()


def test_a_mirrored_scene_is_found_online_and_settles_as_offline(rep):
    """Before, the online path never looked for a mirrored scene: a left hand's normal grasp
    was abnormal (familiarity 0.001) throughout while offline said normal."""
    tracks = _tracks("normal", seed=3)
    flipped = dataclasses.replace(tracks, position=tracks.position * [-1, 1] + [640, 0])
    rec, states = _feed(rep, flipped)
    final = rec.finish()
    assert final.mirrored and final.verdict == "normal"
    assert rec.prefix.mirrored is True
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
    assert d.since_onset < final.observation.time[-1] + 0.25


def test_a_normal_grasp_settles_before_its_hand_arrives(rep):
    """Judged as a movement that ends as it goes (``judge(..., ongoing=True)``), a grasp
    whose grip opened early and is still opening with the wrist 90 % of its way there,
    past its peak speed, settles `normal`, while ``recognize`` of the rows so far still
    calls them `incomplete` (the state's verdict)."""
    tracks = _tracks("normal", seed=11)
    rec, states = _feed(rep, tracks)
    final, d = rec.finish(), rec.decision
    assert d is not None and d.verdict == final.verdict == "normal"
    at = states[next(i for i, s in enumerate(states) if s.decision is not None)]
    assert (at.verdict, at.verdict_detail) == ("unfamiliar", "incomplete")
    assert at.judged_on.slowed < VerdictRules().arrival
    assert at.progress >= SettleRule().approached
    assert d.since_onset < 0.8 * final.observation.time[-1]
    # asked to wait for the hand at the object, the same rows settle later
    later, _ = _feed(rep, tracks, settle=SettleRule(approached=1.0))
    assert later.decision is not None and later.decision.frame > d.frame


def test_a_stream_too_near_the_object_is_refused_as_offline(rep):
    tracks = _tracks("normal", seed=3)
    with pytest.raises(InputError) as offline:
        recognize_tracks(tracks, rep, dataclasses.replace(
            RecognitionSettings(), rules=VerdictRules(min_transport=0.5)))
    # online, every state says why its rows are not judged (recognize of them refuses them),
    # and the end refuses the stream as recognize does
    rec, states = _feed(rep, tracks, settings=dataclasses.replace(
        RecognitionSettings(), rules=VerdictRules(min_transport=0.5)))
    assert "too near" in states[-1].waiting_for and states[-1].verdict is None
    with pytest.raises(InputError) as online:
        rec.finish()
    assert "too near" in str(offline.value) and online.value.problem == offline.value.problem


def test_a_normal_grasp_settles_on_when_its_grip_started_to_open_before_its_end_is_seen(rep):
    """The landmark opening_time needs the movement's end; before it, the evidence's
    opening_progress (how far the wrist had come when the grip started to open) is known as
    soon as the opening starts, and the settle rule reads it (SettleRule.early_opening)."""
    tracks = _tracks("normal", seed=11)
    rec, states = _feed(rep, tracks)
    d = rec.decision
    assert d is not None and d.verdict == "normal"
    at = states[next(i for i, s in enumerate(states) if s.decision is not None)].judged_on
    assert math.isnan(at.observed.opening_time)  # the movement's end not seen yet
    assert at.opening_progress <= SettleRule().early_opening
    # the same rows with a rule that asks for an earlier opening than this one's wait
    late, _ = _feed(rep, tracks, settle=SettleRule(early_opening=at.opening_progress / 2))
    assert late.decision is None or late.decision.frame > d.frame
    # before the grip opens it is not known
    first = next(s for s in states if s.phase == "moving")
    assert math.isnan(first.judged_on.opening_progress)


def test_a_state_says_why_rows_are_not_judged_yet(rep):
    """Before the movement, a state names what ``recognize`` of the rows so far refuses."""
    tracks = _tracks("normal")
    _, states = _feed(rep, tracks)
    rest = [s for s in states if s.phase == "rest"]
    assert rest and all(s.waiting_for and s.verdict is None for s in rest)
    assert all(s.waiting_for is None and s.judged_on is not None
               for s in states if s.phase == "moving")


def test_markers_without_one_recognition_needs_are_refused_at_once_as_recognize_says(rep):
    """The markers are fixed at construction: not a stream at rest until ``finish``."""
    tracks = _tracks("normal")
    keep = [tracks.markers.index(m) for m in ("thumb", "finger", "wrist")]
    short = dataclasses.replace(tracks, markers=tuple(tracks.markers[k] for k in keep),
                                position=tracks.position[:, keep],
                                likelihood=tracks.likelihood[:, keep],
                                status=tracks.status[:, keep])
    with pytest.raises(InputError) as offline:
        recognize_tracks(short, rep)
    with pytest.raises(InputError) as online:
        OnlineRecognizer(rep, markers=short.markers)
    assert online.value.field == "markers" and "markers: " in str(online.value)
    assert online.value.problem == offline.value.problem
    assert "marker 'object' is not in the tracks" in online.value.problem
    with pytest.raises(InputError, match=r"markers 'finger', 'object' are not in the tracks"):
        OnlineRecognizer(rep, markers=("thumb", "index", "wrist"))
    # a marker lost in a row is NaN there, not a marker missing
    rec = OnlineRecognizer(rep, markers=("object", "wrist", "finger", "thumb", "elbow"))
    assert rec.update(np.full((5, 2), np.nan), 0.0).phase == "start"

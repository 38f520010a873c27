"""A frame costs what is new in it (issue 45, item 6): what the rows before it gave is reused,
bitwise the same as a pass from the first row.

* scoring: a movement a frame longer than one scored before (same models and
  settings) is scored from where that one ended, one new frame, and its
  scores are those of a pass from its first frame, bit for bit, for every
  rule, sign and filter gain;
* the scene: a recognition fixes it once, not once to settle the start and
  again to observe (and rows changed in place fix it again).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _demos import default_repertoire

import perception.observation as observation
import perception.recognition.engine as engine
from perception.pipeline import recognize_tracks
from perception.recognition.engine import HammerParams, StepScorer, score_clip
from perception.synthetic.independent import draw_independent, independent_tracks

#: one option row per kind of step: rule, thesis sign, filter gain
PARAMS = [HammerParams(),
          HammerParams(rule="thesis", thesis_sign="printed", w_r=1.0, w_g=0.25, filter_gain=0.0),
          HammerParams(rule="thesis", filter_gain=1.0)]


@pytest.fixture(scope="module")
def rep():
    return default_repertoire()


@pytest.fixture(scope="module")
def scored(rep):
    """A grasp's observation at the reference scale and its models (with a lost frame)."""
    tracks = independent_tracks(draw_independent("normal", np.random.default_rng(5),
                                                 duration=1.0), 5)[0]
    position = tracks.position.copy()
    position[20, list(tracks.markers).index("finger")] = np.nan  # a digit lost for a frame
    rec = recognize_tracks(tracks.replace(position=position), rep)
    return rec.scored_observation, rec.models


def _first(obs, n):
    """The first ``n`` frames of an observation."""
    return dataclasses.replace(obs, frame=obs.frame[:n], time=obs.time[:n],
                               wrist=obs.wrist[:n], finger=obs.finger[:n], thumb=obs.thumb[:n])


def _forget():
    """No scores kept from before (a pass from the first frame)."""
    engine._SCORED.local.__dict__.clear()
    engine._RESUMABLE.local.__dict__.clear()


def _same(a, b):
    for name in ("confidence", "dC_r", "dC_g", "log_likelihood", "mahalanobis", "scored",
                 "familiarity"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and np.array_equal(x, y, equal_nan=True), name
    for name in a.predicted:
        assert np.array_equal(a.predicted[name], b.predicted[name], equal_nan=True), name
    assert (a.names, a.kinds, a.rule) == (b.names, b.kinds, b.rule)


def test_a_movement_a_frame_longer_scores_the_new_frame_alone(scored, monkeypatch):
    obs, models = scored
    calls = []
    predict = StepScorer.predict

    def counted(self, *args):
        calls.append(1)
        return predict(self, *args)

    monkeypatch.setattr(StepScorer, "predict", counted)
    _forget()
    assert obs.n_frames >= 15
    score_clip(_first(obs, 10), models)
    assert len(calls) == 10
    for before, n in ((10, 11), (11, 12), (12, 15)):  # one frame more, then three at once
        del calls[:]
        score_clip(_first(obs, n), models)
        assert len(calls) == n - before
    del calls[:]
    score_clip(_first(obs, 15), models)  # the same movement again: nothing scored
    assert not calls


@pytest.mark.parametrize("params", PARAMS, ids=["likelihood", "thesis-printed-0", "thesis-1"])
def test_resumed_scores_are_a_pass_from_the_first_frame_bit_for_bit(scored, params):
    obs, models = scored
    _forget()
    for n in range(2, obs.n_frames + 1):
        resumed = score_clip(_first(obs, n), models, params)
        _forget()
        fresh = score_clip(_first(obs, n), models, params)
        _same(resumed, fresh)
        _forget()
        score_clip(_first(obs, n), models, params)  # the next one resumes from this one


def test_a_movement_that_is_not_a_longer_one_is_scored_afresh(scored):
    obs, models = scored
    _forget()
    score_clip(_first(obs, 30), models)
    changed = dataclasses.replace(_first(obs, 31), wrist=_first(obs, 31).wrist + 1e-12)
    again = score_clip(changed, models)  # its first frames differ in the last bit
    _forget()
    _same(again, score_clip(changed, models))


def test_a_recognition_fixes_the_scene_once(rep, monkeypatch):
    tracks = independent_tracks(draw_independent("normal", np.random.default_rng(6)), 6)[0]
    calls = []
    fix = observation._scene_transform

    def counted(*args):
        calls.append(1)
        return fix(*args)

    monkeypatch.setattr(observation, "_scene_transform", counted)
    observation._SCENES.local.__dict__.clear()
    first = recognize_tracks(tracks, rep)
    assert len(calls) == 1  # settling the start and observing share it
    # rows changed in place are new rows: the scene is fixed from them
    tracks.position[:, list(tracks.markers).index("object")] += 3.0
    second = recognize_tracks(tracks, rep)
    assert len(calls) == 2
    assert not np.array_equal(first.observation.scene.origin_px, second.observation.scene.origin_px)

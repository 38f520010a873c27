"""The verdict: familiarity calibrated on each model's own demonstrations, stored with it."""

import dataclasses

import h5py
import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

from perception.observation import observe
from perception.pipeline import recognize_clip
from perception.recognition import ModelSpec, Repertoire, SceneSpec, build_model, recognize
from perception.recognition.calibration import calibrate, own_demonstration
from perception.recognition.engine import HammerParams
from perception.recognition.rollout import rollout
from perception.recognition.rules import Evidence, VerdictRules, judge
from perception.recognition.verdict import Calibration, CalibrationParams
from perception.synthetic.independent import draw_independent, independent_tracks

DEFAULT_THRESHOLD = VerdictRules().familiarity_threshold


def decide(kinds, ll, familiarity):
    return judge(Evidence(kinds, ll, familiarity))


EXPECTED = {"normal": "normal", "delayed": "abnormal", "open-close-open": "abnormal",
            "reach": "reach"}


# -- familiarity and the verdict from numbers -------------------------------------------
def test_familiarity_is_the_fitted_share_of_own_demonstrations_that_fit_worse():
    misfits = np.exp(np.random.default_rng(0).normal(1.0, 0.5, 400))
    cal = Calibration(misfits, 1 / 30)
    assert cal.familiarity(np.exp(1.0)) == pytest.approx(0.5, abs=0.03)  # the median
    # the fitted log-normal: 1.645 SD above the centre is the worst 5 %
    assert cal.familiarity(np.exp(1.0 + 1.645 * 0.5)) == pytest.approx(0.05, abs=0.01)
    f = [cal.familiarity(m) for m in (0.1, 1, 3, 10, 100)]
    assert f == sorted(f, reverse=True) and f[0] > 0.99 and f[-1] < 1e-6
    assert np.isnan(cal.familiarity(np.nan))


def test_a_few_extreme_own_demonstrations_do_not_stretch_the_tail():
    misfits = np.exp(np.random.default_rng(1).normal(1.0, 0.5, 50))
    wild = Calibration(np.r_[misfits[:-2], 500.0, 900.0], 1 / 30)
    assert wild.familiarity(40.0) < 0.01  # the empirical share would be 2/50


def test_misfits_are_compared_at_the_calibration_frame_rate():
    cal = Calibration(np.exp(np.linspace(0, 2, 50)), 1 / 30)
    # a clip at 60 frames/s has one-step predictions half as long: its misfit counts 4x
    assert cal.familiarity(0.5, 1 / 60) == pytest.approx(cal.familiarity(2.0, 1 / 30))


def test_decide():
    kinds = ["grasp", "grasp", "reach"]
    ll = np.array([10.0, 4.0, 1.0])
    v = decide(kinds, ll, np.array([0.3, 0.9, 0.9]))
    assert (v.verdict, v.best, v.margin) == ("normal", 0, 6.0)
    assert decide(kinds, ll, np.array([0.01, 0.9, 0.9])).verdict == "abnormal"
    assert decide(kinds, ll[::-1].copy(), np.array([0.9, 0.9, 0.2])).verdict == "reach"
    assert decide(kinds, ll, np.array([np.nan] * 3)).verdict is None
    edge = decide(kinds, ll, np.array([DEFAULT_THRESHOLD, 0, 0]))
    assert edge.verdict == "normal"  # at the threshold is familiar
    assert np.isnan(decide(["grasp"], np.array([1.0]), np.array([0.5])).margin)


def test_bad_calibration_input_is_refused():
    with pytest.raises(ValueError, match="misfits"):
        Calibration(np.array([1.0, np.nan, 2.0, 3.0]), 1 / 30)
    with pytest.raises(ValueError, match="demonstrations"):
        CalibrationParams(demonstrations=3)
    with pytest.raises(ValueError, match="time_scale"):
        CalibrationParams(time_scale=0.7)
    with pytest.raises(ValueError, match="familiarity_threshold"):
        VerdictRules(familiarity_threshold=1.5)
    with pytest.raises(ValueError, match="late_opening"):
        VerdictRules(late_opening=-0.1)


# -- calibration in the repertoire --------------------------------------------------------
@pytest.fixture(scope="module")
def small():
    return Repertoire.build([ModelSpec("g", "grasp", {"duration": 1.0}),
                             ModelSpec("r", "reach", {"duration": 1.0})])


def test_every_model_is_calibrated_once_and_alike(small):
    g = small.models[0]
    assert g.calibration is not None and g.calibration.misfit.size == 50
    alone = calibrate([build_model(g.spec, g.scene)])[0]
    np.testing.assert_array_equal(alone.misfit, g.calibration.misfit)  # seeded by name


def test_the_calibration_is_stored_and_old_files_still_load(small, tmp_path):
    path = small.save(tmp_path / "rep.h5")
    back = Repertoire.load(path)
    for a, b in zip(small, back):
        np.testing.assert_array_equal(a.calibration.misfit, b.calibration.misfit)
        assert a.calibration.params == b.calibration.params
        assert a.calibration.frame_period == b.calibration.frame_period
    with h5py.File(path, "a") as f:  # as written before calibrations existed
        for name in f["models"]:
            del f["models"][name]["calibration"]
    old = Repertoire.load(path)
    assert all(m.calibration is None for m in old)
    # the model a verdict rests on is calibrated then, as the built one was
    tracks = demo_tracks("normal", 2)[0]
    fresh, built = recognize_clip(tracks, old), recognize_clip(tracks, small)
    assert fresh.verdict == built.verdict == "normal"
    assert fresh.decision.familiarity == pytest.approx(built.decision.familiarity)
    again = old.for_scene(SceneSpec.of(fresh.scored_observation))
    # kept for the next clip
    assert again[fresh.judged[fresh.decision.best]].calibration is not None
    # and only those the verdict rests on: the best model at the reference
    # scale and the best reach model of the transport alone
    assert sum(m.calibration is not None for m in again) <= 2


def test_replanned_models_keep_their_calibration(small):
    moved = small.for_scene(SceneSpec(distance=0.20, frame_period=1 / 25))
    for a, b in zip(small, moved):
        assert b is not a and b.calibration is a.calibration


def test_own_demonstrations_are_familiar(small):
    model = small.models[0]
    params = CalibrationParams()
    rng = np.random.default_rng(123)  # other draws than the calibration's
    run = rollout([model], 130, trials=30, cv=params.execution_cv, rng=rng)
    fam = []
    for j in range(30):
        rec = recognize(observe(own_demonstration(model, run, j, params, rng)), [model])
        fam.append(rec.familiarity[0])
    fam = np.array(fam)
    assert 0.3 < np.median(fam) < 0.7  # a fresh own demonstration is a typical one
    assert np.mean(fam >= DEFAULT_THRESHOLD) >= 0.85


# -- the verdict on demonstrations of both generators (in memory) -----------------------
def _tracks(generator: str, condition: str, i: int):
    if generator == "thesis":
        return demo_tracks(condition, 100 + i)[0]
    rng = np.random.default_rng(np.random.SeedSequence(77, spawn_key=(len(condition), i)))
    return independent_tracks(draw_independent(condition, rng), i)[0]


@pytest.mark.slow
def test_the_verdict_is_right_on_demonstrations_of_both_generators():
    """In memory, 120 demonstrations: >= 95 % right overall and >= 90 % in every class.

    Measured over 60 independent demonstrations per condition: normal 97 %, abnormal and
    reach 100 %; the acceptance figure (>= 95 % per class) comes from video
    (test_verdict_video.py, tools/thesis/ch5.py).
    """
    rep = default_repertoire()
    right: dict[tuple, list[bool]] = {}
    for generator in ("independent", "thesis"):
        for condition, want in EXPECTED.items():
            for i in range(20 if condition in ("normal", "reach") else 10):
                rec = recognize_clip(_tracks(generator, condition, i), rep)
                right.setdefault((generator, want), []).append(rec.verdict == want)
                d = rec.to_dict()
                assert d["verdict"] == rec.verdict and 0 <= d["familiarity"] <= 1
                assert d["margin"] >= 0
    everything = [hit for hits in right.values() for hit in hits]
    assert len(everything) == 120 and np.mean(everything) >= 0.95
    for key, hits in right.items():
        assert np.mean(hits) >= 0.9, (key, hits)


def test_abnormal_grasps_are_abnormal_and_their_winner_is_a_grasp_model():
    """Never confidently wrong: an open-close-open grasp whose early closing let a reach model
    win the scene's own pass (before issue 42) is abnormal, and its winner is now the
    verdict's own model: one scoring pass gives both."""
    rep = default_repertoire()
    verdicts = []
    for i in range(12):
        # an early closing (at 58 % of the movement, re-opened by 82 %: the independent
        # generator's before issue 36) is where a reach model won the scene's pass
        rng = np.random.default_rng(np.random.SeedSequence(77, spawn_key=(15, i)))
        early = draw_independent("open-close-open", rng, oco_first_time=0.38,
                                 oco_close_time=0.58, oco_reopen_time=0.82)
        rec = recognize_clip(independent_tracks(early, i)[0], rep)
        assert rec.kinds[rec.names.index(rec.winner)] == "grasp" and rec.winner_note is None
        assert rec.winner == rec.verdict_model
        verdicts.append((rec.verdict, rec.verdict_detail))
    assert verdicts.count(("abnormal", "re-opening")) >= 10, verdicts
    assert ("normal", None) not in verdicts, verdicts


def test_recognition_json_keeps_every_key_and_adds_the_verdict():
    rep = default_repertoire()
    rec = recognize_clip(demo_tracks("normal", 3)[0], rep)
    d = rec.to_dict()
    assert {"clip", "models", "winner", "rule", "time", "confidence"} <= set(d)
    assert {"verdict", "familiarity", "margin", "reference_model", "transport_confidence",
            "aperture", "familiarity_threshold"} <= set(d)
    assert {"name", "kind", "final_confidence", "final_log_likelihood", "misfit",
            "familiarity"} == set(d["models"][0])
    # the verdict is read at the repertoire's reference scale (the shape pass),
    # among the models of the clip's kind (it opens its grip: the grasp models)
    judged = list(rec.judged)
    ll = rec.log_likelihood[judged, -1]
    best = int(np.argmax(ll))
    assert d["familiarity"] == pytest.approx(rec.familiarity[judged][best])
    assert {rec.kinds[i] for i in judged} == {"grasp"}
    assert d["shape"]["model"] == rec.names[judged[best]] == d["winner"]
    second = np.sort(ll)[-2]
    assert d["margin"] == pytest.approx(ll[best] - second)
    thesis = dataclasses.replace(HammerParams(), rule="thesis")
    from perception.pipeline import RecognitionSettings

    other = recognize_clip(demo_tracks("normal", 3)[0], rep, RecognitionSettings(hammer=thesis))
    assert other.to_dict()["verdict"] == d["verdict"]  # the verdict is the likelihood rule's

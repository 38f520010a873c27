"""The verdict's one declared policy: VerdictRules, judge's ordered table, --verdict-rules."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

from hammer_mv.cli import main
from perception.errors import InputError
from perception.landmarks import LandmarkParams, Landmarks
from perception.pipeline import RecognitionSettings, recognize_tracks
from perception.recognition.rules import (
    AT_END,
    RULE_TABLE,
    VERDICT_RULES,
    Evidence,
    VerdictRules,
    judge,
    reason,
)


def _evidence(**kw):
    base = dict(kinds=["grasp", "reach"], log_likelihood=np.array([5.0, 1.0]),
                familiarity=np.array([0.5, 0.5]), transport_familiarity=0.5,
                rest_aperture=0.01, observed=Landmarks(movement_time=1.0, aperture_peaks=1,
                                                       opening_time=0.2),
                reference=None, aperture_gap=0.0)
    return Evidence(**{**base, **kw})


def test_the_rules_are_tried_in_order_and_the_first_that_fires_names_itself():
    assert VERDICT_RULES == tuple(r[0] for r in RULE_TABLE)
    assert VERDICT_RULES[-1] == "familiarity"
    d = judge(_evidence())
    assert (d.verdict, d.rule, d.detail, d.best) == ("normal", "familiarity", None, 0)
    # a whole-hand grasp is out of the verdict's depth before anything else
    d = judge(_evidence(rest_aperture=0.05, observed=Landmarks(aperture_peaks=2)))
    assert (d.verdict, d.rule) == ("unfamiliar", "not-a-precision-grip")
    # a grip that opens twice is abnormal even when the transport is no human reach
    d = judge(_evidence(observed=Landmarks(aperture_peaks=2), transport_familiarity=0.001))
    assert (d.verdict, d.rule, d.detail) == ("abnormal", "grip-departs", "re-opening")
    d = judge(_evidence(transport_familiarity=0.001))
    assert (d.verdict, d.rule) == ("unfamiliar", "not-a-human-reach")
    d = judge(_evidence(aperture_gap=0.5))
    assert (d.verdict, d.rule) == ("unfamiliar", "insufficient-data")
    d = judge(_evidence(familiarity=np.array([0.01, 0.9])))
    assert (d.verdict, d.rule) == ("abnormal", "familiarity")
    # unlike the models, and the transport alone as unlike them: the misfit is the
    # transport's, so the movement is out of the verdict's depth, not an abnormal grasp
    d = judge(_evidence(familiarity=np.array([0.01, 0.9]), transport_familiarity=0.03))
    assert (d.verdict, d.rule, d.detail) == ("unfamiliar", "transport-departs", None)
    d = judge(_evidence(familiarity=np.array([0.01, 0.9]), transport_familiarity=0.06))
    assert (d.verdict, d.rule) == ("abnormal", "familiarity")
    # a familiar grasp stays normal, and a grip that departs stays abnormal, however
    # unlike a reach its transport
    assert judge(_evidence(transport_familiarity=0.03)).verdict == "normal"
    d = judge(_evidence(familiarity=np.array([0.01, 0.9]), transport_familiarity=0.03,
                        observed=Landmarks(aperture_peaks=2)))
    assert (d.verdict, d.rule, d.detail) == ("abnormal", "grip-departs", "re-opening")
    d = judge(_evidence(familiarity=np.array([np.nan, 0.9])))
    assert d.verdict is None and d.rule is None


def test_a_movement_still_being_seen_is_not_cut_short():
    """``ongoing=True`` (a stream's rows so far) leaves out the rules that read the
    movement's end: the hand that has not arrived yet is judged as it goes; every other
    rule fires as it does on a whole movement."""
    under_way = _evidence(slowed=0.3)
    d = judge(under_way)
    assert (d.verdict, d.rule, d.detail) == ("unfamiliar", "incomplete", "incomplete")
    d = judge(under_way, ongoing=True)
    assert (d.verdict, d.rule) == ("normal", "familiarity")
    assert AT_END == ("incomplete",) and set(AT_END) <= set(VERDICT_RULES)
    for kw, rule in (({"transport_familiarity": 0.001}, "not-a-human-reach"),
                     ({"aperture_gap": 0.5}, "insufficient-data"),
                     ({"observed": Landmarks(aperture_peaks=2)}, "grip-departs")):
        assert judge(_evidence(slowed=0.3, **kw), ongoing=True).rule == rule
    # a verdict no rule of AT_END gave is the ongoing one too (the online path judges again
    # only after such a rule)
    for kw in ({}, {"transport_familiarity": 0.001}, {"aperture_gap": 0.5},
               {"familiarity": np.array([0.01, 0.9]), "transport_familiarity": 0.03},
               {"observed": Landmarks(aperture_peaks=2)}):
        d = judge(_evidence(**kw))
        assert d.rule not in AT_END and judge(_evidence(**kw), ongoing=True) == d


def test_peaks_the_landmarks_could_not_count_leave_the_digits_unseen():
    """A gap the landmarks found long enough to hide a closing and re-opening (within the
    movement's own bounds) makes a would-be normal `unfamiliar`, though the scored span's
    own gap is short; its reason quotes the landmark's flag."""
    said = "not seen: a digit was lost for 250 ms, long enough to hide a closing and re-opening"
    hidden = Landmarks(movement_time=1.0, aperture_peaks=None, opening_time=0.2,
                       flags={"aperture_peaks": said})
    d = judge(_evidence(observed=hidden, aperture_gap=0.05))
    assert (d.verdict, d.rule, d.detail) == ("unfamiliar", "insufficient-data", "digits-unseen")
    assert said in reason(d, _evidence(observed=hidden, aperture_gap=0.05))
    # a count the landmarks made is judged as before
    d = judge(_evidence(aperture_gap=0.05))
    assert (d.verdict, d.rule) == ("normal", "familiarity")
    # two peaks seen stand, whatever a loss elsewhere hides
    twice = Landmarks(movement_time=1.0, aperture_peaks=2, opening_time=0.2)
    d = judge(_evidence(observed=twice, aperture_gap=0.5))
    assert (d.verdict, d.rule, d.detail) == ("abnormal", "grip-departs", "re-opening")


def test_every_threshold_is_a_field_that_moves_the_verdict():
    late = _evidence(observed=Landmarks(movement_time=1.0, aperture_peaks=1, opening_time=0.5))
    assert judge(late).verdict == "normal"
    assert judge(late, VerdictRules(late_opening=0.45)).detail == "delayed-opening"
    gap = _evidence(aperture_gap=0.15)
    assert judge(gap).verdict == "normal"
    strict = VerdictRules(landmarks=LandmarkParams(max_gap=0.05, max_gap_share=0.1))
    assert judge(gap, strict).rule == "insufficient-data"
    assert judge(_evidence(transport_familiarity=0.9),
                 VerdictRules(familiarity_threshold=0.6)).verdict == "abnormal"
    # the transport is held to the same threshold
    assert judge(_evidence(), VerdictRules(familiarity_threshold=0.6)).rule == "transport-departs"
    assert judge(_evidence(rest_aperture=0.03), VerdictRules(precision_grip_aperture=0.02)) \
        .rule == "not-a-precision-grip"


@pytest.mark.parametrize("bad", [dict(familiarity_threshold=1.5), dict(late_opening=-0.1),
                                 dict(min_transport=math.nan), dict(grasp_rest_frames=0),
                                 dict(landmarks={"threshold": 0.05})])
def test_bad_rules_are_input_errors_naming_the_field(bad):
    with pytest.raises(InputError) as err:
        VerdictRules(**bad)
    assert next(iter(bad)) in str(err.value)


def test_the_report_carries_the_rules_and_the_passes(tmp_path):
    tracks = demo_tracks("delayed", 0)[0]
    rec = recognize_tracks(tracks, default_repertoire())
    d = rec.to_dict()
    assert d["verdict_rules"] == VerdictRules().to_dict()
    assert d["verdict_rules"]["landmarks"]["opening_level"] == 0.10
    assert VerdictRules.from_dict(d["verdict_rules"]) == VerdictRules()
    assert d["verdict_rule"] == "grip-departs" and d["verdict_detail"] == "delayed-opening"
    p = d["passes"]
    # one scoring pass gives the verdict and the winner (issue 42): every model scored at
    # the repertoire's scale, the verdict's and the winner's of the kind the grip shows
    assert p["winner_from"] == p["verdict_from"] == "reference" and "scene" not in p
    assert p["reference"]["winner"] == d["winner"] == rec.winner
    assert p["reference"]["best"] == d["shape"]["model"] == d["verdict_model"]
    assert p["reference"]["models"] == [m["name"] for m in d["models"]]
    assert set(p["reference"]["judged"]) == {n for n, k in zip(rec.names, rec.kinds)
                                             if k == "grasp"}
    # settings that move a threshold move the verdict, and the report says so
    lenient = RecognitionSettings(rules=VerdictRules(late_opening=0.9, late_mga=1.0))
    other = recognize_tracks(tracks, default_repertoire(), lenient)
    assert other.verdict_rule != "grip-departs"
    assert other.to_dict()["verdict_rules"]["late_opening"] == 0.9


def test_verdict_rules_from_toml_on_the_command_line(tmp_path, capsys):
    tracks = demo_tracks("normal", 0)[0]
    path = tracks.save(tmp_path / "n.tracks.h5")
    rules = tmp_path / "rules.toml"
    rules.write_text("[verdict]\nlate_opening = 0.01\n[verdict.landmarks]\nopening_level = 0.2\n")
    assert main(["recognize", str(path), "-o", str(tmp_path / "o"), "--no-figures",
                 "--verdict-rules", str(rules)]) == 0
    d = json.loads((tmp_path / "o" / "n.recognition.json").read_text())
    assert d["verdict_rules"]["late_opening"] == 0.01
    assert d["verdict_rules"]["landmarks"]["opening_level"] == 0.2
    assert (d["verdict"], d["verdict_detail"]) == ("abnormal", "delayed-opening")
    capsys.readouterr()
    rules.write_text("[verdict]\nlate_opnig = 0.5\n")
    assert main(["recognize", str(path), "-o", str(tmp_path / "p"), "--verdict-rules",
                 str(rules)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "late_opening" in err and "rules.toml" in err
    assert not (tmp_path / "p" / "n.recognition.json").exists()


def test_settings_fingerprint_changes_with_the_rules():
    a = RecognitionSettings().fingerprint()
    b = dataclasses.replace(RecognitionSettings(), rules=VerdictRules(late_mga=0.9)).fingerprint()
    assert a != b and b["rules"]["late_mga"] == 0.9

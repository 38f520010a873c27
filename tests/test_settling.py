"""A clip without a still start is scored from the scene its data give, with a note."""

from __future__ import annotations

import math

import pytest
from _demos import default_repertoire, demo_tracks

from perception.errors import InputError
from perception.landmarks import LandmarkParams
from perception.observation import observe
from perception.pipeline import recognize_tracks


@pytest.fixture(scope="module")
def normal():
    return demo_tracks("normal", 0)


def test_a_clean_start_needs_no_note(normal):
    rec = recognize_tracks(normal[0], default_repertoire())
    assert rec.verdict == "normal" and rec.notes == () and rec.to_dict()["notes"] == []


def test_a_spike_on_the_first_frame_is_left_out_and_said(normal):
    tracks, _ = normal
    pos = tracks.position.copy()
    pos[0] += 40  # 40 px off on the first frame, every marker
    with pytest.raises(InputError, match="at rest"):
        observe(tracks.replace(position=pos))  # observe itself stays strict
    rec = recognize_tracks(tracks.replace(position=pos), default_repertoire())
    assert rec.verdict == "normal"
    assert rec.notes[0].startswith("the first 1 frame(s) (0.03 s) left out")


def test_a_clip_starting_as_the_hand_moves_is_held_at_its_first_frame(normal):
    tracks, truth = normal
    late = tracks.rows(truth["onset_frame"] + 2, len(tracks.time))
    rec = recognize_tracks(late, default_repertoire())
    assert rec.verdict == "normal"
    assert rec.notes[0].startswith(f"no still start: frame {truth['onset_frame'] + 2} held")


def test_a_clip_starting_with_the_grip_open_cannot_be_judged(normal):
    tracks, truth = normal
    mid = tracks.rows(truth["onset_frame"] + 10, len(tracks.time))  # 0.33 s in: open
    with pytest.raises(InputError, match="starts in the middle of the movement"):
        recognize_tracks(mid, default_repertoire())


def test_a_gap_hides_a_reopening_by_its_length_and_its_share_of_the_movement():
    lp = LandmarkParams()
    assert not lp.hides_a_reopening(lp.max_gap, 0.3)                # never at 0.1 s or less
    assert not lp.hides_a_reopening(0.2, 1.5)                       # 13 % of a slow grasp
    assert lp.hides_a_reopening(0.2, 0.5)                           # 40 % of a fast one
    assert lp.hides_a_reopening(lp.max_gap_share * 2.0 + 0.01, 2.0)
    assert lp.hides_a_reopening(0.15, math.nan)                     # unknown: the 0.1 s alone


def test_the_report_names_the_rule_that_gave_the_verdict(normal):
    from perception.recognition.result import VERDICT_RULES

    rep = default_repertoire()
    rec = recognize_tracks(normal[0], rep)
    d = rec.to_dict()
    # every verdict has a reason with its numbers, a normal one too (issue 44)
    assert d["verdict_rule"] == "familiarity"
    assert d["verdict_reason"] == rec.verdict_reason
    assert ">= 0.05 threshold (familiarity_threshold)" in rec.verdict_reason
    assert d["verdict_rules"]["late_opening"] == 0.55
    late = recognize_tracks(demo_tracks("delayed", 0)[0], rep)
    assert (late.verdict, late.verdict_rule) == ("abnormal", "grip-departs")
    lost = demo_tracks("normal", 0, lost={"finger": slice(21, 30)})[0]
    gap = recognize_tracks(lost, rep)
    assert (gap.verdict, gap.verdict_rule) == ("unfamiliar", "insufficient-data")
    assert {rec.verdict_rule, late.verdict_rule, gap.verdict_rule} <= set(VERDICT_RULES)

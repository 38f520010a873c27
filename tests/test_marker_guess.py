"""A recording of both hands: the digits and the wrist are taken from one hand.

Full-body and bimanual marker sets name each hand's markers (``L_THUMB_TIP``,
``RTHUMB``, ``Left_index``). The guess took the first thumb and the first
index whatever their side (a left thumb with a right index), and averaged
both wrists; it now takes one hand's: the one whose digits move farthest.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from perception.io.mocap import read_mocap
from perception.io.mocap_trial import MocapTrial
from perception.reach_data import MarkerMap
from perception.reaches import trial_reaches
from perception.recordings import MocapImport, recognize_reach

DATA = Path(__file__).parent / "data" / "mocap"


@pytest.mark.parametrize("names, hand", [
    (["L_THUMB_TIP", "L_INDEX_TIP", "L_WRIST", "R_THUMB_TIP", "R_INDEX_TIP", "R_WRIST"],
     ("R_THUMB_TIP", "R_INDEX_TIP", ("R_WRIST",))),
    (["LTHUMB", "RTHUMB", "LINDEX", "RINDEX", "LWRIST", "RWRIST"],
     ("RTHUMB", "RINDEX", ("RWRIST",))),
    (["Left_thumb", "Right_index", "Right_thumb", "Left_index"],
     ("Right_thumb", "Right_index", ())),
    (["thumb", "index", "eyeL", "eyeR"], ("thumb", "index", ())),  # one hand: as before
    # OpenPose's hand points, numbered from the base: 4 is the tip; both hands named
    (["right_wrist", "right_hand_thumb_1", "right_hand_thumb_4", "right_hand_index_1",
      "right_hand_index_4", "left_hand_thumb_4", "left_hand_index_4", "left_wrist"],
     ("right_hand_thumb_4", "right_hand_index_4", ("right_wrist",))),
    (["index2", "index", "thumb"], ("thumb", "index", ())),  # a plain name first
    # MediaPipe's: the tips by name
    (["WRIST", "THUMB_CMC", "THUMB_TIP", "INDEX_FINGER_MCP", "INDEX_FINGER_TIP"],
     ("THUMB_TIP", "INDEX_FINGER_TIP", ("WRIST",))),
])
def test_names_of_two_hands_give_one_hands_markers(names, hand):
    guess = MarkerMap.guess(names)
    assert (guess.thumb, guess.finger, guess.wrist) == hand


def _two_hands(trial, moving: str) -> MocapTrial:
    """``trial``'s thumb and index as the ``moving`` side's, the other hand at rest."""
    rest = {m: np.repeat(trial.markers[m][:1] + [0.3, 0.0, 0.0], len(trial.time), axis=0)
            for m in ("thumb", "index")}
    other = "L" if moving == "R" else "R"
    markers = {f"{moving}_thumb": trial.markers["thumb"], f"{moving}_index": trial.markers["index"],
               f"{other}_thumb": rest["thumb"], f"{other}_index": rest["index"]}
    return MocapTrial(trial.name, trial.source, trial.time, markers, trial.rate, trial.units)


@pytest.mark.parametrize("moving", ["R", "L"])
def test_the_hand_that_moves_is_the_one_scored(moving):
    from perception.recognition.repertoire import Repertoire

    trial = read_mocap(DATA / "optotrak-trials.tsv", rate=85.0)[0]
    lost = trial.markers["thumb"].copy()
    lost[3::7] = np.nan  # the moving thumb lost now and then, as real markers are
    trial = MocapTrial(trial.name, trial.source, trial.time, {**trial.markers, "thumb": lost},
                       trial.rate, trial.units)
    both = _two_hands(trial, moving)
    guess = MarkerMap.guess(both.markers)
    assert (guess.thumb, guess.finger) == (f"{moving}_thumb", f"{moving}_index")
    reaches, _ = trial_reaches(both)
    assert len(reaches) == 1 and not any("never seen" in n for n in reaches[0].notes)
    rec, _ = recognize_reach(reaches[0], Repertoire.default(), None, MocapImport(rate=85.0))
    alone, _ = recognize_reach(trial_reaches(trial, MarkerMap("thumb", "index"))[0][0],
                               Repertoire.default(), None, MocapImport(rate=85.0))
    assert rec.verdict == alone.verdict == "normal"
    assert rec.decision.familiarity == pytest.approx(alone.decision.familiarity, abs=1e-9)


def test_a_vicon_c3ds_subject_prefixed_two_hands_give_one_hand(tmp_path):
    # Vicon writes C3D labels Subject:Marker, as its CSV: read alike, then one hand taken
    ezc3d = pytest.importorskip("ezc3d")
    rng = np.random.default_rng(5)
    labels = ("P01:LTHUMB", "P01:LINDEX", "P01:RTHUMB", "P01:RINDEX")
    points = np.ones((4, 4, 40))
    points[:3] = rng.uniform(-400, 400, (3, 4, 1))  # all still ...
    points[:3, 2:, :] += np.linspace(0, 300, 40)  # ... but the right hand, which moves
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = labels
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    c3d["data"]["points"] = points
    path = tmp_path / "both.c3d"
    c3d.write(str(path))
    (trial,) = read_mocap(path)
    assert trial.marker_names() == ("LTHUMB", "LINDEX", "RTHUMB", "RINDEX")
    assert any("P01" in n for n in trial.notes)
    guess = MarkerMap.guess(trial.markers)
    assert (guess.thumb, guess.finger) == ("RTHUMB", "RINDEX")
    # a mapping written with the labels as the C3D stores them still names them
    given = MarkerMap("P01:RTHUMB", "P01:RINDEX").matched(trial.markers)
    assert (given.thumb, given.finger) == ("RTHUMB", "RINDEX")
    given.check(trial.markers, path)

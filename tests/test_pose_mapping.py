"""A lab's pose file as its project named the keypoints, with or without the object.

Labs name keypoints as they like (``Thumb_tip``, ``Index_tip``, ``Wrist``) and
many track the hand alone: the keypoints are taken by the rules motion-capture
markers are guessed by, each said, and a file without an object keypoint gets
the object where the grip ends its reach.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from _demos import default_repertoire, demo_tracks

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io.pose import PoseImport, read_pose
from perception.io.pose_mapping import keypoint_mapping, object_at_grip
from perception.pipeline import recognize_tracks

pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")

LAB = {"thumb": "Thumb_tip", "finger": "Index_tip", "wrist": "Wrist", "object": "Cup"}


def _dlc(tracks, path, names, markers=("thumb", "finger", "wrist", "object")):
    """``tracks`` as a DeepLabCut table whose keypoints are ``names[marker]``."""
    idx = [tracks.markers.index(m) for m in markers]
    columns = pd.MultiIndex.from_product([["DLC_resnet50_labMay1"], [names[m] for m in markers],
                                          ["x", "y", "likelihood"]],
                                         names=["scorer", "bodyparts", "coords"])
    xyp = np.concatenate([tracks.position[:, idx], tracks.likelihood[:, idx, None]], axis=-1)
    pd.DataFrame(xyp.reshape(len(xyp), -1), columns=columns).to_csv(path)
    return path


@pytest.fixture(scope="module")
def grasp():
    return demo_tracks("normal", 0)[0]


def test_a_labs_keypoint_names_are_taken_for_what_they_say(grasp, tmp_path):
    own = read_pose(_dlc(grasp, tmp_path / "ownDLC_x.csv", {m: m for m in LAB}),
                    PoseImport(fps=30, object_diameter_px=80))
    lab = read_pose(_dlc(grasp, tmp_path / "labDLC_x.csv", LAB),
                    PoseImport(fps=30, object_diameter_px=80))
    assert json.loads(lab.tracker["keypoints"]) == LAB
    said = json.loads(lab.tracker["reading_notes"])
    assert said == [f"keypoint {k!r} taken as the {m} (from its name)" for m, k in LAB.items()]
    np.testing.assert_array_equal(lab.position, own.position)
    a, b = (recognize_tracks(t, default_repertoire()) for t in (own, lab))
    assert (a.verdict, a.decision.familiarity) == (b.verdict, b.decision.familiarity) \
        and a.verdict == "normal"
    assert said[0] in b.notes and not a.notes  # the report says what was taken on trust


def test_a_mapping_given_wins_and_a_keypoint_is_taken_once():
    names = ["Thumb_tip", "Index_tip", "Middle_tip", "Wrist", "Cup"]
    mapping, notes = keypoint_mapping(names, {"finger": "Middle_tip"},
                                      ("thumb", "finger", "wrist", "object"))
    assert mapping == {"thumb": "Thumb_tip", "finger": "Middle_tip", "wrist": "Wrist",
                       "object": "Cup"}
    assert len(notes) == 3  # the finger was given, not guessed
    # a keypoint the user gave another marker is not guessed again
    mapping, _ = keypoint_mapping(names, {"thumb": "Index_tip"}, ("thumb", "finger"))
    assert mapping["thumb"] == "Index_tip" and mapping["finger"] != "Index_tip"


def test_a_hand_alone_gets_the_object_where_the_grip_ends_its_reach(grasp, tmp_path):
    path = _dlc(grasp, tmp_path / "handDLC_x.csv", LAB, markers=("thumb", "finger", "wrist"))
    tracks = read_pose(path, PoseImport(fps=30, object_diameter_px=80))
    assert "no object keypoint: the object is where the grip ends its reach" in json.loads(
        tracks.tracker["reading_notes"])
    hand = grasp.position[:, [grasp.markers.index(m) for m in ("thumb", "finger", "wrist")]]
    placed = tracks.position[:, tracks.markers.index("object")]
    np.testing.assert_allclose(placed, object_at_grip(hand), atol=1e-9)
    # the grasp's own object centre (80 px across) is 0.6 px from where the grip ends
    truth = np.nanmedian(grasp.position[:, grasp.markers.index("object")], axis=0)
    assert np.linalg.norm(placed[0] - truth) < 2.0
    assert recognize_tracks(tracks, default_repertoire()).verdict == "normal"


def test_a_hand_alone_without_a_scale_is_refused_in_one_line(grasp, tmp_path, capsys):
    path = _dlc(grasp, tmp_path / "handDLC_x.csv", LAB, markers=("thumb", "finger", "wrist"))
    assert main(["recognize", str(path), "--fps", "30", "-o", str(tmp_path / "o"),
                 "--no-figures", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("hammer-mv recognize: error:") and "--object-diameter-px" in err[-1]


def test_a_digit_no_name_says_is_still_refused_naming_the_keypoints(grasp, tmp_path):
    names = {"thumb": "P1", "finger": "P2", "wrist": "P3", "object": "P4"}
    with pytest.raises(InputError, match=r"keypoint 'thumb' .* not in the file "
                                         r"\(keypoints: P1, P2, P3, P4\)"):
        read_pose(_dlc(grasp, tmp_path / "pDLC_x.csv", names), PoseImport(fps=30))

"""The verdict judges coordination, not speed, size or camera; and says when it cannot judge.

Known answers: the model's own movements at other speeds, distances and
frame rates are its own (normal / reach); a mirrored camera is the same
grasp; a hand that does not move is no reach; a hand that scrabbles sideways
is no human reach.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

from hammer_mv.cli import main
from minvar import GraspTask, shoulder_for
from perception.errors import InputError
from perception.landmarks import movement_time
from perception.observation import observe
from perception.pipeline import recognize_tracks
from perception.recognition.models import SceneSpec
from perception.recognition.rules import VerdictRules
from perception.recognition.shape import canonical, is_mirrored, opens


@pytest.mark.parametrize("duration", [0.6, 1.0, 1.4])
def test_movement_time_is_measured_from_the_wrist(duration):
    obs = observe(demo_tracks("normal", 1, duration=duration)[0])
    assert movement_time(obs, VerdictRules().span_fraction) == pytest.approx(duration, rel=0.1)


@pytest.mark.parametrize("condition, verdict", [("normal", "normal"), ("reach", "reach")])
@pytest.mark.parametrize("duration, distance, fps", [(0.6, 0.25, 30), (1.6, 0.25, 120),
                                                     (1.0, 0.45, 30), (1.0, 0.5, 60),
                                                     (0.8, 0.15, 25)])
def test_the_models_own_movements_at_other_speeds_distances_and_rates_are_familiar(
        condition, verdict, duration, distance, fps):
    tracks = demo_tracks(condition, 0, duration=duration, distance=distance, fps=fps)[0]
    rec = recognize_tracks(tracks, default_repertoire())
    assert rec.verdict == verdict, (rec.decision, rec.normalisation)
    assert rec.decision.familiarity > 0.05
    assert rec.to_dict()["shape"]["movement_time"] == pytest.approx(duration, rel=0.15)


def test_delayed_and_open_close_open_stay_abnormal_at_other_speeds():
    for condition, detail, durations in (("delayed", "delayed-opening", (1.0, 1.4)),
                                         ("open-close-open", "re-opening", (0.7, 1.4))):
        for duration in durations:
            rec = recognize_tracks(demo_tracks(condition, 0, duration=duration)[0],
                                   default_repertoire())
            assert rec.verdict == "abnormal" and rec.verdict_detail == detail, (condition,
                                                                               duration)


def test_a_fast_delayed_grasp_opens_where_real_people_do_and_is_not_confidently_normal():
    """A known limit, measured: the model's 0.7 s delayed grasp starts to open at 52 % of
    its movement (the muscles' lag), inside the 3-68 % real healthy grips open at
    (docs/mocap.md), so the landmark rule cannot call it late; its fit is poor."""
    rep = default_repertoire()
    rec = recognize_tracks(demo_tracks("delayed", 0, duration=0.7)[0], rep)
    opening = rec.landmarks[0].opening_time
    assert 0.45 < opening < 0.55  # measured: 0.524
    assert 0.03 <= opening <= 0.68  # where real healthy grips start to open
    # so no landmark rule calls it abnormal: the verdict is the familiarity's, no detail
    assert rec.verdict == "normal" and rec.verdict_detail is None
    # and its fit is poor: measured 0.08, against 0.90 for the normal grasp of the same
    # speed, seed and scene, which starts to open at a fifth of its movement
    normal = recognize_tracks(demo_tracks("normal", 0, duration=0.7)[0], rep)
    assert normal.verdict == "normal" and normal.landmarks[0].opening_time < 0.3
    assert rec.decision.familiarity < 0.2 * normal.decision.familiarity


def test_canonical_scales_time_and_transport_but_not_the_grip():
    obs = observe(demo_tracks("normal", 0, duration=1.5, distance=0.35)[0])
    scene = SceneSpec()
    out, norm = canonical(obs, scene, (0.6, 1.2))
    assert norm.time_scale == pytest.approx(1.2 / movement_time(obs, VerdictRules().span_fraction))
    assert norm.distance_scale == pytest.approx((0.25 - 0.06) / (obs.start_distance - 0.06))
    assert out.start_distance == scene.distance and out.dt == scene.frame_period
    assert np.nanmax(out.g) == pytest.approx(np.nanmax(obs.g), abs=0.002)
    assert movement_time(out, VerdictRules().span_fraction) == pytest.approx(1.2, rel=0.05)
    # within the repertoire's range the time is left as it is
    same, norm = canonical(observe(demo_tracks("normal", 0)[0]), scene, (0.6, 1.2))
    assert norm.time_scale == 1.0


def test_a_mirrored_scene_is_found_and_scored_as_its_mirror_image(tmp_path, capsys):
    tracks = demo_tracks("normal", 0)[0]
    flipped = dataclasses.replace(tracks, position=tracks.position * [-1, 1] + [640, 0])
    assert not is_mirrored(observe(tracks))
    assert is_mirrored(observe(flipped))
    rec = recognize_tracks(flipped, default_repertoire())
    assert rec.mirrored and rec.verdict == "normal"
    path = flipped.save(tmp_path / "left.tracks.h5")
    assert main(["recognize", str(path), "-o", str(tmp_path / "o"), "--no-figures"]) == 0
    line = capsys.readouterr().out.strip()
    assert "normal" in line and "--mirror" in line
    assert json.loads((tmp_path / "o" / "left.recognition.json").read_text())["mirrored"]


def test_a_still_hand_is_refused_naming_the_movement():
    tracks = demo_tracks("normal", 0)[0]
    rest = tracks.position[:5].mean(axis=0)
    rng = np.random.default_rng(0)
    drift = np.linspace(0, 1, tracks.n_frames)[:, None, None] * [1.6, 1.6]  # ~2 mm at 800 px/m
    still = rest + drift * np.array([1, 1, 1, 0])[None, :, None]
    still = still + 0.3 * rng.standard_normal(still.shape)
    with pytest.raises(InputError, match="no movement: the wrist moves") as info:
        recognize_tracks(dataclasses.replace(tracks, position=still), default_repertoire())
    assert info.value.field == "wrist"


def test_a_hand_that_scrabbles_sideways_is_unfamiliar():
    tracks, truth = demo_tracks("reach", 0)
    t = np.arange(tracks.n_frames)
    wobble = 40 * np.sin(2 * np.pi * t / 12) * (t > truth["onset_frame"])
    pos = tracks.position.copy()
    pos[:, :3, 0] += wobble[:, None]
    rec = recognize_tracks(dataclasses.replace(tracks, position=pos), default_repertoire())
    assert rec.verdict == "unfamiliar" and rec.transport_familiarity < 0.01
    # back and forth, faster than half its peak speed outside the movement: not one reach
    assert rec.to_dict()["verdict"] == "unfamiliar"
    assert (rec.verdict_rule, rec.verdict_detail) == ("insufficient-data", "several-movements")


def test_a_grasp_opens_a_reach_does_not():
    assert opens(observe(demo_tracks("normal", 0)[0]))
    assert not opens(observe(demo_tracks("reach", 0)[0]))


@pytest.mark.parametrize("distance", [0.15, 0.25, 0.33, 0.4, 0.5])
def test_the_start_posture_follows_the_reach(distance):
    task = GraspTask(distance=distance, shoulder_offset=shoulder_for(distance))
    goal = np.linalg.norm(np.subtract(task.wrist_target, task.shoulder))
    assert goal <= 0.9 * sum(task.arm_links) + 1e-9
    if distance <= 0.3:
        assert shoulder_for(distance) == (0.15, -0.25)  # the thesis's posture
    assert shoulder_for(2.0) == (0.15, -0.25)  # no arm reaches 2 m: GraspTask says so


@pytest.mark.parametrize("lost_frames, verdict", [(1, "normal"), (9, "unfamiliar")])
def test_a_grip_lost_long_enough_to_hide_a_second_opening_is_not_called_normal(
        lost_frames, verdict):
    # at 30 fps, 1 frame lost leaves a 0.07 s gap (peaks still counted), 9 frames 0.33 s
    # (over 0.1 s and 20 % of the 0.9 s movement: long enough to hide a closing and re-opening)
    tracks, truth = demo_tracks("normal", 0)
    start = truth["onset_frame"] + 12  # the grip is opening
    lost = demo_tracks("normal", 0, lost={"finger": slice(start, start + lost_frames)})[0]
    full = recognize_tracks(tracks, default_repertoire())
    rec = recognize_tracks(lost, default_repertoire())
    assert full.verdict == "normal"
    assert rec.verdict == verdict, rec.landmarks[0]
    assert rec.verdict_detail == (None if verdict == "normal" else "digits-unseen")
    if verdict == "unfamiliar":
        assert rec.verdict_reason.startswith("insufficient data: the finger was lost 0.3")
        # the rule it breaks is said once, with its thresholds' names
        assert rec.verdict_reason.count("may hide a second opening") == 1, rec.verdict_reason
        assert rec.verdict_reason.endswith(": max_gap, max_gap_share)"), rec.verdict_reason


@pytest.mark.parametrize("condition, verdict", [
    ("normal", "normal"), ("reach", "reach"),
    pytest.param("delayed", "abnormal", marks=pytest.mark.xfail(strict=True, reason=(
        "a known limit since the onset fits the movement's own start: the model's own "
        "0.45 s delayed grasp opens before the late-opening threshold and fits at "
        "familiarity 0.13-0.31 (its normal grasp 1.0): separated, but above 0.05; before, "
        "a 40 ms early onset made it 0.02-0.04 and every fast normal grasp less familiar "
        "too (test_a_fast_delayed_grasp_fits_far_worse_than_the_normal_grasp)")))])
def test_fast_movements_are_judged_against_the_fastest_models(condition, verdict):
    # 0.5 s: the default repertoire's fastest models (0.45 s is scaled to them). Not
    # open-close-open: the model's own below 0.6 s has no second peak to see (its
    # muscles' lag fills the closing in); the independent generator's is checked
    # by tools/evaluate_verdict.py --set fast-heldout
    for duration in (0.45, 0.5):
        rec = recognize_tracks(demo_tracks(condition, 1, duration=duration)[0],
                               default_repertoire())
        assert rec.verdict == verdict, (condition, duration, rec.decision)


def test_a_fast_delayed_grasp_fits_far_worse_than_the_normal_grasp():
    # the model's own 0.45 s grasps, seeds 0-5: every delayed one is less familiar than
    # every normal one, by a factor of three or more (measured 0.13-0.31 against 1.0)
    rep = default_repertoire()
    fam = {c: [recognize_tracks(demo_tracks(c, seed, duration=0.45)[0], rep).decision.familiarity
               for seed in range(6)] for c in ("normal", "delayed")}
    assert max(fam["delayed"]) < 0.35 < 0.9 < min(fam["normal"])


def test_the_transport_is_scaled_about_the_reference_models_own_wrist_goal():
    """Before, the goal was GraspTask's class default (6 cm) whatever the repertoire's tasks
    set: a repertoire whose wrists stop 8 cm short scaled transports about the wrong point."""
    from perception.recognition.planning import default_specs
    from perception.recognition.repertoire import Repertoire

    specs = default_specs((1.0,))
    scene = SceneSpec(distance=0.25, object_size=0.10, frame_period=1 / 30)
    rep = Repertoire.build(specs, scene, task={"wrist_offset": 0.08})
    assert rep.wrist_offset() == 0.08 and default_repertoire().wrist_offset() == 0.06
    tracks = demo_tracks("normal", 0, distance=0.30)[0]
    rec = recognize_tracks(tracks, rep)
    n = rec.normalisation
    assert n.wrist_offset == 0.08 and rec.to_dict()["shape"]["wrist_offset"] == 0.08
    start = rec.observation.start_distance
    assert n.distance_scale == pytest.approx((0.25 - 0.08) / (start - 0.08))


def test_the_time_scale_is_read_from_the_declared_span_fraction():
    """`VerdictRules.span_fraction` is the number the movement time is measured with: the
    report's `verdict_rules` holds it, and another value changes the time scale."""
    obs = observe(demo_tracks("normal", 0, duration=1.5, distance=0.35)[0])
    times = {}
    for fraction in (0.467, 0.5):
        rules = VerdictRules(span_fraction=fraction)
        _, norm = canonical(obs, SceneSpec(), (0.6, 1.2), rules)
        times[fraction] = norm.movement_time
        assert rules.to_dict()["span_fraction"] == fraction
    assert times[0.5] == pytest.approx(times[0.467] * 0.467 / 0.5)

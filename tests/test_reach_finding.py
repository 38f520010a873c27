"""Finding the reaches to grasp in the tasks labs run (perception.reaches, issue 41 item 3).

Every recording here is written by the test: a hand path made of
minimum-jerk strokes (a reach, the object's transport, a lift, a return),
a grip that opens and closes on its own schedule, and, where the task has
one, an object that stands still until the hand carries it. Each case is
one the reach finder got wrong before: the reach and the transport taken as
one movement, a whole-hand or late-opening grasp dropped, a slow reach
hidden by a fast one, back-to-back reaches merged with the withdrawal
before them, an IndexError in reach_tracks, a trial dropped without a word.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from perception.errors import InputError
from perception.io.mocap import MocapTrial
from perception.landmarks import LandmarkParams
from perception.reaches import (
    MarkerMap,
    Reach,
    ReachParams,
    find_reaches,
    reach_tracks,
    recording_reaches,
    trial_reaches,
)

GRIP_AXIS = np.array([0.0, 0.0, 1.0])  # the digits lie across the approach (along z)


def _mj(t, t0, duration):
    """Minimum-jerk progress 0..1 of a stroke from t0 lasting ``duration``."""
    u = np.clip((t - t0) / duration, 0, 1)
    return 10 * u**3 - 15 * u**4 + 6 * u**5


def _grip(t, rest, events):
    """Aperture: ``rest`` plus, for each (t_open, t_peak, t_close, peak, hold), an opening
    to ``peak`` above rest at t_peak, then a closing to ``hold`` above rest at t_close."""
    g = np.full_like(t, rest)
    for t_open, t_peak, t_close, peak, hold in events:
        up = _mj(t, t_open, t_peak - t_open) * peak
        down = _mj(t, t_peak, t_close - t_peak) * (peak - hold)
        g = g + np.where(t < t_peak, up, peak - down)
    return g


def _trial(t, hand, grip, *, name="trial", obj=None, wrist_behind=None, seed=0):
    """A MocapTrial: thumb and index about the hand path at the aperture, with 0.1 mm noise
    (a still real marker jitters; an exactly repeated sample is read as held)."""
    rng = np.random.default_rng(seed)

    def jitter(p):
        return p + 1e-4 * rng.standard_normal(p.shape)

    markers = {"thumb": jitter(hand - 0.5 * grip[:, None] * GRIP_AXIS),
               "index": jitter(hand + 0.5 * grip[:, None] * GRIP_AXIS)}
    if wrist_behind is not None:
        markers["hand"] = jitter(hand + wrist_behind)
    if obj is not None:
        markers["object"] = jitter(obj)
    rate = 1 / (t[1] - t[0])
    return MocapTrial(name, f"{name}.tsv", t, markers, rate, "m")


def _strokes(t, start, strokes):
    """A hand path from ``start``: each (t0, duration, displacement) stroke added."""
    p = np.repeat(np.asarray(start, dtype=float)[None], len(t), axis=0)
    for t0, duration, d in strokes:
        p = p + _mj(t, t0, duration)[:, None] * np.asarray(d, dtype=float)
    return p


def _pick_and_place(rate=200.0, *, with_object=True, seed=0):
    """RTMocap's task: from rest, reach 32 cm, grasp, carry 15 cm sideways without the hand
    stopping at the object first, release, return. Returns the trial and when the object
    starts to move."""
    t = np.arange(0, 2.0, 1 / rate)
    reach = (0.40, 0.45, [0.0, 0.32, 0.0])
    grasp = 0.78  # the transport starts before the reach has quite ended
    transport = (grasp, 0.40, [0.15, 0.0, 0.05])
    ret = (1.30, 0.55, [-0.15, -0.32, -0.05])
    hand = _strokes(t, [0, 0, 0], [reach, transport, ret])
    grip = _grip(t, 0.02, [(0.45, 0.68, 0.80, 0.07, 0.015), (1.25, 1.40, 1.75, 0.03, -0.015)])
    obj = None
    if with_object:
        # the object stands at the hand's grasp point and is carried from ``grasp`` on
        at = hand[np.searchsorted(t, grasp)]
        carried = hand - hand[np.searchsorted(t, grasp)] + at
        obj = np.where((t < grasp)[:, None], at, carried)
        placed = np.searchsorted(t, grasp + 0.45)
        obj[placed:] = obj[placed]
    return _trial(t, hand, grip, name="pnp", obj=obj, seed=seed), grasp


# -- pick-and-place and drinking: the reach ends where the hand stops at the object ------------
def test_pick_and_place_reach_ends_at_the_objects_first_motion():
    trial, grasp = _pick_and_place()
    reaches, unscored = trial_reaches(trial, MarkerMap("thumb", "index", object=("object",)))
    assert len(reaches) == 1 and unscored == []
    r = reaches[0]
    assert abs(r.time[r.end] - grasp) < 0.1          # not through the transport
    assert r.end_bound == "the object's first motion"
    assert r.time[r.onset] == pytest.approx(0.40, abs=0.06)
    # the transport and return are not a reach; they are named in the notes
    assert any(n.startswith("not part of the reach") for n in r.notes)


def test_pick_and_place_without_an_object_marker_ends_at_the_grasps_speed_minimum():
    trial, grasp = _pick_and_place(with_object=False)
    reaches, unscored = trial_reaches(trial, MarkerMap("thumb", "index"))
    assert len(reaches) == 1 and unscored == []
    r = reaches[0]
    assert abs(r.time[r.end] - grasp) < 0.1
    assert "speed minimum" in r.end_bound


def test_a_drinking_reachs_movement_time_ends_at_the_cup_not_after_the_drink():
    rate = 100.0
    t = np.arange(0, 6.0, 1 / rate)
    grasp = 1.25
    hand = _strokes(t, [0, 0, 0], [
        (0.50, 0.80, [0.0, 0.30, 0.0]),             # reach to the cup
        (1.20, 0.70, [0.0, -0.15, 0.30]),           # lift to the mouth, without a stop
        (3.00, 0.80, [0.0, 0.15, -0.30]),           # put the cup back
        (4.20, 0.90, [0.0, -0.30, 0.0])])           # return
    grip = _grip(t, 0.015, [(0.6, 1.0, 1.3, 0.09, 0.07), (3.8, 4.0, 4.5, 0.1, -0.07)])
    trial = _trial(t, hand, grip, name="drink", wrist_behind=np.array([0.0, -0.06, 0.0]))
    reaches, unscored = trial_reaches(trial, MarkerMap("thumb", "index", wrist="hand"))
    assert len(reaches) == 1 and unscored == []
    r = reaches[0]
    assert r.time[r.end] - r.time[r.onset] < 1.0     # not 1.8 s through the lift
    assert abs(r.time[r.end] - grasp) < 0.15


# -- a reach to grasp is told by its transport, not by how far the grip opens ------------------
def _simple_reach(grip_events, rest=0.02, seed=0):
    t = np.arange(0, 3.0, 0.01)
    hand = _strokes(t, [0, 0, 0], [(0.6, 0.9, [0.0, 0.3, 0.05]), (2.0, 0.8, [0, -0.3, -0.05])])
    return _trial(t, hand, _grip(t, rest, grip_events), seed=seed)


def test_a_whole_hand_grasp_from_a_flat_hand_is_a_reach_and_never_abnormal():
    from _demos import default_repertoire

    from perception.recordings import recognize_reach

    # the flat hand's thumb-index distance widens by 6 mm and settles 3 mm wider on the cup
    trial = _simple_reach([(0.7, 1.1, 1.5, 0.006, 0.003), (1.9, 2.1, 2.5, 0.003, -0.003)],
                          rest=0.09)
    reaches, unscored = trial_reaches(trial, MarkerMap("thumb", "index"))
    assert len(reaches) == 1 and unscored == []
    r = reaches[0]
    assert r.time[r.end] - r.time[r.onset] == pytest.approx(0.9, abs=0.15)
    rec, _ = recognize_reach(r, default_repertoire())
    assert rec.verdict != "abnormal", rec.verdict_reason


@pytest.mark.parametrize("events", [
    [(1.25, 1.38, 1.5, 0.04, 0.03)],      # the grip opens late, at 72 % of the movement
    [(0.8, 1.1, 1.45, 0.010, 0.006)],     # it opens barely (10 mm)
])
def test_a_grip_that_opens_late_or_barely_is_still_a_reach(events):
    reaches, unscored = trial_reaches(_simple_reach(events), MarkerMap("thumb", "index"))
    assert len(reaches) == 1 and unscored == []


def test_a_late_opening_variant_written_as_a_recording_is_found():
    from perception.synthetic.variants import late_opening

    # a real grasp that opens only 14 mm (the hand travels nearly closed), its opening moved late
    trial = _simple_reach([(0.75, 1.05, 1.4, 0.014, 0.008)])
    real = recording_reaches(trial, MarkerMap("thumb", "index"))[0]
    late = late_opening(real)
    again = MocapTrial("late", "late.tsv", late.time, {"thumb": late.thumb, "index": late.finger},
                       100.0, "m")
    reaches, unscored = trial_reaches(again, MarkerMap("thumb", "index"))
    assert len(reaches) == 1 and unscored == []


# -- sessions: many reaches in one recording ---------------------------------------------------
def _session(rate, durations, *, rest=1.5, reach=0.3, seed=0, hand_marker=False):
    """Reach, hold, withdraw, rest, once per entry of ``durations`` (each stroke's duration:
    a short one is a fast movement). Returns the trial and the reaches' (start, grasp) times."""
    rng = np.random.default_rng(seed)
    strokes, grips, truth = [], [], []
    t0 = 1.0
    for d in durations:
        target = np.array([rng.uniform(-0.05, 0.05), reach + rng.uniform(-0.03, 0.03), 0.0])
        strokes += [(t0, d, target), (t0 + d + 0.8, d, -target)]
        grips.append((t0 + 0.1 * d, t0 + 0.7 * d, t0 + d, 0.06, 0.04))
        grips.append((t0 + d + 0.7, t0 + d + 0.9, t0 + 2 * d + 0.8, 0.01, -0.05))
        truth.append((t0, t0 + d))
        t0 += 2 * d + 0.8 + rest + rng.uniform(0, 1)
    t = np.arange(0, t0, 1 / rate)
    hand = _strokes(t, [0, 0, 0], strokes)
    trial = _trial(t, hand, _grip(t, 0.015, grips), name="session", seed=seed,
                   wrist_behind=np.array([0.0, -0.07, 0.02]) if hand_marker else None)
    return trial, truth


def test_one_fast_reach_does_not_hide_the_slower_ones():
    trial, truth = _session(100.0, [1.2, 0.35, 1.2, 1.2])     # peaks ~0.5 and ~1.6 m/s
    reaches, unscored = trial_reaches(trial, MarkerMap("thumb", "index"))
    assert len(reaches) == 4 and unscored == []
    for r, (start, grasp) in zip(reaches, truth, strict=True):
        assert abs(r.time[r.onset] - start) < 0.2 and abs(r.time[r.end] - grasp) < 0.2
    assert len(find_reaches(trial.time, 0.5 * (trial.markers["thumb"] +
                                               trial.markers["index"]))) == 4


def test_a_twelve_grasp_session_at_120_hz_gives_twelve_reaches_not_its_withdrawals():
    durations = np.random.default_rng(3).uniform(0.6, 1.4, 12)
    trial, truth = _session(120.0, durations, rest=15.0, hand_marker=True, seed=3)
    assert trial.time[-1] > 200
    reaches, unscored = trial_reaches(trial, MarkerMap("thumb", "index", wrist="hand"))
    assert unscored == []
    assert len(reaches) == 12
    for r, (start, grasp) in zip(reaches, truth, strict=True):
        assert abs(r.time[r.onset] - start) < 0.2 and abs(r.time[r.end] - grasp) < 0.2


def _back_to_back(rate=100.0, n=6, seed=1):
    """The cushion session: each withdrawal flows into the next reach without a stop (the
    hand turns back before it reaches its rest, to a spot of the cushion 20 cm from the
    last, so its speed dips without falling to 5 % of peak); a marker on the cushion."""
    rng = np.random.default_rng(seed)
    strokes, truth = [], []
    t0 = 1.0
    rest = np.array([0.0, 0.45, 0.05])
    spots = [np.array([-0.1, 0.0, 0.0]), np.array([0.1, 0.0, 0.0])]
    at = rest
    for k in range(n):
        d = rng.uniform(0.8, 1.1)
        spot = spots[k % 2]
        strokes.append((t0, d, spot - at))                  # reach toward the cushion
        truth.append((t0, t0 + d))
        strokes.append((t0 + d + 0.4, d, rest - spot))      # withdraw
        at = rest
        t0 += 2 * d + 0.4 - 0.3                             # the next reach overlaps it
    t = np.arange(0, t0 + 2.0, 1 / rate)
    hand = _strokes(t, rest, strokes)
    grip = np.full_like(t, 0.14)                            # a whole-hand grasp of a cushion
    obj = np.repeat([[0.0, 0.0, 0.0]], len(t), axis=0)
    return _trial(t, hand, grip, name="cushion", obj=obj, seed=seed), truth


def test_back_to_back_reaches_each_measure_their_own_movement():
    trial, truth = _back_to_back()
    params = ReachParams()
    reaches, unscored = trial_reaches(trial, MarkerMap("thumb", "index", object=("object",)),
                                      params)
    assert unscored == []
    assert len(reaches) == len(truth)
    for r, (_, grasp) in zip(reaches, truth, strict=True):
        speed = params.landmarks.speed_of(r.time, r.transport)
        peak = int(np.nanargmax(speed))
        # the window's fastest moment is this reach's, not the withdrawal's before it
        assert r.onset <= peak <= r.end, r.name
        assert abs(r.time[r.end] - grasp) < 0.15
        # the hand approaches the cushion throughout the window's movement
        d = np.linalg.norm(r.transport - r.object, axis=1)
        assert d[r.end] < d[r.onset]
        # the bound is the field's or says what it is
        assert r.bound.startswith("5 % of peak speed") or "speed minimum" in r.bound
    assert any("speed minimum" in r.onset_bound for r in reaches[1:])


def test_the_bound_stays_the_fields_in_a_session_that_seldom_rests():
    """The noise floor is the still hand's speed, not the slowest tenth of a busy session."""
    trial, _ = _back_to_back(n=8)
    reaches, _ = trial_reaches(trial, MarkerMap("thumb", "index", object=("object",)))
    assert reaches and not any("still hand" in r.bound for r in reaches)
    assert reaches[0].onset_bound == "5 % of peak speed"


# -- every trial accounted for ------------------------------------------------------------------
def _still(n=300, rate=100.0):
    t = np.arange(n) / rate
    return t, np.zeros((n, 3))


@pytest.mark.parametrize("case, status, reason", [
    ("still", "no reach", "no reach: the hand never moved"),
    ("short", "too short", "too short: 3 samples"),
    ("lost", "marker lost", "marker lost throughout: index"),
    ("starts", "starts in motion", "starts in motion"),
    ("ends", "ends in motion", "ends in motion"),
    ("return", "no reach", "none a reach to grasp"),
])
def test_a_trial_without_a_scored_reach_says_why(case, status, reason):
    t = np.arange(0, 3.0, 0.01)
    hand = _strokes(t, [0, 0, 0], [(0.8, 0.9, [0, 0.3, 0])])
    grip = _grip(t, 0.02, [(0.9, 1.3, 1.7, 0.06, 0.04)])
    if case == "still":
        t, hand = _still()
        grip = np.full(len(t), 0.02)
    elif case == "short":
        t, hand, grip = t[:3], hand[:3], grip[:3]
    elif case == "starts":
        keep = t >= 1.1
        t, hand, grip = t[keep] - t[keep][0], hand[keep], grip[keep]
    elif case == "ends":
        keep = t <= 1.2
        t, hand, grip = t[keep], hand[keep], grip[keep]
    elif case == "return":
        hand = _strokes(t, [0, 0.3, 0], [(0.8, 0.9, [0, -0.3, 0])])
    trial = _trial(t, hand, grip)
    if case == "lost":
        trial = dataclasses.replace(trial, markers={**trial.markers,
                                                    "index": np.full((len(t), 3), np.nan)})
    if case == "return":  # a trial of a return alone, with an object it moves away from
        trial = dataclasses.replace(trial, markers={**trial.markers,
                                                    "object": np.repeat([[0, 0.35, 0]], len(t), 0)})
    mapping = MarkerMap("thumb", "index", object=("object",) if case == "return" else ())
    reaches, unscored = trial_reaches(trial, mapping)
    assert reaches == [] and len(unscored) == 1
    u = unscored[0]
    assert u.status == status and reason in u.reason, u
    assert u.source == "trial.tsv"
    with pytest.raises(InputError, match="no reach to grasp found"):
        recording_reaches(trial, mapping)


def test_a_mapping_naming_a_missing_marker_is_the_only_refusal():
    trial = _simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)])
    with pytest.raises(InputError, match="pinky"):
        trial_reaches(trial, MarkerMap("thumb", "pinky"))


# -- reach_tracks never fails with an IndexError -------------------------------------------------
def _reach_of(trial):
    return recording_reaches(trial, MarkerMap("thumb", "index"))[0]


def test_reach_tracks_of_a_reach_whose_onset_is_after_its_end_is_an_input_error():
    r = _reach_of(_simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)]))
    bad = dataclasses.replace(r, onset=r.end + 5, end=r.end)
    with pytest.raises(InputError, match="not in order"):
        reach_tracks(bad)
    with pytest.raises(InputError, match="not in order"):
        reach_tracks(dataclasses.replace(r, onset=r.onset - len(r.time)))


def test_reach_tracks_of_a_hand_never_seen_to_its_end_is_an_input_error():
    r = _reach_of(_simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)]))
    unseen = r.transport.copy()
    unseen[:r.end + 1] = np.nan
    with pytest.raises(InputError, match="not seen"):
        reach_tracks(dataclasses.replace(r, transport=unseen))


def test_reach_tracks_says_where_the_bounds_are_in_its_rows():
    trial, _ = _pick_and_place()
    r = trial_reaches(trial, MarkerMap("thumb", "index", object=("object",)))[0][0]
    tracks, info, transport, _ = reach_tracks(r)
    b = info["bounds"]
    assert b["end_bound"] == "the object's first motion"
    assert np.allclose(transport[b["end"]], r.transport[r.end])
    assert np.allclose(transport[b["onset"]], r.transport[r.onset])


# -- the declared settings -----------------------------------------------------------------------
def test_one_marker_name_is_a_tuple_of_one_not_of_its_letters():
    m = MarkerMap(wrist="eyeL", object=["cube1", "cube2"])
    assert m.wrist == ("eyeL",) and m.object == ("cube1", "cube2")
    assert MarkerMap("thumb", "index") == MarkerMap(thumb="thumb", finger="index")
    assert hash(MarkerMap("thumb", "index")) == hash(MarkerMap("thumb", "index"))
    guessed = MarkerMap.guess(["thumb_tip", "index_tip", "hand_top", "pillow_left"])
    assert guessed == MarkerMap("thumb_tip", "index_tip", ("hand_top",), ("pillow_left",))


@pytest.mark.parametrize("cls, kwargs, field", [
    (MarkerMap, {"thumb": ""}, "thumb"),
    (MarkerMap, {"wrist": ("a", 3)}, "wrist"),
    (MarkerMap, {"finger": 7}, "finger"),
    (ReachParams, {"min_travel": -0.05}, "min_travel"),
    (ReachParams, {"min_speed": "fast"}, "min_speed"),
    (ReachParams, {"object_size": 2.0}, "object_size"),
    (ReachParams, {"object_position": (1.0, 2.0)}, "object_position"),
    (ReachParams, {"turn": 200}, "turn"),
    (ReachParams, {"landmarks": {"threshold": 0.05}}, "landmarks"),
])
def test_bad_settings_raise_an_input_error_naming_the_field(cls, kwargs, field):
    with pytest.raises(InputError) as err:
        cls(**kwargs)
    assert err.value.location[:2] == (cls.__name__, field)
    assert "\n" not in str(err.value)


def test_reach_params_are_values_and_keep_their_parts():
    p = ReachParams(landmarks=LandmarkParams(threshold=0.1), object_position=[0.1, 0.2, 0.3])
    assert p.object_position == (0.1, 0.2, 0.3)
    assert dataclasses.replace(p, min_travel=0.04).landmarks.threshold == 0.1
    assert hash(p) == hash(ReachParams(landmarks=LandmarkParams(threshold=0.1),
                                       object_position=(0.1, 0.2, 0.3)))
    assert math.isclose(ReachParams().min_opening, 0.015)


def test_reach_bound_reads_as_one_rule_or_two():
    r = _reach_of(_simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)]))
    assert isinstance(r, Reach) and r.bound == "5 % of peak speed"
    two = dataclasses.replace(r, end_bound="the object's first motion")
    assert two.bound == "onset: 5 % of peak speed; end: the object's first motion"

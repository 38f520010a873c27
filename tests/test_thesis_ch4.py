"""Chapter 4's trends that the thesis-derived grasp geometry makes hold (issue 13).

Judged on exact moments (no sampling error). The closed digit tips start
below the line of the digit targets (thesis Fig. 4.4(a), line 814) and the
wrist travels the thesis's 20 cm (line 953); with the tips on the target line
instead, the first two trends fail, which is what these tests can catch.
"""

from dataclasses import replace

import numpy as np
import pytest

from minvar import GraspTask, plan_grasp
from minvar.grasp_stats import end_distance, grasp_moments


def _moments(task):
    return grasp_moments(plan_grasp(task))


def _distance(task):
    return end_distance(_moments(task), "finger", task.finger_target)


def _mga_time(task):
    m = _moments(task)
    return m.relative_time[np.argmax(m.aperture_mean)]


HEIGHTS = (-0.01, -0.005, 0.0, 0.005, 0.01)


def test_geometry_is_the_thesis_text():
    t = GraspTask()
    assert t.transport_distance == pytest.approx(0.20)  # "distance to be moved", line 953
    assert t.wrist_target == (0.0, -0.06)  # "6cm vertically below", line 724
    assert 0 < t.tip_start < t.wrist_offset  # tips start below the target line (line 814)


def test_digit_distance_is_lowest_with_the_viapoints_level():
    # thesis line 788, Figs. 4.3(a,b): falls toward level, rises above
    d = [_distance(replace(GraspTask(), viapoint_height=h)) for h in HEIGHTS]
    assert np.argmin(d) == 2
    assert d[0] > d[1] > d[2] < d[3] < d[4]
    # for each digit (Fig. 4.3(b) is the thumb's); the thumb's systematic miss is larger
    # (97.7 against 81.7 µm at level): the digits mirror each other, the arm does not
    t = [end_distance(_moments(task), "thumb", task.thumb_target)
         for task in (replace(GraspTask(), viapoint_height=h) for h in HEIGHTS)]
    assert t[0] > t[1] > t[2] < t[3] < t[4]
    assert t[2] * 1e6 == pytest.approx(97.7, abs=0.1) and d[2] * 1e6 == pytest.approx(81.7,
                                                                                       abs=0.1)


def test_mga_comes_at_60_to_80_percent_for_every_object_size():
    # thesis line 905, Fig. 4.10(b): sizes 0-8 cm
    times = [_mga_time(replace(GraspTask(), object_size=s)) for s in np.arange(9) * 0.01]
    # holds only at its edge: the smallest object peaks at exactly 60 % (1 % steps), so
    # any change that moves it earlier flips the verdict (numbers.md: conditional)
    assert min(times) == pytest.approx(0.60, abs=1e-9) and max(times) <= 0.80
    assert np.all(np.diff(times) >= 0)  # and later for larger objects (line 903)


def test_viapoint_timing_sd_is_lowest_near_60_percent_in_either_frame():
    # thesis line 834, Fig. 4.5(c,d): lowest near 70 %, rising below it. Ours does not rise
    # below 70 % (numbers.md: differs; test_sd_does_not_rise_below_70_percent). The number
    # pinned here: the exact SD is lowest for a via-point at 55-60 %, in the world frame and
    # about the wrist (the hand frame, which removes the wrist's 95 % share). A U shape with
    # its minimum within 50-80 % was our own former rule, not the thesis's claim.
    times = np.round(np.arange(0.5, 0.851, 0.05), 2)
    world, hand = [], []
    for f in times:
        m = _moments(replace(GraspTask(), viapoint_time=f))
        world.append(np.sqrt(np.trace(m.finger_cov[-1])))
        hand.append(np.sqrt(np.trace(m.finger_cov[-1] - m.wrist_cov[-1])))
    for sd in (world, hand):
        assert times[int(np.argmin(sd))] in (0.55, 0.6)
    assert hand[times.tolist().index(0.6)] < 0.95 * hand[times.tolist().index(0.7)]


def test_with_the_tips_on_the_target_line_the_trends_fail():
    # the previous default (tip_start = wrist_offset): what the tests above guard against
    online = GraspTask(tip_start=GraspTask().wrist_offset)
    d = [_distance(replace(online, viapoint_height=h)) for h in (0.0, 0.005)]
    assert d[1] < d[0]  # lowest above level, not at it
    assert _mga_time(replace(online, object_size=0.0)) < 0.59


def test_per_axis_sd_is_not_lowest_at_level():
    # thesis line 790, Fig. 4.3(c,d) plots x and y apart: per axis ours is lowest off level
    # (x at +0.5 cm, y at -0.5 cm); numbers.md's verdict 'differs' rests on this
    heights = (-0.005, 0.0, 0.005)
    cov = [_moments(replace(GraspTask(), viapoint_height=h)).finger_cov[-1] for h in heights]
    sd_x, sd_y = (np.sqrt([c[i, i] for c in cov]) for i in (0, 1))
    assert heights[int(np.argmin(sd_x))] == 0.005 and heights[int(np.argmin(sd_y))] == -0.005
    total = np.sqrt(sd_x**2 + sd_y**2)
    # the total is lowest at level, but by less than the 3.2 % standard error of an SD
    # from the thesis's 500 repetitions
    assert np.argmin(total) == 1 and total.max() / total.min() - 1 < 1 / np.sqrt(2 * 499)


def test_sd_does_not_rise_below_70_percent():
    # thesis line 834: "below approximately 70 % ... an increase"; ours falls from 70 to 60 %
    sd = {f: np.sqrt(np.trace(_moments(replace(GraspTask(), viapoint_time=f)).finger_cov[-1]))
          for f in (0.6, 0.7)}
    assert sd[0.6] < sd[0.7]

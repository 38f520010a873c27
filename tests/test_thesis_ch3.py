"""Chapter 3 claims checked directly: the LQG iteration's independence of its start."""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from minvar.lqg import solve
from minvar.task import ReachTask, ViaPoint, reach_problem

S = ReachTask((-0.2, 0.5), (-0.4, 0.2), 1.0,
              (ViaPoint((-0.4, 0.4), fraction=0.25), ViaPoint((-0.2, 0.3), fraction=0.75)))


def test_iteration_converges_to_the_same_answer_from_other_starts():
    # thesis line 481: "to the same answer regardless of initialisation"
    problem = reach_problem(S)
    ref = solve(problem)  # first pass with L = 0, as the thesis (line 483)
    other = solve(reach_problem(ReachTask(S.start, S.goal, 1.0, (
        ViaPoint((-0.3, 0.45), fraction=0.4), ViaPoint((-0.35, 0.25), fraction=0.6)))))
    rng = np.random.default_rng(0)
    starts = [2 * ref.L, other.L, 0.1 * np.abs(ref.L).max() * rng.standard_normal(ref.L.shape)]
    for start in starts:
        sol = solve(problem, initial_L=start)
        assert sol.converged
        assert sol.cost == pytest.approx(ref.cost, rel=1e-10)
        np.testing.assert_allclose(sol.L, ref.L, atol=1e-6 * np.abs(ref.L).max())
    # a start is really used: stopped after one iteration, the answers differ
    one = solve(problem, initial_L=other.L, max_iter=1)
    assert not np.allclose(one.L, solve(problem, max_iter=1).L)


def test_initial_gains_are_checked():
    problem = reach_problem(ReachTask((0.2, 0.2), (0.4, 0.5), 0.5))
    with pytest.raises(ValueError, match="initial_L"):
        solve(problem, initial_L=np.zeros((3, 2, 10)))
    bad = np.zeros((problem.horizon, 2, problem.n_states))
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="initial_L"):
        solve(problem, initial_L=bad)


ROOT = Path(__file__).resolve().parents[1]
THESIS_WEIGHTS = {"r": 0.002, "w_v": 0.1, "w_f": 0.01}  # lines 537, 552
THESIS_SETTINGS = {**THESIS_WEIGHTS, "form": "thesis"}  # and the printed model


def _measured(step, *args) -> dict:
    """The chapter 3 claims one measuring step of tools.thesis makes, evaluated by id."""
    from tools.thesis.ch3_claims import CLAIMS
    from tools.thesis.claims import evaluate

    got = {}
    step(None, got, *args)
    return {c["id"]: c for c in evaluate(CLAIMS, got, strict=False)}


@pytest.fixture(scope="module")
def ch3():
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from tools.thesis import ch3_letters, ch3_reach

    return ch3_reach, ch3_letters


def test_a_100_ms_shift_alters_the_path_beyond_the_noise(ch3):
    # thesis line 591: "up to about 100ms do not significantly alter the trajectory";
    # judged against the repetition noise ours differs (pinned)
    assert _measured(ch3[0].fig3_2, 0, {})["viapoint-shift-100ms"]["verdict"] == "differs"


def test_at_the_thesis_settings_the_printed_plant_passes_the_s_and_stops_short():
    # the thesis's settings column: its printed plant and effort form (lines 520-524, 558)
    # at r = 0.002, w_v = 0.1. The numbers pinned, and why they are not the column's old
    # ones: the project's Euler plant at those weights overstates the effort ~2.2 times
    from minvar.reach import simulate_reach
    from minvar.viapoints import expected_path

    def misses(task):
        _, p = expected_path(task)
        return [np.linalg.norm(p - np.asarray(v.position), axis=1).min() * 1000
                for v in task.via_points]

    assert misses(replace(S, **THESIS_SETTINGS)) == pytest.approx([5.8, 5.0], abs=0.1)
    assert misses(replace(S, **THESIS_WEIGHTS)) == pytest.approx([10.5, 12.8], abs=0.1)
    reach = ReachTask((0.2, 0.2), (0.4, 0.5), 0.5, **THESIS_SETTINGS)
    _, p = expected_path(reach)
    assert np.linalg.norm(p[-1] - np.asarray(reach.goal)) * 1000 == pytest.approx(5.0, abs=0.1)
    # line 552's claim (a good tradeoff: the hand reaches the target and halts) is judged
    # at those settings: still moving at the end, 9 % of the peak speed (numbers.md: differs)
    r = simulate_reach(reach, 20, seed=0)
    assert r.mean_speed[-1] > 0.05 * r.mean_speed.max()


@pytest.fixture(scope="module")
def point_to_point(ch3):
    return _measured(ch3[0].fig3_4_3_5, 50, 0, {})


def test_the_straight_mean_path_is_by_construction(point_to_point):
    # line 636: straight 'as expected' with zero-mean noise on a linear plant
    assert point_to_point["mean-straight"]["verdict"] == "by construction"


def test_single_movements_bow_either_way_not_as_people_curve(point_to_point):
    # line 622: 'slightly curved in the same way as human arm movements'; ours scatter
    # to both sides of the straight mean about equally (numbers.md: differs)
    row = point_to_point["single-curved"]
    assert row["verdict"] == "differs" and "bow to one side" in row["ours"]


def test_the_letter_keeps_its_shape_only_above_a_movement_time(ch3):
    # lines 676, 684: the thesis gives neither the times nor the via-points; the verdict
    # turns on the times chosen, so it is conditional, with the time where it crosses
    row = _measured(ch3[1].fig3_8_3_9, 20, 0, {})["a-keeps-shape"]
    assert row["verdict"] == "conditional" and "down to 1500 ms" in row["ours"]


def test_the_s_end_point_sd_falls_beyond_the_noise_at_the_thesis_settings(ch3):
    # line 664: the SD 'decreased as movement speed decreased, although ... a less clear
    # relationship'. No threshold in the thesis, so the noise's: the fall beyond 2 standard
    # errors of an SD from 200 repetitions and a rank trend beyond chance (numbers.md:
    # agree; rho is -0.76, which our former, untied -0.8 called 'differs')
    row = _measured(ch3[1].fig3_6_3_7, 200, 0, THESIS_SETTINGS)["sd-falls-s"]
    assert row["verdict"] == "agree" and "standard errors" in row["ours"]


def test_the_re_timed_letter_is_conditional_on_how_much_faster(ch3):
    # Fig. A.3(a), line 1358: 'a much shorter movement time', not given; the shape keeps
    # within twice the noise for mild re-timings and not for the 2 s -> 1 s we drew
    from tools.thesis.appendix_a import fig_a3
    from tools.thesis.appendix_a_claims import CLAIMS
    from tools.thesis.claims import evaluate

    got = {}
    fig_a3(None, got, 20, 0, {})
    row = evaluate(CLAIMS, got, strict=False)[0]
    assert row["id"] == "retimed-shape"
    assert row["verdict"] == "conditional" and "within twice the noise from" in row["ours"]

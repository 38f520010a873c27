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


TOOLS = Path(__file__).resolve().parents[1] / "tools"
THESIS_WEIGHTS = {"r": 0.002, "w_v": 0.1, "w_f": 0.01}  # lines 537, 552


@pytest.fixture(scope="module")
def ch3():
    sys.path.insert(0, str(TOOLS))
    try:
        import reproduce_ch3
    finally:
        sys.path.remove(str(TOOLS))
    return reproduce_ch3


def test_a_100_ms_shift_alters_the_path_beyond_the_noise(ch3):
    # thesis line 591: "up to about 100ms do not significantly alter the trajectory";
    # judged against the repetition noise ours differs (pinned)
    claims = []
    ch3._fig3_2(None, claims, 0, {})
    flat = next(c for c in claims if c["claim"].startswith("Via-point time differences"))
    assert flat["verdict"] == "differs"


def test_at_the_thesis_weights_the_s_misses_its_viapoints_and_the_reach_stops_short():
    from minvar.reach import simulate_reach
    from minvar.viapoints import expected_path

    _, ours = expected_path(S)
    _, theirs = expected_path(replace(S, **THESIS_WEIGHTS))
    miss = [min(np.linalg.norm(p - np.asarray(v.position), axis=1).min()
                for _ in [0]) for p in (ours, theirs) for v in S.via_points]
    assert max(miss[:2]) < 0.005 < 0.010 < min(miss[2:])  # 4-5 mm vs 10-13 mm
    reach = ReachTask((0.2, 0.2), (0.4, 0.5), 0.5, **THESIS_WEIGHTS)
    _, p = expected_path(reach)
    assert np.linalg.norm(p[-1] - np.asarray(reach.goal)) > 0.008  # 9.4 mm short
    r = simulate_reach(reach, 20, seed=0)
    assert r.mean_speed[-1] > 0.1 * r.mean_speed.max()  # still moving at the end

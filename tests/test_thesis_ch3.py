"""Chapter 3 claims checked directly: the LQG iteration's independence of its start."""

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

"""The fast solver: compiled passes, Todorov's stopping rule, failures named, plans shared."""

import dataclasses
import logging
import os
import subprocess
import sys

import numpy as np
import pytest

from minvar import _kernel, reach_problem, solve
from minvar.moments import _joint_moments, estimation_error_covariance
from minvar.task import ReachTask, ViaPoint

S_TASK = ReachTask((-0.2, 0.5), (-0.4, 0.2), 1.0,
                   (ViaPoint((-0.4, 0.4), fraction=0.25), ViaPoint((-0.2, 0.3), fraction=0.75)))


def _noisy(problem, seed=1):
    """Every noise term of Todorov's model non-zero (the compiled passes' every branch)."""
    rng = np.random.default_rng(seed)
    n, k = problem.n_states, problem.n_outputs
    physical = (np.arange(n) < 8).astype(float)
    return dataclasses.replace(
        problem,
        C0=0.002 * rng.standard_normal((n, 3)) * physical[:, None],
        D=[0.01 * rng.standard_normal((k, n)) * physical[None, :]],
        E0=0.001 * rng.standard_normal((n, 2)) * physical[:, None],
        S1=np.diag(np.r_[1e-4, 1e-4, 1e-3, 1e-3, np.zeros(n - 4)]),
    )


def test_compiled_kernel_is_built():
    # `pip install` builds it (setup.py); the numpy passes are only a fallback
    assert _kernel.loaded(), _kernel._WHY
    assert _kernel.available() == (os.environ.get("MINVAR_KERNEL", "").lower() != "numpy")


@pytest.mark.parametrize("which", ["reference", "noisy", "s"])
def test_compiled_passes_match_numpy_passes(reference_problem, which):
    problem = {"reference": reference_problem, "noisy": _noisy(reference_problem),
               "s": reach_problem(S_TASK)}[which]
    fast = solve(problem, engine="c")
    slow = solve(problem, engine="numpy")
    assert abs(fast.iterations - slow.iterations) <= 1
    np.testing.assert_allclose(fast.K, slow.K, rtol=0, atol=1e-8 * np.abs(slow.K).max())
    np.testing.assert_allclose(fast.L, slow.L, rtol=0, atol=1e-8 * np.abs(slow.L).max())
    np.testing.assert_allclose(fast.mean_states, slow.mean_states, rtol=0, atol=1e-10)
    assert fast.cost == pytest.approx(slow.cost, rel=1e-9)


def test_error_covariance_matches_joint_moments(reference_problem):
    rng = np.random.default_rng(4)
    for p in (reference_problem, _noisy(reference_problem)):
        s = solve(p)
        K = s.K + 0.01 * rng.standard_normal(s.K.shape)  # any gains, not only optimal ones
        L = s.L * (1 + 0.01 * rng.standard_normal(s.L.shape))
        n = p.n_states
        slow = np.array([S[:n, :n] - S[:n, n:] - S[n:, :n] + S[n:, n:]
                         for _, _, S in _joint_moments(p, K, L)])
        for engine in ("c", "numpy"):  # numpy: _joint_moments itself
            np.testing.assert_allclose(estimation_error_covariance(p, K, L, engine=engine),
                                       slow, rtol=0, atol=1e-12 * np.abs(slow).max())


def test_stopping_rule_is_todorovs_absolute_test(todorov, reference_problem, engine):
    sol = solve(reference_problem, engine=engine)
    out = todorov["outputs"]
    assert sol.iterations == out["iterations"]  # the same iteration, not within 2
    h = sol.cost_history
    assert abs(h[-1] - h[-2]) < 1e-15 and abs(h[-2] - h[-3]) >= 1e-15


def test_routine_plans_converge_without_warnings(caplog):
    from perception.recognition.repertoire import Repertoire

    with caplog.at_level(logging.WARNING):
        Repertoire.build()
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


def test_unconverged_plan_is_reported_once(reference_problem, caplog, monkeypatch, engine):
    import minvar.lqg

    monkeypatch.setattr(minvar.lqg, "_REPORTED", set())
    with caplog.at_level(logging.WARNING, logger="minvar.lqg"):
        for _ in range(3):
            s = solve(reference_problem, max_iter=3, engine=engine)
            assert not s.converged
    assert len([r for r in caplog.records if "did not converge" in r.getMessage()]) == 1


def test_overflowing_dynamics_raise_naming_the_cause(reference_problem):
    p = dataclasses.replace(reference_problem, A=reference_problem.A * 1e8)
    with pytest.raises(ValueError, match=r"not finite.*dynamics A grow by 1e\+08"):
        solve(p)


def test_singular_sensor_noise_raises_naming_the_cause(reference_problem, engine):
    p = dataclasses.replace(reference_problem, D0=np.zeros((6, 6)))
    with pytest.raises(ValueError, match=r"observation noise D0 D0' is singular"):
        solve(p, engine=engine)


def test_identical_chain_problems_are_solved_once():
    from minvar.grasp import GraspTask, plan_grasp

    grasp = plan_grasp(GraspTask(duration=0.9))
    reach = plan_grasp(GraspTask(duration=0.9, reach_only=True))
    assert reach.arm.solution is grasp.arm.solution  # one transport, one solve


def test_numpy_fallback_by_environment(tmp_path):
    # MINVAR_KERNEL=numpy makes "auto" mean numpy, silently; engine="c" still runs C
    code = ("from minvar import _kernel; print(_kernel.available(), _kernel.loaded(), "
            "_kernel.use_compiled('auto'), _kernel.use_compiled('c'))")
    env = {**os.environ, "MINVAR_KERNEL": "numpy"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False True False True"
    assert not out.stderr

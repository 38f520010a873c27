"""The fast solver: compiled passes, Todorov's stopping rule, failures named, plans shared."""

import dataclasses
import logging
import os
import subprocess
import sys

import numpy as np
import pytest

from minvar import _kernel, expected_cost, reach_problem, solve
from minvar.moments import Moments, estimation_error_covariance, mean_states
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


def test_compiled_moments_match_numpy_moments(reference_problem):
    # lqg_error_cov and lqg_mean_states are the compiled twins of
    # minvar.moments.Moments.step and minvar.moments.mean_states
    rng = np.random.default_rng(4)
    for p in (reference_problem, _noisy(reference_problem)):
        s = solve(p)
        K = s.K + 0.01 * rng.standard_normal(s.K.shape)  # any gains, not only optimal ones
        L = s.L * (1 + 0.01 * rng.standard_normal(s.L.shape))
        slow = estimation_error_covariance(p, K, L, engine="numpy")
        fast = estimation_error_covariance(p, K, L, engine="c")
        np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-12 * np.abs(slow).max())
        optimal = estimation_error_covariance(p, s.K, s.L, engine="numpy")
        assert np.abs(optimal - slow).max() > 1e-6 * np.abs(slow).max()  # the gains matter
        np.testing.assert_allclose(_kernel.mean_states(p, L), mean_states(p, L), rtol=0,
                                   atol=1e-12)


def test_optimal_filter_step_is_the_general_step(reference_problem):
    # the forward pass steps the moments with Todorov's shortcut for the
    # optimal filter gain; with that gain the general step gives the same
    p = _noisy(reference_problem)
    L = solve(p, engine="numpy").L
    moments = Moments(p)
    A, H = p.A, p.H
    fast = general = moments.start()
    for t in range(p.horizon):
        Mhh, Mhe, Mee = fast
        M = moments.add_sensor_noise(H @ Mee @ H.T, Mhh, Mhe, Mee)
        ASH = A @ Mee @ H.T
        K = np.linalg.solve(M, ASH.T).T  # optimal for these moments
        fast = moments.step(*fast, K, L[t], KMK=K @ ASH.T)
        general = moments.step(*general, K, L[t])
        for name, a, b in zip(("Mhh", "Mhe", "Mee"), fast, general):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-11 * np.abs(b).max() + 1e-300,
                                       err_msg=f"{name} at step {t + 1}")
    assert np.abs(fast[1]).max() > 0  # internal noise: the estimate-error moment is tracked


def test_stopping_rule_is_todorovs_absolute_test(todorov, reference_problem, engine):
    sol = solve(reference_problem, engine=engine)
    out = todorov["outputs"]
    assert sol.iterations == out["iterations"]  # the same iteration, not within 2
    h = sol.cost_history
    assert abs(h[-1] - h[-2]) < 1e-15 and abs(h[-2] - h[-3]) >= 1e-15


def test_routine_plans_converge_without_warnings(caplog, engine):
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


def test_overflowing_dynamics_raise_naming_the_cause(reference_problem, engine):
    p = dataclasses.replace(reference_problem, A=reference_problem.A * 1e8)
    with pytest.raises(ValueError, match=r"not finite.*dynamics A grow by 1e\+08"):
        solve(p, engine=engine)


def test_singular_sensor_noise_solves_and_a_breakdown_names_it(reference_problem, engine,
                                                             monkeypatch):
    # no sensory noise: the pseudo-inverse's filter, on an error covariance kept symmetric
    # (its rounding once grew until the SVD failed at iteration 6)
    p = dataclasses.replace(reference_problem, D0=np.zeros((6, 6)))
    s = solve(p, engine=engine)
    assert s.converged and np.isfinite(s.K).all() and np.isfinite(s.L).all()
    assert expected_cost(p, s.K, s.L) == pytest.approx(s.cost, rel=1e-8)

    def broken(M):
        raise np.linalg.LinAlgError("SVD did not converge")

    # should the pseudo-inverse still fail, the error says which noise is singular
    monkeypatch.setattr(np.linalg, "pinv", broken)
    with pytest.raises(ValueError, match=r"observation noise D0 D0' is singular"):
        solve(p, engine=engine)


def test_identical_chain_problems_are_solved_once(engine):
    from minvar.grasp import GraspTask, plan_grasp

    grasp = plan_grasp(GraspTask(duration=0.9))
    reach = plan_grasp(GraspTask(duration=0.9, reach_only=True))
    assert reach.arm.solution is grasp.arm.solution  # one transport, one solve


def test_plans_shared_between_solves_are_those_of_the_engine(monkeypatch):
    # the process-wide cache of chain solutions holds each engine's own
    from collections import OrderedDict

    from minvar import grasp
    from minvar.grasp import GraspTask, plan_grasp

    monkeypatch.setattr(grasp, "_SOLVED", OrderedDict())
    task = GraspTask(duration=0.8)
    plans = {}
    for engine in ("c", "numpy", "c"):
        monkeypatch.setenv("MINVAR_KERNEL", engine)
        plans.setdefault(engine, []).append(plan_grasp(task).arm.solution)
    assert plans["c"][0] is plans["c"][1]  # shared within an engine
    assert plans["numpy"][0] is not plans["c"][0]
    by_numpy = solve(plan_grasp(task).arm.problem, engine="numpy")
    assert plans["numpy"][0].cost_history.tobytes() == by_numpy.cost_history.tobytes()


def test_numpy_fallback_by_environment(tmp_path):
    # MINVAR_KERNEL=numpy makes "auto" mean numpy, silently; engine="c" still runs C
    code = ("from minvar import _kernel; print(_kernel.available(), _kernel.loaded(), "
            "_kernel.use_compiled('auto'), _kernel.use_compiled('c'))")
    env = {**os.environ, "MINVAR_KERNEL": "numpy"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False True False True"
    assert not out.stderr


def test_kernel_checks_the_buffers_it_is_given(reference_problem):
    if not _kernel.loaded():
        pytest.skip(f"the compiled LQG kernel is not available: {_kernel._WHY}")
    from minvar import _lqg_kernel

    p = reference_problem
    T, n, m = p.horizon, p.n_states, p.n_controls
    dims = (T, n, m, p.n_outputs, 0, 0)
    L = np.random.default_rng(0).standard_normal((T, m, n))
    X = np.empty((T + 1, n))
    _lqg_kernel.mean_states(dims, p.A, p.B, L, p.X1, X)  # read-only inputs are fine
    np.testing.assert_allclose(X, mean_states(p, L), rtol=0, atol=1e-12 * np.abs(X).max())
    frozen = np.empty_like(X)
    frozen.setflags(write=False)
    bad = [({"X": frozen}, ValueError, rf"X: expected {(T + 1) * n} writable C-contiguous"),
           ({"X": X[:-1]}, ValueError, rf"X: expected {(T + 1) * n} .* got {T * n * 8} bytes"),
           ({"L": np.asfortranarray(L)}, ValueError, r"L: expected \d+ C-contiguous float64"),
           ({"L": L.astype(np.float32)}, ValueError, r"L: .* of 'f'"),
           ({"X1": list(p.X1)}, TypeError, r"X1: expected 10 C-contiguous float64 .* got list")]
    for change, error, message in bad:
        args = {"A": p.A, "B": p.B, "L": L, "X1": p.X1, "X": X, **change}
        with pytest.raises(error, match=rf"_lqg_kernel\.mean_states: {message}"):
            _lqg_kernel.mean_states(dims, *args.values())
    with pytest.raises(ValueError, match=r"sizes \(T, n, m, k, nc, nd\) = \(-1, "):
        _lqg_kernel.mean_states((-1, n, m, 6, 0, 0), p.A, p.B, L, p.X1, X)

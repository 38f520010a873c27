"""The solver against Todorov's own code, exact moments and Monte Carlo, with each engine."""

import dataclasses
import logging
import os
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from minvar import expected_cost, simulate, solve, state_moments


def test_matches_todorov_reference(todorov, reference_problem, engine):
    out = todorov["outputs"]
    sol = solve(reference_problem, engine=engine)
    np.testing.assert_allclose(sol.K, np.array(out["K"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.L, np.array(out["L"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.mean_states, np.array(out["Xa"]), rtol=0, atol=1e-8)
    assert abs(sol.cost - out["Cost_final"]) < 1e-10
    assert abs(sol.iterations - out["iterations"]) <= 2
    assert sol.converged
    n = min(len(sol.cost_history), len(out["Cost"]))
    np.testing.assert_allclose(sol.cost_history[:n], out["Cost"][:n], rtol=0, atol=1e-10)


def test_two_iterations_match_reference_exactly(todorov, reference_problem, engine):
    out = todorov["outputs_niter2"]
    sol = solve(reference_problem, max_iter=2, engine=engine)
    assert sol.iterations == 2
    np.testing.assert_allclose(sol.K, np.array(out["K"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.L, np.array(out["L"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.mean_states, np.array(out["Xa"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.cost_history, out["Cost"], rtol=0, atol=1e-10)


def test_gains_are_read_only(reference_problem, engine):
    sol = solve(reference_problem, engine=engine)
    with pytest.raises(ValueError):
        sol.K[0, 0, 0] = 1.0


def _all_noise(problem, seed=1):
    """The reference problem with every noise term of Todorov's model non-zero."""
    rng = np.random.default_rng(seed)
    n, k = problem.n_states, problem.n_outputs
    physical = (np.arange(n) < 8).astype(float)  # the constant 1s stay noise-free
    return dataclasses.replace(
        problem,
        C0=0.002 * rng.standard_normal((n, 3)) * physical[:, None],
        D=[0.01 * rng.standard_normal((k, n)) * physical[None, :]],
        E0=0.001 * rng.standard_normal((n, 2)) * physical[:, None],
        S1=np.diag(np.r_[1e-4, 1e-4, 1e-3, 1e-3, np.zeros(n - 4)]),
    )


@pytest.fixture(scope="module")
def noisy(reference_problem, engine):
    """The noisy problem and its plan by ``engine``."""
    p = _all_noise(reference_problem)
    return p, solve(p, engine=engine)


@pytest.fixture(scope="module")
def noisy_mc(reference_problem):
    """Monte Carlo runs (20000 trials each) of the noisy problem's plan by the
    numpy passes, summarised: what each engine's exact numbers are compared
    with. The engines' gains agree to ~1e-9 of their size (test_speed_solver.py),
    far below what 20000 trials resolve, so one sample serves both."""
    p = _all_noise(reference_problem)
    s = solve(p, engine="numpy")
    cost = simulate(p, s, 20000, seed=7).cost
    end = simulate(p, s, 20000, seed=11).states[:, -1, :2].copy()
    tr = simulate(p, s, 20000, seed=13)
    err = tr.states - tr.estimates
    return SimpleNamespace(solution=s, cost=cost, end=end,
                           error={t: err[:, t, :4].copy() for t in (10, 30, 50)})


def test_reported_cost_is_exact_expected_cost(reference_problem, noisy, engine):
    # the passes' moments (specialised to the optimal K) against Moments.step (any gains)
    sol = solve(reference_problem, engine=engine)
    assert expected_cost(reference_problem, sol.K, sol.L) == pytest.approx(sol.cost, rel=1e-9)
    p, s = noisy
    assert s.converged
    assert expected_cost(p, s.K, s.L) == pytest.approx(s.cost, rel=1e-9)


def test_monte_carlo_cost_within_sampling_error(noisy, noisy_mc):
    _, s = noisy  # this engine's cost, against the sample of the numpy passes' gains
    np.testing.assert_allclose(s.L, noisy_mc.solution.L, rtol=0,
                               atol=1e-8 * np.abs(s.L).max())
    cost = noisy_mc.cost
    stderr = cost.std(ddof=1) / np.sqrt(cost.size)
    assert abs(cost.mean() - s.cost) < 4 * stderr
    assert stderr < 0.01 * s.cost  # the check has teeth


@pytest.mark.parametrize("which", ["K", "L"])
def test_perturbing_gains_raises_cost(noisy, which):
    p, s = noisy
    rng = np.random.default_rng(3)
    gains = {"K": s.K, "L": s.L}
    for _ in range(5):
        delta = rng.standard_normal(gains[which].shape) * 0.05 * np.abs(gains[which]).mean()
        for sign in (1.0, -1.0):  # a minimum, not a slope: both directions cost more
            trial = dict(gains)
            trial[which] = gains[which] + sign * delta
            assert expected_cost(p, trial["K"], trial["L"]) > s.cost


def test_exact_moments_match_monte_carlo(reference_problem, noisy_mc):
    p, s = _all_noise(reference_problem), noisy_mc.solution
    mean, cov = state_moments(p, s.K, s.L)
    end = noisy_mc.end
    np.testing.assert_allclose(end.mean(0), mean[-1, :2], atol=4 * np.sqrt(cov[-1, 0, 0] / 2e4))
    np.testing.assert_allclose(np.cov(end.T), cov[-1, :2, :2], rtol=0.06)


def test_singular_filter_falls_back_to_pseudo_inverse(reference_problem, engine):
    # No sensory noise and a known start: H S H' + D0 D0' is exactly zero at
    # t = 0; additive process noise makes it positive definite from t = 1.
    n = reference_problem.n_states
    C0 = np.zeros((n, 8))
    C0[:8, :8] = 1e-3 * np.eye(8)
    p = dataclasses.replace(reference_problem, D0=np.zeros((6, 1)), C0=C0)
    s = solve(p, engine=engine)
    assert np.all(np.isfinite(s.K)) and np.all(np.isfinite(s.L))
    assert np.allclose(s.K[0], 0.0)
    assert expected_cost(p, s.K, s.L) == pytest.approx(s.cost, rel=1e-8)


@pytest.mark.parametrize("sigma_s", [0.0, 0.001, 0.01])
def test_a_reach_with_little_sensory_noise_converges(sigma_s, engine):
    # the filter's error covariance is symmetric only in exact arithmetic: unsymmetrised,
    # its rounding grew until the cost bounced to 1e11 (0.001 m), the SVD failed (none),
    # or 21 iterations ended unconverged (0.01 m)
    import minvar

    task = minvar.ReachTask((0.2, 0.2), (0.4, 0.5), 0.5)
    p = minvar.reach_problem(task, minvar.PointMassPlant(sigma_s=sigma_s))
    s = solve(p, engine=engine)
    assert s.converged and s.iterations <= 6
    assert expected_cost(p, s.K, s.L) == pytest.approx(s.cost, rel=1e-8)
    end = state_moments(p, s.K, s.L)[0][-1][:2]
    assert np.linalg.norm(end - np.asarray(task.goal)) < 0.003


def test_simulation_is_reproducible(reference_problem, engine):
    s = solve(reference_problem, engine=engine)
    a = simulate(reference_problem, s, 50, seed=5).states
    b = simulate(reference_problem, s, 50, seed=5).states
    c = simulate(reference_problem, s, 50, seed=6).states
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)


def test_execution_noise_can_differ_from_planning(reference_problem, engine):
    s = solve(reference_problem, engine=engine)
    quiet = dataclasses.replace(reference_problem, C=[0.01 * np.eye(2)])
    loud = simulate(reference_problem, s, 400, seed=1).states[:, -1, :2].std(0)
    soft = simulate(reference_problem, s, 400, seed=1, execution=quiet).states[:, -1, :2].std(0)
    assert np.all(soft < 0.5 * loud)


@pytest.mark.parametrize("field", ["A", "B", "H", "Q", "R", "X1"])
def test_an_execution_with_another_plant_or_cost_is_refused(reference_problem, field):
    # only the execution's noise is simulated: another plant was run as the planned one
    s = solve(reference_problem, engine="numpy")
    other = dataclasses.replace(reference_problem,
                                **{field: 1.01 * getattr(reference_problem, field)})
    with pytest.raises(ValueError, match=rf"execution\.{field} differs"):
        simulate(reference_problem, s, 5, execution=other)
    same = dataclasses.replace(reference_problem,
                               **{field: getattr(reference_problem, field).copy()})
    assert simulate(reference_problem, s, 5, execution=same).states.shape[0] == 5


@pytest.mark.parametrize("trials", [0, 2.5, True])
def test_simulate_refuses_a_number_of_trials_that_is_not_whole(reference_problem, trials):
    s = solve(reference_problem, engine="numpy")
    with pytest.raises(ValueError, match="trials must be a whole number"):
        simulate(reference_problem, s, trials)


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("B", np.zeros((9, 2)), r"LQGProblem\.B: expected shape \(10, m\) to match A"),
        ("Q", np.zeros((5, 9, 9)), r"LQGProblem\.Q: expected shape \(T\+1, 10, 10\)"),
        ("R", np.eye(3), r"LQGProblem\.R: expected shape \(2, 2\)"),
        ("C", [np.eye(3)], r"LQGProblem\.C\[0\]: expected shape \(2, 2\)"),
        ("D", [np.zeros((6, 9))], r"LQGProblem\.D\[0\]: expected shape \(6, 10\)"),
        ("X1", np.zeros(9), r"LQGProblem\.X1: expected shape \(10\)"),
        ("A", np.full((10, 10), np.nan), r"LQGProblem\.A: contains non-finite"),
        ("H", np.zeros((6, 9)), r"LQGProblem\.H: expected shape \(k, 10\)"),
    ],
)
def test_bad_problem_names_the_field(reference_problem, field, value, message):
    with pytest.raises(ValueError, match=message):
        dataclasses.replace(reference_problem, **{field: value})


def test_bad_solver_options(reference_problem):
    with pytest.raises(ValueError, match="max_iter"):
        solve(reference_problem, max_iter=0)
    with pytest.raises(ValueError, match="trials"):
        simulate(reference_problem, solve(reference_problem, max_iter=1), 0)


def test_estimation_error_covariance_matches_monte_carlo(reference_problem, noisy_mc, engine):
    from minvar.moments import estimation_error_covariance

    p, s = _all_noise(reference_problem), noisy_mc.solution
    P = estimation_error_covariance(p, s.K, s.L, engine=engine)  # of the gains sampled
    assert np.allclose(P[0], p.S1)
    for t, err in noisy_mc.error.items():
        exact = P[t, :4, :4]
        # standard error of each sample covariance element of a Gaussian
        d = np.diag(exact)
        se = np.sqrt((np.outer(d, d) + exact**2) / err.shape[0])
        assert np.all(np.abs(np.cov(err.T) - exact) < 4 * se)


@pytest.mark.parametrize("field, value, message", [
    ("R", np.array([[1e-6, 1e-6], [0.0, 1e-6]]), "symmetric"),
    ("R", -1e-6 * np.eye(2), "positive semi-definite"),
    ("S1", np.diag([-1e-4] + [0.0] * 9), "positive semi-definite"),
])
def test_costs_and_initial_covariance_must_be_psd(reference_problem, field, value, message):
    with pytest.raises(ValueError, match=rf"LQGProblem\.{field}: .*{message}"):
        dataclasses.replace(reference_problem, **{field: value})


def test_unconverged_solve_is_reported(reference_problem, caplog, monkeypatch, engine):
    import minvar.lqg

    monkeypatch.setattr(minvar.lqg, "_REPORTED", set())  # reported once per process
    solve(reference_problem, max_iter=2, engine=engine)
    assert "did not converge" in caplog.text


def test_a_cost_bouncing_on_its_rounding_floor_stops_the_iteration(engine, monkeypatch):
    from collections import OrderedDict

    from minvar import GraspTask, GripVia, grasp, plan_grasp

    # plan_grasp solves with engine "auto", which MINVAR_KERNEL sets; a fresh
    # cache of chain solutions, or the other engine's would be reused
    monkeypatch.setenv("MINVAR_KERNEL", engine)
    monkeypatch.setattr(grasp, "_SOLVED", OrderedDict())
    # an open-close-open grip schedule; the thumb's targets near pi rad make its
    # cost a small difference of large terms
    vias = (GripVia(0.062, 0.0, 0.40), GripVia(0.015, 0.0, 0.60), GripVia(0.065, 0.0, 0.82))
    plan = plan_grasp(GraspTask(object_size=0.10, distance=0.25, duration=0.98, grip_via=vias))
    sol = plan.thumb.solution
    assert sol.converged and sol.iterations < 100
    # its mirror, to the solver's own tolerance: a cost on its rounding floor is
    # known no better than the bounce it stopped on (2e-8 with numpy 2.4's BLAS)
    from minvar.lqg import _FLOOR_RTOL

    np.testing.assert_allclose(sol.cost, plan.finger.solution.cost, rtol=_FLOOR_RTOL)


def _count_compiled_calls(monkeypatch):
    """A list that grows by one per call of the compiled forward pass."""
    from minvar import _kernel

    calls = []
    forward = _kernel.forward
    monkeypatch.setattr(_kernel, "forward", lambda *a: calls.append(1) or forward(*a))
    return calls


def test_grasp_plans_are_the_same_with_each_engine(engine, monkeypatch):
    from collections import OrderedDict

    import minvar.lqg
    from minvar import GraspTask, _kernel, grasp, plan_grasp

    monkeypatch.setenv("MINVAR_KERNEL", engine)  # what plan_grasp's solves ("auto") use
    monkeypatch.setattr(grasp, "_SOLVED", OrderedDict())
    monkeypatch.setattr(minvar.lqg, "_REPORTED", set())  # the fixed-length solves below
    calls = _count_compiled_calls(monkeypatch)
    plan = plan_grasp(GraspTask(object_size=0.07, distance=0.3, duration=0.9))
    assert bool(calls) == (engine == "c")  # the engine asked for is the one that ran
    other = "numpy" if engine == "c" else "c" if _kernel.loaded() else "numpy"
    for chain in (plan.arm, plan.finger, plan.thumb):
        ours = chain.solution
        assert ours.converged
        # the same number of iterations: the 1e-15 stopping test is at the
        # cost's rounding level, so the engines may stop one apart, and the
        # gains of consecutive iterations differ by ~1e-6 of their size
        ref = solve(chain.problem, engine=other, atol=0.0, max_iter=ours.iterations)
        assert ref.iterations == ours.iterations
        for name in ("K", "L"):
            a, b = getattr(ours, name), getattr(ref, name)
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-9 * np.abs(b).max(), err_msg=name)
        np.testing.assert_allclose(ours.mean_states, ref.mean_states, rtol=0, atol=1e-9)
        assert ours.cost == pytest.approx(ref.cost, rel=1e-9)


def test_engine_argument_is_checked(reference_problem):
    from minvar.moments import estimation_error_covariance

    for bad in ("bogus", "C", None):
        with pytest.raises(ValueError, match=r"solve: engine must be one of 'auto', 'c', "):
            solve(reference_problem, engine=bad)
    s = solve(reference_problem, max_iter=1)
    with pytest.raises(ValueError, match=r"estimation_error_covariance: engine"):
        estimation_error_covariance(reference_problem, s.K, s.L, engine="bogus")


def test_engine_parameter_wins_over_the_environment(reference_problem, engine, monkeypatch):
    other = {"c": "numpy", "numpy": "c"}[engine]
    monkeypatch.setenv("MINVAR_KERNEL", other)
    calls = _count_compiled_calls(monkeypatch)
    solve(reference_problem, max_iter=2, engine=engine)
    assert bool(calls) == (engine == "c")


def test_unknown_environment_engine_is_named(reference_problem, monkeypatch):
    monkeypatch.setenv("MINVAR_KERNEL", "fortran")
    with pytest.raises(ValueError, match=r"MINVAR_KERNEL must be .* got 'fortran'"):
        solve(reference_problem, max_iter=1)
    solve(reference_problem, max_iter=1, engine="numpy")  # an explicit engine needs no variable


def test_kernel_engine_says_which_passes_run(reference_problem, engine, monkeypatch):
    from minvar import _kernel, kernel_engine

    assert kernel_engine() == engine  # "auto", told by MINVAR_KERNEL (the fixture)
    calls = _count_compiled_calls(monkeypatch)
    solve(reference_problem, max_iter=2)
    assert bool(calls) == (engine == "c")
    assert kernel_engine("numpy") == "numpy"
    monkeypatch.delenv("MINVAR_KERNEL")
    assert kernel_engine() == ("c" if _kernel.loaded() else "numpy")
    with pytest.raises(ValueError, match=r"kernel_engine: engine must be one of 'auto'"):
        kernel_engine("fortran")


def _without_kernel(monkeypatch):
    """The process as an install without a C compiler sees it."""
    from minvar import _kernel

    monkeypatch.setattr(_kernel, "_KERNEL", None)
    monkeypatch.setattr(_kernel, "_WHY", "it was not built: no C compiler (test)")
    monkeypatch.setattr(_kernel, "_WARNED", False)
    monkeypatch.delenv("MINVAR_KERNEL", raising=False)


def test_c_engine_without_the_kernel_raises(reference_problem, monkeypatch):
    from minvar.lqg import KernelUnavailableError
    from minvar.moments import estimation_error_covariance

    _without_kernel(monkeypatch)
    with pytest.raises(KernelUnavailableError, match=r"engine='c' needs the compiled.*no C "):
        solve(reference_problem, engine="c")
    assert issubclass(KernelUnavailableError, ImportError)
    monkeypatch.setenv("MINVAR_KERNEL", "c")  # "auto" told by the environment to use it
    with pytest.raises(KernelUnavailableError):
        solve(reference_problem)
    s = solve(reference_problem, engine="numpy")
    with pytest.raises(KernelUnavailableError):
        estimation_error_covariance(reference_problem, s.K, s.L, engine="c")


def test_auto_engine_without_the_kernel_warns_once(reference_problem, monkeypatch, caplog,
                                                   todorov):
    from minvar import kernel_engine

    _without_kernel(monkeypatch)
    assert kernel_engine() == "numpy" and kernel_engine("c") == "c"  # silently
    with caplog.at_level(logging.WARNING, logger="minvar"):
        first = solve(reference_problem)
        second = solve(reference_problem, engine="auto")
    warned = [r for r in caplog.records if "compiled LQG kernel is not available" in r.message]
    assert len(warned) == 1 and warned[0].levelno == logging.WARNING
    assert warned[0].name == "minvar" and "no C compiler" in warned[0].message
    assert first.cost == second.cost  # and the numpy passes did the work
    assert abs(first.cost - todorov["outputs"]["Cost_final"]) < 1e-10


def test_numpy_engine_without_the_kernel_is_silent(reference_problem, monkeypatch, caplog):
    _without_kernel(monkeypatch)
    monkeypatch.setenv("MINVAR_KERNEL", "numpy")
    with caplog.at_level(logging.WARNING, logger="minvar"):
        solve(reference_problem, max_iter=2)
        solve(reference_problem, max_iter=2, engine="numpy")
    # nothing from the kernel's loader (two iterations do not converge: the solver's own
    # warning, once per problem and process, is another matter and was order-dependent here)
    assert not [r for r in caplog.records if r.module == "_kernel"]


def test_an_install_without_the_kernel_solves_and_says_so_once():
    # what a user sees where no C compiler built minvar._lqg_kernel: the numpy
    # passes, and one warning on stderr (logging's default), not a silent slow-down
    code = ("import sys; sys.modules['minvar._lqg_kernel'] = None  # as if never built\n"
            "import minvar\n"
            "p = minvar.reach_problem(minvar.ReachTask((0.2, 0.2), (0.4, 0.5), 0.5))\n"
            "a, b = minvar.solve(p), minvar.solve(p, engine='auto')\n"
            "print(minvar.kernel_engine(), a.converged, a.cost == b.cost)\n")
    env = {k: v for k, v in os.environ.items() if k != "MINVAR_KERNEL"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["numpy", "True", "True"]
    warnings = [line for line in out.stderr.splitlines() if line.strip()]
    assert len(warnings) == 1, out.stderr
    assert warnings[0].startswith("minvar: the compiled LQG kernel is not available (it was "
                                  "not built: no C compiler")

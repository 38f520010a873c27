"""The solver against Todorov's own code, exact moments and Monte Carlo."""

import dataclasses

import numpy as np
import pytest

from minvar import expected_cost, simulate, solve, state_moments


def test_matches_todorov_reference(todorov, reference_problem):
    out = todorov["outputs"]
    sol = solve(reference_problem)
    np.testing.assert_allclose(sol.K, np.array(out["K"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.L, np.array(out["L"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.mean_states, np.array(out["Xa"]), rtol=0, atol=1e-8)
    assert abs(sol.cost - out["Cost_final"]) < 1e-10
    assert abs(sol.iterations - out["iterations"]) <= 2
    assert sol.converged
    n = min(len(sol.cost_history), len(out["Cost"]))
    np.testing.assert_allclose(sol.cost_history[:n], out["Cost"][:n], rtol=0, atol=1e-10)


def test_two_iterations_match_reference_exactly(todorov, reference_problem):
    out = todorov["outputs_niter2"]
    sol = solve(reference_problem, max_iter=2)
    assert sol.iterations == 2
    np.testing.assert_allclose(sol.K, np.array(out["K"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.L, np.array(out["L"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.mean_states, np.array(out["Xa"]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.cost_history, out["Cost"], rtol=0, atol=1e-10)


def test_gains_are_read_only(reference_problem):
    sol = solve(reference_problem)
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
def noisy(reference_problem):
    p = _all_noise(reference_problem)
    return p, solve(p)


def test_reported_cost_is_exact_expected_cost(reference_problem, noisy):
    sol = solve(reference_problem)
    assert expected_cost(reference_problem, sol.K, sol.L) == pytest.approx(sol.cost, rel=1e-9)
    p, s = noisy
    assert s.converged
    assert expected_cost(p, s.K, s.L) == pytest.approx(s.cost, rel=1e-9)


def test_monte_carlo_cost_within_sampling_error(noisy):
    p, s = noisy
    cost = simulate(p, s, 20000, seed=7).cost
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


def test_exact_moments_match_monte_carlo(noisy):
    p, s = noisy
    mean, cov = state_moments(p, s.K, s.L)
    X = simulate(p, s, 20000, seed=11).states
    end = X[:, -1, :2]
    np.testing.assert_allclose(end.mean(0), mean[-1, :2], atol=4 * np.sqrt(cov[-1, 0, 0] / 2e4))
    np.testing.assert_allclose(np.cov(end.T), cov[-1, :2, :2], rtol=0.06)


def test_singular_filter_falls_back_to_pseudo_inverse(reference_problem):
    # No sensory noise and a known start: H S H' + D0 D0' is exactly zero at
    # t = 0; additive process noise makes it positive definite from t = 1.
    n = reference_problem.n_states
    C0 = np.zeros((n, 8))
    C0[:8, :8] = 1e-3 * np.eye(8)
    p = dataclasses.replace(reference_problem, D0=np.zeros((6, 1)), C0=C0)
    s = solve(p)
    assert np.all(np.isfinite(s.K)) and np.all(np.isfinite(s.L))
    assert np.allclose(s.K[0], 0.0)
    assert expected_cost(p, s.K, s.L) == pytest.approx(s.cost, rel=1e-8)


def test_simulation_is_reproducible(reference_problem):
    s = solve(reference_problem)
    a = simulate(reference_problem, s, 50, seed=5).states
    b = simulate(reference_problem, s, 50, seed=5).states
    c = simulate(reference_problem, s, 50, seed=6).states
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)


def test_execution_noise_can_differ_from_planning(reference_problem):
    s = solve(reference_problem)
    quiet = dataclasses.replace(reference_problem, C=[0.01 * np.eye(2)])
    loud = simulate(reference_problem, s, 400, seed=1).states[:, -1, :2].std(0)
    soft = simulate(reference_problem, s, 400, seed=1, execution=quiet).states[:, -1, :2].std(0)
    assert np.all(soft < 0.5 * loud)


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


def test_estimation_error_covariance_matches_monte_carlo(noisy):
    from minvar.lqg import estimation_error_covariance

    p, s = noisy
    P = estimation_error_covariance(p, s.K, s.L)
    tr = simulate(p, s, 20000, seed=13)
    err = tr.states - tr.estimates
    assert np.allclose(P[0], p.S1)
    for t in (10, 30, 50):
        exact = P[t, :4, :4]
        # standard error of each sample covariance element of a Gaussian
        d = np.diag(exact)
        se = np.sqrt((np.outer(d, d) + exact**2) / err.shape[0])
        assert np.all(np.abs(np.cov(err[:, t, :4].T) - exact) < 4 * se)


@pytest.mark.parametrize("field, value, message", [
    ("R", np.array([[1e-6, 1e-6], [0.0, 1e-6]]), "symmetric"),
    ("R", -1e-6 * np.eye(2), "positive semi-definite"),
    ("S1", np.diag([-1e-4] + [0.0] * 9), "positive semi-definite"),
])
def test_costs_and_initial_covariance_must_be_psd(reference_problem, field, value, message):
    with pytest.raises(ValueError, match=rf"LQGProblem\.{field}: .*{message}"):
        dataclasses.replace(reference_problem, **{field: value})


def test_unconverged_solve_is_reported(reference_problem, caplog, monkeypatch):
    import minvar.lqg

    monkeypatch.setattr(minvar.lqg, "_REPORTED", set())  # reported once per process
    solve(reference_problem, max_iter=2)
    assert "did not converge" in caplog.text


def test_a_cost_bouncing_on_its_rounding_floor_stops_the_iteration():
    from minvar import GraspTask, GripVia, plan_grasp

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

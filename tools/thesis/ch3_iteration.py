"""Chapter 3's iteration and noise claims, measured: the filter/controller iteration
(lines 481, 483), noise-blind laws (line 388) and a post-movement period (line 545)."""

from __future__ import annotations

import logging
from contextlib import contextmanager
from dataclasses import replace

import numpy as np

from minvar.lqg import solve
from minvar.plant import PointMassPlant
from minvar.reach import simulate_reach
from minvar.similarity import path_distance
from minvar.task import ReachTask, ViaPoint, reach_problem
from minvar.viapoints import expected_path
from tools.thesis.ch3_tasks import REACH, S_TASK
from tools.thesis.claims import Measured
from tools.thesis.common import rng_for


def _initial_laws(opt: np.ndarray, seed: int) -> dict[str, np.ndarray]:
    """First-pass control laws to start the iteration from, by name."""
    other = solve(reach_problem(replace(S_TASK, via_points=(
        ViaPoint((-0.3, 0.45), fraction=0.4), ViaPoint((-0.35, 0.25), fraction=0.6)))))
    rng = rng_for(seed, "convergence")
    scale = np.abs(opt).max()
    return {
        "zero (the thesis's)": np.zeros_like(opt),
        "the optimum x 2": 2 * opt,
        "the optimum x 5": 5 * opt,
        "the optimum of an 's' with other via-points": other.L,
        "random gains at 0.1 of the optimum's size": 0.1 * scale * rng.standard_normal(opt.shape),
        "random gains at 0.3 of the optimum's size": 0.3 * scale * rng.standard_normal(opt.shape),
        "the optimum x -1": -opt,
    }


#: Iterations allowed per start (the zero start converges in 9; a start that overflows
#: would otherwise iterate on NaN up to the solver's default 500).
MAX_ITER = 40


def convergence(got: dict, seed: int, w: dict) -> None:
    """Line 481: the iteration converges to the same answer regardless of initialisation."""
    problem = reach_problem(replace(S_TASK, **w))
    ref = solve(problem)
    same, overflow = [], []
    with np.errstate(all="ignore"), _quiet("minvar.lqg"):
        for name, law in _initial_laws(ref.L, seed).items():
            try:
                sol = solve(problem, initial_L=law, max_iter=MAX_ITER)
            except ValueError:  # the first pass's moments overflow: the solver says so
                overflow.append(name)
                continue
            gap = max(abs(sol.cost / ref.cost - 1), np.abs(sol.L - ref.L).max()
                      / np.abs(ref.L).max())
            same.append((name, gap, sol.iterations))
    worst = max(g for _, g, _ in same)
    got["same-answer"] = Measured(
        f"{len(same)} of {len(same) + len(overflow)} starts converge to the same cost and "
        f"gains (largest relative difference {worst:.0e}; {min(i for *_, i in same)}-"
        f"{max(i for *_, i in same)} iterations)"
        + (f"; {'; '.join(overflow)}: overflow in the first pass" if overflow else ""),
        {"largest_relative_difference": worst},
        note="a start that makes the closed loop explode (e.g. positive feedback) sends "
        "the first forward pass's second moments past the largest double (1e308) within the "
        "100 steps, so the iteration cannot be carried out in floating point: those starts "
        "test nothing either way" if overflow else "")


@contextmanager
def _quiet(name: str):
    """Silence a logger (the solver's warning about the overflowing starts)."""
    logger = logging.getLogger(name)
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


def exponential(got: dict, w: dict) -> None:
    """Line 481: the iteration converges exponentially."""
    sol = solve(reach_problem(replace(S_TASK, **w)))
    err = np.abs(np.asarray(sol.cost_history, dtype=float) - sol.cost)[:-1]
    err = err[err > 1e-12 * abs(sol.cost)]
    ratios = err[1:] / err[:-1]
    got["exponential"] = Measured(
        "cost error per iteration falls by factors "
        + ", ".join(f"{x:.2g}" for x in ratios) + f" ({sol.iterations} iterations)",
        {"shrinks_every_iteration": bool(len(ratios) and np.all(ratios < 1))})


def noise(got: dict, trials: int, seed: int, w: dict) -> None:
    """Line 388: a noise-blind law makes the same trajectory at any noise level; line 545:
    a post-movement period does not change the trajectory."""
    s_task = replace(S_TASK, **w)
    low, high = PointMassPlant(sigma_u=0.2), PointMassPlant(sigma_u=0.8)
    moved = path_distance(expected_path(s_task, low)[1], expected_path(s_task, high)[1])
    got["noise-blind"] = Measured(
        f"minimum variance expected 's' at signal-dependent noise 0.2 vs 0.8: paths up to "
        f"{moved * 1000:.1f} mm apart", {"plan_change_m": moved},
        note="the noise-blind half is by construction: with a fixed linear law and "
        "zero-mean noise the mean path is the noiseless one at any noise level")
    reach = replace(REACH, **w)
    hold = 0.2  # s at rest after the movement, the goal held as a via-point at 500 ms
    held = ReachTask(reach.start, reach.goal, reach.duration + hold,
                     (ViaPoint(reach.goal, fraction=reach.duration / (reach.duration + hold)),),
                     **w)
    t_a, p_a = expected_path(reach)
    t_b, p_b = expected_path(held)
    apart = path_distance(p_a, p_b[t_b <= reach.duration + 1e-9])
    r = simulate_reach(reach, trials, seed=rng_for(seed, "post-movement"))
    scatter = float(np.median([path_distance(p, r.mean_position) for p in r.position]))
    got["post-movement"] = Measured(
        f"expected paths with and without {hold * 1000:.0f} ms at rest up to "
        f"{apart * 1000:.1f} mm apart (a repetition's median distance from the mean path: "
        f"{scatter * 1000:.1f} mm)", {"apart_m": apart, "scatter_m": scatter})



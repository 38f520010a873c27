"""Benchmark: 500 grasps (planning included) against same-run baselines.

Run ``python tools/bench_grasp.py`` or ``make bench`` (``tools/bench.py`` picks
up this module's ``main`` as the ``grasp`` section). Prints, asserts nothing.
"""

from __future__ import annotations

import sys

from bench import table, timeit  # also puts the project root on sys.path

from minvar.execution import simulate
from minvar.grasp import GraspTask, plan_grasp, simulate_grasp


def _per_trial_loop(task: GraspTask, trials: int) -> None:
    """Baseline: the same plan executed one repetition at a time per chain."""
    plan = plan_grasp(task)
    for cp in plan.chains.values():
        for i in range(trials):
            simulate(cp.problem, cp.solution, 1, seed=i, execution=cp.execution)


def main() -> None:
    """Print the grasp benchmark table."""
    task = GraspTask()
    plan = plan_grasp(task)
    full = timeit(lambda: simulate_grasp(task, 500, seed=0), repeat=5)
    planning = timeit(lambda: plan_grasp(task), repeat=5)
    execution = timeit(lambda: simulate_grasp(task, 500, seed=0, plan=plan), repeat=5)
    loop = timeit(lambda: _per_trial_loop(task, 500), repeat=1, min_time=0.0)
    table("minvar: grasping (arm + 2 digits, T = 100 steps)", [
        ("500 grasps, planning included", f"{full * 1e3:.0f} ms",
         f"target <= 500 ms; per-trial loop {loop * 1e3:.0f} ms", f"{loop / full:.0f}x faster"),
        ("  planning alone (3 joint-space LQGs)", f"{planning * 1e3:.0f} ms", "", ""),
        ("  execution alone (3 x 500 repetitions)", f"{execution * 1e3:.0f} ms", "", ""),
    ])


if __name__ == "__main__":
    main()
    sys.exit(0)

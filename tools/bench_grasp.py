"""Benchmark: 500 grasps (planning included) against same-run baselines.

Run ``python tools/bench_grasp.py`` or ``make bench`` (``tools/bench.py`` picks
up this module's ``main`` as the ``grasp`` section). Prints, asserts nothing.

Planning is timed uncached: ``plan_grasp`` keeps the last solutions in a
process-wide cache (``minvar.grasp._SOLVED``), and a cached plan costs a
dictionary look-up, not a solve; the cache is emptied before every timed
call. The baseline is what a user without a C compiler gets: the same
planning with the solver's numpy passes (``MINVAR_KERNEL=numpy``), timed in
a fresh process.
"""

from __future__ import annotations

import os
import subprocess
import sys

from bench import ROOT, table, timeit  # also puts the project root on sys.path

from minvar import grasp
from minvar.grasp import GraspTask, plan_grasp, simulate_grasp

#: Planning with the numpy passes, uncached, in a fresh process (prints seconds).
_NUMPY_PLAN = """
import time
from minvar import grasp
from minvar.grasp import GraspTask, plan_grasp
task = GraspTask()
runs = []
for _ in range(3):
    grasp._SOLVED.clear()
    t0 = time.perf_counter()
    plan_grasp(task)
    runs.append(time.perf_counter() - t0)
print(min(runs))
"""


def _uncached(fn):
    def run():
        grasp._SOLVED.clear()
        return fn()
    return run


def _numpy_planning() -> float:
    env = {**os.environ, "MINVAR_KERNEL": "numpy"}
    out = subprocess.run([sys.executable, "-c", _NUMPY_PLAN], check=True, capture_output=True,
                         text=True, cwd=ROOT, env=env)
    return float(out.stdout.split()[-1])


def main() -> None:
    """Print the grasp benchmark table."""
    task = GraspTask()
    plan = plan_grasp(task)
    full = timeit(_uncached(lambda: simulate_grasp(task, 500, seed=0)), repeat=5)
    planning = timeit(_uncached(lambda: plan_grasp(task)), repeat=5)
    cached = timeit(lambda: plan_grasp(task), repeat=5)
    execution = timeit(lambda: simulate_grasp(task, 500, seed=0, plan=plan), repeat=5)
    numpy_planning = _numpy_planning()
    table("minvar: grasping (arm + 2 digits, T = 100 steps), planning uncached", [
        ("500 grasps, planning included", f"{full * 1e3:.0f} ms", "target <= 500 ms", ""),
        ("  planning alone (3 joint-space LQGs)", f"{planning * 1e3:.1f} ms",
         f"numpy passes {numpy_planning * 1e3:.0f} ms", f"{numpy_planning / planning:.1f}x faster"),
        ("  the same plan again (process-wide cache)", f"{cached * 1e3:.2f} ms", "", ""),
        ("  execution alone (3 x 500 repetitions)", f"{execution * 1e3:.0f} ms", "", ""),
    ])


if __name__ == "__main__":
    main()
    sys.exit(0)

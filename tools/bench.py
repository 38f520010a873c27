"""hammer-mv benchmarks: prints figures against targets and same-run baselines.

Run ``make bench`` or ``python tools/bench.py [--only SECTION ...]``. Nothing
here asserts; the figures go in closing notes and pull requests. Each section
is a function printing one table; sections living in ``tools/bench_*.py``
modules are picked up by name.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import json
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

# as the hammer-mv command runs: one BLAS/OpenMP thread (set before numpy loads)
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))
# the sections' `from bench import table` must reach this very module (run as a
# script it is __main__), so that every table is kept for the markdown file
sys.modules.setdefault("bench", sys.modules[__name__])

from minvar import (  # noqa: E402
    LQGProblem,
    ReachTask,
    ViaPoint,
    reach_problem,
    simulate,
    solve,
)

#: Fastest batch of the last :func:`timeit` call, s per call: what the code
#: costs when nothing else wants the cores (the median says what a busy machine gives).
BEST = {"last": float("nan")}


def timeit(fn: Callable[[], object], *, repeat: int = 7, min_time: float = 0.2) -> float:
    """Median wall time of ``fn`` in seconds over ``repeat`` batches (fastest in ``BEST``)."""
    fn()  # warm caches
    n = 1
    while True:
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        if time.perf_counter() - t0 > min_time / repeat or n > 1000:
            break
        n *= 2
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        runs.append((time.perf_counter() - t0) / n)
    BEST["last"] = min(runs)
    return statistics.median(runs)


#: Every table printed in this run, as markdown (``make bench`` writes them to a file).
TABLES: list[str] = []


def table(title: str, rows: list[tuple[str, str, str, str]]) -> None:
    """Print rows of (what, measured, baseline/target, verdict); keep them as markdown too."""
    cells = [("what", "measured", "target / baseline", ""), *rows]
    TABLES.append("\n".join([f"## {title}", "", *(
        "| " + " | ".join(c.replace("|", "\\|") for c in r) + " |"
        for r in cells[:1]), "|---|---|---|---|", *(
        "| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in rows), ""]))
    print(f"\n## {title}")
    w = [max(len(r[i]) for r in rows + [("what", "measured", "target / baseline", "")])
         for i in range(4)]
    print(f"{'what':<{w[0]}}  {'measured':>{w[1]}}  {'target / baseline':<{w[2]}}  ")
    for r in rows:
        print(f"{r[0]:<{w[0]}}  {r[1]:>{w[1]}}  {r[2]:<{w[2]}}  {r[3]}")


S_TASK = ReachTask(
    (-0.2, 0.5), (-0.4, 0.2), 1.0,
    (ViaPoint((-0.4, 0.4), fraction=0.25), ViaPoint((-0.2, 0.3), fraction=0.75)),
)


def _numpy_passes(fn: Callable[[], object]) -> Callable[[], object]:
    """``fn`` with the solver's numpy passes instead of the compiled ones
    (``MINVAR_KERNEL=numpy``: what ``engine="auto"`` then picks; set by this
    tool, an application, around the timed call only)."""
    import os

    def run():
        before = os.environ.get("MINVAR_KERNEL")
        os.environ["MINVAR_KERNEL"] = "numpy"
        try:
            return fn()
        finally:
            if before is None:
                os.environ.pop("MINVAR_KERNEL")
            else:
                os.environ["MINVAR_KERNEL"] = before

    return run


def section_solver() -> None:
    """LQG solve times: thesis 's' problem and the reference reach."""
    from minvar import _kernel

    ref = json.loads((ROOT / "tests" / "data" / "todorov_reach.json").read_text())
    octave_ms = ref["info"]["time_per_call_median_s"] * 1000
    rows = []
    for label, problem in [
        ("solve 's' (T=100, n=14, 2 via-points)", reach_problem(S_TASK)),
        ("solve reference reach (T=50, n=10)",
         LQGProblem(**{k: np.array(v, float) for k, v in ref["inputs"].items()})),
    ]:
        ours = timeit(lambda p=problem: solve(p))
        best = BEST["last"]
        numpy_passes = timeit(_numpy_passes(lambda p=problem: solve(p)), repeat=3)
        sol = solve(problem)
        rows.append((f"{label}, {sol.iterations} it",
                     f"{ours * 1e3:.1f} ms (best {best * 1e3:.1f})",
                     f"numpy passes {numpy_passes * 1e3:.0f} ms",
                     f"{numpy_passes / ours:.1f}x faster"))
    rows[0] = (*rows[0][:3], rows[0][3] + ("; target <= 10 ms " + (
        "ok" if float(rows[0][1].split()[0]) <= 10 else "MISSED (median)")))
    sol = solve(LQGProblem(**{k: np.array(v, float) for k, v in ref["inputs"].items()}))
    out = ref["outputs"]
    err = max(float(np.abs(sol.K - np.array(out["K"])).max()),
              float(np.abs(sol.L - np.array(out["L"])).max()),
              float(np.abs(sol.mean_states - np.array(out["Xa"])).max()))
    rows[1] = (*rows[1][:3], rows[1][3] + f"; Octave {octave_ms:.0f} ms (reference file)")
    rows.append(("  vs Todorov's output: iterations; max |K, L, Xa| error",
                 f"{sol.iterations} / {out['iterations']}; {err:.1e}", "same; <= 1e-8",
                 "ok" if sol.iterations == out["iterations"] and err <= 1e-8 else "MISSED"))
    rows.append(("  compiled passes in use", "yes" if _kernel.available() else "NO (numpy)",
                 "minvar/_lqg_kernel.c, built by pip install", ""))
    table("minvar: LQG solver", rows)


def section_execution() -> None:
    """Monte Carlo execution: 500 repetitions x 100 steps."""
    problem = reach_problem(S_TASK)
    sol = solve(problem)
    vec = timeit(lambda: simulate(problem, sol, 500, seed=0))
    loop = timeit(lambda: [simulate(problem, sol, 1, seed=i) for i in range(500)], repeat=3)
    table("minvar: Monte Carlo execution", [
        ("500 repetitions x 100 steps (vectorised)", f"{vec * 1e3:.1f} ms",
         f"target <= 50 ms; per-trial loop {loop * 1e3:.0f} ms", f"{loop / vec:.0f}x faster"),
    ])


SECTIONS: dict[str, Callable[[], None]] = {
    "solver": section_solver,
    "execution": section_execution,
}


def _discover() -> dict[str, Callable[[], None]]:
    """Built-in sections plus ``main`` of each ``tools/bench_<name>.py``."""
    found = dict(SECTIONS)
    for path in sorted((ROOT / "tools").glob("bench_*.py")):
        mod = importlib.import_module(path.stem)
        run = mod.main
        if inspect.signature(run).parameters:  # its own options: take their defaults
            run = (lambda f: lambda: f([]))(run)
        found[path.stem.removeprefix("bench_")] = run
    return found


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark sections named in ``argv`` (default: all)."""
    sections = _discover()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=sorted(sections), help="sections to run")
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "out" / "bench.md",
                        help="markdown file the tables are written to (default: out/bench.md)")
    args = parser.parse_args(argv)
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    header = (f"hammer-mv benchmarks, {time.strftime('%Y-%m-%d %H:%M')} (python "
              f"{sys.version.split()[0]}, numpy {np.__version__}; {os.cpu_count()} cores, load "
              f"average {load} at the start: other work on the machine slows every figure)")
    print(header)
    for name in args.only or list(sections):
        sections[name]()
    from perception.io.atomic import write_text

    args.output.parent.mkdir(parents=True, exist_ok=True)
    write_text(args.output, "# " + header + "\n\n" + "\n".join(TABLES))
    print(f"\nwrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

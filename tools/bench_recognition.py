"""Recognition benchmarks: one clip against a repertoire, and batch throughput.

Targets (issue: HAMMER-MV recognition): recognising one 1 s clip's tracks
against a built repertoire of >= 10 models <= 50 ms; batch throughput from 1
to 2 processes >= 1.7x.
"""

from __future__ import annotations

import dataclasses
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from bench import table, timeit  # noqa: E402


def main() -> None:
    """Print the recognition and batch figures."""
    from _demos import demo_tracks

    from perception.batch import discover, run_batch
    from perception.observation import observe
    from perception.recognition.engine import recognize
    from perception.recognition.repertoire import Repertoire, SceneSpec
    from perception.synthetic.recipes import load_recipe, synthesize

    t0 = time.perf_counter()
    rep = Repertoire.build(scene=SceneSpec())
    build = time.perf_counter() - t0
    obs = observe(demo_tracks("normal", 0)[0])
    all_at_once = timeit(lambda: recognize(obs, rep))
    one_by_one = timeit(lambda: [recognize(obs, [m]) for m in rep.models], repeat=3)
    rows = [
        (f"recognise a 1 s clip ({obs.n_frames} frames) vs {len(rep)} models",
         f"{all_at_once * 1e3:.1f} ms",
         f"target <= 50 ms; model by model {one_by_one * 1e3:.0f} ms",
         "ok" if all_at_once <= 0.05 else "MISSED"),
        (f"build and calibrate the default repertoire ({len(rep)} models: 3 plans and "
         "50 own demonstrations each)",
         f"{build * 1e3:.0f} ms", "once; saved to HDF5 and reused", ""),
    ]

    work = Path(tempfile.mkdtemp(prefix="hammer-bench-"))
    try:
        recipe = load_recipe(ROOT / "datasets" / "smoke.toml")
        recipe = dataclasses.replace(recipe, counts={"normal": 14, "delayed": 13,
                                                     "open-close-open": 13})
        synthesize(recipe, work / "clips", seed=0)
        items = discover(work / "clips")
        times = {}
        for jobs in (1, 2):
            t0 = time.perf_counter()
            run_batch(items, work / f"out{jobs}", rep, quiet=True, jobs=jobs)
            times[jobs] = time.perf_counter() - t0
        speedup = times[1] / times[2]
        rows.append((f"batch: track + recognise + report {len(items)} clips, 2 processes",
                     f"{len(items) / times[2]:.1f} clips/s",
                     f"1 process {len(items) / times[1]:.1f} clips/s; speedup {speedup:.2f}x "
                     "(target >= 1.7x)", "ok" if speedup >= 1.7 else "MISSED"))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    table("perception: HAMMER-MV recognition", rows)


if __name__ == "__main__":
    main()

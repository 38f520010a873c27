"""`make demo`: the whole pipeline on synthetic clips, ending in a report.

1. render the smoke recipe (normal, delayed-opening and open-close-open grasps
   from the minimum variance model) into out/demo/clips/;
2. build the default HAMMER-MV repertoire once (out/demo/repertoire.h5);
3. track, recognise and report every clip in parallel (out/demo/report.html).

Rerunning reuses the clips, the repertoire and every current clip report.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hammer_mv.cli import main  # noqa: E402


def run() -> int:
    out = ROOT / "out" / "demo"
    clips, rep = out / "clips", out / "repertoire.h5"
    start = time.perf_counter()
    if not (clips / "manifest.csv").exists():
        if main(["synth", str(ROOT / "datasets" / "smoke.toml"), "-o", str(clips), "--seed", "0",
                 "--jobs", "2"]):
            return 2
    if not rep.exists() and main(["repertoire", "build", "-o", str(rep)]):
        return 2
    status = main(["batch", str(clips / "manifest.csv"), "-o", str(out), "--repertoire",
                   str(rep), "--jobs", "2"])
    print(f"\ndemo finished in {time.perf_counter() - start:.0f} s")
    print(f"report: {out / 'report.html'}")
    return status


if __name__ == "__main__":
    sys.exit(run())

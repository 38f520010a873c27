"""Benchmark: a 60-trial motion-capture table scored end to end, with a same-run baseline.

Run ``python tools/bench_mocap.py`` or ``make bench`` (``tools/bench.py``
picks up this module's ``main`` as the ``mocap`` section). Prints, asserts
nothing. The table is made from the four real Optotrak trials shipped in
``tests/data/mocap/`` repeated 15 times (60 trials, 85 Hz, no time column),
so it needs nothing outside the repository.

* ``hammer-mv recognize TABLE --no-figures``: every reach read, cleaned,
  found and scored in one process (target: 60 trials in 60 s or less on 2
  cores);
* ``hammer-mv batch`` of a folder holding the table, ``--jobs 2``, with
  every figure and the batch report;
* baseline: one trial of the same table, ``recognize --no-figures``, whole
  process (60 times it is what scoring trial by trial would cost).
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from bench import table  # also puts the project root on sys.path
from bench_speed import HAMMER, _timed

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "tests" / "data" / "mocap" / "optotrak-trials.tsv"
RATE = "85"


def make_table(path: Path, copies: int = 15) -> int:
    """Write the shipped trials ``copies`` times, renumbered; return the number of trials."""
    lines = SOURCE.read_text().splitlines()
    header, rows = lines[0], [line.split("\t") for line in lines[1:]]
    trials = sorted({int(r[0]) for r in rows})
    out = [header]
    for c in range(copies):
        out += ["\t".join([str(c * len(trials) + int(r[0])), *r[1:]]) for r in rows]
    path.write_text("\n".join(out) + "\n")
    return copies * len(trials)


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="bench-mocap-"))
    try:
        folder = work / "session"
        folder.mkdir()
        big = folder / "trials.tsv"
        n = make_table(big)
        one = work / "one.tsv"
        lines = SOURCE.read_text().splitlines()
        one.write_text("\n".join([lines[0], *[x for x in lines[1:] if x.split("\t")[0] == "0"]])
                       + "\n")
        base_wall, base_cpu = _timed([*HAMMER, "recognize", str(one), "--rate", RATE, "-o",
                                      str(work / "one"), "--no-figures", "--quiet"], repeat=3)
        wall, cpu = _timed([*HAMMER, "recognize", str(big), "--rate", RATE, "-o",
                            str(work / "all"), "--no-figures", "--quiet"], repeat=1)
        out = work / "report"
        batch_wall, batch_cpu = _timed([*HAMMER, "batch", str(folder), "--rate", RATE, "-o",
                                        str(out), "--jobs", "2", "--quiet"], repeat=1)
        shutil.rmtree(out)  # a second run would reuse every report
        table(f"motion capture: a {n}-trial table (85 Hz, real grasps)", [
            (f"recognize, {n} trials, no figures", f"{wall:.1f} s (CPU {cpu:.1f} s)",
             f"target <= 60 s; one trial {base_wall:.2f} s x {n} = {base_wall * n:.0f} s",
             "ok" if wall <= 60 else "MISSED"),
            (f"batch --jobs 2, {n} trials, figures and report", f"{batch_wall:.1f} s "
             f"(CPU {batch_cpu:.1f} s)", "target <= 60 s",
             "ok" if batch_wall <= 60 else "MISSED"),
        ])
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

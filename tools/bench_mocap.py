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

The ``size`` part (issue 46; ``python tools/bench_mocap.py --only size``)
builds a 1,000,000-row table of the same trials (1,984 trials, 95 MB) and
runs ``hammer-mv landmarks`` of it in a subprocess: wall time and peak
resident memory (Linux ``wait4``), against the targets of 60 s and 4 times
the file's size, beside the floor measured in the same run (a process that
imports ``perception``, pandas and scipy.signal, and does nothing).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench import table  # also puts the project root on sys.path
from bench_speed import HAMMER, _on_two_cores, _timed

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "tests" / "data" / "mocap" / "optotrak-trials.tsv"
RATE = "85"
#: Copies of the shipped trials in the size benchmark: 496 x 4 trials, 1,000,432 rows.
BIG_COPIES = 496
#: The memory target: this many times the table's size.
MEMORY_TARGET = 4


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


def scoring() -> None:
    """The 60-trial table scored by ``recognize`` and ``batch``, against one trial."""
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


def _peak(cmd: list[str]) -> tuple[float, float]:
    """Wall time, s, and peak resident memory, bytes, of ``cmd`` in a fresh process (Linux)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT,
                            preexec_fn=_on_two_cores)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode not in (0, 1):  # 1: a trial not measured, still a run to the end
        raise subprocess.CalledProcessError(proc.returncode, cmd)
    return wall, usage.ru_maxrss * 1024.0  # kB on Linux


def size() -> None:
    """``landmarks`` of a 1,000,000-row table: wall time and peak memory against the targets."""
    work = Path(tempfile.mkdtemp(prefix="bench-mocap-size-"))
    try:
        big = work / "big.tsv"
        n = make_table(big, BIG_COPIES)
        rows = sum(1 for _ in big.open()) - 1
        mb = big.stat().st_size / 1e6
        _, floor = _peak([sys.executable, "-c", "import perception, pandas, scipy.signal"])
        wall, peak = _peak([*HAMMER, "landmarks", str(big), "--rate", RATE, "-o",
                            str(work / "out.csv"), "--quiet"])
        target = MEMORY_TARGET * big.stat().st_size
        table(f"motion capture: landmarks of a {rows:,}-row table ({n:,} trials, {mb:.0f} MB)", [
            ("landmarks, wall time", f"{wall:.1f} s", "target <= 60 s",
             "ok" if wall <= 60 else "MISSED"),
            ("landmarks, peak memory", f"{peak / 1e6:.0f} MB ({peak / big.stat().st_size:.1f}x "
             "the file)", f"target <= {MEMORY_TARGET}x the file, {target / 1e6:.0f} MB; floor "
             f"(imports alone) {floor / 1e6:.0f} MB", "ok" if peak <= target else "MISSED"),
        ])
    finally:
        shutil.rmtree(work, ignore_errors=True)


PARTS = {"scoring": scoring, "size": size}


def main(argv: list[str] | None = None) -> None:
    """Run the parts named (default: all)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=sorted(PARTS), help="parts to run")
    for name in parser.parse_args(argv).only or list(PARTS):
        PARTS[name]()


if __name__ == "__main__":
    sys.exit(main())

"""The device kit's benchmark parts (issue 45), one table each, sized for one call.

``run.sh`` runs each part in its own process under ``timeout``, so that a part that
overruns or fails costs only itself. Each part is the benchmark tool's own code
(``tools/bench_recognition.py``, ``tools/bench_online.py``, ``tools/bench_mocap.py``)
at the sizes given here, through their own flags.

Run: ``python3 tools/device/parts.py PART [options]`` from anywhere; ``--help`` lists
the parts. ``--markdown FILE`` appends the part's tables to FILE.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT), str(ROOT / "tools"), str(ROOT / "tests")]

import bench  # noqa: E402  (one BLAS/OpenMP thread before numpy loads, as bench.py runs)


def _cores() -> int:
    """The cores this process may use (a container's share, not the host's)."""
    return (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
            else os.cpu_count() or 1)


def scaling(args) -> None:
    """``bench_recognition.py``'s scaling run: ``--clips`` clips at 1 process and at
    every core, the N one-process batches side by side, a dask cluster of N
    single-threaded workers; one round (targets: N processes >= 90 % of N x one,
    dask >= 95 % of N local, every summary identical)."""
    import bench_recognition

    bench_recognition.main(["--rounds", "1", "--clips", str(args.clips),
                            "--counts", str(_cores())])


def phases(args) -> None:
    """``bench_recognition.py --only phases``: where a motion-capture batch with figures
    and report spends its time (issue 45 item 1), a ``--trials`` table at each of
    ``--counts`` processes against one process on a ``--base-trials`` table (the issue's
    own baseline, "the 60-trial rate"; target >= 90 % at 16)."""
    import bench_recognition

    bench_recognition.main(["--only", "phases", "--rounds", "1", "--trials", str(args.trials),
                            "--base-trials", str(args.base_trials), "--counts", args.counts])


def study(args) -> None:
    """``bench_recognition.py --only study``: ``--participants`` x ``--study-trials``
    trials through ``hammer-mv batch --jobs`` (every core), with a tenth of the
    participants for the memory a trial (target: 10,000 trials <= 120 s at 16)."""
    import bench_recognition

    bench_recognition.main(["--only", "study", "--participants", str(args.participants),
                            "--study-trials", str(args.study_trials)])


def online(args) -> None:
    """``bench.py --only online`` (``bench_online.py``), its sizes as given (defaults:
    the tool's: 6 clips x 3 runs, a 30 s stream fed 3 times; targets: median <= 2 ms,
    p99 <= 10 ms, the stream's trend within +-5 % in each run)."""
    import bench_online

    bench_online.main(["--clips", str(args.videos), "--runs", "3", "--stream",
                       str(args.stream), "--stream-runs", "3"])


def mocap(_args) -> None:
    """``bench_mocap.py --only scoring``: the 60-trial table by ``recognize`` and by
    ``batch --jobs 2`` and ``--jobs 1`` with figures and report (target <= 15 s at
    ``--jobs 1``), and a clip's figures (target <= 0.3 s)."""
    import bench_mocap

    bench_mocap.main(["--only", "scoring"])


PARTS = {"scaling": scaling, "phases": phases, "study": study, "online": online,
         "mocap": mocap}


def main(argv: list[str] | None = None) -> int:
    """Run one part; print its tables, and append them to ``--markdown``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("part", choices=sorted(PARTS))
    parser.add_argument("--clips", type=int, default=120,
                        help="scaling: rendered clips (120)")
    parser.add_argument("--videos", type=int, default=6,
                        help="online: clips of 90 frames a run (6)")
    parser.add_argument("--trials", type=int, default=600,
                        help="phases: trials of the table timed at --counts (600)")
    parser.add_argument("--base-trials", type=int, default=60,
                        help="phases: trials of the one-process baseline (60)")
    parser.add_argument("--counts", default="4,8,16",
                        help="phases: process counts (4,8,16; capped at the cores)")
    parser.add_argument("--participants", type=int, default=100, help="study (100)")
    parser.add_argument("--study-trials", type=int, default=100, help="study (100)")
    parser.add_argument("--stream", type=float, default=30.0, help="online: stream, s (30)")
    parser.add_argument("--markdown", type=Path, help="file the part's tables are appended to")
    args = parser.parse_args(argv)
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"part {args.part}: {_cores()} cores, load average {load}", flush=True)
    t0 = time.perf_counter()
    PARTS[args.part](args)
    print(f"\npart {args.part}: {time.perf_counter() - t0:.0f} s", flush=True)
    if args.markdown is not None:
        with args.markdown.open("a") as md:
            md.write("\n".join(bench.TABLES) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Benchmark: a 60-trial motion-capture table scored end to end, with a same-run baseline.

Run ``python tools/bench_mocap.py`` or ``make bench`` (``tools/bench.py``
picks up this module's ``main`` as the ``mocap`` section). Prints, asserts
nothing. The table is made from the four real Optotrak trials shipped in
``tests/data/mocap/`` repeated 15 times (60 trials, 85 Hz, no time column),
so it needs nothing outside the repository.

* ``hammer-mv recognize TABLE --no-figures``: every reach read, cleaned,
  found and scored in one process (target: 60 trials in 60 s or less on 2
  cores);
* ``hammer-mv batch`` of a folder holding the table, ``--jobs 2`` and
  ``--jobs 1``, with every figure and the batch report (issue 45: at most
  20 s at ``--jobs 2`` on 2 cores; at most 15 s at ``--jobs 1`` on a quiet
  16-core machine, judged here by the process's CPU time);
* a clip's figures (confidence, paths, kinematics: a motion-capture trial
  has no contact sheet, a video's fourth), drawn and saved as the clip
  report draws them, CPU time per trial, median over the shipped trials,
  against the same figures drawn the old way in the same run (a new figure
  on matplotlib's own canvas per figure, saved by ``savefig``; target 0.3 s);
* baseline: one trial of the same table, ``recognize --no-figures``, whole
  process (60 times it is what scoring trial by trial would cost).

The ``trial`` part (issue 45's 10,000-trial study: what one trial costs a batch)
runs the table's trials through the batch's own per-trial path in one warm
process (``--jobs 1``), each also without its figures in turn: CPU a trial,
every thread and the batch's thread alone. ``trial-instructions`` counts the
instructions a trial (``valgrind --tool=callgrind``, instrumentation on only
while the trials run; not in the default run: it needs valgrind and takes
minutes).

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
import statistics
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
        batch = {}
        for jobs in (2, 1):
            batch[jobs] = _timed([*HAMMER, "batch", str(folder), "--rate", RATE, "-o",
                                  str(out), "--jobs", str(jobs), "--quiet"], repeat=1)
            shutil.rmtree(out)  # a second run would reuse every report
        new, old = clip_figures(work / "figures")
        table(f"motion capture: a {n}-trial table (85 Hz, real grasps)", [
            (f"recognize, {n} trials, no figures", f"{wall:.1f} s (CPU {cpu:.1f} s)",
             f"target <= 60 s; one trial {base_wall:.2f} s x {n} = {base_wall * n:.0f} s",
             "ok" if wall <= 60 else "MISSED"),
            # the workers' CPU is not the parent's (forkserver's children): not shown
            (f"batch --jobs 2, {n} trials, figures and report", f"{batch[2][0]:.1f} s",
             "target <= 20 s (2 cores)",
             "ok" if batch[2][0] <= 20 else "MISSED"),
            (f"batch --jobs 1, {n} trials, figures and report", f"{batch[1][0]:.1f} s "
             f"(CPU {batch[1][1]:.1f} s)", "target <= 15 s on a quiet 16-core machine; "
             "here its CPU time", "ok" if batch[1][1] <= 15 else "MISSED"),
            ("a clip's figures (3: confidence, paths, kinematics)", f"{new:.3f} s CPU",
             f"target <= 0.3 s; drawn the old way in the same run {old:.3f} s "
             f"({old / new:.1f}x)", "ok" if new <= 0.3 else "MISSED"),
        ])
    finally:
        shutil.rmtree(work, ignore_errors=True)


def clip_figures(folder: Path, rounds: int = 3) -> tuple[float, float]:
    """CPU time, s, to draw and save one trial's three figures: median over the shipped
    trials (``rounds`` times each), as the clip report draws them and the old way.

    The two ways alternate trial by trial, each after one trial drawn to warm it.
    The old way: each figure new, on matplotlib's own Agg canvas, saved by
    ``savefig`` (Pillow's PNG); the report's: the process's kept figure of each
    kind, its string masks and :func:`~perception.report.canvas.png_bytes`.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from perception import Repertoire
    from perception.recordings import MocapImport, read_reaches, recognize_reach
    from perception.report.figures import DPI, confidence_figure, paths_figure, write_figure
    from perception.report.kinematics import kinematics_figure

    rep = Repertoire.default()
    recs = [recognize_reach(r, rep)[0] for r in read_reaches(SOURCE, MocapImport(rate=85))]
    kinds = {"confidence": confidence_figure, "paths": paths_figure,
             "kinematics": kinematics_figure}
    folder.mkdir(parents=True, exist_ok=True)

    def report(rec) -> None:
        for kind, draw in kinds.items():
            write_figure(draw(rec, reuse=True), folder / f"{rec.clip}.{kind}", "png", DPI)

    def old(rec) -> None:
        for kind, draw in kinds.items():
            fig = draw(rec)
            FigureCanvasAgg(fig)
            fig.savefig(folder / f"{rec.clip}.{kind}.old.png", dpi=DPI)

    times: dict = {report: [], old: []}
    for way in times:
        way(recs[0])  # imports, fonts, the first kept figures
    for _ in range(rounds):
        for rec in recs:
            for way, spent in times.items():
                t0 = time.process_time()
                way(rec)
                spent.append(time.process_time() - t0)
    return statistics.median(times[report]), statistics.median(times[old])


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


def trial_runs(trials: int = 24, warm: int = 4, work: Path | None = None,
               figures_off: bool = True, toggle=None) -> dict[str, list[float]]:
    """CPU time of each motion-capture trial as a batch runs it in one process, warm.

    The 60-trial table's reaches go through the batch's own per-trial path
    (``_Job.run``: recognition, the clip report, its figures), one process,
    after ``warm`` trials (imports, fonts, the kept figures). With
    ``figures_off`` each trial is also recognised and reported without its
    figures, in turn with the other (the same-run baseline). ``toggle(on)``
    (callgrind's instrumentation) is called around the measured trials.

    Returns
    -------
    dict
        ``process``: the process's CPU a trial (every thread: the PNG
        encoding's too), s; ``caller``: this thread's; ``no figures``: the
        process's without figures (empty without ``figures_off``).
    """
    from perception import Repertoire
    from perception.batch import _Job, _Work
    from perception.discovery import BatchItem
    from perception.pipeline import RecognitionSettings
    from perception.recordings import MocapImport, read_reaches, recognize_reach
    from perception.report.clip import write_clip_report

    work = Path(tempfile.mkdtemp(prefix="bench-mocap-trial-")) if work is None else work
    try:
        table_path = work / "trials.tsv"
        make_table(table_path)
        settings = RecognitionSettings(mocap=MocapImport(rate=float(RATE)))
        repertoire = Repertoire.default()
        reaches = read_reaches(table_path, settings.mocap)
        job = _Job(work / "report", settings, "bench")
        job.out.mkdir()
        items = [_Work(BatchItem(r.name, table_path, "mocap", reach=k), r)
                 for k, r in enumerate(reaches)]
        items = (items * (1 + (warm + trials) // len(items)))[:warm + trials]

        def bare(w: _Work) -> None:  # recognised and reported, no figures
            rec, info = recognize_reach(w.reach, repertoire, settings, settings.mocap,
                                        plan_cache=job.plan_cache)
            write_clip_report(rec, work / "bare", extra={"mocap": info}, figures=False)

        for w in items[:warm]:
            job.run(w, repertoire)
            if figures_off:
                bare(w)
        spent: dict[str, list[float]] = {"process": [], "caller": [], "no figures": []}
        if toggle is not None:
            toggle(True)
        for w in items[warm:]:
            t0, c0 = time.process_time(), time.thread_time()
            result = job.run(w, repertoire)
            spent["process"].append(time.process_time() - t0)
            spent["caller"].append(time.thread_time() - c0)
            if result.status != "ok":
                raise RuntimeError(f"{w.item.clip}: {result.status} {result.error}")
            if figures_off:
                t0 = time.process_time()
                bare(w)
                spent["no figures"].append(time.process_time() - t0)
        if toggle is not None:
            toggle(False)
        return spent
    finally:
        shutil.rmtree(work, ignore_errors=True)


def trial(trials: int = 24) -> None:
    """A motion-capture trial's CPU in a batch (``--jobs 1``, warm), with and without its
    figures in the same run."""
    spent = trial_runs(trials)
    per = {k: 1000 * statistics.mean(v) for k, v in spent.items()}
    mid = {k: 1000 * statistics.median(v) for k, v in spent.items()}
    table(f"motion capture: a trial in a batch, CPU (one warm process, {trials} trials)", [
        ("a trial: recognised, reported, figures", f"{per['process']:.0f} ms "
         f"(median {mid['process']:.0f})", "every thread (PNG encoding too); issue 45: "
         "10,000 trials in 2 min on 16 cores needs about 0.17 s", ""),
        ("the same, the batch's thread alone", f"{per['caller']:.0f} ms "
         f"(median {mid['caller']:.0f})", "drawing, files; the rest is PNG encoding "
         "in its own thread", ""),
        ("the same trial without figures", f"{per['no figures']:.0f} ms "
         f"(median {mid['no figures']:.0f})", "same run, in turn: recognition, CSV, JSON",
         ""),
    ])


def trial_instructions(trials: int = 6) -> None:
    """Instructions a trial (callgrind, every thread): the trials of :func:`trial_runs`
    in a process under valgrind, counted only while they run."""
    if shutil.which("valgrind") is None:
        print("trial-instructions: needs valgrind (callgrind)")
        return
    with tempfile.TemporaryDirectory(prefix="bench-mocap-cg-") as folder:
        out = Path(folder) / "callgrind.out"
        done = subprocess.run(
            ["valgrind", "--tool=callgrind", "--instr-atstart=no",
             f"--callgrind-out-file={out}", sys.executable, __file__, "--counted",
             str(trials)], capture_output=True, text=True, cwd=ROOT)
        counted = [int(line.split()[-1].replace(",", "")) for line in done.stderr.splitlines()
                   if "Collected :" in line]
        if done.returncode or not counted:
            print(done.stderr[-2000:])
            raise RuntimeError("callgrind run failed")
    table(f"motion capture: a trial in a batch, instructions (callgrind, {trials} trials)", [
        ("a trial: recognised, reported, figures", f"{counted[0] / trials / 1e6:.0f} million",
         "every thread, warm process (valgrind --tool=callgrind)", ""),
    ])


def _counted(trials: int) -> None:
    """Inside valgrind: run the trials, instrumentation on only while they run."""
    def toggle(on: bool) -> None:
        subprocess.run(["callgrind_control", "-i", "on" if on else "off", str(os.getpid())],
                       check=True, stdout=subprocess.DEVNULL)

    trial_runs(trials, warm=3, figures_off=False, toggle=toggle)


PARTS = {"scoring": scoring, "size": size, "trial": trial,
         "trial-instructions": trial_instructions}


def main(argv: list[str] | None = None) -> None:
    """Run the parts named (default: all)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=sorted(PARTS), help="parts to run "
                        "(default: all but trial-instructions, which needs valgrind)")
    parser.add_argument("--counted", type=int, metavar="N", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.counted:  # trial-instructions' own process, under valgrind
        return _counted(args.counted)
    for name in args.only or [p for p in PARTS if p != "trial-instructions"]:
        PARTS[name]()


if __name__ == "__main__":
    sys.exit(main())

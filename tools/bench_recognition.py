"""Recognition benchmarks: one clip against a repertoire, and how batches scale.

Targets (issues: HAMMER-MV recognition; 11, speed; 45, sixteen cores):
recognising one 1 s clip's tracks against a built repertoire of >= 10
models <= 50 ms; batch parallel efficiency (throughput with N processes / N
x throughput with 1) >= 90 % (issue 45: at 16 processes); a dask cluster of
N single-threaded workers >= 95 % of N local processes; ``synth --jobs N``
against one process. The same-run baselines are the one-process figures,
and for each N the throughput of N independent one-process batches side by
side: how far the machine itself lets N single-threaded processes scale,
which no way of sharing the clips can beat. ``--clips`` and ``--counts``
size the scaling run (``tools/device/run.sh`` measures 1 and 16 processes
in one call).

The ``study`` part (issue 45; ``--only study``; ``tools/study_memory.py``) writes
the shipped Optotrak trials as a lab's study, ``--participants`` x ``--study-trials`` (100 x 100 =
10,000 trials by default), one file per participant with a ``participant``
and a ``condition`` column, runs ``hammer-mv batch`` of it with its figures
and report at ``--jobs``, and prints the wall time, trials/s, the peak
resident memory of the whole process tree and of the batch's own process
(psutil, sampled every 0.1 s), and what the batch's own process holds per
trial: its peak over that of the same study with a tenth of the participants,
per trial more, against the targets (10,000 trials in 2 minutes at ``--jobs
16``; memory a trial small and the same at any size). With ``--traced`` the
batch's own process runs under tracemalloc (slower: for small studies) and
the table adds what it held when the clips were in and its peaks, while the
clips ran, in the report and over the run, a trial more: Python's and
numpy's allocations, without the allocator's noise.

``--only report-reads`` times the batch report's reads of a kept clip: a whole
summary (unpickled) and its curves alone (``KeptSummaries.curves``), µs of thread
CPU a clip and pass (``--trials``: the clips kept, 600 by default).
"""

from __future__ import annotations

import dataclasses
import math
import os
import resource
import shutil
import sys
import tempfile
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from bench import table, timeit  # noqa: E402

#: Clips in the scaling runs per core, at least 40 (the conditions in turn; the
#: smoke recipe's look): enough that every process gets several, so that the
#: figure is throughput rather than start-up.
CLIPS_PER_CORE = 8
#: Runs of each batch configuration; the best counts.
ROUNDS = 5


def _counts(cores: int, total: int | None = None) -> dict[str, int]:
    """Clips of each condition for a machine of ``cores`` cores (``total`` in all if given)."""
    total = total or max(40, CLIPS_PER_CORE * cores)
    names = ("normal", "delayed", "open-close-open")
    return {c: total // 3 + (i < total % 3) for i, c in enumerate(names)}


def _worker_counts(cores: int, asked: str | None = None) -> list[int]:
    """1, 2, 4, ... and every core: the process counts a batch is timed with; ``asked``
    (``"8,16"``) names them instead (1, the baseline, always among them)."""
    if asked:
        return sorted({1, *(min(int(c), cores) for c in asked.split(","))})
    counts, n = {1, cores}, 2
    while n < cores:
        counts.add(n)
        n *= 2
    return sorted(counts)


def _cpu_s() -> float:
    """CPU time of this process so far (all its threads), s."""
    use = resource.getrusage(resource.RUSAGE_SELF)
    return use.ru_utime + use.ru_stime


def _batch(items, out: Path, rep, **kwargs):
    """Wall time (s), summary and this process's CPU time (s; its workers' not
    included) of one batch run."""
    from perception.batch import run_batch

    shutil.rmtree(out, ignore_errors=True)
    t0, c0 = time.perf_counter(), _cpu_s()
    summary = run_batch(items, out, rep, quiet=True, **kwargs)
    elapsed = time.perf_counter() - t0
    assert (summary["status"] == "ok").all(), summary[summary["status"] != "ok"]
    return elapsed, summary, _cpu_s() - c0


def _alone(items, out: Path, rep, ready, results) -> None:
    """One of :func:`_side_by_side`'s processes: a one-process batch, as a worker runs."""
    import cv2
    import pandas  # noqa: F401  (the report's imports: a batch's main process has them)
    import scipy.special  # noqa: F401
    from threadpoolctl import threadpool_limits

    from perception.pipeline import RecognitionSettings

    # as a batch's worker process runs (perception.workers.init_worker, and the
    # settings a batch gives its workers)
    cv2.setNumThreads(1)
    threadpool_limits(1)
    ready.wait(timeout=300)  # a sibling that died before it would otherwise hang us
    t0 = time.perf_counter()
    _batch(items, out, rep, settings=RecognitionSettings(decoder_threads=1, planning_threads=1))
    results.put((t0, time.perf_counter()))


def _side_by_side(items, out: Path, rep, processes: int) -> float:
    """Wall time of ``processes`` independent one-process batches that share the clips
    and start together: what the machine itself allows N single-threaded processes,
    with no work shared between them (the ceiling of a batch's efficiency).

    Each starts and imports before the clock does; the clock runs from the
    first start to the last finish (perf_counter is system-wide on Linux).
    """
    import multiprocessing

    from perception.batch import _file_size

    ctx = multiprocessing.get_context("spawn")  # one BLAS thread: bench.py's environment
    ready, results = ctx.Barrier(processes), ctx.Queue()
    # largest first, dealt in turn, so that each gets as much work
    ranked = sorted(items, key=_file_size, reverse=True)
    procs = [ctx.Process(target=_alone, args=(ranked[k::processes], out / f"alone{k}",
                                              rep, ready, results))
             for k in range(processes)]
    for proc in procs:
        proc.start()
    for proc in procs:  # each puts two floats: the pipe holds them while it exits
        proc.join()
    failed = [k for k, proc in enumerate(procs) if proc.exitcode != 0]
    if failed:
        raise RuntimeError(f"one-process batches {failed} failed (their tracebacks above)")
    spans = [results.get(timeout=10) for _ in procs]
    return max(end for _, end in spans) - min(start for start, _ in spans)


def _dask(items, out: Path, rep, workers: int):
    """Wall times of a batch on a new cluster and of the next batch on it, and the summary.

    The workers start before the clock does (local workers start within
    it), from nannies set as docs/recognition.md tells a cluster's owner
    (``tools/bench_cluster.py --only parity`` also times dask's default
    nannies, whose workers map every frame afresh: a clip a third to a half
    slower). A new cluster's workers then import the package and warm up
    during the first batch (0.7 s each); a running cluster's have done so,
    as the calling process of a local batch has.
    """
    import dask
    import distributed  # noqa: F401 - its configuration's defaults
    from bench_cluster import WORKER_ENVIRON, _cluster

    documented = {**dask.config.get("distributed.nanny.pre-spawn-environ"), **WORKER_ENVIRON}
    with _cluster(workers, documented) as cluster:
        first, _, _ = _batch(items, out, rep, scheduler=cluster.scheduler_address)
        again, summary, _ = _batch(items, out, rep, scheduler=cluster.scheduler_address)
    return first, again, summary


def _per_clip(rep, demo_tracks) -> tuple[str, str, str, str]:
    """CPU per clip of ``recognize_tracks`` (observe, bring to the reference scale, plan,
    score, judge) over 12 clips of 4 conditions and 3 scenes, the repertoire's plans for
    each scene made in the run."""
    from perception.pipeline import recognize_tracks

    clips = [demo_tracks(c, k, distance=d, fps=f)[0]
             for k, (c, (d, f)) in enumerate((c, s) for c in ("normal", "delayed",
                                                              "open-close-open", "reach")
                                             for s in ((0.22, 30.0), (0.3, 25.0), (0.35, 60.0)))]
    fresh = type(rep)(list(rep.models))  # no plans cached from earlier sections
    t0 = time.process_time()
    for tracks in clips:
        recognize_tracks(tracks, fresh).to_dict()
    per_clip = (time.process_time() - t0) / len(clips)
    return (f"recognize_tracks, {len(clips)} clips of 3 scenes: CPU per clip",
            f"{per_clip * 1e3:.0f} ms", "each scene's plans made in the run",
            "(issue 42: 83-92 ms before one pass)")


def _phases(summary, jobs: int, wall: float) -> tuple[str, str, str, str]:
    """One row of the phase table: where a batch of ``jobs`` processes spent ``wall`` s.

    From ``run_batch``'s ``attrs["timing"]``: reading the input, the clips
    (handed out to the last result) and the report; within the clips, each
    worker's start-up (the clips' start to its first clip: imports, the
    repertoire), its idle time between clips (hand-offs) and at the end
    (waiting for the last clips), and the busy share (every clip's time
    over the clips phase x processes).
    """
    import numpy as np

    timing = summary.attrs["timing"]
    runs = timing["runs"][~np.isnan(timing["runs"][:, 0])]
    clip_start = runs[:, 1].min()
    busy = (runs[:, 2] - runs[:, 1]).sum()
    start_up, between, tail = [], 0.0, []
    clip_end = runs[:, 2].max()
    for pid in np.unique(runs[:, 0]):
        mine = runs[runs[:, 0] == pid]
        mine = mine[np.argsort(mine[:, 1])]
        start_up.append(mine[0, 1] - clip_start)
        between += (mine[1:, 1] - mine[:-1, 2]).sum()
        tail.append(clip_end - mine[-1, 2])
    span = clip_end - clip_start
    cpu = runs[:, 3].sum()
    return (f"  {jobs} process{'es' * (jobs > 1)}: {wall:.1f} s",
            f"read {timing['read']:.1f} s, clips {timing['clips']:.1f} s, "
            f"report {timing['report']:.1f} s",
            f"busy {busy / (span * jobs):.0%} (CPU {cpu / busy:.0%} of it); start-up "
            f"{float(np.median(start_up)):.2f} s, between clips {between / len(runs) * 1e3:.0f} "
            f"ms/clip, idle at the end {float(np.mean(tail)):.1f} s", "")


def phase_rows(cores: int, rounds: int = 1, trials: int = 600, counts: str | None = None,
               base_trials: int | None = None) -> list[tuple[str, str, str, str]]:
    """Where a batch's time goes at 1, 2, 4, ... processes (issue 45 item 1; ``counts``,
    e.g. ``"8,16"``, names them): a ``trials``-trial motion-capture table (the shipped
    Optotrak trials repeated) with its figures and report. The best of ``rounds`` runs
    of each. The efficiency is against one process on the same table, or on a
    ``base_trials``-trial table (the issue's own baseline, "the 60-trial rate": a 600-trial
    table at one process alone takes minutes)."""
    from bench_mocap import RATE, make_table

    from perception.batch import discover, run_batch
    from perception.pipeline import RecognitionSettings
    from perception.recognition.repertoire import Repertoire
    from perception.recordings import MocapImport, _cached

    work = Path(tempfile.mkdtemp(prefix="hammer-bench-phases-"))
    rows = []
    try:
        rep = Repertoire.default()
        settings = RecognitionSettings(mocap=MocapImport(rate=float(RATE)))
        tables = {}

        def table_of(size: int):
            if size not in tables:
                (work / f"session{size}").mkdir()
                n = make_table(work / f"session{size}" / "trials.tsv", copies=max(1, size // 4))
                tables[size] = n, discover(work / f"session{size}")
            return tables[size]

        base = None
        for jobs in _worker_counts(cores, counts):
            n, items = table_of(base_trials if jobs == 1 and base_trials else trials)
            best = None
            for _ in range(rounds):
                shutil.rmtree(work / "out", ignore_errors=True)
                _cached.cache_clear()  # the table read in each run, as by a new command
                t0 = time.perf_counter()
                summary = run_batch(items, work / "out", rep, settings, jobs=jobs, quiet=True)
                wall = time.perf_counter() - t0
                if best is None or wall < best[0]:
                    best = wall, summary
            wall, summary = best
            what, *rest = _phases(summary, jobs, wall)
            rows.append((f"{what} ({n} trials)", *rest))
            print(*rows[-1], sep="  ", flush=True)  # a run cut short still says the last
            if base is None:
                base = n / wall
                continue
            eff = n / wall / (jobs * base)
            rows.append(("", f"efficiency {eff:.0%}", "of as many times one process's rate; "
                         "target >= 90 % at 16", ("ok" if eff >= 0.9 else "MISSED")
                         if jobs >= 16 else ""))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return [("phases of motion-capture batches with figures (the shipped Optotrak trials "
             "repeated)", "", "", ""), *rows]


def report_reads_rows(trials: int = 400, rounds: int = 15) -> list[tuple[str, str, str, str]]:
    """The batch report's reads of a kept clip (:class:`~perception.batch_clip.ModelRows`):
    a whole summary, and its time, aperture and the reference model's curves alone
    (:meth:`~perception.batch_clip.KeptSummaries.curves`); thread CPU a clip and pass,
    fastest and median of ``rounds`` passes over ``trials`` real Optotrak trials' summaries
    (the shipped four, recognised, kept under new names in turn)."""
    import statistics

    from bench_mocap import SOURCE

    from perception.batch_clip import ClipResult, ModelRows
    from perception.recognition.repertoire import Repertoire
    from perception.recordings import MocapImport, read_reaches, recognize_reach
    from perception.report.clip import ClipSummary

    rep = Repertoire.default()
    shipped = [ClipSummary.from_recognition(recognize_reach(r, rep)[0])
               for r in read_reaches(SOURCE, MocapImport(rate=85))]
    model = shipped[0].reference_model
    spent: dict[str, list[float]] = {"whole": [], "curves": []}
    with tempfile.TemporaryDirectory() as folder, ModelRows(Path(folder)) as rows:
        kept = [rows.keep(ClipResult(f"t{k}", None, "ok", summary=dataclasses.replace(
            shipped[k % len(shipped)], clip=f"t{k}"))).summary for k in range(trials)]
        whole = rows.summaries(kept, model)
        reads = {"whole": whole, "curves": whole.curves(model)}
        for _ in range(rounds):
            for kind, clips in reads.items():
                t0 = time.thread_time()
                for clip in clips:
                    clips[clip]
                spent[kind].append((time.thread_time() - t0) / trials * 1e6)
    return [(f"report: a kept clip read back, {what}", f"{min(spent[kind]):.0f} µs",
             f"median {statistics.median(spent[kind]):.0f} µs a clip and pass ({trials} "
             f"trials, {rounds} passes); {note}", "")
            for kind, what, note in (
                ("whole", "whole", "six of the report's twelve passes"),
                ("curves", "its curves alone", "the other six: profiles, typical clips, "
                 "every clip's confidence"))]


def main(argv: list[str] | None = None) -> None:
    """Print the recognition and scaling figures."""
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=ROUNDS,
                        help=f"runs of each batch configuration, the best counts ({ROUNDS})")
    parser.add_argument("--only", choices=("phases", "study", "report-reads"),
                        help="only the phase table of a motion-capture batch, only the "
                        "study, or only the report's reads of a kept clip")
    parser.add_argument("--trials", type=int, default=600,
                        help="trials of the phase table's table (600)")
    parser.add_argument("--participants", type=int, default=100,
                        help="the study's participants (100)")
    parser.add_argument("--study-trials", type=int, default=100,
                        help="the study's trials per participant (100)")
    parser.add_argument("--jobs", type=int, default=None,
                        help="the study's batch's worker processes (default: every core)")
    parser.add_argument("--clips", type=int, default=None,
                        help="the scaling run's clips (default: 8 a core, 40 at least)")
    parser.add_argument("--counts", default=None, metavar="N,N",
                        help="process counts of the scaling run and the phase table, e.g. "
                        "8,16 (default: 1, 2, 4, ... and every core; 1, the baseline, always)")
    parser.add_argument("--base-trials", type=int, default=None,
                        help="the phase table's one-process baseline on a table of this many "
                        "trials (default: the same table as the others)")
    parser.add_argument("--conditions", type=int, default=2,
                        help="the study's conditions, taking turns trial by trial (2; 0: no "
                        "condition column)")
    parser.add_argument("--traced", action="store_true",
                        help="the study's batch process under tracemalloc (slower): what it "
                        "holds and its peaks, a trial more")
    args = parser.parse_args(argv)
    rounds = args.rounds
    cores = (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
             else os.cpu_count() or 1)
    if args.only == "study":
        from study_memory import study_rows

        jobs = args.jobs or cores
        table(f"perception: a lab's study through batch ({cores} cores)",
              study_rows(args.participants, args.study_trials, jobs, args.conditions,
                         args.traced))
        return
    if args.only == "report-reads":
        table("perception: the batch report's reads of a clip (thread CPU)",
              report_reads_rows(args.trials))
        return
    if args.only == "phases":
        table(f"perception: where a batch's time goes ({cores} cores)",
              phase_rows(cores, min(rounds, 2), args.trials, args.counts, args.base_trials))
        return
    from _demos import demo_tracks

    from perception.batch import discover
    from perception.observation import observe
    from perception.recognition.engine import recognize
    from perception.recognition.repertoire import Repertoire, SceneSpec
    from perception.synthetic.recipes import load_recipe, synthesize

    rep = Repertoire.build(scene=SceneSpec())
    obs = observe(demo_tracks("normal", 0)[0])
    all_at_once = timeit(lambda: recognize(obs, rep))
    one_by_one = timeit(lambda: [recognize(obs, [m]) for m in rep.models], repeat=3)
    rows = [
        (f"recognise a 1 s clip ({obs.n_frames} frames) vs {len(rep)} models",
         f"{all_at_once * 1e3:.1f} ms",
         f"target <= 50 ms; model by model {one_by_one * 1e3:.0f} ms",
         "ok" if all_at_once <= 0.05 else "MISSED"),
        _per_clip(rep, demo_tracks),
    ]

    # the cores this process may use (a container's share, not the host's)
    cores = (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
             else os.cpu_count() or 1)
    work = Path(tempfile.mkdtemp(prefix="hammer-bench-"))
    try:
        recipe = dataclasses.replace(load_recipe(ROOT / "datasets" / "smoke.toml"),
                                     counts=_counts(cores, args.clips))
        t0 = time.perf_counter()
        synthesize(recipe, work / "clips1", seed=0)
        synth1 = time.perf_counter() - t0
        t0 = time.perf_counter()
        synthesize(recipe, work / "clips", seed=0, jobs=cores)
        synthn = time.perf_counter() - t0
        rows.append((f"synth {recipe.n_clips} clips, --jobs {cores}", f"{synthn:.1f} s",
                     f"--jobs 1 {synth1:.1f} s", f"{synth1 / synthn:.2f}x"))
        items = discover(work / "clips")
        n = len(items)
        counts = _worker_counts(cores, args.counts)
        workers = counts[-1]  # dask's, against as many local processes
        times, summaries = {}, {}
        # Best of ROUNDS, the configurations taking turns: on a shared machine
        # a run's speed drifts by 20 % within seconds, and the best time is
        # the one least disturbed by other work (as timeit takes).
        cores_used = []  # by the one process: it decodes on other threads
        ceiling = {}  # process count: wall time of as many one-process batches side by side
        for _ in range(rounds):
            for jobs in counts:
                elapsed, summaries[jobs], cpu = _batch(items, work / f"out{jobs}", rep,
                                                       jobs=jobs)
                times[jobs] = min(times.get(jobs, elapsed), elapsed)
                if jobs > 1:
                    alone = _side_by_side(items, work / "alone", rep, jobs)
                    ceiling[jobs] = min(ceiling.get(jobs, alone), alone)
                if jobs == 1:
                    cores_used.append(cpu / elapsed)
            try:
                first, again, dask_summary = _dask(items, work / "dask", rep, workers)
            except Exception:  # noqa: BLE001 (no cluster: the local rows still count)
                traceback.print_exc()
                first = again = math.inf
                dask_summary = None
            times["dask"] = min(times.get("dask", again), again)
            times["dask, new"] = min(times.get("dask, new", first), first)
        base = n / times[1]
        used = sorted(cores_used)[len(cores_used) // 2]
        rows.append((f"batch: track + recognise + report {n} clips, 1 process",
                     f"{base:.1f} clips/s", f"the baseline (best of {rounds} runs each); it "
                     f"keeps {used:.2f} cores busy", ""))
        for jobs in sorted(k for k in times if isinstance(k, int)):
            if jobs == 1:
                continue
            eff = n / times[jobs] / (jobs * base)
            bound = n / ceiling[jobs] / (jobs * base)
            rows.append((f"  {jobs} processes", f"{n / times[jobs]:.1f} clips/s",
                         f"efficiency {eff:.0%} (target >= 90 %)",
                         "ok" if eff >= 0.9 else "MISSED"))
            rows.append((f"    {jobs} one-process batches side by side",
                         f"{n / ceiling[jobs]:.1f} clips/s",
                         f"{bound:.0%}: the machine's own limit (nothing shared)",
                         f"the batch gets {eff / bound:.0%} of it"))
        dask_time = times["dask"]
        ratio = times[workers] / dask_time
        rows.append((f"  dask, a running cluster of {workers} single-threaded workers "
                     "(nannies as docs/recognition.md says)", f"{n / dask_time:.1f} clips/s",
                     f"{ratio:.0%} of {workers} local processes (target >= 95 %)",
                     "ok" if ratio >= 0.95 else "MISSED"))
        cold = times[workers] / times["dask, new"]
        rows.append(("    its first batch (workers import and warm up)",
                     f"{n / times['dask, new']:.1f} clips/s",
                     f"{cold:.0%} of {workers} local processes", ""))
        if dask_summary is None:
            rows.append(("  dask", "FAILED", "the cluster did not start (above)", "MISSED"))
        same = all(s.equals(summaries[1]) for s in summaries.values()) and (
            dask_summary is None or dask_summary.equals(summaries[1]))
        rows.append(("  summaries of every run identical", "yes" if same else "NO",
                     "" if dask_summary is not None else "local runs only", ""))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    table(f"perception: HAMMER-MV recognition and scaling ({cores} cores)", rows)


if __name__ == "__main__":
    main()

"""Benchmarks of batches on dask: its workers against as many local processes, and
one clip's time on a dask worker by the environment dask's nanny started it with.

Run ``python tools/bench_cluster.py [--only parity|nanny]`` or ``make bench``
(``tools/bench.py`` picks up this module's ``main`` as the ``cluster``
section). Prints, asserts nothing. Needs the ``cluster`` extra (dask.distributed).

``parity`` (issue 45 item 2: dask within 95 % of local processes, the same
summaries): a batch of rendered clips (8 a core) and one of a
motion-capture table (30 trials a core: on 2 cores the shared 60-trial
Optotrak table where there is one, else the shipped trials repeated), each
run by ``--jobs N`` and by a running dask cluster of ``N`` single-threaded
worker processes (``LocalCluster``, its nannies dask's default or as
docs/recognition.md says, started and warmed by a clip a worker before the
clock, closed after), ``N`` the cores, taking turns for several rounds
(median clips/s). Each run's phase row says where its time went
(:func:`phase_row`); a clip's CPU time compares the workers' own cost.

``nanny``: dask's nanny starts a worker with ``distributed.nanny.pre-spawn-environ``,
whose default ``MALLOC_TRIM_THRESHOLD_=65536`` also fixes glibc's mmap
threshold at 128 KiB: every frame-sized array is then a fresh ``mmap`` and
page-faults in anew. The environment docs/recognition.md gives for the
workers (:data:`WORKER_ENVIRON`) keeps frames on the heap. Each row is the
median time per clip (tracked, planned, recognised, as a batch's worker
does) on a one-worker, one-thread cluster; the baseline is dask's default
environment, measured in the same run on the same clips.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import resource
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench import table  # noqa: E402

#: Rendered clips and motion-capture trials per core in the parity runs, and rounds of
#: each configuration.
PARITY_CLIPS_PER_CORE, PARITY_TRIALS_PER_CORE, PARITY_ROUNDS = 8, 30, 3
#: The shared 60-trial Optotrak table (85 Hz, no time column), where this machine has
#: it: the table of 2 cores (more cores: the shipped trials, repeated).
SHARED_TABLE = Path("/work/shared/realdata/optotrak-grasps/trials.tsv")

#: What docs/recognition.md tells a cluster's owner to give its nannies: glibc's
#: thresholds at what a plain process's dynamic ones grow to (mmap 32 MiB, trim 64 MiB).
WORKER_ENVIRON = {"MALLOC_MMAP_THRESHOLD_": "33554432", "MALLOC_TRIM_THRESHOLD_": "67108864"}
#: Clips timed per environment (after one untimed), and rounds over the environments.
CLIPS, ROUNDS = 4, 2


def _clip_times(videos: list[str], folder: str) -> tuple[list[float], int]:
    """On the worker: each clip recognised as a batch's worker does (s each), and the
    page faults they took."""
    from threadpoolctl import threadpool_limits

    from perception.pipeline import RecognitionSettings, recognize_clip
    from perception.recognition.repertoire import Repertoire

    threadpool_limits(1)
    settings = RecognitionSettings(decoder_threads=1, planning_threads=1)
    rep = Repertoire.default()
    times = []
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for i, video in enumerate(videos):
        out = Path(folder) / f"{i}.tracks.h5"
        t0 = time.perf_counter()
        recognize_clip(video, rep, settings, tracks_out=out)
        times.append(time.perf_counter() - t0)
        out.unlink()
    return times[1:], resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults


def _on_worker(videos: list[str], folder: str, environ: dict | None) -> tuple[list[float], int]:
    from dask.distributed import Client

    with _cluster(1, environ) as c, Client(c) as client:
        return client.submit(_clip_times, videos, folder, pure=False).result()


def nanny() -> None:
    """Print the time per clip under dask's default nanny environment and the documented one."""
    import dask
    import distributed  # noqa: F401 - its configuration's defaults

    from perception.synthetic.demos import render_demo_clip

    default = dict(dask.config.get("distributed.nanny.pre-spawn-environ"))
    documented = {**default, **WORKER_ENVIRON}
    work = Path(tempfile.mkdtemp(prefix="hammer-bench-cluster-"))
    try:
        videos = [str(render_demo_clip(work, f"c{i}.mp4", n=60, seed=i)[0].video)
                  for i in range(CLIPS + 1)]
        runs: dict[str, list[float]] = {"default": [], "documented": []}
        faults: dict[str, int] = {}
        for _ in range(ROUNDS):
            for name, environ in (("default", None), ("documented", documented)):
                times, faults[name] = _on_worker(videos, str(work), environ)
                runs[name] += times
    finally:
        shutil.rmtree(work, ignore_errors=True)
    base, ours = (statistics.median(runs[k]) for k in ("default", "documented"))
    table("dask worker started by the nanny: time per 2 s clip (median)", [
        (f"nanny environment of docs/recognition.md {WORKER_ENVIRON}", f"{ours:.3f} s",
         f"dask's default ({default}) {base:.3f} s", f"{base / ours:.2f}x faster"),
        ("  page faults per clip", f"{faults['documented'] / (CLIPS + 1):,.0f}",
         f"dask's default {faults['default'] / (CLIPS + 1):,.0f}", ""),
    ])


def phase_row(name: str, summary, t0: float, wall: float, workers: int
              ) -> tuple[str, str, str, str]:
    """Where one batch's ``wall`` s went, from its ``attrs["timing"]`` (``t0``: its
    ``perf_counter`` at the call).

    read: finding the clips and reading recordings before the first is handed
    out; clips: from then to the last result; report: the batch report after
    it. Per worker process: its start-up (the clips phase's start to its first
    clip), the gaps between its clips (the hand-offs: pickling, the scheduler,
    fetching results), its idle time at the end; busy: the clips' time over
    the clips phase x workers; a clip's median wall and CPU time (each
    process's first clip left out: it imports and plans).
    """
    import numpy as np

    timing = summary.attrs["timing"]
    runs = timing["runs"][~np.isnan(timing["runs"][:, 0])]
    begin, end = t0 + timing["read"], t0 + timing["read"] + timing["clips"]
    busy = (runs[:, 2] - runs[:, 1]).sum()
    start_up, between, tail, later = [], 0.0, [], []
    for pid in np.unique(runs[:, 0]):
        mine = runs[runs[:, 0] == pid]
        mine = mine[np.argsort(mine[:, 1])]
        start_up.append(mine[0, 1] - begin)
        between += (mine[1:, 1] - mine[:-1, 2]).sum()
        tail.append(end - mine[-1, 2])
        later.append(mine[1:])
    later = np.concatenate(later)
    return (f"    {name}: {wall:.1f} s",
            f"read {timing['read']:.2f} s, clips {timing['clips']:.1f} s, report "
            f"{timing['report']:.1f} s",
            f"busy {busy / (timing['clips'] * workers):.0%}; start-up "
            f"{float(np.median(start_up)):.2f} s, between clips "
            f"{between / len(runs) * 1e3:.0f} ms/clip, idle at the end "
            f"{float(np.mean(tail)):.2f} s; {len(np.unique(runs[:, 0]))} processes",
            f"a clip {np.median(later[:, 2] - later[:, 1]) * 1e3:.0f} ms, "
            f"CPU {np.median(later[:, 3]) * 1e3:.0f} ms")


def _cluster(workers: int, environ: dict | None):
    """A running LocalCluster of ``workers`` single-threaded worker processes, their
    nannies' environment dask's default or ``environ``."""
    import dask
    from dask.distributed import LocalCluster

    config = {} if environ is None else {"distributed.nanny.pre-spawn-environ": environ}
    before = dict(os.environ)  # the nanny sets its variables here, and prefers them next time
    try:
        with dask.config.set(config):
            return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                dashboard_address=None)
    finally:
        os.environ.clear()
        os.environ.update(before)


def _parity_sets(work: Path, cores: int):
    """(name, items, settings) of the parity runs: rendered clips, a motion-capture table."""
    import dataclasses

    from bench_mocap import RATE, make_table

    from perception.batch import discover
    from perception.recordings import MocapImport
    from perception.synthetic.recipes import load_recipe, synthesize

    total = max(16, PARITY_CLIPS_PER_CORE * cores)
    names = ("normal", "delayed", "open-close-open")
    recipe = dataclasses.replace(
        load_recipe(ROOT / "datasets" / "smoke.toml"),
        counts={c: total // 3 + (i < total % 3) for i, c in enumerate(names)})
    synthesize(recipe, work / "clips", seed=0, jobs=cores)
    (work / "mocap").mkdir()
    trials = max(60, PARITY_TRIALS_PER_CORE * cores)
    if trials == 60 and SHARED_TABLE.is_file():
        (work / "mocap" / "trials.tsv").symlink_to(SHARED_TABLE)
        what = "the shared Optotrak table"
    else:
        trials = make_table(work / "mocap" / "trials.tsv", copies=-(-trials // 4))
        what = f"the shipped Optotrak trials repeated ({trials})"
    return [(f"{recipe.n_clips} rendered clips", discover(work / "clips"), None),
            (what, discover(work / "mocap"), dict(mocap=MocapImport(rate=float(RATE))))]


def _timed_batch(items, out: Path, rep, settings, cores: int, environ, warm: list
                 ) -> tuple[float, object, float]:
    """Wall time, summary and clock start of one batch: ``--jobs cores`` (``environ``
    ``"local"``) or on a running cluster of ``cores`` workers whose nannies have
    ``environ`` (None: dask's default), started and warmed with the rendered clips
    ``warm`` before the clock (its workers have imported what a clip needs, as a
    running cluster's have), closed after: no idle cluster shares the cores with
    another run (two idle clusters of 2 workers took 0.17 of a core)."""
    from perception.batch import run_batch
    from perception.recordings import _cached

    shutil.rmtree(out, ignore_errors=True)
    with contextlib.ExitStack() as stack:
        if environ == "local":
            kind = dict(jobs=cores)
        else:
            cluster = stack.enter_context(_cluster(cores, environ))
            kind = dict(scheduler=cluster.scheduler_address)
            run_batch(warm, out, rep, quiet=True, **kind)
            shutil.rmtree(out)
        _cached.cache_clear()  # the table read in each run, as by a new command
        t0 = time.perf_counter()
        summary = run_batch(items, out, rep, settings, quiet=True, **kind)
        return time.perf_counter() - t0, summary, t0


def parity(rounds: int = PARITY_ROUNDS) -> None:
    """Print clips/s of ``--jobs N`` and of N dask workers, both sets, and their phases."""
    import statistics

    import dask
    import distributed  # noqa: F401 - its configuration's defaults

    from perception.pipeline import RecognitionSettings
    from perception.recognition.repertoire import Repertoire

    cores = (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
             else os.cpu_count() or 1)
    work = Path(tempfile.mkdtemp(prefix="hammer-bench-parity-"))
    rows = []
    documented = {**dask.config.get("distributed.nanny.pre-spawn-environ"), **WORKER_ENVIRON}
    kinds = {"local": "local", "dask": None, "dask, documented nannies": documented}
    try:
        sets = _parity_sets(work, cores)
        warm = sets[0][1][:cores]  # a rendered clip per worker
        rep = Repertoire.default()
        for name, items, settings in sets:
            settings = RecognitionSettings(**(settings or {}))
            walls: dict[str, list] = {k: [] for k in kinds}
            phases: dict[str, list] = {k: [] for k in kinds}
            summaries = {}
            order = list(kinds)
            for r in range(rounds):
                for kind in order[r % len(order):] + order[:r % len(order)]:  # turns
                    wall, summaries[kind], t0 = _timed_batch(
                        items, work / "out", rep, settings, cores, kinds[kind], warm)
                    walls[kind].append(wall)
                    phases[kind].append(phase_row(f"{kind}, round {r + 1}", summaries[kind],
                                                  t0, wall, cores))
            n = len(summaries["local"])
            med = {k: statistics.median(v) for k, v in walls.items()}
            rows.append((f"{name}: {n} clips, --jobs {cores}", f"{n / med['local']:.2f} clips/s",
                         f"median of {rounds}: "
                         f"{', '.join(f'{w:.1f}' for w in walls['local'])} s", ""))
            for kind in list(kinds)[1:]:
                ratio = med["local"] / med[kind]
                rows.append((f"  {kind}, {cores} single-thread workers",
                             f"{n / med[kind]:.2f} clips/s",
                             f"{ratio:.0%} of local (target >= 95 %); "
                             f"{', '.join(f'{w:.1f}' for w in walls[kind])} s",
                             "ok" if ratio >= 0.95 else "MISSED"))
            same = all(s.equals(summaries["local"]) for s in summaries.values())
            rows.append(("  summaries identical", "yes" if same else "NO", "", ""))
            for kind in kinds:
                rows += phases[kind]
    finally:
        shutil.rmtree(work, ignore_errors=True)
    table(f"dask against local processes ({cores} cores, {cores} workers each)", rows)


PARTS = {"parity": parity, "nanny": nanny}


def main(argv: list[str] | None = None) -> None:
    """Run the parts named (default: all)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=sorted(PARTS), help="parts to run")
    parser.add_argument("--rounds", type=int, default=PARITY_ROUNDS,
                        help=f"turns of each configuration in parity ({PARITY_ROUNDS})")
    args = parser.parse_args(argv)
    for name in args.only or list(PARTS):
        PARTS[name](args.rounds) if name == "parity" else PARTS[name]()


if __name__ == "__main__":
    main()

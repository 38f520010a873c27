"""Benchmark: one clip's time on a dask worker that dask's nanny started, by its environment.

Run ``python tools/bench_cluster.py`` or ``make bench`` (``tools/bench.py``
picks up this module's ``main`` as the ``cluster`` section). Prints, asserts
nothing. Needs the ``cluster`` extra (dask.distributed).

dask's nanny starts a worker with ``distributed.nanny.pre-spawn-environ``,
whose default ``MALLOC_TRIM_THRESHOLD_=65536`` also fixes glibc's mmap
threshold at 128 KiB: every frame-sized array is then a fresh ``mmap`` and
page-faults in anew. The environment docs/recognition.md gives for the
workers (:data:`WORKER_ENVIRON`) keeps frames on the heap. Each row is the
median time per clip (tracked, planned, recognised, as a batch's worker
does) on a one-worker, one-thread cluster; the baseline is dask's default
environment, measured in the same run on the same clips.
"""

from __future__ import annotations

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
    import dask
    from dask.distributed import Client, LocalCluster

    config = {} if environ is None else {"distributed.nanny.pre-spawn-environ": environ}
    before = dict(os.environ)  # the nanny sets its variables here, and prefers them next time
    try:
        with dask.config.set(config), LocalCluster(n_workers=1, threads_per_worker=1,
                                                   processes=True, dashboard_address=None) as c:
            with Client(c) as client:
                return client.submit(_clip_times, videos, folder, pure=False).result()
    finally:
        os.environ.clear()
        os.environ.update(before)


def main() -> None:
    """Print the time per clip under dask's default nanny environment and the documented one."""
    import dask

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


if __name__ == "__main__":
    main()

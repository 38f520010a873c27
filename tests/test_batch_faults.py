"""Batches that clean up after themselves (issue 33, item 4), each case once measured broken.

A batch killed with SIGKILL left its workers (250 MB each), the fork server and
the resource tracker running for ever; with ``--scheduler`` a relative ``-o``
put every clip's report in the dask worker's folder; one worker killed failed
the clips of every other worker and every clip not yet started; and a rerun
that failed on a full disk left a new ``summary.csv`` beside the previous
run's ``batch.json`` and ``report.html``.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import psutil
import pytest
from _demos import default_repertoire, demo_tracks
from _reports import disk_full_at

from perception.batch import REPORT_SET, discover, run_batch
from perception.recognition.repertoire import Repertoire


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    """Four demonstrations as tracks files (no video: fast)."""
    src = tmp_path_factory.mktemp("src")
    for cond in ("normal", "delayed"):
        for k in range(2):
            demo_tracks(cond, k)[0].save(src / f"{cond}{k}.tracks.h5")
    return src


@pytest.fixture(scope="module")
def repfile(tmp_path_factory):
    return default_repertoire().save(tmp_path_factory.mktemp("rep") / "rep.h5")


def _batch(src, out, *extra):
    return [sys.executable, "-m", "hammer_mv", "batch", str(src), "-o", str(out), "--quiet",
            *extra]


def _alive(procs: list[psutil.Process]) -> list[psutil.Process]:
    """Those of ``procs`` still running after 120 s (a zombie has ended)."""
    def running(p):
        try:
            return p.status() != psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False

    # a bound for a bug (workers that never end), not a speed: returns once all have ended
    return [p for p in psutil.wait_procs(procs, timeout=120)[1] if running(p)]


def test_killing_the_main_process_ends_its_workers(clips, repfile, tmp_path):
    out = tmp_path / "out"
    main = subprocess.Popen(_batch(clips, out, "--repertoire", str(repfile), "--jobs", "2"),
                            stderr=subprocess.DEVNULL)
    parent = psutil.Process(main.pid)
    deadline = time.monotonic() + 60
    kids: list[psutil.Process] = []
    try:  # once a clip is done, while the workers run the others
        while not list(out.glob("*.json")) and time.monotonic() < deadline:
            time.sleep(0.02)
            kids = parent.children(recursive=True)
        # the resource tracker, the fork server and two workers (started by the fork server)
        assert len(kids) == 4 and main.poll() is None, kids
        main.send_signal(signal.SIGKILL)
        main.wait()
        assert _alive(kids) == []
    finally:
        for p in kids:
            with contextlib.suppress(psutil.NoSuchProcess):
                p.kill()


def test_a_relative_output_on_a_cluster_is_the_clients_folder(clips, repfile, tmp_path,
                                                              monkeypatch):
    from dask.distributed import LocalCluster

    client, worker = tmp_path / "client", tmp_path / "worker"
    shutil.copytree(clips, client / "src")
    worker.mkdir()
    monkeypatch.chdir(worker)  # the dask worker runs in this process, in another folder
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                      host="127.0.0.1", dashboard_address=None) as cluster:
        proc = subprocess.run(_batch("src", "out", "--repertoire", str(repfile),
                                     "--scheduler", cluster.scheduler_address),
                              cwd=client, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert (pd.read_csv(client / "out" / "summary.csv")["status"] == "ok").all()
    assert len(list((client / "out").glob("*.recognition.json"))) == 4
    assert list(worker.iterdir()) == []


class _KillsOneWorker(Repertoire):
    """The first clip to plan its models kills its worker (as the out-of-memory killer does)."""

    token: Path

    def for_scene(self, scene, cache=None, **kwargs):
        try:
            self.token.unlink()  # once, in whichever worker gets here first
        except FileNotFoundError:
            return super().for_scene(scene, cache, **kwargs)
        os.kill(os.getpid(), signal.SIGKILL)


def test_a_killed_worker_fails_only_the_clip_it_held(clips, tmp_path):
    rep = _KillsOneWorker(default_repertoire().models)
    rep.token = tmp_path / "token"
    rep.token.touch()
    summary = run_batch(discover(clips), tmp_path / "out", rep, quiet=True, jobs=2)
    failed = summary[summary["status"] == "failed"]
    assert len(failed) == 1 and (summary["status"] == "ok").sum() == 3, summary["error"]
    assert "worker process running it died" in failed["error"].iloc[0]
    assert not list((tmp_path / "out").glob(f"{failed['clip'].iloc[0]}.*"))


@pytest.mark.parametrize("fails", ["summary.csv", "report.html", "batch.json"])
def test_a_report_set_is_never_half_replaced(clips, tmp_path, monkeypatch, fails):
    out = tmp_path / "out"
    items = [i for i in discover(clips) if i.clip in ("normal0", "delayed0")]
    run_batch(items, out, default_repertoire(), quiet=True)
    old = {p.name: p.read_bytes() for p in out.iterdir() if p.name in REPORT_SET}
    assert {"summary.csv", "report.html", "batch.json"} <= old.keys()
    disk_full_at(monkeypatch, fails)
    with pytest.raises(OSError, match="No space left"):
        run_batch(items, out, default_repertoire(), quiet=True)  # a rerun: a new summary
    now = {p.name: p.read_bytes() for p in out.iterdir() if p.name in REPORT_SET}
    assert now in ({}, old)  # never a mix of two runs
    assert not list(out.glob(".*part*"))


class _KillsEveryWorker(Repertoire):
    """A clip that kills every worker that plans its models."""

    clip: str

    def for_scene(self, scene, cache=None, **kwargs):
        # every clip is planned at the one reference scene (issue 42): the clip is told
        # by the recognition that asks, two frames up
        if sys._getframe(1).f_locals.get("clip") == self.clip:
            os.kill(os.getpid(), signal.SIGKILL)
        return super().for_scene(scene, cache, **kwargs)


def test_a_clip_that_kills_its_dask_workers_fails_alone(tmp_path):
    """Before, dask's KilledWorker ended the whole batch without a report."""
    import dask
    from dask.distributed import LocalCluster

    src = tmp_path / "src"
    src.mkdir()
    for k, distance in enumerate((0.25, 0.25, 0.3)):
        demo_tracks("normal", k, distance=distance)[0].save(src / f"c{k}.tracks.h5")
    rep = _KillsEveryWorker(default_repertoire().models)
    rep.clip = "c2"
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True, protocol="tcp",
                         host="127.0.0.1", dashboard_address=None) as cluster:
        summary = run_batch(discover(src), tmp_path / "out", rep, quiet=True,
                            scheduler=cluster.scheduler_address)
    status = dict(zip(summary["clip"], summary["status"]))
    assert status == {"c0": "ok", "c1": "ok", "c2": "failed"}, summary["error"]
    assert "dask workers running it died" in summary.set_index("clip").loc["c2", "error"]

"""A batch on dask works as local processes do (issue 45 item 2): a recording's reaches are
scored while it is read (dask read every recording first, the cluster idle meanwhile), the
rows, names and reports are those of one process, and the batch's process imports the
report's libraries only once a worker is idle (it did so while every worker was busy).
"""

import json
import os
import shutil
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

import perception.recordings as recordings
from perception.batch import discover, run_batch
from perception.errors import InputError
from perception.pipeline import RecognitionSettings
from perception.recognition.repertoire import Repertoire
from perception.recordings import MocapImport

distributed = pytest.importorskip("distributed")

pytestmark = pytest.mark.slow

TABLE = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"
SETTINGS = RecognitionSettings(mocap=MocapImport(rate=85.0))
#: Longest wait, s, for a worker to score the first reach while the reading waits for it.
WAIT_S = 20.0


@pytest.fixture(scope="module")
def cluster():
    """Two single-threaded worker processes, as a user's cluster runs (each item pickled)."""
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, protocol="tcp",
                      dashboard_address=":0") as c:
        yield c.scheduler_address


@pytest.fixture
def session(tmp_path):
    folder = tmp_path / "session"
    folder.mkdir()
    shutil.copy(TABLE, folder / "trials.tsv")
    recordings._cached.cache_clear()
    return folder


def _same_reports(a: Path, b: Path) -> None:
    """The same summary.csv, batch.json and per-trial reports in two report folders."""
    pd.testing.assert_frame_equal(pd.read_csv(a / "summary.csv"), pd.read_csv(b / "summary.csv"))
    assert json.loads((a / "batch.json").read_text()) == json.loads((b / "batch.json").read_text())
    names = sorted(p.name for p in a.glob("*.recognition.json"))
    assert names and names == sorted(p.name for p in b.glob("*.recognition.json"))
    for name in names:
        assert json.loads((a / name).read_text()) == json.loads((b / name).read_text()), name


def _here_and_on_dask(session, tmp_path, cluster):
    """The session's batch in this process, then on the cluster (read afresh)."""
    rep = Repertoire.default()
    one = run_batch(discover(session), tmp_path / "one", rep, SETTINGS, quiet=True)
    recordings._cached.cache_clear()
    return one, run_batch(discover(session), tmp_path / "dask", rep, SETTINGS, quiet=True,
                          scheduler=cluster)


def test_a_recording_on_dask_gives_one_process_rows(session, tmp_path, cluster):
    shutil.copy(TABLE, session / "more.tsv")
    one, remote = _here_and_on_dask(session, tmp_path, cluster)
    assert len(one) == 8 and one.attrs["trials"] == remote.attrs["trials"] == 8
    pd.testing.assert_frame_equal(one, remote)  # timing is in attrs, not the rows
    _same_reports(tmp_path / "one", tmp_path / "dask")
    runs = remote.attrs["timing"]["runs"]
    assert len(runs) == 8 and {int(p) for p in runs[:, 0]}.isdisjoint({os.getpid()})


def test_dask_scores_a_recording_while_it_reads_it(session, tmp_path, cluster, monkeypatch):
    """Before, the batch read the whole table and then submitted its reaches: here the
    reading waits, after the first trial, for that trial's report, which never came."""
    out = tmp_path / "out"
    real = recordings.iter_recording
    waited: list[bool] = []

    def waits_for_the_first_report(path, options=None):
        for k, trial in enumerate(real(path, options)):
            yield trial
            if k == 0:
                deadline = time.monotonic() + WAIT_S
                while not list(out.glob("*.recognition.json")) and time.monotonic() < deadline:
                    time.sleep(0.05)
                waited.append(bool(list(out.glob("*.recognition.json"))))

    monkeypatch.setattr(recordings, "iter_recording", waits_for_the_first_report)
    summary = run_batch(discover(session), out, Repertoire.default(), SETTINGS, quiet=True,
                        scheduler=cluster)
    assert waited == [True]  # a worker scored trial 0 before trial 1 was read
    assert len(summary) == 4 and (summary["status"] == "ok").all()


def test_a_recording_that_fails_at_its_end_on_dask(session, tmp_path, cluster, monkeypatch):
    """Its reaches went out as it was read: they are taken back, and the recording is one
    failed row, as in one process that reads it whole first."""
    real = recordings.iter_recording

    def fails_at_the_end(path, options=None):
        yield from real(path, options)
        raise InputError("marker 'thumb' is never seen in any of its 4 trials", path)

    monkeypatch.setattr(recordings, "iter_recording", fails_at_the_end)
    shutil.copy(TABLE, session / "other.tsv")
    one, remote = _here_and_on_dask(session, tmp_path, cluster)
    pd.testing.assert_frame_equal(one, remote)
    assert list(remote["clip"]) == ["other", "trials"]
    assert (remote["status"] == "failed").all()
    assert not list((tmp_path / "dask").glob("*.recognition.json"))  # taken back


# -- run_on_cluster itself, on workers in this process --------------------------------------

@pytest.fixture(scope="module")
def threads_cluster():
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=":0") as c:
        yield c.scheduler_address


def _where(item, shared):
    """What ran ``item``: its thread and the shared object it was given."""
    time.sleep(0.05 * (item % 3))
    return item, threading.get_ident(), id(shared)


def test_the_report_is_prepared_once_a_worker_is_idle(threads_cluster):
    """Before, the batch's process imported the report's libraries (1 s of CPU) as soon as
    the items were submitted, beside workers busy with all of them."""
    from perception.cluster import run_on_cluster

    given: list[int] = []
    at: list[int] = []
    for item, _, _ in run_on_cluster(range(8), _where, {"models": 1}, threads_cluster,
                                     at_tail=lambda: at.append(len(given))):
        given.append(item)
    assert sorted(given) == list(range(8))
    assert at == [7]  # once, with one item left: one of the two workers has nothing to do


def test_the_shared_object_is_one_per_worker(threads_cluster):
    """Scattered once: every item a worker runs gets the same object, which keeps what a
    worker learns between items (the models it re-plans for a scene)."""
    from perception.cluster import run_on_cluster

    seen: dict[int, set[int]] = {}
    for _, thread, shared in run_on_cluster(range(12), _where, Repertoire.default(),
                                            threads_cluster):
        seen.setdefault(thread, set()).add(shared)
    assert seen and all(len(ids) == 1 for ids in seen.values())


#: Set by a worker (in this process) when it runs item 0.
_FIRST_RAN = threading.Event()


def _flag(item, shared):
    if item == 0:
        _FIRST_RAN.set()
    return item


def test_items_go_out_as_they_are_made(threads_cluster):
    """The next item is asked for only after the ones before it were submitted: a worker
    runs the first while the second is still being made."""
    from perception.cluster import run_on_cluster

    _FIRST_RAN.clear()

    def items():
        yield 0
        assert _FIRST_RAN.wait(WAIT_S), "item 0 was not submitted before item 1 was made"
        yield 1

    assert sorted(run_on_cluster(items(), _flag, None, threads_cluster)) == [0, 1]


def test_workers_that_map_every_array_are_named(cluster, caplog):
    """dask's nanny starts workers whose glibc maps every frame and figure canvas afresh
    (a clip 15-25 % more CPU): a batch says so, once, and changes nothing."""
    from perception.cluster import run_on_cluster

    with caplog.at_level("WARNING", logger="perception.cluster"):
        assert sorted(run_on_cluster([1, 2], max, 0, cluster)) == [1, 2]
    said = [r.getMessage() for r in caplog.records if r.name == "perception.cluster"]
    assert len(said) == 1 and "2 of the cluster's 2 dask workers" in said[0]
    assert "MALLOC_MMAP_THRESHOLD_" in said[0] and "15 to 25 % more CPU" in said[0]


@pytest.mark.parametrize("environ, held", [
    ({"MALLOC_TRIM_THRESHOLD_": "65536"}, True),  # dask's nanny default
    ({"MALLOC_TRIM_THRESHOLD_": "67108864", "MALLOC_MMAP_THRESHOLD_": "33554432"}, False),
    ({}, False),  # a plain process: glibc raises its threshold as it goes
])
def test_which_workers_map_every_frame(monkeypatch, environ, held):
    from perception.cluster import _mmap_threshold_held

    for name in ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_"):
        monkeypatch.delenv(name, raising=False)
    for name, value in environ.items():
        monkeypatch.setenv(name, value)
    assert _mmap_threshold_held() is (held and sys.platform.startswith("linux"))


def _profiled(item, shared):
    from distributed import get_worker

    return get_worker().periodic_callbacks["profile"].is_running()


def test_the_profiler_is_paused_while_a_batch_runs(threads_cluster):
    """dask's profiler walked every running clip's stack each 10 ms (a motion-capture
    trial 16 % slower): paused while the batch's plugin is registered, then restarted."""
    from distributed import Client

    from perception.cluster import run_on_cluster

    with Client(threads_cluster) as client:
        before = client.run(lambda dask_worker: dask_worker.periodic_callbacks[
            "profile"].is_running())
        assert all(before.values())
        assert not any(run_on_cluster(range(4), _profiled, None, threads_cluster))
        after = client.run(lambda dask_worker: dask_worker.periodic_callbacks[
            "profile"].is_running())
    assert after == before

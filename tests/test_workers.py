"""Worker processes for ``--jobs`` (perception.workers): a standard pool, one thread each."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from perception.workers import run_pool


class _Where:
    """Where an item ran: the item, the process, which shared object and the worker's threads."""

    def run(self, item: int, shared: dict) -> tuple:
        import cv2
        from threadpoolctl import threadpool_info

        time.sleep(0.05)  # long enough that both workers get items
        return (item, os.getpid(), id(shared), shared["name"], cv2.getNumThreads(),
                {pool["num_threads"] for pool in threadpool_info()})


def test_items_run_once_in_workers_each_getting_the_shared_object_once():
    results = list(run_pool(range(8), _Where(), 2, shared={"name": "rep"}))
    assert sorted(r[0] for r in results) == list(range(8))
    pids = {r[1] for r in results}
    assert os.getpid() not in pids and 1 <= len(pids) <= 2
    for pid in pids:  # one copy per worker, unpickled when it started, not one per item
        assert len({r[2] for r in results if r[1] == pid}) == 1
    assert {r[3] for r in results} == {"rep"}
    assert {(r[4], *r[5]) for r in results} == {(1, 1)}  # one OpenCV and BLAS thread


def test_the_calling_process_is_left_as_it_was():
    import cv2
    from threadpoolctl import threadpool_info

    before = (cv2.getNumThreads(), threadpool_info(), dict(os.environ))
    list(run_pool(range(3), _Where(), 2, shared={"name": "s"}))
    assert (cv2.getNumThreads(), threadpool_info(), dict(os.environ)) == before


def test_one_job_runs_here_largest_first():
    results = list(run_pool([3, 9, 1, 7], _Where(), 1, shared={"name": "s"},
                            size=lambda i: i))
    assert [r[0] for r in results] == [9, 7, 3, 1]
    assert {r[1] for r in results} == {os.getpid()}


class _Dies:
    """A worker dies on item 0 (after the others have had time to finish)."""

    def __init__(self, parent: int):
        self.parent = parent

    def run(self, item: int, shared: None) -> int:
        if item == 0 and os.getpid() != self.parent:
            time.sleep(1.0)
            os._exit(3)  # as a crash in a library, or the out-of-memory killer, would
        return item


class _DiesReported(_Dies):
    def lost(self, item: int, message: str) -> tuple[str, int]:
        return message, item


@pytest.mark.parametrize("first", [False, True])
def test_a_dead_worker_loses_only_its_item_and_nothing_hangs(first):
    # item 0 first (largest) or last: while its worker dies the other one runs
    results = list(run_pool(range(6), _DiesReported(os.getpid()), 2,
                            size=lambda i: -i if first else i))
    lost = [r for r in results if isinstance(r, tuple)]
    assert sorted(r for r in results if isinstance(r, int)) == [1, 2, 3, 4, 5]
    assert [r[1] for r in lost] == [0]
    assert "worker process running it died" in lost[0][0] and "rerun" in lost[0][0]


def test_a_dead_worker_ends_a_job_without_lost_with_an_oserror():
    # an OSError: a command reports it in one line (not BrokenProcessPool's traceback)
    with pytest.raises(ChildProcessError, match="worker process running it died"):
        list(run_pool(range(4), _Dies(os.getpid()), 2))


class _Touch:
    def __init__(self, folder: Path):
        self.folder = folder

    def run(self, item: int, shared: None) -> int:
        time.sleep(0.1)
        (self.folder / str(item)).touch()
        return item


def test_stopping_early_drops_the_items_not_started(tmp_path):
    results = run_pool(range(40), _Touch(tmp_path), 2)
    next(results)
    results.close()  # as an interrupted batch does: the pool is shut down at once
    assert len(list(tmp_path.iterdir())) < 40

"""Work shared between a process and its spawned workers (perception.workers)."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import pytest

from perception.workers import PRELOAD, Claims, largest_first, run_shared


def test_largest_first_gives_both_ends_the_largest_and_the_middle_the_smallest():
    sizes = [5, 9, 1, 7, 3, 8, 2, 6, 4]
    order = largest_first(sizes, workers=2, size=lambda s: s)
    assert sorted(order) == sorted(sizes)
    # ranked 9 8 7 6 5 4 3 2 1: every third (7, 4, 1) goes to the back
    assert order == [9, 8, 6, 5, 3, 2, 1, 4, 7]
    front, back = order[:6], order[6:][::-1]
    assert front == sorted(front, reverse=True) and back == sorted(back, reverse=True)


def test_largest_first_keeps_the_order_of_equal_sizes():
    items = ["a", "b", "c", "d"]
    assert largest_first(items, workers=1, size=lambda _: 0) == ["a", "c", "d", "b"]


def test_an_item_is_claimed_once():
    claims = Claims(3)
    assert claims.take(1)
    assert not claims.take(1)
    assert claims.take(0) and claims.take(2)


def _wait_until(ready, what: str, seconds: float = 30) -> None:
    """Poll ``ready()`` until true; a TimeoutError naming ``what`` after ``seconds``."""
    deadline = time.monotonic() + seconds
    while not ready():
        if time.monotonic() > deadline:
            raise TimeoutError(what)
        time.sleep(0.01)


class _Record:
    """Sleeps for an item, then leaves a file naming the item and the process."""

    def __init__(self, folder: Path):
        self.folder = folder

    def run(self, item: int, shared: str) -> tuple[int, int, str]:
        if item == 0:
            # The first item waits until every other item is done: a process
            # that left a queued item undone while it waits never sees that.
            _wait_until(lambda: len(list(self.folder.glob("done-*"))) >= 5,
                        "the other items were not done", seconds=20)
        else:
            time.sleep(0.2)
        (self.folder / f"done-{item}-{os.getpid()}").touch()
        return item, os.getpid(), shared


def test_every_item_runs_once_and_nothing_queued_waits_behind_a_long_one(tmp_path):
    # Item 0 (the front: a worker's first) ends only when items 1-5 are done.
    # Without claims, the worker's next item sits queued behind it, and item
    # 0 times out waiting for it.
    results = list(run_shared(list(range(6)), _Record(tmp_path), 2, shared="rep",
                              folder=tmp_path, name="test"))
    assert sorted(r[0] for r in results) == list(range(6))
    assert {r[2] for r in results} == {"rep"}  # the shared object reached the worker
    assert len(list(tmp_path.glob("done-*"))) == 6  # none ran twice
    assert not list(tmp_path.glob(".test-*"))  # the shared pickle's folder is gone


@pytest.mark.parametrize("jobs", [1, 3])
def test_results_come_from_every_process_that_took_part(tmp_path, jobs):
    results = list(run_shared(list(range(1, 9)), _Record(tmp_path), jobs, shared="s",
                              folder=tmp_path))
    assert sorted(r[0] for r in results) == list(range(1, 9))
    assert (os.getpid() in {r[1] for r in results}) and len({r[1] for r in results}) <= jobs


class _Modules:
    """Item 1 (this process's first) waits for item 0, which a worker must therefore run."""

    def __init__(self, folder: Path):
        self.folder = folder

    def run(self, item: int, shared: None) -> list[str] | None:
        if item == 1:
            _wait_until((self.folder / "0").exists, "no worker ran item 0")
            return None
        loaded = [m for m in PRELOAD if m in sys.modules]
        (self.folder / "0").touch()
        return loaded


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a fork server")
def test_workers_start_with_the_preloaded_modules_imported(tmp_path):
    # this test module imports none of them: a spawned worker would not have them
    results = list(run_shared([0, 1], _Modules(tmp_path), 2))
    assert [r for r in results if r is not None] == [list(PRELOAD)]


class _Dies:
    """A worker dies on item 0; this process's first item waits until one has taken it."""

    def __init__(self, folder: Path, parent: int):
        self.folder, self.parent = folder, parent

    def run(self, item: int, shared: None) -> int:
        if item == 0 and os.getpid() != self.parent:
            (self.folder / "took-0").touch()
            os._exit(3)  # as a crash in a library would
        if item == 3:
            _wait_until((self.folder / "took-0").exists, "no worker took item 0")
        return item


class _DiesReported(_Dies):
    def lost(self, item: int, message: str) -> tuple[str, int]:
        return message, item


def test_a_dead_workers_item_is_reported_lost_and_the_rest_are_done(tmp_path):
    results = list(run_shared(list(range(4)), _DiesReported(tmp_path, os.getpid()), 2))
    lost = [r for r in results if isinstance(r, tuple)]
    assert sorted(r for r in results if isinstance(r, int)) == [1, 2, 3]
    assert [r[1] for r in lost] == [0] and "ended abruptly" in lost[0][0]


def test_a_dead_worker_ends_a_job_without_lost_with_an_oserror(tmp_path):
    # an OSError: a command reports it in one line (not BrokenProcessPool's traceback)
    with pytest.raises(ChildProcessError, match="worker process ended abruptly"):
        list(run_shared(list(range(4)), _Dies(tmp_path, os.getpid()), 2))


def test_a_shared_object_needs_a_folder():
    with pytest.raises(ValueError, match="needs a folder"):
        list(run_shared([1, 2], _Record(Path(".")), 2, shared="s"))

"""Batches on a dask.distributed cluster (``hammer-mv batch --scheduler``).

Optional: dask is the ``cluster`` extra (``pip install 'hammer-mv[cluster]'``);
this module is imported only when a batch is given a scheduler.

A cluster's workers are shared: a batch sets each worker up for its clips
through a :class:`OneThreadPerWorker` plugin that it registers before the
first clip and removes after the last, and the plugin puts back what it
changed — never a permanent change to another user's workers. How the
workers' processes start (glibc's allocator thresholds among them) is the
cluster owner's to set, in dask's nanny configuration: docs/recognition.md
says what a batch's clips want, and a batch says so when the workers' glibc
maps every large array afresh (dask's default).
"""

from __future__ import annotations

import asyncio
import logging
import os
import sys
from collections.abc import Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor

from distributed import Client, KilledWorker, WorkerPlugin
from distributed import as_completed as dask_completed
from distributed.comm import connect

from perception.errors import InputError

__all__ = ["SCHEDULER_TIMEOUT_S", "OneThreadPerWorker", "check_scheduler", "run_on_cluster"]

log = logging.getLogger(__name__)

#: Seconds to wait for a dask scheduler to answer before giving up.
SCHEDULER_TIMEOUT_S = 10.0

#: The worker's periodic callbacks that sample its running tasks' stacks (dask's
#: statistical profiler, ``distributed.worker.profile``) and roll the samples up.
_PROFILER = ("profile", "profile-cycle")


class OneThreadPerWorker(WorkerPlugin):
    """Set a dask worker up as a batch's local workers run, and put it back after.

    While registered: one OpenCV thread (the cluster's other workers use the
    other cores), and dask's statistical profiler paused: every 10 ms it
    holds the GIL to walk the running task's stack, which cost a
    motion-capture trial about 16 % more CPU and a rendered clip about 8 %
    (2-core machine, same runs; the dashboard's profile of the batch's tasks
    stays empty). FFmpeg's decoding and planning threads are
    settings the clips carry (a batch gives them one each); BLAS has one
    thread on a worker that dask's nanny started (its
    ``distributed.nanny.pre-spawn-environ``). ``teardown`` restores
    OpenCV's pool and restarts the profiler where it ran.
    """

    name = "hammer-mv-one-thread-per-worker"

    def setup(self, worker=None, **_) -> None:  # noqa: D102 - dask's API
        import cv2

        self._before = cv2.getNumThreads()
        cv2.setNumThreads(1)
        callbacks = getattr(worker, "periodic_callbacks", {})
        self._paused = [callbacks[k] for k in _PROFILER
                        if k in callbacks and callbacks[k].is_running()]
        for callback in self._paused:
            callback.stop()

    def teardown(self, **_) -> None:  # noqa: D102 - dask's API
        import cv2

        cv2.setNumThreads(self._before)
        for callback in self._paused:
            callback.start()


def check_scheduler(address: str) -> None:
    """Refuse ``address`` unless a dask scheduler answers there within the time limit.

    ``Client(address, timeout=...)`` waits for ever on a port that accepts
    and says nothing (its connection handshake is not bounded): ask the
    scheduler for its identity first, under an overall limit, on a loop of
    our own in another thread (the caller may be running one).

    Parameters
    ----------
    address : str
        The scheduler, ``tcp://host:port``.

    Raises
    ------
    InputError
        Nothing answers there as a dask scheduler within :data:`SCHEDULER_TIMEOUT_S`.
    """
    async def identity():
        comm = await connect(address, timeout=SCHEDULER_TIMEOUT_S)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    async def bounded():
        return await asyncio.wait_for(identity(), SCHEDULER_TIMEOUT_S)

    with ThreadPoolExecutor(1) as pool:
        try:
            answer = pool.submit(asyncio.run, bounded()).result()
        except (OSError, ValueError, TypeError) as exc:  # TimeoutError is an OSError
            first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise InputError(f"no dask scheduler answered at {address!r} within "
                             f"{SCHEDULER_TIMEOUT_S:g} s ({type(exc).__name__}: {first})",
                             field="scheduler") from None
    if not isinstance(answer, dict) or answer.get("type") != "Scheduler":
        raise InputError(f"{address!r} answered, but not as a dask scheduler",
                         field="scheduler")


def _mmap_threshold_held() -> bool:
    """On a worker: whether glibc maps every allocation over 128 KiB afresh. dask's nanny
    starts workers with ``MALLOC_TRIM_THRESHOLD_``, which stops glibc raising its mmap
    threshold as a plain process's rises; ``MALLOC_MMAP_THRESHOLD_`` sets it."""
    return (sys.platform.startswith("linux") and "MALLOC_TRIM_THRESHOLD_" in os.environ
            and "MALLOC_MMAP_THRESHOLD_" not in os.environ)


def _say_if_arrays_are_mapped(client: Client) -> None:
    """Warn, once per batch, when workers map every large array afresh (the cluster's
    owner sets their environment: a batch changes nothing of it)."""
    held = client.run(_mmap_threshold_held)
    if any(held.values()):
        log.warning("%d of the cluster's %d dask workers run with dask's default "
                    "MALLOC_TRIM_THRESHOLD_ and no MALLOC_MMAP_THRESHOLD_: every video frame "
                    "and figure canvas is mapped afresh there, and a clip takes 15 to 25 %% "
                    "more CPU (docs/recognition.md, 'On a dask cluster', gives the nannies' "
                    "settings)", sum(held.values()), len(held))


def run_on_cluster(items: Iterable, run, repertoire, scheduler: str, *, at_tail=None,
                   lost=None) -> Iterator:
    """``run(item, repertoire)`` for every item on the cluster at ``scheduler``, as they finish.

    Each item is submitted as ``items`` gives it, so the cluster works while
    a lazy ``items`` is still being made (a batch's recordings read trial by
    trial); results that finish meanwhile are yielded between items. Each
    result is fetched as soon as its item finishes, in the background, and
    the cluster forgets it once it is yielded.

    Parameters
    ----------
    items : iterable
        The work, in the order to submit it (largest first); may be a
        generator still reading it.
    run : callable
        A picklable callable of ``(item, repertoire)``.
    repertoire : object
        Sent once to every worker, where every item's ``run`` gets the same
        object (a worker keeps the models it re-plans between items).
    scheduler : str
        The scheduler's address.
    at_tail : callable, optional
        Called once, when every item is submitted and fewer are left than the
        cluster has worker threads: a worker has nothing more to do, and
        neither has this process until the last results come.
    lost : callable, optional
        ``lost(item, message)``: the result of an item whose workers died
        running it (dask retried it on others first); without it such an
        item ends the run (``distributed.KilledWorker``).
    """
    check_scheduler(scheduler)
    with Client(scheduler, timeout=SCHEDULER_TIMEOUT_S) as client:
        client.register_plugin(OneThreadPerWorker())
        try:
            _say_if_arrays_are_mapped(client)
            threads = sum(client.nthreads().values())
            shared = client.scatter(repertoire, broadcast=True)
            running: dict = {}  # future: its item
            finished = dask_completed(loop=client.loop, with_results=True, raise_errors=False)

            def result(fut, value):
                item = running.pop(fut)
                if fut.status == "finished":
                    return value
                try:
                    return fut.result()  # raises it (the worker's traceback), or cancelled
                except KilledWorker:  # the others go on
                    if lost is None:
                        raise
                    return lost(item, "the dask workers running it died (killed, out of "
                                      "memory or a crash in a library); rerun to retry it")

            for item in items:
                fut = client.submit(run, item, shared, pure=False)
                running[fut] = item
                finished.add(fut)
                while finished.has_ready():
                    yield result(*next(finished))
            while True:
                if at_tail is not None and len(running) < threads:  # a worker is idle
                    at_tail()
                    at_tail = None
                if not running:
                    break
                yield result(*next(finished))
        finally:
            client.unregister_worker_plugin(OneThreadPerWorker.name)

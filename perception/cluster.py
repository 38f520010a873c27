"""Batches on a dask.distributed cluster (``hammer-mv batch --scheduler``).

Optional: dask is the ``cluster`` extra (``pip install 'hammer-mv[cluster]'``);
this module is imported only when a batch is given a scheduler.

A cluster's workers are shared: a batch sets each worker up for its clips
through a :class:`OneThreadPerWorker` plugin that it registers before the
first clip and removes after the last, and the plugin puts back what it
changed — never a permanent change to another user's workers.
"""

from __future__ import annotations

import asyncio
import ctypes
import os
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

from distributed import Client, KilledWorker, WorkerPlugin
from distributed import as_completed as dask_completed
from distributed.comm import connect

from perception.errors import InputError

__all__ = ["SCHEDULER_TIMEOUT_S", "OneThreadPerWorker", "check_scheduler", "run_on_cluster"]

#: Seconds to wait for a dask scheduler to answer before giving up.
SCHEDULER_TIMEOUT_S = 10.0

#: glibc's ``mallopt`` parameters and the thresholds a plain process's dynamic
#: ones grow to (``mallopt(3)``: mmap at most 32 MiB, trim at twice that).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_MMAP_THRESHOLD, _TRIM_THRESHOLD = 32 << 20, 64 << 20
#: glibc's default mmap threshold, where ``MALLOC_TRIM_THRESHOLD_`` fixes it.
_DEFAULT_MMAP_THRESHOLD = 128 << 10


def _mallopt():
    try:
        return ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # not glibc: its allocator is not the one tuned
        return None


class OneThreadPerWorker(WorkerPlugin):
    """Set a dask worker up as a batch's local workers are, and put it back after.

    While registered: one OpenCV thread, one FFmpeg decoding thread and one
    planning thread (the cluster's other workers use the other cores); and,
    on a worker that dask's nanny started with ``MALLOC_TRIM_THRESHOLD_``
    (which fixes glibc's mmap threshold at 128 KiB, so that every
    frame-sized array is a fresh ``mmap``: 40,000 page faults and a third
    more time per clip), glibc's thresholds at what a plain process grows
    to. ``teardown`` restores all of it.
    """

    name = "hammer-mv-one-thread-per-worker"

    def setup(self, **_) -> None:  # noqa: D102 - dask's API (it passes worker=, not needed)
        import cv2

        from perception.io import video
        from perception.recognition import planning

        self._before = cv2.getNumThreads(), video.decoder_threads, planning.threads
        cv2.setNumThreads(1)
        video.decoder_threads = 1
        planning.threads = 1
        trim = os.environ.get("MALLOC_TRIM_THRESHOLD_")
        mallopt = _mallopt() if trim is not None else None
        self._trim = trim if mallopt and mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD) and \
            mallopt(_M_TRIM_THRESHOLD, _TRIM_THRESHOLD) else None

    def teardown(self, **_) -> None:  # noqa: D102 - dask's API
        import cv2

        from perception.io import video
        from perception.recognition import planning

        cv2.setNumThreads(self._before[0])
        video.decoder_threads, planning.threads = self._before[1:]
        mallopt = _mallopt() if self._trim is not None else None
        if mallopt:  # what the variable had set (it fixes the mmap threshold at glibc's default)
            mallopt(_M_TRIM_THRESHOLD, int(self._trim))
            mallopt(_M_MMAP_THRESHOLD, _DEFAULT_MMAP_THRESHOLD)


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
                             field="--scheduler") from None
    if not isinstance(answer, dict) or answer.get("type") != "Scheduler":
        raise InputError(f"{address!r} answered, but not as a dask scheduler",
                         field="--scheduler")


def run_on_cluster(items: list, run, repertoire, scheduler: str, *, while_waiting=None,
                   lost=None) -> Iterator:
    """``run(item, repertoire)`` for every item on the cluster at ``scheduler``, as they finish.

    Parameters
    ----------
    items : list
        The work, in the order to submit it (largest first).
    run : callable
        A picklable callable of ``(item, repertoire)``.
    repertoire : object
        Sent once to every worker.
    scheduler : str
        The scheduler's address.
    while_waiting : callable, optional
        Called once the work is submitted, while the cluster works.
    lost : callable, optional
        ``lost(item, message)``: the result of an item whose workers died
        running it (dask retried it on others first); without it such an
        item ends the run (``distributed.KilledWorker``).
    """
    check_scheduler(scheduler)
    with Client(scheduler, timeout=SCHEDULER_TIMEOUT_S) as client:
        client.register_plugin(OneThreadPerWorker())
        try:
            shared = client.scatter(repertoire, broadcast=True)
            futures = {client.submit(run, it, shared, pure=False): it for it in items}
            if while_waiting is not None:
                while_waiting()
            for fut in dask_completed(list(futures)):
                try:
                    result = fut.result()
                except KilledWorker:  # the others go on
                    if lost is None:
                        raise
                    result = lost(futures[fut], "the dask workers running it died (killed, out "
                                                "of memory or a crash in a library); rerun to "
                                                "retry it")
                yield result
        finally:
            client.unregister_worker_plugin(OneThreadPerWorker.name)

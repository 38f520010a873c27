"""Batches on a dask.distributed cluster (``hammer-mv batch --scheduler``).

Optional: dask is the ``cluster`` extra (``pip install 'hammer-mv[cluster]'``);
this module is imported only when a batch is given a scheduler.

A cluster's workers are shared: a batch sets each worker up for its clips
through a :class:`OneThreadPerWorker` plugin that it registers before the
first clip and removes after the last, and the plugin puts back what it
changed — never a permanent change to another user's workers. How the
workers' processes start (glibc's allocator thresholds among them) is the
cluster owner's to set, in dask's nanny configuration: docs/recognition.md
says what a batch's clips want.
"""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

from distributed import Client, KilledWorker, WorkerPlugin
from distributed import as_completed as dask_completed
from distributed.comm import connect

from perception.errors import InputError

__all__ = ["SCHEDULER_TIMEOUT_S", "OneThreadPerWorker", "check_scheduler", "run_on_cluster"]

#: Seconds to wait for a dask scheduler to answer before giving up.
SCHEDULER_TIMEOUT_S = 10.0

class OneThreadPerWorker(WorkerPlugin):
    """Set a dask worker's OpenCV thread pool to one thread, and put it back after.

    The cluster's other workers use the other cores. FFmpeg's decoding and
    planning threads are settings the clips carry (a batch gives them one
    each); BLAS has one thread on a worker that dask's nanny started
    (its ``distributed.nanny.pre-spawn-environ``). ``teardown`` restores
    OpenCV's pool.
    """

    name = "hammer-mv-one-thread-per-worker"

    def setup(self, **_) -> None:  # noqa: D102 - dask's API (it passes worker=, not needed)
        import cv2

        self._before = cv2.getNumThreads()
        cv2.setNumThreads(1)

    def teardown(self, **_) -> None:  # noqa: D102 - dask's API
        import cv2

        cv2.setNumThreads(self._before)


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

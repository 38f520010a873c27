"""Worker processes for ``--jobs``: a standard process pool, one thread per worker.

A batch (and ``synth --jobs``) hands its items, largest first, to ``jobs``
worker processes of a :class:`concurrent.futures.ProcessPoolExecutor`;
this process waits for their results. The workers are started from
multiprocessing's fork server where there is one (POSIX), else spawned:
never forked from this process, whose OpenCV/BLAS thread pools would
deadlock a forked child.

Each worker's initialiser makes that process single-threaded in OpenCV and
BLAS (``threadpoolctl.threadpool_limits``; the parallelism is the
processes') and receives what every item shares (a repertoire) once;
FFmpeg's decoding and planning threads are settings the job carries
(:class:`~perception.pipeline.RecognitionSettings`: a batch gives its
workers one each).

Each worker is a one-process executor handed one item at a time, so a
worker that dies (killed, out of memory) loses only the item it held; a new
worker takes its place. A worker ends when this process ends, even killed
by SIGKILL: it watches its end of multiprocessing's pipe from this process.
"""

from __future__ import annotations

import itertools
import multiprocessing
import os
import pickle
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Protocol

__all__ = ["Job", "init_worker", "run_pool"]


class Job(Protocol):
    """What :func:`run_pool` runs: picklable, its ``run`` importable in a worker.

    A job may also have ``lost(item, message)``: the result of an item whose
    worker died running it (killed, the out-of-memory killer, a crash in a
    library); the other items go on. Without it, such a death ends the run
    with a :class:`ChildProcessError` (an ``OSError``).
    """

    def run(self, item: Any, shared: Any) -> Any: ...


#: A worker's job and shared object (set by :func:`init_worker`).
_WORKER: dict = {}


def init_worker(job_and_shared: bytes) -> None:
    """A worker process's initialiser: one OpenCV and BLAS thread; the job; a thread
    that ends the worker when its parent ends.

    The job and the shared object come pickled once (bytes), so that the
    parent's write to a starting worker does not wait while the worker
    imports what unpickling them needs.

    Parameters
    ----------
    job_and_shared : bytes
        ``pickle.dumps((job, shared))``.
    """
    import cv2
    from threadpoolctl import threadpool_limits

    cv2.setNumThreads(1)
    _WORKER["job"], _WORKER["shared"] = pickle.loads(job_and_shared)
    threadpool_limits(1)  # numpy's BLAS, and OpenCV's: loaded by now
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with, args=(parent,), daemon=True).start()


def _exit_with(parent) -> None:
    """Exit once ``parent`` has ended: its end of a pipe to this process closes."""
    parent.join()
    os._exit(1)


def _run(item: Any) -> Any:
    return _WORKER["job"].run(item, _WORKER["shared"])


def _context():
    """The fork server where there is one, else spawn."""
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def run_pool(items: Iterable, job: Job, jobs: int, *, shared: Any = None,
             size: Callable[[Any], float] | None = None) -> Iterator[Any]:
    """``job.run(item, shared)`` of every item, in ``jobs`` worker processes, as they finish.

    With ``jobs`` 1 (or a single item) the items run here, in order, with
    no worker.

    Parameters
    ----------
    items : iterable
        The work (picklable); without ``size``, taken one at a time as
        workers come free (a generator may still be making them).
    job : Job
        Picklable; ``job.run`` returns each item's (picklable) result.
    jobs : int
        Worker processes.
    shared : object, optional
        Passed to every ``run``; sent to each worker once, when it starts.
    size : callable, optional
        An item's expected cost (e.g. its file's size): the largest are
        handed out first, so that the last to finish are the shortest.

    Yields
    ------
    object
        Each item's result, in the order they finish.
    """
    if size is not None:
        items = sorted(items, key=size, reverse=True)  # stable: equal sizes keep their order
    todo = iter(items)  # else taken as they come: the caller may still be making them
    first = list(itertools.islice(todo, 2))
    if jobs <= 1 or len(first) <= 1:
        for item in itertools.chain(first, todo):
            yield job.run(item, shared)
        return
    todo = itertools.chain(first, todo)
    state = pickle.dumps((job, shared), protocol=pickle.HIGHEST_PROTOCOL)

    def worker() -> ProcessPoolExecutor:  # starts its process when first given an item
        return ProcessPoolExecutor(1, mp_context=_context(), initializer=init_worker,
                                   initargs=(state,))

    idle = [worker() for _ in range(jobs)]
    running: dict = {}  # future: (its worker, its item)
    more = True
    try:
        while more or running:
            while more and idle:
                item = next(todo, _END)
                if item is _END:
                    more = False
                    break
                w = idle.pop()
                running[w.submit(_run, item)] = w, item
            if not running:
                break
            for future in wait(running, return_when=FIRST_COMPLETED).done:
                w, item = running.pop(future)
                try:
                    result = future.result()
                except BrokenProcessPool as exc:  # that worker died: a new one for the rest
                    w.shutdown()
                    w, result = worker(), _lost(job, item, exc)
                idle.append(w)
                yield result
    finally:  # interrupted, or a consumer that stops early: nothing more starts
        for w in idle + [w for w, _ in running.values()]:
            w.shutdown(wait=True)


#: What the items' iterator gives when it has no more.
_END = object()


def _lost(job: Job, item: Any, exc: BaseException) -> Any:
    """The result of an item whose worker died running it, or (a job without ``lost``)
    an error a command reports in one line."""
    why = "the worker process running it died (killed, out of memory or a crash in a library)"
    if not hasattr(job, "lost"):
        raise ChildProcessError(why) from exc
    return job.lost(item, f"{why}; rerun to retry it")

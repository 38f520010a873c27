"""Worker processes: one thread each, and work shared with the process that starts them.

A batch (and ``synth --jobs``) runs in this process and ``jobs - 1``
worker processes, forked from a fork server where there is one (see
:func:`run_shared`). Every process is single-threaded (OpenCV, FFmpeg,
BLAS): the parallelism is the processes'.

Workers take items from the front of the queue and this process from the
back. Each item is claimed once, in a table the processes share, by
whichever process starts it first. A worker keeps a few items queued so it
never waits for this process; at the end this process takes back the ones
a worker has not started yet instead of waiting for them. The last process
then finishes less than one item after the others.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import multiprocessing
import os
import pickle
import tempfile
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any, Protocol, TypeVar

from perception.io.atomic import owner_tag, remove_stale
from perception.recognition.planning import THREADS_VARIABLE

__all__ = ["PRELOAD", "THREAD_VARIABLES", "Claims", "Job", "largest_first", "limit_threads",
           "one_thread", "reuse_freed_memory", "run_shared", "single_threaded_children",
           "start_early"]

T = TypeVar("T")

#: Thread pools of the numerical libraries, one thread each in a worker: set in
#: the environment a worker is spawned with, because they are read when numpy
#: (its BLAS) and OpenCV load, before any code of the worker runs.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")


def limit_threads() -> None:
    """One OpenCV and one FFmpeg thread in this process: parallelism comes from the processes."""
    import cv2

    from perception.io import video

    cv2.setNumThreads(1)
    video.decoder_threads = 1


#: glibc's ``mallopt`` parameters, and the values a plain process's dynamic
#: thresholds grow to (``mallopt(3)``: at most 32 MiB, trim at twice that).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_MMAP_THRESHOLD, _TRIM_THRESHOLD = 32 << 20, 64 << 20


@functools.cache
def reuse_freed_memory() -> bool:
    """Let glibc reuse freed frames in a worker started with ``MALLOC_TRIM_THRESHOLD_``.

    dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536``,
    and setting any threshold also fixes glibc's mmap threshold at 128 KiB:
    every frame-sized array (0.9 MB at 640x480) is then a fresh ``mmap``,
    zeroed page by page. A clip took 40,000 page faults and 35 % more time
    than in a local process. Returns whether the thresholds were changed
    (only where the variable is set and the C library is glibc).
    """
    if os.environ.get("MALLOC_TRIM_THRESHOLD_") is None:
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # not glibc: its allocator is not the one tuned
        return False
    return bool(mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD)
                and mallopt(_M_TRIM_THRESHOLD, _TRIM_THRESHOLD))


@contextlib.contextmanager
def single_threaded_children():
    """Processes spawned inside get one BLAS/OpenMP thread (the environment they inherit)."""
    names = (*THREAD_VARIABLES, THREADS_VARIABLE)
    before = {k: os.environ.get(k) for k in names}
    os.environ.update({k: "1" for k in names})
    try:
        yield
    finally:
        for k, v in before.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@contextlib.contextmanager
def one_thread():
    """OpenCV and FFmpeg single-threaded in this process while it works beside its
    workers: their thread pools would otherwise take the cores the workers run on."""
    import cv2

    from perception.io import video

    before = cv2.getNumThreads(), video.decoder_threads
    cv2.setNumThreads(1)
    video.decoder_threads = 1
    try:
        yield
    finally:
        cv2.setNumThreads(before[0])
        video.decoder_threads = before[1]


class Claims:
    """Which items a process has started: one byte per item in shared memory.

    Parameters
    ----------
    n : int
        Number of items.
    context : multiprocessing context, optional
        The context the workers are started with (they get the table when
        they start, as it cannot be pickled later).
    """

    def __init__(self, n: int, context=None):
        self._taken = (context or multiprocessing).Array("B", int(n))

    #: Who claimed an item: nobody, the process that started the workers, a worker.
    FREE, CALLER, WORKER = 0, 1, 2

    def take(self, index: int, by: int = CALLER) -> bool:
        """Claim item ``index`` for ``by``; whether it was free (then the caller must do it)."""
        with self._taken.get_lock():
            if self._taken[index]:
                return False
            self._taken[index] = by
            return True

    def owner(self, index: int) -> int:
        """Who claimed item ``index`` (:data:`FREE` if nobody has)."""
        return self._taken[index]


class Job(Protocol):
    """What :func:`run_shared` runs: picklable, its ``run`` importable in a worker.

    A job may also have ``lost(item, message)``: the result of an item whose
    worker died while running it (a crash in a library, or the kernel's
    out-of-memory killer). Without it, such a death ends the run with a
    :class:`ChildProcessError` (an ``OSError``).
    """

    def run(self, item: Any, shared: Any) -> Any: ...


def largest_first(items: Sequence[T], workers: int, size: Callable[[T], float]) -> list[T]:
    """``items`` in the order :func:`run_shared` should get them: largest first for all.

    Workers take from the front and the calling process from the back, so
    of the items ranked by ``size`` every ``workers + 1``-th goes to the
    back: both ends start with the largest, and the queue ends where they
    meet with the smallest (the last items bound how long the first process
    to finish waits for the others).

    Parameters
    ----------
    items : sequence
        The work.
    workers : int
        Spawned workers beside the calling process.
    size : callable
        An item's expected cost (e.g. its file's size).
    """
    ranked = sorted(items, key=size, reverse=True)  # stable: equal sizes keep their order
    k = workers + 1
    front = [it for i, it in enumerate(ranked) if i % k != workers]
    back = ranked[workers::k]
    return front + back[::-1]


#: State of a worker process (set by its initializer; empty in the calling process).
_WORKER: dict = {}


def _init_worker(claims: Claims, shared_file: str | None) -> None:
    """Worker set-up: one thread, glibc's thresholds, the claims table and the shared object.

    The shared object comes as a file, not pickled in the start-up
    arguments: the parent blocks writing those to a new worker until the
    worker has started (and, spawned, imported everything: about a second).
    """
    limit_threads()
    reuse_freed_memory()  # inherited from a process that has used dask
    _WORKER["claims"] = claims
    if shared_file is None:
        return
    try:
        _WORKER["shared"] = pickle.loads(Path(shared_file).read_bytes())
    except FileNotFoundError:
        # The work ended before this worker had started, and shuts it down
        # without an item (the pool does not wait for it).
        pass


def _claimed(index: int, item: Any, job: Job) -> tuple[bool, Any]:
    """``job.run`` in a worker, unless another process has claimed the item."""
    if not _WORKER["claims"].take(index, Claims.WORKER):
        return False, None
    return True, job.run(item, _WORKER.get("shared"))


#: What a worker imports before its first item, in the fork server (which
#: workers are forked from, so they start with these imported).
PRELOAD = ("perception.batch", "perception.tracking.tracker", "perception.tracking.overlay",
           "perception.report.figures", "perception.report.chart_png", "perception.io.config",
           "PIL.ImageDraw", "PIL.ImageFont", *(f"PIL.{f}ImagePlugin" for f in
                                                ("Bmp", "Gif", "Jpeg", "Png", "Ppm")))


@functools.cache
def _context():
    """Workers are forked from a fork server where there is one (POSIX), else spawned.

    Not forked from this process: one that has already rendered or planned
    holds OpenCV/BLAS thread pools, and forking those deadlocks the workers.
    The fork server is a fresh single-threaded process that imports
    :data:`PRELOAD` once; every worker forked from it starts with those
    imported (spawned, each worker imports them itself: 0.4 s of CPU, and
    0.2 s more of first-use imports in its first clip). It lives as long as
    this process, so later runs start their workers at once.
    """
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(list(PRELOAD))
    return ctx


def start_early() -> None:
    """Start the fork server now (if not yet), so that it imports while this process
    goes on: a command that will run workers calls this before its own set-up."""
    ctx = _context()
    if ctx.get_start_method() == "forkserver":
        with single_threaded_children():  # the environment every worker inherits
            from multiprocessing import forkserver

            forkserver.ensure_running()


def run_shared(items: Sequence, job: Job, jobs: int, *, shared: Any = None,
               folder: str | os.PathLike | None = None, name: str = "shared",
               while_waiting: Callable[[], None] | None = None) -> Iterator[Any]:
    """``job.run(item, shared)`` of every item, in this process and ``jobs - 1`` workers.

    Parameters
    ----------
    items : sequence
        The work, in the order to do it (see :func:`largest_first`).
    job : Job
        Picklable; ``job.run`` returns each item's (picklable) result.
    jobs : int
        Processes, this one included.
    shared : object, optional
        Passed to every ``run``; each worker reads it once, from a pickle in
        a private temporary folder under ``folder``.
    folder : str or os.PathLike, optional
        Where that folder goes (required with ``shared``; e.g. the output folder).
    name : str
        What ``shared`` is: the folder is ``.NAME-h<host>p<pid>-…`` (a killed
        run's is removed by the next run there) and the file ``NAME.pickle``.
    while_waiting : callable, optional
        Called once if this process has done its share and waits for workers.

    Yields
    ------
    object
        Each item's result, in the order they finish.
    """
    if shared is not None and folder is None:
        raise ValueError("run_shared: a shared object needs a folder for its pickle")
    if jobs <= 1 or len(items) <= 1:
        for item in items:
            yield job.run(item, shared)
        return
    ctx = _context()
    claims = Claims(len(items), ctx)
    with contextlib.ExitStack() as stack:
        stack.enter_context(single_threaded_children())
        start_early()
        shared_file = None
        if shared is not None:
            remove_stale(folder, f".{name}-h*p*")  # left by a run that was killed
            tmp = stack.enter_context(tempfile.TemporaryDirectory(
                prefix=f".{name}-{owner_tag()}-", dir=folder))
            # Pickled, not HDF5 (a repertoire: 0.1 s to write here and 0.1 s to
            # read in each worker): the folder is this process's own (mode 0700)
            # and lives while the work runs.
            shared_file = Path(tmp) / f"{name}.pickle"
            shared_file.write_bytes(pickle.dumps(shared, protocol=pickle.HIGHEST_PROTOCOL))
            shared_file = str(shared_file)
        stack.enter_context(one_thread())
        pool = ProcessPoolExecutor(max_workers=jobs - 1, initializer=_init_worker,
                                   initargs=(claims, shared_file), mp_context=ctx)
        broken: list[BrokenProcessPool] = []  # a worker died: the pool takes nothing more
        try:
            yield from _share(items, job, shared, claims, pool, jobs - 1, while_waiting, broken)
        finally:
            # The workers exit on their own (0.2 s) while this process goes
            # on (a batch writes its report); Python joins them before it exits.
            # (A broken pool's futures are failed by its own thread: cancelling
            # them too raises InvalidStateError there, in Python 3.11.)
            pool.shutdown(wait=False, cancel_futures=not broken)


def _lost(job: Job, item: Any, exc: BaseException) -> Any:
    """The result of an item whose worker died while running it, or (a job without
    ``lost``) an error a command reports in one line."""
    why = "ended abruptly (a crash in a library, or out of memory)"
    if not hasattr(job, "lost"):
        raise ChildProcessError(f"a worker process {why}") from exc
    return job.lost(item, f"the worker process running it {why}; rerun to retry it")


def _share(items: Sequence, job: Job, shared: Any, claims: Claims, pool: ProcessPoolExecutor,
           workers: int, while_waiting: Callable[[], None] | None,
           broken: list[BrokenProcessPool]) -> Iterator[Any]:
    """This process's share of the items and the workers', until all are done."""
    running: dict = {}
    front, back = 0, len(items)  # next item submitted to the workers; one past this process's

    def feed():
        # a few items queued per worker, so that it never waits for this process
        nonlocal front
        while front < back and len(running) < 4 * workers and not broken:
            try:
                running[pool.submit(_claimed, front, items[front], job)] = front
            except BrokenProcessPool as exc:
                broken.append(exc)
                return
            front += 1

    def collect(futures):
        for f in futures:
            index = running.pop(f)
            try:
                done, result = f.result()
            except BrokenProcessPool as exc:
                # Every item the pool had is lost. One nobody claimed is this
                # process's to do (it claims down to the first); one a worker
                # had claimed may be what killed it, and is not run again here.
                broken.append(exc)
                if claims.owner(index) == Claims.WORKER:
                    yield _lost(job, items[index], exc)
                continue
            if done:
                yield result

    # The first items go to the pool from a thread: starting a worker waits
    # until the fork server has imported (0.4 s, the first time), and this
    # process spends that time on its own first item.
    failed: list[BaseException] = []

    def start():
        try:
            feed()
        except BaseException as exc:  # noqa: BLE001 - raised in this process's thread
            failed.append(exc)

    starter = threading.Thread(target=start, name="start workers", daemon=True)
    starter.start()
    try:
        while back > 0:
            back -= 1
            if claims.take(back):
                yield job.run(items[back], shared)
            starter.join()
            if failed:
                raise failed[0]
            yield from collect([f for f in running if f.done()])
            feed()
    finally:
        starter.join()
    # Every item is claimed: what is left is what the workers are doing, and
    # queued items a worker will find claimed (milliseconds each; not
    # cancelled: in Python 3.11 a pool that breaks after a future was
    # cancelled raises InvalidStateError in its own thread).
    if running and while_waiting is not None:
        while_waiting()
    yield from collect(as_completed(list(running)))

"""Frames read ahead in a bounded thread (:class:`ReadAhead`), the time axis of frame time
stamps (:class:`TimeResolver`), and cameras and streams (:class:`LiveSource`)."""

from __future__ import annotations

import contextlib
import itertools
import math
import queue
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from perception.errors import InputError
from perception.io.names import live_kind

#: Frames a source holds ahead of its consumer: a second at 30 frames/s (the
#: pause of a watch's scene fix, about one, is absorbed, not dropped).
READ_AHEAD = 32
#: Seconds past the stall timeout before the wait for a stuck reader ends.
STALL_GRACE = 1.0
_DONE = object()


class ReadAhead:
    """The items of ``produce()``, called and read in a thread ``name``, ``size`` at most waiting.

    The thread takes a token before each item, the consumer gives one back per
    item taken (C-level SimpleQueues: two calls that wait without the GIL). A
    ``live`` reader, once its first item is taken, never waits for room (its
    source must be drained): it drops the oldest waiting item, counted in
    ``dropped``. A daemon, as a driver may block in a read for good: close it.
    """

    def __init__(self, produce: Callable[[], Iterator], size: int, *, live: bool = False,
                 name: str = "read-ahead"):
        self.live, self.dropped, self.stalled, self.started = live, 0, False, False
        self._items, self._tokens = queue.SimpleQueue(), queue.SimpleQueue()
        for _ in range(max(int(size), 1)):
            self._tokens.put(True)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, args=(produce,), name=name, daemon=True)
        self._thread.start()

    def _run(self, produce: Callable[[], Iterator]) -> None:
        try:
            with contextlib.closing(produce()) as items:
                for item in items:
                    if self._stop.is_set() or not self._room():
                        return
                    self._items.put(item)
            self._items.put(_DONE)
        except BaseException as exc:  # raised again in the consumer's thread
            self._items.put(exc)

    def _room(self) -> bool:
        """Wait for room for an item (False: stop); a live reader drops the oldest instead."""
        if self.live and self.started:  # its first item (a header) is never dropped
            with contextlib.suppress(queue.Empty):
                return self._tokens.get_nowait()
            with contextlib.suppress(queue.Empty):
                self._items.get_nowait()  # only the reader puts anything but frames
                self.dropped += 1
                return True
        return self._tokens.get()

    def next(self, timeout: float | None = None) -> Any:
        """The next item (None: the reader ended or sent none for ``timeout`` s), or its error.

        Waits in slices of 0.1 s: Ctrl-C is delivered at once.
        """
        for _ in itertools.count() if timeout is None else range(math.ceil(timeout / 0.1)):
            with contextlib.suppress(queue.Empty):
                item = self._items.get(timeout=0.1)
                if isinstance(item, BaseException):
                    raise item
                if item is _DONE:
                    self._items.put(item)  # for a later call too
                    return None
                self._tokens.put(True)
                self.started = True
                return item
        self.stalled = True
        return None

    def close(self, timeout: float | None = None) -> None:
        """Stop the reader; wait for it up to ``timeout`` s (not at all once it has stalled)."""
        if not self._stop.is_set():
            self._stop.set()
            self._tokens.put(False)  # wakes a reader waiting for room
            self._thread.join(0 if self.stalled else timeout)


class TimeResolver:
    """Turn per-frame container timestamps into a strictly increasing time axis.

    A container time is used when it is finite, non-negative and later than the
    previous frame's; otherwise the frame gets ``previous + 1/fps`` (``0`` for
    the first frame), and the fallback is counted.

    Parameters
    ----------
    fps : float
        Nominal frame rate, frames/s, for the fallback.
    use_container : bool
        Use the container's times at all (False: every frame at ``index / fps``).
    """

    def __init__(self, fps: float, *, use_container: bool = True):
        self.fps, self.use_container, self.previous = fps, use_container, None
        self.n_container = self.n_fallback = 0

    def __call__(self, pos_msec: float) -> float:
        """Return the time (s) of the next frame given its ``CAP_PROP_POS_MSEC``."""
        t = pos_msec / 1000.0
        if (self.use_container and math.isfinite(t) and t >= 0
                and (self.previous is None or t > self.previous)):
            self.n_container += 1
        else:
            if not (self.fps > 0 and math.isfinite(self.fps)):
                raise InputError("the container gives neither frame timestamps nor a frame rate")
            t = 0.0 if self.previous is None else self.previous + 1.0 / self.fps
            self.n_fallback += 1
        self.previous = t
        return t

    @property
    def source(self) -> str:
        """``"container"``, ``"index/fps"`` (no frame had a usable time) or ``"mixed"``."""
        if self.n_fallback == 0:
            return "container"
        # A lone first frame at t=0 says nothing about the container.
        return "index/fps" if self.n_container <= 1 else "mixed"


class Source(contextlib.AbstractContextManager):
    """What a source of frames shares: iterated once; a context manager that closes it."""

    kind, dropped = "file", 0

    def __iter__(self) -> Iterator[tuple[int, float, Any]]:
        if self._started:
            raise RuntimeError(f"{self.path}: a {type(self).__name__} can be iterated only once")
        self._started = True
        return self._frames()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        with contextlib.suppress(Exception):
            self.close()


class RowsSource(Source):
    """Marker positions as a stream: ``(index, time_s, (positions (M, 2) px, likelihood (M,),
    status (M,)))`` per row of ``tracks`` (a pose file's, read whole: ``kind`` ``"pose"``).

    Parameters
    ----------
    tracks : Tracks
        The rows, with their ``markers`` and ``tracker`` attributes.
    path : str
        What it was read from.
    """

    kind = "pose"

    def __init__(self, tracks: Any, path: str):
        self.tracks, self.path, self._started = tracks, str(path), False
        steps = np.diff(np.asarray(tracks.time, dtype=float))
        self.fps = float(1 / np.median(steps)) if steps.size else 0.0

    def _frames(self) -> Iterator[tuple[int, float, Any]]:
        t = self.tracks
        for i in range(t.n_frames):
            yield int(t.frame[i]), float(t.time[i]), (t.position[i], t.likelihood[i],
                                                      t.status[i])

    def attrs(self) -> dict[str, Any]:
        """The ``/video`` attributes the tracks carry."""
        return dict(self.tracks.video)

    def close(self) -> None:
        """Nothing to release: the rows were read whole."""


def read_frames(cap: Any) -> Iterator[tuple[Any, float]]:
    """``(frame, CAP_PROP_POS_MSEC)`` of an OpenCV capture ``cap`` until a read fails."""
    import cv2

    while (got := cap.read())[0] and got[1] is not None:
        yield got[1], cap.get(cv2.CAP_PROP_POS_MSEC)


def source_kind(source: str | Any) -> str:
    """``"camera"`` (an index such as ``"0"``), ``"stream"`` (a URL) or ``"file"``: ``source``
    (:func:`perception.io.names.live_kind`)."""
    return live_kind(str(source)) or "file"


class LiveSource(Source):
    """A camera's or stream's frames, read ahead in a thread of their own; ``fps``: its header's.

    ``source``, ``stall_timeout`` and ``read_ahead``: :func:`perception.io.video.open_source`.
    """

    def __init__(self, source: str, *, stall_timeout: float = 5.0, read_ahead: int | None = None):
        self.path, self.kind, self.stall = str(source), source_kind(source), stall_timeout
        if not (math.isfinite(stall_timeout) and 0 < stall_timeout <= 2147483.647):
            raise InputError(f"expected a positive number of seconds (at most 2147483.647), "
                             f"got {stall_timeout}", field="stall_timeout")  # int32 ms
        if self.kind == "camera" and int(source) >= 2**31:
            raise InputError("not a camera (camera indices are below 2**31)", self.path)
        self._started, self._ahead = False, ReadAhead(
            self._read, read_ahead or READ_AHEAD, live=True, name=f"read:{self.path}")
        try:  # opened in the reader's thread: Ctrl-C ends this wait at once
            self.fps = self._ahead.next(max(stall_timeout, 10.0) + STALL_GRACE)
            if self.fps is None:
                raise InputError("cannot open the camera or stream", self.path)
        except BaseException:
            self._ahead.close(0)  # not waiting for an open under way
            raise

    def _read(self) -> Iterator:
        """In the reader's thread: the header frame rate, then ``(index, time_s, frame)``."""
        import cv2

        camera, ms = self.kind == "camera", int(self.stall * 1000)
        cap = cv2.VideoCapture(int(self.path) if camera else self.path,
                               cv2.CAP_ANY if camera else cv2.CAP_FFMPEG,
                               [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, max(ms, 10000),
                                cv2.CAP_PROP_READ_TIMEOUT_MSEC, ms])
        try:
            if not cap.isOpened():
                raise InputError("cannot open the camera or stream", self.path)
            fps, t0 = cap.get(cv2.CAP_PROP_FPS), time.monotonic()
            yield (fps := float(fps) if math.isfinite(fps) and 0 < fps < 1000 else 0.0)
            times = TimeResolver(fps or 30.0)  # a camera's times are this clock's, a stream's own
            for n, (frame, msec) in enumerate(read_frames(cap)):
                yield n, time.monotonic() - t0 if camera else times(msec), frame
        finally:
            cap.release()

    dropped = property(lambda self: self._ahead.dropped)  # the consumer fell behind

    def attrs(self) -> dict[str, Any]:
        """The ``/video`` attributes: the source and its header frame rate."""
        return {"source": self.path, "fps": self.fps}

    def _frames(self) -> Iterator[tuple[int, float, Any]]:
        try:  # a read stuck past FFmpeg's own timeout is abandoned STALL_GRACE s later
            while (item := self._ahead.next(self.stall + STALL_GRACE)) is not None:
                yield item
        finally:
            self.close()

    def close(self) -> None:
        """Stop reading and let the source go (waits at most for the read under way)."""
        self._ahead.close(self.stall + STALL_GRACE)

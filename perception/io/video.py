"""Video files: lazy sequential frames with real timestamps, and clip writing.

:class:`FrameSource` reads a file front to back (pims/trackpy style) and
yields ``(index, time_s, frame)``. Times come from the container
(``CAP_PROP_POS_MSEC`` after each read); only a frame the container gives no
usable time for gets ``previous + 1/fps``, and :attr:`FrameSource.time_source`
records whether that happened. The file is checked when opened (exists,
non-empty, decodable, at least one frame), and a stream that ends before the
frame count its header claims is kept with a warning and the true count.

:class:`VideoWriter` writes a clip atomically: mp4v ``.mp4`` (default), MJPG
``.avi`` or FFV1 ``.mkv`` (lossless).

What a file's container says before decoding, and how OpenCV is handed a
file (:func:`opencv_name`, :func:`quiet_native_stderr`), live in
:mod:`perception.io.video_files` (importable from here too). :func:`open_source`
opens a file, a camera or a stream; :mod:`perception.io.capture` reads the latter.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import sys
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import cv2
import numpy as np

from perception.errors import InputError
from perception.io import capture
from perception.io.atomic import atomic_path
from perception.io.capture import LiveSource, TimeResolver
from perception.io.files import input_file, sha256_file
from perception.io.video_files import (
    avi_header_rate,
    fourcc_str,
    opencv_name,
    quiet_native_stderr,
    utf8_name,
)
from perception.limits import MAX_FPS, MAX_FRAMES, MAX_VIDEO_PIXELS, MAX_VIDEO_SIDE, MIN_FPS

logger = logging.getLogger(__name__)

#: Output extension -> FourCC the writer uses for it.
CODECS: Mapping[str, str] = MappingProxyType({".mp4": "mp4v", ".avi": "MJPG", ".mkv": "FFV1"})

#: Values of :attr:`FrameSource.time_source`.
TIME_SOURCES = ("container", "index/fps", "mixed")
#: A stream counts as truncated when it ends this fraction (and at least 2
#: frames) short of the count its header claims.
TRUNCATION_TOLERANCE = 0.02
#: ``FrameSource(prefetch=None)`` reads ahead as many frames as fit in this
#: many bytes, :data:`READ_AHEAD_FRAMES` frames at most and at least.
READ_AHEAD_BYTES = 32 * 2**20
READ_AHEAD_FRAMES = (8, 32)


def _refs_when_free() -> int:
    """What :func:`sys.getrefcount` says of a list's item that nothing else holds."""
    probe = [np.empty(1)]
    return sys.getrefcount(probe[0])


class FramePool:
    """Decoding into the buffers of frames that nothing holds any more.

    Decoded into fresh memory, a frame costs a page fault for each 4 KiB
    written (225 for 640 x 480): frames read ahead by one thread and dropped
    by another come from memory the allocator has handed back to the
    system, and tracking a 3,510-frame clip took 9,000-30,000 faults more
    than decoding it in one thread, 0.1-0.25 s of system time, in the
    decoding thread, which sets the pace (tools/bench_tracking.py). A buffer is
    decoded into again only when its reference count says that nothing but
    the pool holds it (no frame in the tracker's look-ahead, no crop of it,
    no frame kept for a contact sheet); otherwise the frame is decoded into
    new memory, kept for later while the pool has room. The pixels are the
    same either way (OpenCV copies the converted frame into the buffer).

    Parameters
    ----------
    size : int
        Most buffers kept.

    Attributes
    ----------
    n_reused : int
        Frames decoded into a buffer decoded into before.
    """

    _FREE = _refs_when_free()

    def __init__(self, size: int):
        self.size = max(int(size), 1)
        self.n_reused = 0
        self._buffers: list[np.ndarray] = []

    def _free(self) -> np.ndarray | None:
        """A buffer nothing else holds, or None."""
        buffers = self._buffers
        for i in range(len(buffers)):
            if sys.getrefcount(buffers[i]) == self._FREE:
                return buffers[i]
        return None

    def read_one(self, cap: Any) -> tuple[bool, np.ndarray | None]:
        """``cap.read()`` of an OpenCV capture, into a free buffer where there is one."""
        buffer = self._free()
        if buffer is None:
            ok, frame = cap.read()
        else:
            ok, frame = cap.read(buffer)
            if ok and frame is buffer:
                self.n_reused += 1
            elif ok and frame is not None:  # another size: decoded into new memory
                self._buffers = [b for b in self._buffers if b is not buffer]
        if ok and frame is not None and frame is not buffer and len(self._buffers) < self.size:
            self._buffers.append(frame)
        return ok, frame

    def read(self, cap: Any) -> Iterator[tuple[np.ndarray, float]]:
        """``(frame, CAP_PROP_POS_MSEC)`` of an OpenCV capture until a read fails."""
        while True:
            ok, frame = self.read_one(cap)
            if not ok or frame is None:
                return
            yield frame, cap.get(cv2.CAP_PROP_POS_MSEC)
            frame = None  # not held here while the next buffer is chosen


@dataclass(frozen=True)
class VideoInfo:
    """What the container says about a video.

    Attributes
    ----------
    path : str
        The file as given.
    sha256 : str
        Hex digest of the file's bytes.
    fps_nominal : float
        Frame rate from the header, frames/s (0 if the container has none).
    n_frames_header : int
        Frame count the header claims (may be an estimate; 0 if unknown).
    width, height : int
        Frame size, px.
    fourcc : str
        Codec FourCC, e.g. ``"FMP4"``, ``"MJPG"``, ``"FFV1"``.
    """

    path: str
    sha256: str
    fps_nominal: float
    n_frames_header: int
    width: int
    height: int
    fourcc: str


class FrameSource(capture.Source):
    """Lazy, sequential frames of one video file.

    Opening checks the file and decodes the first frame; iterating yields
    ``(index, time_s, frame)`` once, front to back. Decoding runs in a
    background thread a few frames ahead (OpenCV releases the GIL while
    decoding), so work done on each frame overlaps the next frame's decoding;
    at most ``prefetch`` frames are held. Frames are decoded into the buffers
    of earlier frames that nothing holds any more (:class:`FramePool`).

    Parameters
    ----------
    path : str or os.PathLike
        Video file.
    prefetch : int or None
        Frames decoded ahead (0: decode in the caller's thread; None: as many
        as fit in :data:`READ_AHEAD_BYTES`, 8 to 32: 32 of 640 x 480, 8 of
        1920 x 1080).
    hash : bool
        Compute the file's SHA-256 (one extra sequential read of the file,
        in a background thread while frames are decoded; :attr:`info` waits
        for it).
    keep_truncated : bool
        Keep the frames of a stream that ends well before the frame count its
        header claims (a truncated or corrupt file) instead of refusing it.
    fps : float, optional
        The true frame rate, frames/s: frame times become ``index / fps``,
        whatever the container says (for files whose header is wrong).
    threads : int
        Threads FFmpeg decodes with (0: FFmpeg's choice, about one per core).
        A process working beside others (a batch worker) passes 1: its
        parallelism is theirs, and one decoding thread spends the least CPU
        per frame.

    Raises
    ------
    InputError
        Missing, zero-byte, unreadable or non-video file, or no decodable frame.

    Attributes
    ----------
    info : VideoInfo
        Header metadata and the file's SHA-256 (waits for the hash).
    header : VideoInfo
        Header metadata without waiting (``sha256`` empty until ``info`` is read).
    n_decoded : int
        Frames yielded so far; the true frame count once iteration has ended.
    complete : bool
        True once the stream has been read to its end.
    """

    def __init__(self, path: str | os.PathLike, *, prefetch: int | None = 8, hash: bool = True,
                 keep_truncated: bool = False, fps: float | None = None, threads: int = 0):
        self.path = Path(path)
        self.prefetch = prefetch
        self.keep_truncated = bool(keep_truncated)
        if fps is not None and not (math.isfinite(fps) and 0 < fps <= MAX_FPS):
            raise InputError(f"expected a frame rate in (0, {MAX_FPS:g}] frames/s, "
                             f"got {fps!r}", field="fps")
        self.fps_override = fps
        if not self.path.exists():
            raise InputError("no such file", self.path)
        input_file(self.path, "video", empty=False)  # a FIFO or device would block or never end
        with opencv_name(self.path) as name:
            cap = (cv2.VideoCapture(name, cv2.CAP_FFMPEG, [cv2.CAP_PROP_N_THREADS, int(threads)])
                   if threads > 0 else cv2.VideoCapture(name, cv2.CAP_FFMPEG))
        if not cap.isOpened():
            cap.release()
            raise InputError("not a readable video (FFmpeg could not open it)", self.path)
        width, height = (cap.get(p) for p in (cv2.CAP_PROP_FRAME_WIDTH,
                                              cv2.CAP_PROP_FRAME_HEIGHT))
        if (not (math.isfinite(width) and math.isfinite(height))
                or max(width, height) > MAX_VIDEO_SIDE or width * height > MAX_VIDEO_PIXELS):
            cap.release()  # before a frame of it is decoded: one of 16000 x 16000 is 768 MB
            raise InputError(f"frames of {width:g} x {height:g} px are larger than this reads "
                             f"(at most {MAX_VIDEO_SIDE} px a side, {MAX_VIDEO_PIXELS} px in "
                             "all)", self.path, field="frame size")
        claimed = cap.get(cv2.CAP_PROP_FRAME_COUNT)
        if math.isfinite(claimed) and claimed > MAX_FRAMES:
            cap.release()  # its tracks could not be read back
            raise InputError(f"the container claims {claimed:.0f} frames, more than the "
                             f"{MAX_FRAMES} a tracks file may hold", self.path,
                             field="frame count")
        if prefetch is None:
            least, most = READ_AHEAD_FRAMES
            frame_bytes = max(3 * width * height, 1.0)  # 0 where the header gives no size
            self.prefetch = min(max(int(READ_AHEAD_BYTES // frame_bytes), least), most)
        else:
            self.prefetch = int(prefetch)
        # frames held at once: those read ahead, the one being decoded, a tracker's look-ahead
        self._pool = FramePool(self.prefetch + 16)
        ok, first = self._pool.read_one(cap)
        if not ok or first is None:
            cap.release()
            raise InputError("no decodable frames (empty, truncated or corrupt video)", self.path)
        self._cap, self._first, self._first_msec = cap, first, cap.get(cv2.CAP_PROP_POS_MSEC)
        height, width = first.shape[:2]
        n_header = cap.get(cv2.CAP_PROP_FRAME_COUNT)
        fps = cap.get(cv2.CAP_PROP_FPS)
        # read and hashed in a thread (both release the GIL): no time taken from tracking
        self._sha256 = capture.ReadAhead(lambda: iter((sha256_file(self.path),)), 1,
                                 name=f"sha256:{self.path.name}") if hash else None
        self._info = VideoInfo(
            path=os.fspath(path),
            sha256="",
            fps_nominal=float(fps) if math.isfinite(fps) and fps > 0 else 0.0,
            n_frames_header=int(n_header) if math.isfinite(n_header) and n_header > 0 else 0,
            width=int(width),
            height=int(height),
            fourcc=fourcc_str(cap.get(cv2.CAP_PROP_FOURCC)),
        )
        if self.fps_override is not None:
            self._times = TimeResolver(self.fps_override, use_container=False)
        else:
            self._check_rate()
            self._times = TimeResolver(self._info.fps_nominal)
        self.n_decoded, self.complete, self._started = 0, False, False
        self._ahead: capture.ReadAhead | None = None

    # -- iteration ---------------------------------------------------------
    def _frames(self) -> Iterator[tuple[int, float, np.ndarray]]:
        try:
            # decoded in a thread from the first frame taken on, overlapping the caller's work
            # (what it opens or computes once before it asks for the second frame too)
            if self.prefetch > 0:
                self._ahead = capture.ReadAhead(lambda: self._pool.read(self._cap),
                                                self.prefetch, name=f"decode:{self.path.name}")
            yield 0, self._times(self._first_msec), self._first
            self._first = None
            self.n_decoded = 1
            for frame, msec in (iter(self._ahead.next, None) if self._ahead
                                else self._pool.read(self._cap)):
                self.n_decoded += 1
                yield self.n_decoded - 1, self._times(msec), frame
            self.complete = True
            self._check_count()
        finally:
            self.close()

    def _check_rate(self) -> None:
        """Refuse a header frame rate no camera films a hand at (it would rescale time).

        The rate must lie in ``[MIN_FPS, MAX_FPS)`` (:mod:`perception.limits`):
        1000 is what a millisecond time base reports for a stream stating no
        rate, and FFmpeg reads an AVI header's rate of 0 as 25, so an AVI's
        own header is read to tell.
        """
        fps = self._info.fps_nominal
        stated = avi_header_rate(self.path)
        if stated is not None and not stated > 0:
            fps = 0.0
        if fps >= MAX_FPS or fps < MIN_FPS:
            self._cap.release()
            self._cap = None
            if fps <= 0:
                problem = "the container states no frame rate (0 frames/s)"
            elif fps < MIN_FPS:
                problem = (f"the container claims {fps:g} frames/s, fewer than any camera "
                           f"filming a hand ({MIN_FPS:g})")
            else:
                problem = (f"the container claims {fps:g} frames/s, more than this believes "
                           f"of a header (below {MAX_FPS:g})")
            raise InputError(f"{problem}; give the true rate with `fps`", self.path,
                             field="frame rate")

    def _check_count(self) -> None:
        claimed = self._info.n_frames_header
        # Header counts of some containers are estimates (duration x rate):
        # a frame or two short is not a truncated file.
        missing = claimed - self.n_decoded
        if claimed and missing > max(2, TRUNCATION_TOLERANCE * claimed):
            if not self.keep_truncated:
                raise InputError(
                    f"truncated or corrupt video: decoded {self.n_decoded} of the {claimed} "
                    "frames its header claims (`keep_truncated` uses the decoded frames)",
                    self.path)
            logger.warning("%s: decoded %d of the %d frames the header claims; keeping them "
                           "(`keep_truncated`)", self.path, self.n_decoded, claimed)
        if self._times.n_fallback and self.fps_override is None:
            logger.warning("%s: %d of %d frames had no usable container timestamp; used "
                           "previous + 1/fps", self.path, self._times.n_fallback, self.n_decoded)

    @property
    def header(self) -> VideoInfo:
        """Header metadata at once: ``sha256`` stays empty until :attr:`info` has waited for it."""
        return self._info

    @property
    def info(self) -> VideoInfo:
        """Header metadata and the file's SHA-256 (waits for the hash to be read)."""
        if self._sha256 is not None:
            self._info = replace(self._info, sha256=self._sha256.next())
            self._sha256 = None
        return self._info

    @property
    def fps(self) -> float:
        """The rate frames are timed by, frames/s: ``fps`` if given, else the header's."""
        return self.fps_override or self._info.fps_nominal

    @property
    def time_source(self) -> str:
        """Where frame times came from so far: see :class:`TimeResolver`."""
        return self._times.source

    def attrs(self) -> dict[str, Any]:
        """The ``/video`` attributes of a tracks file.

        ``n_frames`` is the true decoded count once iteration has ended, the
        header's claim before; ``n_frames_header`` and ``time_source`` are
        recorded beside it.
        """
        info = asdict(self.info)
        info["n_frames"] = self.n_decoded if self.complete else info["n_frames_header"]
        info["time_source"] = self.time_source
        return info

    # -- lifetime ------------------------------------------------------------
    def close(self) -> None:
        """Stop the decoding thread and release the file."""
        if self._ahead is not None:
            self._ahead.close()
        if self._cap is not None:
            self._cap.release()
            self._cap = None


def open_source(source: str, *, stall_timeout: float = 5.0, keep_truncated: bool = False,
                fps: float | None = None, read_ahead: int | None = None) -> capture.Source:
    """Open ``source`` for reading frame by frame, as a context manager.

    Both kinds yield ``(index, time_s, frame)`` (times: a file's container's,
    a stream's own, a camera's this clock's at arrival) and have ``kind``,
    ``fps``, ``dropped`` and ``attrs()``. A file's reader waits for room, a
    live one drops the oldest frame and counts it.

    Parameters
    ----------
    source : str
        A camera index (``"0"``), a video file or a URL FFmpeg opens: a file
        gives a :class:`FrameSource`, a camera or stream a :class:`LiveSource`.
    stall_timeout : float
        A camera or stream that sends no frame for this long has ended, s.
    keep_truncated, fps
        As :class:`FrameSource` (files only).
    read_ahead : int, optional
        Most frames waiting (:data:`~perception.io.capture.READ_AHEAD`).

    Raises
    ------
    InputError
        No such file, camera or stream, or a bad timeout.
    """
    if capture.source_kind(source) != "file":
        return LiveSource(source, stall_timeout=stall_timeout, read_ahead=read_ahead)
    if not Path(source).exists():
        raise InputError("no such file (nor a camera index or stream URL)", source)
    return FrameSource(source, prefetch=read_ahead or capture.READ_AHEAD,
                       keep_truncated=keep_truncated, fps=fps)


#: ``open_video(path, **kwargs)``: the video at ``path`` for sequential reading.
open_video = FrameSource


def codec_for(path: str | os.PathLike, codec: str | None = None) -> str:
    """FourCC to write ``path`` with: ``codec`` if given, else from the extension.

    Raises
    ------
    InputError
        Unknown extension with no codec, or a codec that is not 4 characters.
    """
    if codec is None:
        ext = Path(path).suffix.lower()
        if ext not in CODECS:
            raise InputError(f"unknown video extension {ext!r} (expected one of "
                             f"{', '.join(CODECS)})", path)
        return CODECS[ext]
    if len(codec) != 4:
        raise InputError(f"codec: expected a 4-character FourCC, got {codec!r}", path)
    return codec


class VideoWriter:
    """Write a clip frame by frame; the file appears only when complete.

    Use as a context manager; frames go to a temporary file beside ``path``,
    renamed on a clean exit and removed if the block raises.

    Parameters
    ----------
    path : str or os.PathLike
        Output file (``.mp4`` -> mp4v, ``.avi`` -> MJPG, ``.mkv`` -> FFV1).
    fps : float
        Frame rate, frames/s.
    size : (int, int)
        ``(width, height)``, px.
    codec : str, optional
        FourCC overriding the extension's default.
    """

    def __init__(self, path: str | os.PathLike, fps: float, size: tuple[int, int],
                 codec: str | None = None):
        self.path = Path(path)
        self.codec = codec_for(self.path, codec)
        if not (math.isfinite(fps) and fps > 0):
            raise ValueError(f"VideoWriter.fps: expected a positive frame rate, got {fps!r}")
        width, height = (int(s) for s in size)
        if width <= 0 or height <= 0:
            raise ValueError(f"VideoWriter.size: expected positive (width, height), got {size!r}")
        self.fps = float(fps)
        self.size = (width, height)
        self.n_written = 0
        self._stack: contextlib.ExitStack | None = None
        self._vw: cv2.VideoWriter | None = None
        self.tmp_path: Path | None = None

    def __enter__(self) -> VideoWriter:
        # An error here exits the atomic output with it (its temporary file is removed);
        # pop_all keeps the output open past the block otherwise.
        with contextlib.ExitStack() as stack:
            self.tmp_path = stack.enter_context(atomic_path(self.path))
            if not utf8_name(self.tmp_path):
                raise InputError("OpenCV cannot write a video whose name is not valid UTF-8; "
                                 "choose another name", self.path)
            with quiet_native_stderr():
                vw = cv2.VideoWriter(os.fspath(self.tmp_path),
                                     cv2.VideoWriter_fourcc(*self.codec), self.fps, self.size)
            if not vw.isOpened():
                raise OSError(f"{self.path}: OpenCV cannot write {self.codec!r} video here")
            self._stack, self._vw = stack.pop_all(), vw
        return self

    def write(self, frame: np.ndarray) -> None:
        """Append one frame: ``(height, width, 3)`` uint8, BGR."""
        w, h = self.size
        if frame.shape != (h, w, 3) or frame.dtype != np.uint8:
            raise ValueError(f"VideoWriter.write: expected a ({h}, {w}, 3) uint8 frame, "
                             f"got {frame.shape} {frame.dtype}")
        self._vw.write(frame)
        self.n_written += 1

    def __exit__(self, exc_type, exc, tb) -> bool:
        assert self._stack is not None and self._vw is not None
        self._vw.release()
        if exc_type is not None:
            return bool(self._stack.__exit__(exc_type, exc, tb))
        with self._stack:  # an error here removes the temporary file
            if self.n_written == 0:
                raise ValueError(f"{self.path}: no frames written")
            if not _readable(self.tmp_path, self.n_written):
                # OpenCV reports no write errors: a full disk shows as a file
                # FFmpeg cannot open, or one with fewer frames than written.
                raise OSError(f"cannot write {self.path}: the video came out incomplete "
                              "(is the disk full?)")
        return False


def _readable(path: Path, n_frames: int) -> bool:
    """Whether FFmpeg opens a just-written clip and its header counts ``n_frames``."""
    with quiet_native_stderr(), opencv_name(path) as name:
        cap = cv2.VideoCapture(name, cv2.CAP_FFMPEG)
    try:
        if not cap.isOpened():
            return False
        count = cap.get(cv2.CAP_PROP_FRAME_COUNT)
        if math.isfinite(count) and count > 0:
            return int(count) == n_frames
        # No count in the header (an unfinished AVI, for one): count what decodes.
        with quiet_native_stderr():
            decoded = 0
            while decoded <= n_frames and cap.grab():
                decoded += 1
        return decoded == n_frames
    finally:
        cap.release()


def write_video(frames: Iterable[np.ndarray], path: str | os.PathLike, fps: float,
                codec: str | None = None) -> int:
    """Write an iterable of BGR frames to ``path`` atomically; return the frame count.

    Parameters
    ----------
    frames : iterable of (H, W, 3) uint8
        BGR frames; the size is taken from the first.
    path : str or os.PathLike
        Output video (see :class:`VideoWriter` for extensions and codecs).
    fps : float
        Frame rate, frames/s.
    codec : str, optional
        FourCC overriding the extension's default.
    """
    it = iter(frames)
    try:
        first = next(it)
    except StopIteration:
        raise ValueError(f"{path}: no frames to write") from None
    h, w = first.shape[:2]
    with VideoWriter(path, fps, (w, h), codec) as vw:
        vw.write(first)
        for frame in it:
            vw.write(frame)
    return vw.n_written

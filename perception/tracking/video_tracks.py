"""A video (or any stream of frames) tracked into a tracks file.

:func:`track_frames` feeds frames through a :class:`~perception.tracking.tracker.Tracker`
(its look-ahead included) into an open
:class:`~perception.io.tracks.TracksWriter`; :func:`track_video` does it for
a video file: decoding, the tracks file written whole or not at all, an
optional labelled video and frame sample, progress, and the one-line refusal
of a marker never found.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from perception.errors import InputError
from perception.io.tracks import TracksWriter, tracks_path_for
from perception.io.video import FrameSource, VideoWriter
from perception.tracking.markers import MarkerSet, default_markers
from perception.tracking.overlay import Labeller
from perception.tracking.params import TrackerParams
from perception.tracking.reacquisition import ROI
from perception.tracking.tracker import Tracker

if TYPE_CHECKING:
    from perception.io.frame_sample import FrameSample

__all__ = ["track_frames", "track_video"]

logger = logging.getLogger(__name__)


def track_frames(
    frames: Iterable[tuple[int, float, np.ndarray]],
    writer: TracksWriter,
    tracker: Tracker,
    *,
    progress: Any = None,
    each_frame: Any = None,
) -> Tracker:
    """Track a stream of frames into an open :class:`TracksWriter`.

    The frames go through :meth:`Tracker.feed` and :meth:`Tracker.flush`:
    the first ``tracker.params.init_frames`` are read ahead (the hand at
    rest) so that first detection can reject candidates that move; memory
    holds those few frames only.

    Parameters
    ----------
    frames : iterable of (int, float, (H, W, 3) uint8)
        ``(index, time_s, frame)``, as :class:`~perception.io.video.FrameSource` yields.
    writer : TracksWriter
        Open writer whose markers are the tracker's.
    tracker : Tracker
        Tracker state (updated in place).
    progress : callable, optional
        Called with no arguments after each frame.
    each_frame : callable, optional
        Called as ``each_frame(index, time_s, frame, position, likelihood,
        status)`` after each frame (a labelled video, a contact sheet).

    Returns
    -------
    Tracker
        ``tracker``, for chaining.
    """
    for item in itertools.chain(frames, [None]):
        rows = tracker.flush() if item is None else tracker.feed(item[2], item[1], item[0])
        for index, time_s, *marks, frame in rows:  # marks: position, likelihood, status
            writer.append(index, time_s, *marks)
            if each_frame is not None:
                each_frame(index, time_s, frame, *marks)
            if progress is not None:
                progress()
    return tracker


def _decoding_threads() -> int:
    """FFmpeg's threads beside the tracker's: one fewer than this process's cores, at
    least one. FFmpeg's own choice (a thread per core) took the tracker's core: on a
    quiet 2-core machine tracking ran at 0.73x plain decoding, with one thread 0.82x
    (tools/bench_tracking.py)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return max(1, (cores or 1) - 1)


def track_video(
    video: str | os.PathLike,
    out: str | os.PathLike | None = None,
    *,
    markers: MarkerSet | None = None,
    params: TrackerParams | None = None,
    rois: Mapping[str, ROI] | None = None,
    progress: bool = False,
    prefetch: int | None = None,
    labelled_video: str | os.PathLike | None = None,
    keep_truncated: bool = False,
    fps: float | None = None,
    frames: FrameSample | None = None,
    decoder_threads: int = 0,
) -> Path:
    """Track a video file into a tracks file (``<stem>.tracks.h5`` beside it by default).

    Parameters
    ----------
    video : str or os.PathLike
        Input video.
    out : str or os.PathLike, optional
        Output tracks file.
    markers, params, rois
        See :class:`Tracker`.
    progress : bool
        Show a progress bar on stderr.
    prefetch : int, optional
        Frames decoded ahead in a background thread (default: as many as fit
        in 32 MiB, 8 to 32, :class:`~perception.io.video.FrameSource`). The
        decoding thread sets the pace: with 8 frames ahead it waited 80-110 ms
        of a 3,510-frame clip while the tracker made its first detection or
        paused, with 32 (28 MiB of 640 x 480 frames) 2-14 ms.
    labelled_video : str or os.PathLike, optional
        Also write the video with the markers drawn on it
        (:class:`~perception.tracking.overlay.Labeller`), atomically.
    keep_truncated : bool
        Track the frames a truncated video does hold (its header claims
        more) instead of refusing it; a warning says how many are missing.
    fps : float, optional
        The true frame rate, frames/s, for a container whose rate or times
        are wrong: frame times become ``index / fps`` (the labelled video
        is written at this rate too).
    frames : FrameSample, optional
        Keeps a few of the frames as they are decoded (for the contact sheet).
    decoder_threads : int
        Threads FFmpeg decodes with (0: one fewer than the cores this process
        may use, at least one, so that tracking keeps a core; a batch worker
        passes 1, see :class:`~perception.io.video.FrameSource`).

    Returns
    -------
    Path
        The tracks file, written atomically.

    Raises
    ------
    InputError
        Bad video (see :class:`~perception.io.video.FrameSource`: truncated
        unless ``keep_truncated``, a frame rate no camera has unless ``fps``),
        a bad ROI, or a marker never found (the message says why: rejected
        candidates, or ambiguity); no output file is left behind.

    Notes
    -----
    OpenCV's thread pool is left as the caller set it: the ``hammer-mv``
    commands that track turn it off (:func:`hammer_mv.cli.serial_opencv`
    says why); a Python caller tracking many clips may do the same with
    ``cv2.setNumThreads(1)``.
    """
    from perception.boundary import expect

    expect(params, TrackerParams, "track_video(params=)", optional=True)
    markers = default_markers() if markers is None else markers
    out_path = tracks_path_for(video) if out is None else Path(out)
    tracker = Tracker(markers, params, rois)
    with contextlib.ExitStack() as stack:
        src = stack.enter_context(FrameSource(video, prefetch=prefetch,
                                              keep_truncated=keep_truncated, fps=fps,
                                              threads=decoder_threads or _decoding_threads()))
        # The first frame taken starts the decoding thread, which sets the pace: it
        # decodes ahead while the tracks file is opened (h5py's import, 23 ms).
        decoded = iter(src)
        first = next(decoded)
        # /video (with the file's SHA-256, read meanwhile) and /tracker are
        # written when tracking is done; until then only src.header is read.
        w = stack.enter_context(TracksWriter(out_path, markers.names))
        each = None
        if labelled_video is not None:
            rate = fps or src.header.fps_nominal or 30.0
            vw = stack.enter_context(VideoWriter(labelled_video, rate,
                                                 (src.header.width, src.header.height)))
            labeller = Labeller(markers.names, [m.bgr for m in markers])

            def each(index, time_s, frame, position, likelihood, status):
                vw.write(labeller.draw(frame, position, likelihood, status))
        if frames is not None:
            frames.start(src.header.n_frames_header, src.header.width * src.header.height * 3)
            label = each

            def each(index, time_s, frame, *marks):
                frames.offer(index, frame)
                if label is not None:
                    label(index, time_s, frame, *marks)

        bar = None
        if progress:
            from tqdm import tqdm

            bar = stack.enter_context(tqdm(total=src.header.n_frames_header or None, unit="frame",
                                           file=sys.stderr, desc=Path(video).name,
                                           leave=False))
        try:
            track_frames(itertools.chain([first], decoded), w, tracker,
                         progress=bar.update if bar else None, each_frame=each)
        except InputError as exc:
            if exc.path is None:
                raise InputError(exc.problem, video) from None
            raise
        missing = tracker.never_found
        if missing:
            why = "; ".join(f"{m}: {tracker.why_not_found(m)}" for m in missing)
            raise InputError(
                f"marker{'s' if len(missing) > 1 else ''} {', '.join(missing)} never found "
                f"in {src.n_decoded} frames ({why}); check the colour models and marker "
                "sizes (a setup file: hammer-mv calibrate), or give `rois` MARKER X Y W H",
                video,
            )
        w.update(video=src.attrs(), tracker=tracker.attrs())
    logger.info("%s: tracked %d frames -> %s", video, src.n_decoded, out_path)
    return out_path

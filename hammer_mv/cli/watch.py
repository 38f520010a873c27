"""``hammer-mv watch``: recognise a movement while it is filmed (docs/online.md)."""

from __future__ import annotations

import argparse
import math
import queue
import re
import sys
import threading
import time
from pathlib import Path

from hammer_mv.cli.options import add_recognition_options

#: A frame period longer than this many nominal periods means frames were dropped.
GAP_PERIODS = 1.5


def register(sub) -> None:
    """Add the ``watch`` subcommand to ``sub`` (an argparse subparsers action).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The top-level parser's subparsers.
    """
    p = sub.add_parser("watch", help="recognise a movement while it is filmed (camera, file, "
                       "stream)", description="Track SOURCE frame by frame and recognise the "
                       "movement as it unfolds: one line when the verdict settles (and with "
                       "--live one per frame), and when the stream ends (or on Ctrl-C) the "
                       "report `recognize` writes, DIR/<clip>.recognition.json and its CSV, "
                       "with an `online` entry: when the verdict settled, dropped frames.")
    p.add_argument("source", metavar="SOURCE",
                   help="camera index (0), video file, or stream URL FFmpeg opens "
                        "(udp://127.0.0.1:5000, tcp://HOST:PORT, rtsp://...)")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                   help="folder for the clip's report")
    p.add_argument("--clip", metavar="NAME",
                   help="clip name (default: the file's stem, camera<N> or stream)")
    p.add_argument("--live", action="store_true",
                   help="print a line per frame: time, leading model, provisional verdict")
    p.add_argument("--as-fast-as-possible", action="store_true",
                   help="read a video file as fast as it decodes (default: at its frame rate)")
    p.add_argument("--labelled-video", type=Path, metavar="OUT.mp4",
                   help="also write the frames with the markers and confidence bars drawn")
    p.add_argument("--stall-timeout", type=float, default=5.0, metavar="S",
                   help="a camera or stream that sends no frame for this long has ended")
    p.add_argument("--no-figures", action="store_true",
                   help="write the JSON and CSV only, not the figures")
    add_recognition_options(p)
    p.set_defaults(func=run)


def _frames(source: str, settings, args):
    """``(kind, header fps, iterator of (index, time s, frame), info)`` of ``source``."""
    from perception.errors import InputError

    kind = _device(source)
    if kind is not None:  # a camera's frames are timed by this clock, a stream's by its own
        camera = kind == "camera"
        return kind, *_capture(int(source) if camera else source, args, clock=camera)
    path = Path(source)
    if not path.exists():
        raise InputError("no such file (nor a camera index or stream URL)", path)
    from perception.io.video import FrameSource

    src = FrameSource(path, keep_truncated=settings.keep_truncated, fps=settings.fps)
    return "file", src.header.fps_nominal, iter(src), src


def _device(source: str) -> str | None:
    """``"camera"`` or ``"stream"`` for a camera index or a URL; None for a file."""
    if re.fullmatch(r"\d+", source):
        return "camera"
    return "stream" if "://" in source else None


def _capture(target, args, *, clock: bool):
    """Frames of a camera or stream, read in a thread so that the source is drained.

    Times are the stream's own (its time stamps) or, for a camera, this
    process's clock when the frame came: never an index over a frame rate.
    """
    import cv2

    from perception.errors import InputError
    from perception.io.video import TimeResolver

    stall = args.stall_timeout
    if not (math.isfinite(stall) and stall > 0):
        raise InputError(f"expected a positive number of seconds, got {stall}",
                         field="--stall-timeout")
    ms = int(stall * 1000)
    cap = cv2.VideoCapture(target, cv2.CAP_ANY if clock else cv2.CAP_FFMPEG,
                           [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, max(ms, 10000),
                            cv2.CAP_PROP_READ_TIMEOUT_MSEC, ms])
    if not cap.isOpened():
        raise InputError("cannot open the camera or stream", str(target))
    fps = cap.get(cv2.CAP_PROP_FPS)
    fps = float(fps) if math.isfinite(fps) and 0 < fps < 1000 else 0.0
    times = TimeResolver(fps or 30.0)
    out: queue.SimpleQueue = queue.SimpleQueue()
    stop = threading.Event()  # set when the frames are no longer wanted

    def read() -> None:
        t0, n = time.monotonic(), 0
        try:
            while not stop.is_set():
                ok, frame = cap.read()
                if not ok or frame is None:
                    break
                t = time.monotonic() - t0 if clock else times(cap.get(cv2.CAP_PROP_POS_MSEC))
                out.put((n, t, frame))
                n += 1
        finally:  # a read that raised ends the stream too, not the wait for it
            out.put(None)
            cap.release()

    threading.Thread(target=read, name="watch-reader", daemon=True).start()
    return fps, _received(out, stall, stop), None


#: Seconds past ``--stall-timeout`` before the wait for a stuck reader ends.
STALL_GRACE = 1.0


def _received(out: queue.SimpleQueue, stall: float, stop: threading.Event):
    """The reader's frames until it ends or sends none for ``stall`` s.

    The backend's read timeout does not hold everywhere (a camera's driver
    may block in ``read`` for good): the wait ends here too, whatever the
    reader is stuck in, :data:`STALL_GRACE` s later, once FFmpeg, where its
    timeout holds, has ended the stream and handed over the frames its
    decoder still held.
    """
    try:
        while True:
            try:
                item = out.get(timeout=stall + STALL_GRACE)
            except queue.Empty:
                return
            if item is None:
                return
            yield item
    finally:
        stop.set()


def _clip(source: str, kind: str, name: str | None) -> str:
    if name:
        return name
    return {"camera": f"camera{source}", "stream": "stream"}.get(kind) or Path(source).stem


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv watch`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    import numpy as np

    from hammer_mv.cli.checks import output_folder
    from hammer_mv.cli.options import load_repertoire, recognition_settings
    from perception.io.atomic import check_output
    from perception.online import OnlineRecognizer, decision_summary
    from perception.pipeline import clip_fingerprint
    from perception.report.clip import write_clip_report
    from perception.report.tracking import write_tracking_report

    output_folder(args.output)
    if args.labelled_video is not None:  # refused before the first frame, not after
        files = [args.repertoire, None if _device(args.source) else args.source]
        check_output(args.labelled_video, [f for f in files if f is not None])
    settings = recognition_settings(args)
    rep, rep_id = load_repertoire(args)
    kind, fps, frames, src = _frames(args.source, settings, args)
    clip = _clip(args.source, kind, args.clip)
    rec = OnlineRecognizer(rep, settings, clip=clip)
    say = (lambda line: None) if args.quiet else (lambda line: print(line, flush=True))
    draw = _Drawer(args.labelled_video, fps) if args.labelled_video else None
    pace = kind == "file" and not args.as_fast_as_possible
    latency, dropped, last_t, decided, interrupted = [], 0, None, None, False
    start = time.monotonic()
    try:
        for index, t, frame in frames:
            if pace:  # played at its own rate
                time.sleep(max(0.0, t - (time.monotonic() - start)))
            if last_t is not None and fps > 0 and t - last_t > GAP_PERIODS / fps:
                dropped += int(round((t - last_t) * fps)) - 1
            last_t = t
            t0 = time.perf_counter()
            state = rec.update(frame, t, index)
            latency.append(time.perf_counter() - t0)
            if draw is not None:
                draw(frame, state, rec)
            if args.live:
                say(f"{t:8.3f} s  {state.phase:<6}  {state.leading or '-':<12} "
                    f"{state.verdict or '-':<9} {'settled' if state.settled else ''}")
            if state.decision is not None and decided is None:
                decided = state.decision
                detail = f" ({decided.detail})" if decided.detail else ""
                say(f"{clip}: settled {decided.verdict}{detail} at {decided.time:.3f} s "
                    f"({decided.since_onset:.3f} s after the onset)")
    except KeyboardInterrupt:  # the outputs of what was seen
        interrupted = True
    except BaseException:  # a failed run leaves no labelled video behind
        if draw is not None:
            draw.close(*sys.exc_info())
        raise
    if draw is not None:
        draw.close()
    video = src.attrs() if src is not None else {"source": args.source, "fps": fps}
    result = rec.finish(video, source=args.source)
    online = {**decision_summary(result, rec.decision), "source": kind,
              "frames": len(latency), "dropped_frames": dropped, "interrupted": interrupted,
              "latency_ms": {"median": float(np.median(latency) * 1e3),
                             "p99": float(np.percentile(latency, 99) * 1e3)}}
    tracks = rec.tracks(video)
    extra = {"fingerprint": clip_fingerprint(args.source, settings, rep_id)} if kind == "file" \
        else {}
    extra.update({"condition": None, "input": args.source,
                  "tracking": write_tracking_report(tracks, args.output, clip, sheet=False),
                  "online": online})
    paths = write_clip_report(result, args.output, extra=extra, figures=not args.no_figures)
    detail = f" ({result.verdict_detail})" if result.verdict_detail else ""
    say(f"{clip}: {result.verdict or 'no verdict'}{detail}, winner {result.winner} "
        f"({len(latency)} frames, {dropped} dropped) -> {paths['json']}")
    return 130 if interrupted else 0


class _Drawer:
    """The labelled video: markers (as ``track --labelled-video``) and a bar per model."""

    def __init__(self, path: Path, fps: float):
        self.path, self.fps, self.writer, self.labeller = path, fps or 30.0, None, None

    def __call__(self, frame, state, rec) -> None:
        import cv2
        import numpy as np

        from perception.io.video import VideoWriter
        from perception.tracking.overlay import Labeller

        if self.writer is None:
            # kept only once entered: close() must not finish a writer that never opened
            self.writer = VideoWriter(self.path, self.fps,
                                      (frame.shape[1], frame.shape[0])).__enter__()
            self.labeller = Labeller(rec.markers, [(0, 255, 255)] * len(rec.markers))
        row = rec.last_row
        img = frame.copy() if row is None else self.labeller.draw(frame, *row)
        ll = np.asarray(state.log_likelihood, dtype=float)
        share = np.exp(ll - ll.max()) / np.exp(ll - ll.max()).sum() if ll.size else ll
        # stacked above the verdict line: the top left holds the markers' legend
        bottom = img.shape[0] - 30 - 14 * (len(state.names) - 1)
        for i, (name, p) in enumerate(zip(state.names, share)):
            y = bottom + 14 * i
            cv2.rectangle(img, (8, y - 9), (8 + int(120 * p), y + 1), (80, 200, 80), -1)
            cv2.putText(img, name, (132, y), cv2.FONT_HERSHEY_PLAIN, 0.9, (255, 255, 255))
        text = f"{state.verdict or '-'}{' (settled)' if state.settled else ''}"
        cv2.putText(img, text, (8, img.shape[0] - 10), cv2.FONT_HERSHEY_PLAIN, 1.2,
                    (255, 255, 255), 1)
        self.writer.write(img)

    def close(self, *exc_info) -> None:
        """Finish the video; given an exception's ``sys.exc_info()``, discard it instead."""
        writer, self.writer = self.writer, None
        if writer is not None:
            writer.__exit__(*(exc_info or (None, None, None)))

"""``hammer-mv watch``: recognise a movement while it is filmed (docs/online.md)."""

from __future__ import annotations

import argparse
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
    from perception.io.capture import source_kind
    from perception.io.video import open_source
    from perception.online import OnlineRecognizer, decision_summary
    from perception.pipeline import clip_fingerprint
    from perception.report.clip import write_clip_report
    from perception.report.tracking import write_tracking_report

    output_folder(args.output)
    if args.labelled_video is not None:  # refused before the first frame, not after
        files = [args.repertoire, args.source if source_kind(args.source) == "file" else None]
        check_output(args.labelled_video, [f for f in files if f is not None])
    settings = recognition_settings(args)
    rep, rep_id = load_repertoire(args)
    latency, dropped, last, decided, interrupted = [], 0, None, None, False
    with (open_source(args.source, stall_timeout=args.stall_timeout, fps=settings.fps,
                      keep_truncated=settings.keep_truncated) as src,
          _Drawer(args.labelled_video, src.fps) as draw):  # a failed run leaves no video
        kind, fps = src.kind, src.fps
        clip = args.clip or {"camera": f"camera{args.source}", "stream": "stream"}.get(kind) \
            or Path(args.source).stem
        rec = OnlineRecognizer(rep, settings, clip=clip)
        say = (lambda line: None) if args.quiet else (lambda line: print(line, flush=True))
        pace, start = kind == "file" and not args.as_fast_as_possible, time.monotonic()
        try:
            for index, t, frame in src:
                if pace:  # played at its own rate
                    time.sleep(max(0.0, t - (time.monotonic() - start)))
                if last is not None:  # frames the read-ahead dropped, or never sent
                    gap = fps > 0 and t - last[1] > GAP_PERIODS / fps
                    dropped += max(index - last[0], round((t - last[1]) * fps) if gap else 1) - 1
                last = index, t
                t0 = time.perf_counter()
                state = rec.update(frame, t, index)
                latency.append(time.perf_counter() - t0)
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
    video = src.attrs()
    result = rec.finish(video, source=args.source)
    online = {**decision_summary(result, rec.decision), "source": kind,
              "frames": len(latency), "dropped_frames": dropped,
              "read_ahead_dropped": src.dropped, "interrupted": interrupted,
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
    """The labelled video (none if ``path`` is None): markers (as ``track``'s) and model bars."""

    def __init__(self, path: Path | None, fps: float):
        self.path, self.fps, self.writer, self.labeller = path, fps or 30.0, None, None

    def __enter__(self) -> _Drawer:
        return self

    def __call__(self, frame, state, rec) -> None:
        if self.path is None:
            return
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

    def __exit__(self, *exc_info) -> None:
        """Finish the video; when the block raised, discard it instead."""
        writer, self.writer = self.writer, None
        if writer is not None:
            writer.__exit__(*exc_info)

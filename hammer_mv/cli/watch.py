"""``hammer-mv watch``: recognise a movement while it is filmed (docs/online.md)."""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import threading
import time
from pathlib import Path

from hammer_mv.cli import _user_error
from hammer_mv.cli.options import add_recognition_options
from perception.errors import HammerMVError

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
                   help="camera index (0), video file, stream URL FFmpeg opens "
                        "(udp://127.0.0.1:5000, tcp://HOST:PORT, rtsp://...), a pose "
                        "file (DeepLabCut, SLEAP, ...) fed row by row, or a motion-capture "
                        "recording (C3D, OpenSim TRC, Qualisys TSV, a lab table) replayed "
                        "reach by reach")
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
    from hammer_mv.cli.flags import field_flag

    field_flag("stall_timeout", "--stall-timeout")
    p.add_argument("--no-figures", action="store_true",
                   help="write the JSON and CSV only, not the figures")
    add_recognition_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv watch`` with parsed ``args``; return the exit status.

    SIGINT, SIGTERM and SIGHUP end the watch with the report of what was seen, exit
    status 128 + the signal's number; their handlers are the watch's only (restored
    when it ends).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    with _Signals() as signals:
        try:
            return _watch(args, signals)
        except (KeyboardInterrupt, HammerMVError) as exc:
            if isinstance(exc, HammerMVError) and signals.received is None:
                raise
            # before the first frame, or too few frames to report
            why = f", no report: {exc}" if isinstance(exc, HammerMVError) else ""
            print(f"hammer-mv watch: interrupted ({signals.name or 'SIGINT'}){why}",
                  file=sys.stderr)
            return 128 + (signals.received or signal.SIGINT)


def _watch(args: argparse.Namespace, signals: _Signals) -> int:
    """:func:`run`'s watch, ``signals`` its handlers."""
    from hammer_mv.cli.checks import writable_folder
    from hammer_mv.cli.options import load_repertoire, recognition_settings
    from perception.errors import InputError
    from perception.io.atomic import check_output
    from perception.io.capture import RowsSource, source_kind
    from perception.io.video import codec_for, open_source
    from perception.online import OnlineRecognizer
    from perception.pipeline import clip_fingerprint, clip_name, load_clip
    from perception.report import clip as report
    from perception.report.tracking import write_tracking_report
    from perception.sources import check_command

    taken = check_command(args.source, "watch")  # a tracks file: recognize's
    if taken is not None and taken.name == "mocap":
        return _watch_recording(args, signals)
    kind = source_kind(args.source)
    if taken is not None and taken.name == "pose":
        kind = "pose"  # a pose file's keypoints, row by row
    clip = args.clip or clip_name(args.source)[0]
    # every output refused before the source opens if it cannot be written or is an input
    # (the source named as a path or as FFmpeg's file: URL)
    source = [] if kind == "camera" else [args.source, args.source.removeprefix("file:")]
    inputs = [f for f in (args.repertoire, *source) if f is not None]
    for path in report.clip_outputs(writable_folder(args.output), clip).values():
        check_output(path, inputs)
    if args.labelled_video is not None and kind == "pose":
        raise InputError("a pose file has no frames to label (track the video instead)",
                         args.labelled_video, field="--labelled-video")
    if args.labelled_video is not None:
        codec_for(check_output(args.labelled_video, inputs))
        writable_folder(args.labelled_video.parent, "--labelled-video")
    settings = recognition_settings(args)
    rep, rep_id = load_repertoire(args)
    with (_Drawer(args.labelled_video) as draw,  # a watch that fails leaves no video
          (RowsSource(load_clip(args.source, pose=settings.pose, **settings.video_options()),
                      args.source) if kind == "pose" else
           open_source(args.source, stall_timeout=args.stall_timeout, fps=settings.fps,
                       keep_truncated=settings.keep_truncated)) as src):
        rows = getattr(src, "tracks", None)
        rec = OnlineRecognizer(rep, settings, clip=clip) if rows is None else OnlineRecognizer(
            rep, settings, clip=clip, markers=rows.markers, tracker_attrs=dict(rows.tracker))
        online = _stream(src, rec, args, signals, draw, pace=kind in ("file", "pose"))
        video = src.attrs()
        result = rec.finish(video, source=args.source)
        extra = {"fingerprint": clip_fingerprint(args.source, settings, rep_id)} \
            if kind in ("file", "pose") else {}
        extra.update({"condition": None, "input": args.source,
                      "tracking": write_tracking_report(rec.tracks(video), args.output, clip,
                                                        sheet=False),
                      "online": {**online(result), "source": kind}})
        paths = report.write_clip_report(result, args.output, extra=extra,
                                         figures=not args.no_figures)
    _say_result(args, clip, result, online, paths)
    if draw.error is not None:  # the user's disk or folder: the report is kept, status 2
        print(f"hammer-mv watch: error: labelled video not written: {draw.error}",
              file=sys.stderr)
    return 128 + signals.received if signals.received else 2 if draw.error else 0


def _watch_recording(args: argparse.Namespace, signals: _Signals) -> int:
    """``watch`` of a motion-capture recording: each reach's rows streamed as a pose file's,
    then scored as ``recognize`` scores it, every trial accounted for as it does
    (docs/online.md). A signal ends the replay after the reach under way is reported."""
    from hammer_mv.cli.recording import score_recording
    from perception.errors import InputError
    from perception.io.capture import RowsSource
    from perception.online import OnlineRecognizer
    from perception.recordings import prepare_reach

    if args.labelled_video is not None:
        raise InputError("a motion-capture recording has no frames to label (leave out "
                         "--labelled-video)", args.labelled_video, field="--labelled-video")
    path = Path(args.source)

    def named(entry):  # --clip names the recording: its trials and reaches keep their tails
        if args.clip is None:
            return entry.name
        return args.clip + (entry.name[len(path.stem):] if entry.name.startswith(path.stem)
                            else f"-{entry.name}")

    def score(reach, settings, options, rep):
        prepared = prepare_reach(reach, settings, options)
        rows = prepared.tracks
        rec = OnlineRecognizer(rep, prepared.settings, clip=reach.name, markers=rows.markers,
                               tracker_attrs=dict(rows.tracker))
        with RowsSource(rows, str(path)) as src:
            online = _stream(src, rec, args, signals, _Drawer(None), pace=True)
        result = rec.finish(dict(rows.video), source=reach.source, paths=prepared.paths)
        return result, {"mocap": prepared.info, "online": {**online(result),
                                                           "source": "recording"}}, \
            lambda rec, paths: _say_result(args, reach.name, rec, online, paths, rows=True)

    def stopped():
        return f"not replayed: watch interrupted ({signals.name})" if signals.received else None

    status = score_recording(args, path, score, name=named, stopped=stopped)
    return 128 + signals.received if signals.received else status


def _stream(src, rec, args: argparse.Namespace, signals: _Signals, draw: _Drawer, *,
            pace: bool):
    """Feed ``src``'s frames (or rows) to ``rec`` one at a time, printing what
    :func:`_say_state` prints; a signal ends it. Return ``online(result)``: the report's
    ``online`` entry once ``rec`` is finished into ``result``.

    A file (or a recording's rows) is played at its own rate unless
    ``--as-fast-as-possible``. A frame is judged and drawn whole or not at all; from the
    end of the stream on, a signal waits for the outputs.
    """
    import numpy as np

    from perception.online import decision_summary

    say = (lambda line: None) if args.quiet else (lambda line: print(line, flush=True))
    pace = pace and not args.as_fast_as_possible
    latency, dropped, last, decided, interrupted = [], 0, None, None, False
    start = time.monotonic()
    try:
        if signals.received:  # came while the outputs of an earlier reach were written
            raise KeyboardInterrupt
        signals.holding = False
        for index, t, frame in src:
            if pace:
                time.sleep(max(0.0, t - (time.monotonic() - start)))
            if last is not None:  # frames the read-ahead dropped, or never sent
                gap = src.fps > 0 and t - last[1] > GAP_PERIODS / src.fps
                dropped += max(index - last[0], round((t - last[1]) * src.fps) if gap else 1) - 1
            last = index, t
            signals.holding = True
            t0 = time.perf_counter()
            state = (rec.update(frame[0], t, index, likelihood=frame[1], status=frame[2])
                     if isinstance(frame, tuple) else rec.update(frame, t, index))
            latency.append(time.perf_counter() - t0)
            draw(frame, state, rec)
            signals.holding = False
            if signals.received:  # one came meanwhile
                raise KeyboardInterrupt
            decided = _say_state(say, rec.clip, t, state, decided, args.live)
    except KeyboardInterrupt:  # the outputs of what was seen
        interrupted = True
    signals.holding = True
    src.close()
    error = draw.finish()
    ms = np.asarray(latency) * 1e3
    return lambda result: {
        **decision_summary(result, rec.decision), "frames": len(latency),
        "dropped_frames": dropped, "read_ahead_dropped": src.dropped,
        "interrupted": interrupted, "signal": signals.name if interrupted else None,
        "labelled_video_error": error,
        "latency_ms": {"median": float(np.median(ms)), "p99": float(np.percentile(ms, 99))}}


def _say_result(args: argparse.Namespace, clip: str, result, online, paths: dict, *,
                rows: bool = False) -> None:
    """The final line of a clip or reach (``rows``: a recording's): its verdict, winner,
    frames (rows) and report."""
    if not args.quiet:
        info = online(result)
        seen = (f"{info['frames']} rows" if rows else
                f"{info['frames']} frames, {info['dropped_frames']} dropped")
        detail = f" ({result.verdict_detail})" if result.verdict_detail else ""
        print(f"{clip}: {result.verdict or 'no verdict'}{detail}, winner {result.winner} "
              f"({seen}) -> {paths['json']}", flush=True)


def _say_state(say, clip: str, t: float, state, decided, live: bool):
    """Print a frame's state (``--live``: a settled verdict in capitals, a provisional one
    with a ?) and the verdict the first time it settles; return the settled one so far."""
    if live:
        say(f"{t:8.3f} s  {state.phase:<6}  {state.leading or '-':<12} {_shown(state):<22}")
    if state.decision is not None and decided is None:
        decided = state.decision
        detail = f" ({decided.detail})" if decided.detail else ""
        say(f"{clip}: settled {decided.verdict}{detail} at {decided.time:.3f} s "
            f"({decided.since_onset:.3f} s after the onset)")
    return decided


def _shown(state) -> str:
    """A state's verdict as the live lines and the labelled video show it: the settled one in
    capitals (it stays), else the provisional one with a question mark."""
    d = state.decision
    if d is not None:
        return f"SETTLED {d.verdict.upper()}" + (f" ({d.detail})" if d.detail else "")
    if state.verdict is None:
        return "-"
    return f"{state.verdict}?" + (f" ({state.verdict_detail})" if state.verdict_detail else "")


class _Signals:
    """SIGINT, SIGTERM and SIGHUP while a watch runs (set from the main thread only; one
    the process ignores, as under ``nohup``, stays ignored).

    The first ends the watch: a ``KeyboardInterrupt`` at once, or, while the watch is
    ``holding`` (a frame, the outputs), when that is done. Later ones change nothing.
    """

    def __init__(self):
        self.received, self.holding, self.previous = None, False, {}

    def __enter__(self) -> _Signals:
        if threading.current_thread() is threading.main_thread():
            for number in (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", None)):
                if number is not None and signal.getsignal(number) is not signal.SIG_IGN:
                    self.previous[number] = signal.signal(number, self._received)
        return self

    def _received(self, number: int, frame) -> None:
        first, self.received = self.received is None, self.received or number
        if first and not self.holding:
            raise KeyboardInterrupt

    @property
    def name(self) -> str | None:
        """The first signal's name (``"SIGTERM"``), or None."""
        return None if self.received is None else signal.Signals(self.received).name

    def __exit__(self, *exc_info) -> None:
        for number, handler in self.previous.items():
            signal.signal(number, signal.SIG_DFL if handler is None else handler)


class _Drawer:
    """The labelled video (none if ``path`` is None): markers (as ``track``'s) and model bars.

    A failure to write it (a full disk) costs the video only: it is discarded, the
    watch goes on, and ``error`` tells it. A watch that fails leaves none.
    """

    def __init__(self, path: Path | None):
        self.path, self.fps, self.writer, self.error, self.done = path, 0.0, None, None, False

    def __enter__(self) -> _Drawer:
        return self

    def __call__(self, frame, state, rec) -> None:
        if self.path is not None and self.error is None:
            try:
                self._draw(frame, state, rec)
            except (OSError, HammerMVError) as exc:
                self.error = _user_error(exc)
                self.__exit__(type(exc), exc, exc.__traceback__)

    def _draw(self, frame, state, rec) -> None:
        import cv2
        import numpy as np

        from perception.io.video import VideoWriter
        from perception.tracking.overlay import Labeller

        if self.writer is None:
            # kept only once entered: close() must not finish a writer that never opened
            self.writer = VideoWriter(self.path, self.fps or 30.0,
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
        text = _shown(state)
        cv2.putText(img, text, (8, img.shape[0] - 10), cv2.FONT_HERSHEY_PLAIN, 1.2,
                    (255, 255, 255), 1)
        self.writer.write(img)

    def finish(self) -> str | None:
        """Finish the video (under its own name); the error that cost it, if one did."""
        writer, self.writer = self.writer, None
        try:
            if writer is not None:
                writer.__exit__(None, None, None)
                self.done = True
        except (OSError, HammerMVError) as exc:  # its temporary file is removed
            self.error = _user_error(exc)
        return self.error

    def __exit__(self, *exc_info) -> None:
        """When the block raised, discard the video (remove it if already finished)."""
        writer, self.writer = self.writer, None
        if exc_info[0] is not None and writer is not None:
            with contextlib.suppress(OSError):  # an OSError is raised again, renamed
                writer.__exit__(*exc_info)
        elif exc_info[0] is not None and self.done:
            self.path.unlink(missing_ok=True)

"""``hammer-mv``: the command line interface.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``, which adds its parser and sets ``func`` (a callable
taking the parsed ``argparse.Namespace`` and returning an exit status). Every
parser shows its defaults, and every command takes ``-v/--verbose`` and
``--quiet`` before or after its name.

A user's mistake (a :class:`~perception.errors.HammerMVError`, or an
``OSError`` from the user's files) is printed as one line on stderr and exits
with status 2 (:func:`error_line`: where the library names a field, the line
names the flag that sets it, :mod:`hammer_mv.cli.flags`); anything else (a
bare ``ValueError`` included) is a bug: it shows its traceback, a line saying
so, and exits with status 1. Library warnings
(numpy's RuntimeWarnings and the like) are shown with ``-v``; otherwise they
are counted and summarised in one line at the end (nothing with ``--quiet``).
"""

from __future__ import annotations

import argparse
import gc
import importlib
import logging
import os
import sys
import traceback
import warnings
from pathlib import Path

from minvar import __version__
from perception.errors import HammerMVError

#: Subcommands, in the order ``--help`` lists them, and their one-line help. A
#: command's module (``hammer_mv.cli.<name>``) is imported only when that
#: command runs (or for the full parser), so ``--version`` and ``--help``
#: start at once; tests/test_cli.py checks these lines against the modules.
COMMANDS = {
    "reach": "simulate noisy repetitions of a reach (figures + CSV)",
    "grasp": "simulate reach-to-grasp movements and the thesis's chapter 4 experiments",
    "synth": "render synthetic grasp clips from a recipe",
    "calibrate": "learn the colour models and marker sizes of a setup from one clip",
    "track": "track the thumb, finger, wrist and object markers of a video",
    "tracks": "inspect or export a tracks file",
    "repertoire": "build or inspect a model repertoire",
    "recognize": "recognise the grasp in one video or tracks file",
    "landmarks": "measure reach-to-grasp landmarks, no models (CSV)",
    "batch": "recognise a folder of clips (or a synth manifest)",
    "watch": "recognise a movement while it is filmed (camera, file, stream)",
}

_EVERY = object()

#: Thread-pool sizes of BLAS and OpenMP a user may set: where one is set, the
#: command leaves the thread pools as the libraries read it (:func:`one_blas_thread`).
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "VECLIB_MAXIMUM_THREADS")

#: The commands that track video: OpenCV's own thread pool is off while they
#: run (:func:`serial_opencv`).
TRACKING_COMMANDS = frozenset({"calibrate", "track", "recognize", "batch", "watch"})


def serial_opencv() -> None:
    """Turn OpenCV's own thread pool off in this process (``cv2.setNumThreads(1)``).

    Tracking converts small regions, a few thousand pixels each, which
    OpenCV still splits over its pool: a second thread then spins for as
    long as the first converts, on the core FFmpeg's decoding threads (not
    OpenCV's pool) need; the split costs more time than it saves. The
    library leaves the process-wide setting alone; the commands that track
    (:data:`TRACKING_COMMANDS`) set it here, when they run, so that
    ``--version`` and ``--help`` never load OpenCV.
    """
    import cv2

    cv2.setNumThreads(1)


def _may_track(args: argparse.Namespace) -> bool:
    """Whether the command may track video: ``recognize`` of a tracks, pose or
    motion-capture file does not, and need not load OpenCV (0.2 s) to set its pool."""
    if args.command != "recognize":
        return True
    from perception.pipeline import VIDEO_SUFFIXES

    return Path(args.input).suffix.lower() in VIDEO_SUFFIXES


def one_blas_thread() -> None:
    """One BLAS/OpenMP thread in this process (``threadpoolctl.threadpool_limits``),
    unless the user set one of :data:`THREAD_VARIABLES`.

    Every matrix here is small, and waking a BLAS thread pool costs more than
    it saves (planning a repertoire: 0.17 s with one thread, 0.25 s with two).
    The limit reaches the thread pools loaded when it is set: numpy's BLAS
    (loaded here) and, for the commands that track, OpenCV's
    (:func:`serial_opencv` runs first). The worker processes of ``--jobs``
    limit their own (:func:`perception.workers.init_worker`).
    """
    if any(os.environ.get(name) for name in THREAD_VARIABLES):
        return
    import numpy  # noqa: F401 - its BLAS loaded, so that the limit reaches it
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)


#: What ``hammer-mv --help`` says before the commands.
DESCRIPTION = """\
Minimum variance models of reaching and grasping, and HAMMER-MV grasp recognition.

  video --track--> tracks (.tracks.h5) --observe--> the movement in metres
        --recognize--> every model of the repertoire predicts each frame
        --report--> winner, verdict, confidence profiles (JSON, CSV, figures, HTML)

example:
  hammer-mv synth datasets/smoke.toml -o clips      # render test clips
  hammer-mv recognize clips/normal-01.mp4 -o out    # track and recognise one
  hammer-mv batch clips/manifest.csv -o report      # all of them: report/report.html

'hammer-mv COMMAND --help' describes each command; docs/ describes the files."""


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Descriptions as written; each option's default shown unless its help gives it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if ("default" in text or default is None or default is argparse.SUPPRESS
                or isinstance(default, bool) or action.option_strings == []):
            return text
        shown = " ".join(map(str, default)) if isinstance(default, list | tuple) else default
        return f"{text} (default: {shown})"


class _Parser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line and exit status 2, defaults shown."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {message}\n")


def _common_flags(parser: argparse.ArgumentParser, top: bool = True) -> None:
    """Give ``parser`` and every command parser below it ``-v/--verbose`` and ``--quiet``.

    Below the top level they default to SUPPRESS, so ``hammer-mv -v track``
    and ``hammer-mv track -v`` mean the same.
    """
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    for child in {id(c): c for a in subs for c in a.choices.values()}.values():
        _common_flags(child, top=False)
    if top or not subs:
        default = False if top else argparse.SUPPRESS
        parser.add_argument("-v", "--verbose", action="store_true", default=default,
                            help="log progress details and show library warnings")
        parser.add_argument("--quiet", action="store_true", default=default,
                            help="no progress bars or summaries")


def build_parser(command: str | None | object = _EVERY) -> argparse.ArgumentParser:
    """Return the top-level parser.

    Parameters
    ----------
    command : str or None, optional
        Register only this subcommand in full (the others get a stub that
        lists them in ``--help``), or none with None; by default every one.
    """
    parser = _Parser(prog="hammer-mv", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"hammer-mv {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name, summary in COMMANDS.items():
        if command is _EVERY or command == name:
            importlib.import_module(f"{__name__}.{name}").register(sub)
        else:
            sub.add_parser(name, help=summary)
    _common_flags(parser)
    return parser


def _command(argv: list[str]) -> str | None:
    for arg in argv:
        if arg == "--":
            return None
        if not arg.startswith("-"):
            return arg if arg in COMMANDS else None
    return None


def _first_line(text: str) -> str:
    text = text.strip()
    return text.splitlines()[0] if text else ""


def _user_error(exc: BaseException) -> str:
    """The one line that tells a user's mistake: the file (and field) and the problem."""
    if isinstance(exc, OSError) and not isinstance(exc, HammerMVError):
        names = [str(f) for f in (exc.filename, exc.filename2) if f is not None]
        reason = _first_line(exc.strerror or str(exc)) or type(exc).__name__
        return f"{' -> '.join(names)}: {reason}" if names else reason
    return _first_line(str(exc)) or type(exc).__name__


def error_line(command: str, exc: HammerMVError | OSError) -> str:
    """The one line ``main`` prints for a user's mistake, the fields it names given as the
    command's flags (``--px-per-m``, where the library says ``px_per_m``).

    Parameters
    ----------
    command : str
        The command that ran (its flags are those its parser registered).
    exc : HammerMVError or OSError
        The error.
    """
    from hammer_mv.cli.flags import as_flags

    return f"hammer-mv {command}: error: {_user_error(as_flags(exc))}"


def _warnings_line(command: str, caught: list[warnings.WarningMessage]) -> str:
    first = caught[0]
    return (f"hammer-mv {command}: {len(caught)} library warning(s) hidden (first: "
            f"{first.category.__name__}: {_first_line(str(first.message))}); -v shows them")


def _run(args: argparse.Namespace) -> int:
    """Run the command; library warnings shown with -v, else counted in one line at the end.

    Without ``-v`` the warnings the filters let through (the user's own
    ``-W``/``PYTHONWARNINGS`` included) are recorded instead of printed: a
    long run is not buried in numpy's RuntimeWarnings, yet none goes unseen.
    A command that fails prints its one line only. Our own warnings go
    through ``logging`` and show as always. The commands that track run
    with OpenCV's thread pool off (:func:`serial_opencv`), every command with
    one BLAS thread (:func:`one_blas_thread`).
    """
    if args.command in TRACKING_COMMANDS and _may_track(args):
        serial_opencv()
    one_blas_thread()
    if args.verbose:
        return int(args.func(args) or 0)
    with warnings.catch_warnings(record=True) as caught:
        status = int(args.func(args) or 0)
    if caught and not args.quiet:
        print(_warnings_line(args.command, caught), file=sys.stderr)
    return status


def entry() -> int:
    """The ``hammer-mv`` command (console script and ``python -m hammer_mv``): :func:`main`,
    with no cyclic garbage collection while the command's modules import, and the
    objects made so far frozen out of the interpreter's last collection.

    The imports make hundreds of thousands of objects (numpy, scipy, pydantic, ...) and
    no garbage worth collecting; each collection meanwhile walks them all: about 6 % of a
    ``recognize``'s start-up. Collection resumes, those objects frozen out of it, before
    the command runs (:func:`main`'s ``quiet_start``). The last collection walked them
    too: about 40 ms of a 0.4 s ``track`` of a short clip. Not in :func:`main`, which
    tests and scripts call in their own processes.
    """
    gc.disable()
    sys.stdout = _Console(sys.stdout)
    status = main(quiet_start=True)
    gc.freeze()
    return status


class _Console:
    """Standard output that goes quiet, not the command, when its reader closes early.

    ``hammer-mv recognize REC | head -1``: the reader leaves after a line and the next
    print raises ``BrokenPipeError``, which stopped the command half-way (two of four
    reaches reported, no trials table). The command's work is its files; the console is
    a view of it. So the first write that finds the pipe closed points the stream at
    ``os.devnull`` (the interpreter's own flush at exit would fail too) and the command
    goes on; the console's lines after it are dropped.
    """

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._reader_gone()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._reader_gone()

    def _reader_gone(self) -> None:
        try:
            descriptor = self._stream.fileno()
        except (AttributeError, OSError, ValueError):  # a stream without one: replace it
            self._stream = open(os.devnull, "w")  # noqa: SIM115 - the process's, to its end
            return
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, descriptor)
        os.close(devnull)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv: list[str] | None = None, *, quiet_start: bool = False) -> int:
    """Run ``hammer-mv`` with ``argv`` (default ``sys.argv[1:]``); return the exit status.

    0 on success; 1 if some of the work failed (a batch's clips) or on a bug
    (its traceback shown); 2 for a user's mistake (one line on stderr); 130
    when interrupted.

    Parameters
    ----------
    argv : list of str, optional
        The arguments.
    quiet_start : bool
        Garbage collection is off while the command's modules import (:func:`entry`):
        freeze what they made and turn it on before the command runs.
    """
    # FFmpeg and OpenCV print their own warnings about broken files on stderr;
    # we report those files in one line ourselves. Set before any video opens.
    os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
    os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(_command(argv))
    args = parser.parse_args(argv)
    if quiet_start:
        gc.freeze()
        gc.enable()
    ours = set(logging.getLogger().handlers)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    for handler in set(logging.getLogger().handlers) - ours:  # the handler made here only
        handler.addFilter(_flag_words)
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return 2
    try:
        return _run(args)
    except (HammerMVError, OSError) as exc:  # the user's to fix: one line
        print(error_line(args.command, exc), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("hammer-mv: interrupted", file=sys.stderr)
        return 130
    except Exception:  # noqa: BLE001 - a bug: its traceback, and who to tell
        traceback.print_exc()
        print(f"hammer-mv {args.command}: this is a bug in hammer-mv (not in your input); "
              "please report it with the traceback above", file=sys.stderr)
        return 1


def _flag_words(record: logging.LogRecord) -> bool:
    """A library's log line with the fields it names given as their flags (as an error's)."""
    from hammer_mv.cli.flags import flag_text

    text = record.getMessage()
    flagged = flag_text(text)
    if flagged != text:
        record.msg, record.args = flagged, None
    return True


if __name__ == "__main__":  # python -m hammer_mv.cli
    sys.exit(main())

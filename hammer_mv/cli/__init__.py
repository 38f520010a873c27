"""``hammer-mv``: the command line interface.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``, which adds its parser and sets ``func`` (a callable
taking the parsed ``argparse.Namespace`` and returning an exit status).

A user's mistake (``InputError``, ``ValueError``, ``OSError``) is printed as one
line on stderr and exits with status 2; anything else is a bug and shows a
traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys

from minvar import __version__

#: Subcommand modules, in the order ``--help`` lists them.
COMMANDS = ("reach", "grasp", "synth", "calibrate", "track", "tracks", "repertoire", "recognize",
            "batch")


class _Parser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line and exit status 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    """Return the top-level parser with every subcommand registered."""
    parser = _Parser(prog="hammer-mv", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"hammer-mv {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``hammer-mv`` with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    # FFmpeg and OpenCV print their own warnings about broken files on stderr;
    # we report those files in one line ourselves. Set before any video opens.
    os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
    os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(args.func(args) or 0)
    except (ValueError, OSError) as exc:  # InputError is a ValueError
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        print(f"hammer-mv {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("hammer-mv: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # python -m hammer_mv.cli
    sys.exit(main())

"""``hammer-mv recognize``: score one clip against the repertoire."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hammer_mv.cli.options import add_recognition_options, load_repertoire, recognition_settings
from perception.errors import InputError
from perception.pipeline import TRACKS_SUFFIX, clip_fingerprint, clip_name, recognize_clip
from perception.report.clip import write_clip_report
from perception.report.tracking import write_tracking_report


def register(sub) -> None:
    """Add the ``recognize`` subcommand to ``sub`` (an argparse subparsers action).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The top-level parser's subparsers.
    """
    p = sub.add_parser("recognize", help="recognise the grasp in one video or tracks file",
                       description="Track INPUT (a video) or load it (a .tracks.h5), score it "
                       "against every model with HAMMER-MV and write DIR/<clip>.recognition.json, "
                       "a per-step CSV and figures.")
    p.add_argument("input", type=Path, metavar="INPUT")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR")
    add_recognition_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv recognize`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    path: Path = args.input
    if not path.exists():
        raise InputError("input not found", path)
    if path.is_dir():
        raise InputError("expected a video or tracks file, got a folder (use hammer-mv batch)",
                         path)
    clip, kind = clip_name(path)
    if kind == "unknown":
        raise InputError("not a video or .tracks.h5 file", path)
    settings = recognition_settings(args)
    rep, rep_id = load_repertoire(args)
    rec = recognize_clip(path, rep, settings, clip=clip,
                         tracks_out=args.output / "tracks" / f"{clip}{TRACKS_SUFFIX}",
                         progress=not args.quiet and sys.stderr.isatty())
    extra = {"fingerprint": clip_fingerprint(path, settings, rep_id), "condition": None,
             "input": str(path)}
    tracks_file = path if kind == "tracks" else args.output / "tracks" / f"{clip}{TRACKS_SUFFIX}"
    extra["tracking"] = write_tracking_report(tracks_file, args.output, clip)
    paths = write_clip_report(rec, args.output, extra=extra)
    print(f"{clip}: winner {rec.winner} ({rec.rule} rule) -> {paths['json']}")
    return 0

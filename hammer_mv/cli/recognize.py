"""``hammer-mv recognize``: score one clip against the repertoire."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from perception.batch import BatchItem, BatchSettings, clip_name, process_clip
from perception.errors import InputError
from hammer_mv.cli.options import add_recognition_options, hammer_params, load_repertoire, observe_params


def register(sub) -> None:
    """Add the ``recognize`` subcommand to ``sub`` (an argparse subparsers action)."""
    p = sub.add_parser("recognize", help="recognise the grasp in one video or tracks file",
                       description="Track INPUT (a video) or load it (a .tracks.h5), score it "
                       "against every model with HAMMER-MV and write DIR/<clip>.recognition.json, "
                       "a per-step CSV and figures.")
    p.add_argument("input", type=Path, metavar="INPUT")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR")
    add_recognition_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv recognize`` with parsed ``args``; return the exit status."""
    path: Path = args.input
    if not path.exists():
        raise InputError("input not found", path)
    if path.is_dir():
        raise InputError("expected a video or tracks file, got a folder (use hammer-mv batch)",
                         path)
    clip, kind = clip_name(path)
    if kind == "unknown":
        raise InputError("not a video or .tracks.h5 file", path)
    settings = BatchSettings(observe=observe_params(args), hammer=hammer_params(args),
                             quiet=args.quiet)
    rep, rep_id = load_repertoire(args)
    row = process_clip(BatchItem(clip, path, kind), args.output, rep, settings, rep_id)
    if row["status"] == "failed":
        print(f"hammer-mv recognize: error: {row['error']}", file=sys.stderr)
        return 2
    print(f"{clip}: winner {row['winner']} ({row['rule']} rule) -> "
          f"{args.output / (clip + '.recognition.json')}")
    return 0


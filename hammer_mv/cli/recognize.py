"""``hammer-mv recognize``: score one clip against the repertoire."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hammer_mv.cli.options import add_recognition_options


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
                       "a per-step CSV and figures. A current tracks file of the video (in "
                       "DIR/tracks/ or beside the video) is reused instead of tracking again.")
    p.add_argument("input", type=Path, metavar="INPUT")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR")
    p.add_argument("--no-figures", action="store_true",
                   help="write the JSON and CSV only, not the two figures (faster)")
    add_recognition_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv recognize`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from hammer_mv.cli.options import load_repertoire, recognition_settings
    from perception.errors import InputError
    from perception.pipeline import TRACKS_SUFFIX, clip_fingerprint, clip_name, recognize_clip

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
    if args.no_figures:
        json_path = write_tables(rec, args.output, extra)
    else:
        from perception.report.clip import write_clip_report  # matplotlib: only for figures

        json_path = write_clip_report(rec, args.output, extra=extra)["json"]
    print(f"{clip}: winner {rec.winner} ({rec.rule} rule) -> {json_path}")
    return 0


#: The report files ``--no-figures`` writes (named as perception.report.clip.clip_outputs
#: names them; tests/test_cli_recognize.py checks that they agree).
TABLES = {"json": "{clip}.recognition.json", "csv": "{clip}.confidence.csv"}
FIGURES = ("{clip}.confidence.png", "{clip}.paths.png")


def write_tables(rec, out: Path, extra: dict) -> Path:
    """The clip report without figures (and without importing matplotlib).

    Figures of an earlier run are removed: they would show another result.
    """
    from perception.io.atomic import write_csv, write_json

    for name in FIGURES:
        (out / name.format(clip=rec.clip)).unlink(missing_ok=True)
    write_csv(out / TABLES["csv"].format(clip=rec.clip), rec.to_pandas())
    # the JSON last: its presence marks the clip's report complete
    return write_json(out / TABLES["json"].format(clip=rec.clip), {**rec.to_dict(), **extra})

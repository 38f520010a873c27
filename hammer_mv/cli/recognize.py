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
                       description="Track INPUT (a video), load it (a .tracks.h5) or read it "
                       "(a DeepLabCut, SLEAP, Lightning Pose or movement pose file, or a "
                       "motion-capture recording: every reach in it), score it "
                       "against every model with HAMMER-MV and write DIR/<clip>.recognition.json, "
                       "a per-step CSV and figures. A current tracks file of the video (in "
                       "DIR/tracks/ or beside the video) is reused instead of tracking again.")
    p.add_argument("input", type=Path, metavar="INPUT",
                   help="video, .tracks.h5, pose file (.h5, .csv, .slp, .nc, .nwb) or "
                        "motion-capture file (.c3d, Qualisys .tsv, X/Y/Z table)")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                   help="folder for the clip's report")
    p.add_argument("--no-figures", action="store_true",
                   help="write the JSON and CSV only, not the figures (faster)")
    add_figure_options(p)
    add_recognition_options(p)
    p.set_defaults(func=run)


def _dpi(text: str) -> int:
    try:
        dpi = int(text)
    except ValueError:
        dpi = 0
    if dpi < 1:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, got {text!r}")
    return dpi


def add_figure_options(p: argparse.ArgumentParser) -> None:
    """Add ``--figure-format`` and ``--dpi``: how every figure of the command is written.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    from perception.report.figures import DPI, FIGURE_FORMATS

    p.add_argument("--figure-format", choices=FIGURE_FORMATS, default=FIGURE_FORMATS[0],
                   help="format of the figures: png, or svg / pdf (vector, for a paper; "
                        f"default: {FIGURE_FORMATS[0]})")
    p.add_argument("--dpi", type=_dpi, default=DPI, metavar="N",
                   help=f"resolution of PNG figures, dots per inch (default: {DPI})")


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv recognize`` with parsed ``args``; return the exit status.

    Prints one line (the clip, its verdict and winner, the report) unless ``--quiet``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from hammer_mv.cli.checks import output_folder
    from hammer_mv.cli.options import load_repertoire, recognition_settings
    from perception.errors import InputError
    from perception.io.frame_sample import FrameSample
    from perception.io.names import output_folder as subfolder
    from perception.io.names import output_stem
    from perception.pipeline import (
        TRACKS_SUFFIX,
        clip_fingerprint,
        clip_name,
        load_clip,
        recognize_tracks,
    )
    from perception.report.clip import write_clip_report
    from perception.report.tracking import write_tracking_report

    path: Path = args.input
    output_folder(args.output)  # before any tracking
    if not path.exists():
        raise InputError("input not found", path)
    if path.is_dir():
        raise InputError("expected a video, tracks or pose file, got a folder "
                         "(use hammer-mv batch)", path)
    from perception.io.mocap import is_mocap_file

    if is_mocap_file(path):
        return _run_mocap(args, path)
    clip, kind = clip_name(path)
    if kind == "unknown":
        raise InputError("not a video, .tracks.h5 or pose file", path)
    settings = recognition_settings(args)
    rep, rep_id = load_repertoire(args)
    # a few frames for the contact sheet, kept while tracking
    frames = None if args.no_figures else FrameSample()
    tracks_out = subfolder(args.output, "tracks") / f"{output_stem(clip)}{TRACKS_SUFFIX}"
    tracks = load_clip(path, tracks_out=tracks_out, progress=not args.quiet and sys.stderr.isatty(),
                       setup=settings.tracking, pose=settings.pose, frames=frames,
                       **settings.video_options())
    rec = recognize_tracks(tracks, rep, settings, clip=clip, source=path)
    extra = {"fingerprint": clip_fingerprint(path, settings, rep_id), "condition": None,
             "input": str(path),
             "tracking": write_tracking_report(tracks, args.output, clip,
                                               sheet=not args.no_figures, frames=frames)}
    paths = write_clip_report(rec, args.output, extra=extra, figures=not args.no_figures,
                              figure_format=args.figure_format, dpi=args.dpi)
    if not args.quiet:
        detail = f" ({rec.verdict_detail})" if rec.verdict_detail else ""
        mirror = ""
        if rec.mirrored:  # the scene was found the other way round from what was asked
            mirror = ("; the scene is not mirrored: scored without --mirror" if args.mirror
                      else "; the scene is mirrored: scored as with --mirror")
        print(f"{clip}: {rec.verdict or 'no verdict'}{detail}, winner {rec.winner} "
              f"({rec.rule} rule){mirror} -> {paths['json']}")
    return 0


def _run_mocap(args: argparse.Namespace, path: Path) -> int:
    """``recognize`` of a motion-capture file: every reach in it, one report each."""
    from hammer_mv.cli.options import load_repertoire, mocap_import, recognition_settings
    from perception.pipeline import clip_fingerprint
    from perception.recordings import read_reaches, recognize_reach
    from perception.report.clip import write_clip_report

    settings = recognition_settings(args)
    options = settings.mocap or mocap_import(args)
    reaches = read_reaches(path, options)
    rep, rep_id = load_repertoire(args)
    for k, reach in enumerate(reaches):
        fingerprint = clip_fingerprint(path, settings, f"{rep_id}#reach{k}")
        rec, info = recognize_reach(reach, rep, settings, options)
        extra = {"fingerprint": fingerprint, "condition": None, "input": str(path),
                 "mocap": info}
        paths = write_clip_report(rec, args.output, extra=extra, figures=not args.no_figures,
                                  figure_format=args.figure_format, dpi=args.dpi)
        for warning in rec.warnings:
            print(f"{reach.name}: warning: {warning}", file=sys.stderr)
        if not args.quiet:
            why = rec.verdict_detail or (rec.verdict_reason if rec.verdict == "unfamiliar"
                                         else None)
            detail = f" ({why})" if why else ""
            print(f"{reach.name}: {rec.verdict or 'no verdict'}{detail}, winner {rec.winner} "
                  f"-> {paths['json']}")
    return 0

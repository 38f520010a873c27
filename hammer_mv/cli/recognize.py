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
                       "DIR/tracks/ or beside the video) is reused instead of tracking again. "
                       "A recording also gets DIR/<recording>.trials.csv, a row per reach and "
                       "per trial not scored, with its status and reason; exit status 1 when "
                       "a trial or reach could not be scored (docs/mocap.md).")
    # kept as typed (a Path would make "udp://host" "udp:/host"): its kind is read first
    p.add_argument("input", metavar="INPUT",
                   help="video, .tracks.h5, pose file (.h5, .csv, .slp, .nc, .nwb) or "
                        "motion-capture file (.c3d, .trc, Qualisys .tsv, X/Y/Z table)")
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
    from hammer_mv.cli.flags import field_flag
    from perception.report.figures import DPI, FIGURE_FORMATS

    p.add_argument("--figure-format", choices=FIGURE_FORMATS, default=FIGURE_FORMATS[0],
                   help="format of the figures: png, or svg / pdf (vector, for a paper; "
                        f"default: {FIGURE_FORMATS[0]})")
    field_flag("figure_format", "--figure-format")
    p.add_argument("--dpi", type=_dpi, default=DPI, metavar="N",
                   help=f"resolution of PNG figures, dots per inch (default: {DPI})")


def _say_unread(args: argparse.Namespace, kind: str) -> None:
    """Warn of the flags given that an input of ``kind`` does not read (another kind's)."""
    from hammer_mv.cli.options import flags_not_read

    if not args.quiet and (unread := flags_not_read(args, kind)) is not None:
        print(f"hammer-mv recognize: warning: {unread}", file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv recognize`` with parsed ``args``; return the exit status.

    Prints one line (the clip, its verdict and winner, the report) unless ``--quiet``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from hammer_mv.cli.checks import writable_folder
    from hammer_mv.cli.flags import flag_text
    from hammer_mv.cli.options import load_repertoire, recognition_settings
    from perception.errors import InputError
    from perception.io.files import input_file
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
    from perception.sources import check_command, files_taken

    kind = check_command(args.input, "recognize")  # a camera or a stream: watch's
    path = args.input = Path(args.input)
    writable_folder(args.output)  # before any tracking
    if not path.exists():
        raise InputError("input not found", path)
    if path.is_dir():
        raise InputError(f"expected a {files_taken('recognize')}, got a folder (use hammer-mv "
                         "batch)", path)
    if kind is not None and kind.name == "mocap":
        status = _run_mocap(args, path)
        _say_unread(args, "mocap")  # once the input is read: a refusal stays one line
        return status
    from perception.recordings import unknown_layout

    if (why := unknown_layout(path)) is not None:
        raise InputError(why, path)
    clip, kind = clip_name(path)
    if kind == "unknown":
        what = files_taken("recognize")
        input_file(path, what, empty=False)  # an empty file is of no kind: it says so
        raise InputError(f"not a {what}", path)
    clip = _own_clip(args.output, clip, path)
    settings = recognition_settings(args)
    rep, rep_id = load_repertoire(args)
    # a few frames for the contact sheet, kept while tracking
    frames = None if args.no_figures else FrameSample()
    tracks_out = subfolder(args.output, "tracks") / f"{output_stem(clip)}{TRACKS_SUFFIX}"
    tracks = load_clip(path, tracks_out=tracks_out, progress=not args.quiet and sys.stderr.isatty(),
                       setup=settings.tracking, pose=settings.pose, frames=frames,
                       **settings.video_options())
    _say_unread(args, kind)  # once the input is read: a refusal stays one line
    rec = recognize_tracks(tracks, rep, settings, clip=clip, source=path)
    extra = {"fingerprint": clip_fingerprint(path, settings, rep_id), "condition": None,
             "input": str(path),
             "tracking": write_tracking_report(tracks, args.output, clip,
                                               sheet=not args.no_figures, frames=frames)}
    paths = write_clip_report(rec, args.output, extra=extra, figures=not args.no_figures,
                              figure_format=args.figure_format, dpi=args.dpi)
    if not args.quiet:
        mirror = ""
        if rec.mirrored:  # the scene was found the other way round from what was asked
            mirror = ("; the scene is not mirrored: scored without --mirror" if args.mirror
                      else "; the scene is mirrored: scored as with --mirror")
        print(f"{verdict_line(rec, rule=True)}{mirror} -> {paths['json']}")
        for warning in rec.warnings:
            print(f"{clip}: warning: {flag_text(warning)}", file=sys.stderr)
    return 0


def verdict_line(rec, rule: bool = False) -> str:
    """``clip: verdict (kind), winner W: reason``: a scored clip's console line.

    A winner whose kind contradicts the verdict (a reach model on a
    ``normal`` grasp) is named for what it is: ``closest model W (a reach
    model; the verdict's model: M)`` (:attr:`Recognition.winner_note`).

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    rule : bool
        Name the rule that picked the winner (``likelihood rule``).
    """
    detail = f" ({rec.verdict_detail})" if rec.verdict_detail else ""
    how = f" ({rec.rule} rule)" if rule else ""
    if rec.winner_note is not None:
        kind = rec.kinds[rec.names.index(rec.winner)]
        winner = (f"closest model {rec.winner} (a {kind} model{how}; the verdict's model: "
                  f"{rec.verdict_model})")
    else:
        winner = f"winner {rec.winner}{how}"
    return f"{rec.clip}: {rec.verdict or 'no verdict'}{detail}, {winner}: {rec.verdict_reason}"


def _run_mocap(args: argparse.Namespace, path: Path) -> int:
    """``recognize`` of a motion-capture file: every reach in it, one report each, and
    ``<recording>.trials.csv`` accounting for every trial (exit 1 when one is not scored)."""
    from hammer_mv.cli.recording import score_recording
    from perception.recordings import recognize_reach

    def score(reach, settings, options, rep):
        rec, info = recognize_reach(reach, rep, settings, options)
        return rec, {"mocap": info}, lambda rec, paths: print(
            f"{verdict_line(rec)} -> {paths['json']}")

    return score_recording(args, path, score,
                           name=lambda entry: _own_clip(args.output, entry.name, path))


def _own_clip(out: Path, name: str, path: Path) -> str:
    """``name``, or the input's full file name in its place (``P01.tsv-trial3``,
    ``P01.mp4``) when ``out`` holds a report of that name made from another input: two
    recordings' reports never overwrite each other (a video and a table of one stem)."""
    import json

    from hammer_mv.cli.recording import same_file
    from perception.report.clip import clip_outputs

    report = clip_outputs(out, name)["json"]
    if not report.is_file():
        return name
    try:
        source = json.loads(report.read_text()).get("input")
    except (OSError, ValueError, AttributeError):
        return name
    if source is None or same_file(source, path):
        return name
    tail = name[len(path.stem):] if name.startswith(path.stem) else f"-{name}"
    return f"{path.name}{tail}"

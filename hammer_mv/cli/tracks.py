"""``hammer-mv tracks info|export FILE``: inspect a tracks file or export it as a table."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``tracks`` subcommand and its actions to ``subparsers``."""
    p = subparsers.add_parser("tracks", help="inspect or export a tracks file")
    actions = p.add_subparsers(dest="tracks_action", metavar="ACTION")
    actions.required = True

    info = actions.add_parser("info", help="summarise a tracks file")
    info.add_argument("file", type=Path, metavar="FILE", help="tracks file (.tracks.h5)")
    info.set_defaults(func=run_info)

    export = actions.add_parser("export", help="export a tracks file as a CSV table")
    export.add_argument("file", type=Path, metavar="FILE", help="tracks file (.tracks.h5)")
    export.add_argument(
        "--format",
        required=True,
        choices=("dlc", "trackpy", "csv"),
        help="dlc: DeepLabCut wide table (scorer/bodyparts/coords header rows); "
        "trackpy: long table, one row per frame and marker; csv: plain wide table",
    )
    export.add_argument("-o", "--output", type=Path, required=True, metavar="OUT")
    export.add_argument(
        "--max-gap",
        type=int,
        default=0,
        metavar="N",
        help="first fill gaps of up to N lost frames by linear interpolation (status 3)",
    )
    export.add_argument(
        "--trim",
        action="store_true",
        help="export only the movement recognition scores (onset to end of activity; "
        "needs the object and a hand at rest in the first frames)",
    )
    export.set_defaults(func=run_export)


def run_info(args: argparse.Namespace) -> int:
    """Print a summary of ``args.file``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from perception.io.tracks import Status, Tracks

    t = Tracks.load(args.file)
    v = t.video
    print(f"{args.file}: hammer-mv tracks, {t.n_frames} frames, markers {', '.join(t.markers)}")
    if v:
        print(
            f"video: {v.get('path', '?')} {v.get('width', '?')}x{v.get('height', '?')} "
            f"{v.get('fourcc', '?')} {v.get('fps_nominal', 0):g} fps, "
            f"{v.get('n_frames', '?')} frames (header {v.get('n_frames_header', '?')}), "
            f"times from {v.get('time_source', '?')}, "
            f"sha256 {str(v.get('sha256', ''))[:12]}"
        )
    if t.n_frames:
        print(f"time: {t.time[0]:.3f} .. {t.time[-1]:.3f} s")
        print(_movement_line(t))
    header = (
        f"{'marker':<8} {'tracked':>8} {'reacq.':>7} {'lost':>7} {'interp.':>8} {'mean lik.':>9}"
    )
    print(header)
    for j, name in enumerate(t.markers):
        counts = [int((t.status[:, j] == s).sum()) for s in Status]
        valid = t.valid[:, j]
        lik = float(t.likelihood[valid, j].mean()) if valid.any() else 0.0
        print(f"{name:<8} {counts[0]:>8} {counts[1]:>7} {counts[2]:>7} {counts[3]:>8} {lik:>9.3f}")
    return 0


def _movement_line(t) -> str:
    """The movement recognition would score, or why none can be found."""
    from perception.errors import InputError
    from perception.observation import movement_span

    try:
        span = movement_span(t)
    except InputError as exc:
        return f"active: none ({exc.problem})"
    last = span.stop - 1
    return (f"active: frames {span.onset_frame} .. {span.end_frame} "
            f"({t.time[span.start]:.3f} .. {t.time[last]:.3f} s, the movement recognition "
            "scores)")


def run_export(args: argparse.Namespace) -> int:
    """Write ``args.file`` as a table in ``args.format`` to ``args.output``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from perception.errors import InputError
    from perception.io.tracks import Tracks
    from perception.observation import movement_span

    if args.max_gap < 0:
        raise InputError(f"--max-gap: expected >= 0 frames, got {args.max_gap}")
    t = Tracks.load(args.file)
    span = None
    if args.trim:  # on the tracks as recorded, as recognition sees them
        try:
            span = movement_span(t)
        except InputError as exc:
            raise InputError(f"--trim: {exc.problem}", args.file) from None
    if args.max_gap:
        t = t.interpolate(args.max_gap)
    if span is not None:
        t = t.rows(span.start, span.stop)
    t.export(args.output, args.format)
    return 0

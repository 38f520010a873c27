"""``hammer-mv tracks info|export|render FILE``: inspect, export or draw a tracks file."""

from __future__ import annotations

import argparse
from pathlib import Path

from hammer_mv.cli.flags import field_flag


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``tracks`` subcommand and its actions to ``subparsers``."""
    p = subparsers.add_parser("tracks", help="inspect or export a tracks file")
    actions = p.add_subparsers(dest="tracks_action", metavar="ACTION", required=True)

    info = actions.add_parser("info", help="summarise a tracks file")
    info.add_argument("file", type=Path, metavar="FILE", help="tracks file (.tracks.h5)")
    info.set_defaults(func=run_info)

    export = actions.add_parser(
        "export", help="export a tracks file for DeepLabCut, movement, trackpy or pandas",
        description="Write the tracks of FILE in the format another tool reads "
        "(docs/pose-files.md describes every column).")
    export.add_argument("file", type=Path, metavar="FILE", help="tracks file (.tracks.h5)")
    export.add_argument(
        "--format", required=True, choices=("dlc", "movement", "trackpy", "csv"),
        help="dlc: DeepLabCut table, a real .h5 (pandas HDF, key df_with_missing) or a .csv "
        "by OUT's ending, plus OUT's stem .status.csv; movement: a movement poses dataset "
        "(.nc); trackpy: long table, one row per frame and seen marker; csv: plain wide table")
    field_flag("format", "--format")
    export.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="output file")
    export.add_argument("--max-gap", type=int, default=0, metavar="N",
                        help="first fill gaps of up to N lost frames by linear interpolation "
                             "(status 3)")
    export.add_argument("--trim", action="store_true",
                        help="export only the movement recognition scores (onset to end of "
                             "activity; needs the object and a hand at rest in the first frames)")
    export.set_defaults(func=run_export)

    render = actions.add_parser(
        "render", help="draw the tracked markers on their video (a labelled video)",
        description="Write VIDEO (default: the video the tracks record) with every marker "
        "drawn: name, likelihood and a short trail; lost markers are a grey cross at their "
        "last position, ambiguous ones are marked in the legend.")
    render.add_argument("file", type=Path, metavar="TRACKS.h5", help="tracks file")
    render.add_argument("video", type=Path, nargs="?", metavar="VIDEO",
                        help="the tracked video (default: /video path of the tracks)")
    render.add_argument("-o", "--output", type=Path, required=True, metavar="LABELLED.mp4",
                        help="labelled video to write (.mp4, .avi or .mkv)")
    render.add_argument("--trail", type=int, default=12, metavar="N",
                        help="frames of trail behind each marker (default 12)")
    render.set_defaults(func=run_render)


def run_info(args: argparse.Namespace) -> int:
    """Print a summary of ``args.file``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from perception.io.tracks import Status, Tracks
    from perception.report.tracking import tracking_quality

    t = Tracks.load(args.file)
    v = t.video
    print(f"{args.file}: hammer-mv tracks, {t.n_frames} frames, markers {', '.join(t.markers)}")
    if v:
        print(f"video: {v.get('path', '?')} {v.get('width', '?')}x{v.get('height', '?')} "
              f"{v.get('fourcc', '?')} {v.get('fps_nominal', 0):g} fps, "
              f"{v.get('n_frames', '?')} frames (header {v.get('n_frames_header', '?')}), "
              f"times from {v.get('time_source', '?')}, sha256 {str(v.get('sha256', ''))[:12]}")
    if t.n_frames:
        print(f"time: {t.time[0]:.3f} .. {t.time[-1]:.3f} s")
        print(_movement_line(t))
    print(f"{'marker':<8} {'tracked':>8} {'reacq.':>7} {'lost':>7} {'interp.':>8} {'ambig.':>7} "
          f"{'mean lik.':>9}")
    for j, name in enumerate(t.markers):
        counts = [int((t.status[:, j] == s).sum()) for s in Status]
        valid = t.valid[:, j]
        lik = float(t.likelihood[valid, j].mean()) if valid.any() else 0.0
        print(f"{name:<8} {counts[0]:>8} {counts[1]:>7} {counts[2]:>7} {counts[3]:>8} "
              f"{counts[4]:>7} {lik:>9.3f}")
    print("quality:")
    print(f"{'marker':<8} {'frames %':>8} {'min lik.':>8} {'median lik.':>11} "
          f"{'reacquisitions':>14} {'ambiguous':>9}")
    for q in tracking_quality(t).markers:
        print(f"{q.marker:<8} {100 * q.tracked:>8.1f} {q.min_likelihood:>8.3f} "
              f"{q.median_likelihood:>11.3f} {q.reacquisitions:>14} {q.ambiguous:>9}")
    if not args.quiet:
        print(INFO_LEGEND)
    return 0


#: What the columns of ``tracks info`` mean (docs/tracks-format.md has the codes).
INFO_LEGEND = """\
columns: frames per status code - tracked (0: found where predicted), reacq. (1: found
  again by a search of the whole frame after being lost), lost (2: not found; no position),
  interp. (3: filled by --max-gap), ambig. (4: two candidates fit; not guessed); mean lik.
  over the frames with a position. active: the frames recognition scores (movement onset
  to end of activity). quality: the share of frames with a position, the lowest and
  median likelihood of those, how often the marker was re-acquired, frames ambiguous.
  (--quiet drops this note)"""


def _movement_line(t) -> str:
    """The movement recognition would score, or why none can be found."""
    from perception.errors import InputError
    from perception.observation import movement_span

    try:
        span = movement_span(t)
    except InputError as exc:
        return f"active: none ({exc.problem})"
    return (f"active: frames {span.onset_frame} .. {span.end_frame} "
            f"({t.time[span.start]:.3f} .. {t.time[span.stop - 1]:.3f} s, the movement "
            "recognition scores)")


def run_export(args: argparse.Namespace) -> int:
    """Write ``args.file`` as a table in ``args.format`` to ``args.output``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from perception.errors import InputError
    from perception.io.atomic import check_output
    from perception.io.exports import export_tracks, status_path_for
    from perception.io.tracks import Tracks
    from perception.observation import movement_span

    outputs = [args.output] + ([status_path_for(args.output)] if args.format == "dlc" else [])
    for out in outputs:
        check_output(out, inputs=[args.file])
    if args.max_gap < 0:
        raise InputError(f"expected >= 0 frames, got {args.max_gap}", field="--max-gap")
    t = Tracks.load(args.file)
    span = None
    if args.trim:  # on the tracks as recorded, as recognition sees them
        try:
            span = movement_span(t)
        except InputError as exc:
            raise InputError(exc.problem, args.file, field="--trim") from None
    if args.max_gap:
        t = t.interpolate(args.max_gap)
    if span is not None:
        t = t.rows(span.start, span.stop)
    written = export_tracks(t, args.output, args.format)
    if not getattr(args, "quiet", False):
        print(f"wrote {', '.join(map(str, written))} ({t.n_frames} frames, {args.format})")
    return 0


def run_render(args: argparse.Namespace) -> int:
    """Write the labelled video of ``args.file`` to ``args.output``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from perception.errors import InputError
    from perception.io.atomic import check_output
    from perception.io.tracks import Tracks
    from perception.tracking.overlay import render_labelled

    if args.trail < 1:
        raise InputError(f"--trail: expected >= 1 frame, got {args.trail}", field="--trail")
    t = Tracks.load(args.file)
    stored = t.video.get("path")
    if args.video is None and stored and not Path(stored).is_absolute():
        stored = Path(args.file).parent / stored  # where render_labelled will look
    check_output(args.output, [p for p in (args.file, args.video or stored) if p])
    # render_labelled checks the video is the tracked one (its SHA-256)
    out = render_labelled(t, args.video, args.output, trail=args.trail)
    print(f"{out}: {t.n_frames} frames labelled")
    return 0

"""``hammer-mv track VIDEO``: track the colour markers of a video into a tracks file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hammer_mv.cli.flags import add_video_options


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``track`` subcommand to ``subparsers`` (an argparse subparsers action)."""
    p = subparsers.add_parser(
        "track", help="track the thumb, finger, wrist and object markers of a video",
        description="Track the colour markers of VIDEO with CamShift and write their pixel "
        "positions, likelihoods and status per frame to an HDF5 tracks file.")
    p.add_argument("video", type=Path, metavar="VIDEO", help="video file (mp4, avi, mkv, ...)")
    p.add_argument("-o", "--output", type=Path, metavar="OUT.h5",
                   help="tracks file (default: <video stem>.tracks.h5 beside the video)")
    p.add_argument("--colours", type=Path, metavar="FILE",
                   help="JSON or TOML file overriding marker colour models")
    p.add_argument("--roi", nargs=5, action="append", default=[],
                   metavar=("MARKER", "X", "Y", "W", "H"),
                   help="look for MARKER only inside this first-frame rectangle (px); repeatable")
    p.add_argument("--setup", type=Path, metavar="SETUP.toml",
                   help="colour models and marker sizes of the session (hammer-mv calibrate); "
                        "--colours overrides its colours")
    p.add_argument("--labelled-video", type=Path, metavar="OUT.mp4",
                   help="also write the video with every marker drawn (name, likelihood, trail)")
    add_video_options(p)
    p.set_defaults(func=run)


def parse_rois(specs: list[list[str]], names: tuple[str, ...]) -> dict[str, tuple[int, ...]]:
    """``[[MARKER, X, Y, W, H], ...]`` -> ``{marker: (x, y, w, h)}``, validated.

    Parameters
    ----------
    specs : list of list of str
        The ``--roi`` arguments as given.
    names : tuple of str
        Known marker names.

    Raises
    ------
    InputError
        Unknown or repeated marker, non-integer or non-positive sizes.
    """
    from perception.errors import InputError

    rois: dict[str, tuple[int, ...]] = {}
    for spec in specs:
        name, *numbers = spec
        shown = " ".join(spec)
        if name not in names:
            raise InputError(f"--roi {shown}: unknown marker {name!r} "
                             f"(expected {', '.join(names)})")
        if name in rois:
            raise InputError(f"--roi {shown}: a second ROI for {name}")
        try:
            x, y, w, h = (int(v) for v in numbers)
        except ValueError:
            raise InputError(f"--roi {shown}: expected integer pixels X Y W H") from None
        if x < 0 or y < 0 or w <= 0 or h <= 0:
            raise InputError(f"--roi {shown}: expected X, Y >= 0 and W, H > 0")
        rois[name] = (x, y, w, h)
    return rois


def run(args: argparse.Namespace) -> int:
    """Track ``args.video``; print a one-line summary unless ``--quiet``.

    OpenCV's thread pool is off by then: :func:`hammer_mv.cli.serial_opencv`
    (run by the command line for every command that tracks) says why.
    """
    from perception.io.atomic import check_output
    from perception.io.tracks import tracks_path_for
    from perception.tracking.markers import load_markers
    from perception.tracking.setup import TrackingSetup, load_setup
    from perception.tracking.video_tracks import track_video

    inputs = [p for p in (args.video, args.colours, args.setup) if p is not None]
    out = check_output(args.output or tracks_path_for(args.video), inputs)
    if args.labelled_video is not None:
        check_output(args.labelled_video, [*inputs, out])
    setup = load_setup(args.setup) if args.setup else TrackingSetup()
    markers = load_markers(args.colours, setup.markers) if args.colours else setup.markers
    rois = parse_rois(args.roi, markers.names)
    progress = not args.quiet and sys.stderr.isatty()
    out = track_video(args.video, out, markers=markers, params=setup.params, rois=rois,
                      progress=progress, labelled_video=args.labelled_video,
                      keep_truncated=args.keep_truncated, fps=args.fps)
    if not args.quiet:
        print(summary_line(out))
    return 0


def summary_line(out: Path) -> str:
    """``OUT: N frames; found thumb 100 %, ...``: the share of frames in which each marker
    was placed, and its ambiguous frames (:func:`perception.io.tracks.marker_counts`)."""
    from perception.io.tracks import marker_counts

    markers, placed, ambiguous = marker_counts(out)
    found = ", ".join(
        f"{name} {100 * placed[:, j].mean():.0f} %"
        + (f" ({int(ambiguous[j])} frames ambiguous)" if ambiguous[j] else "")
        for j, name in enumerate(markers)
    )
    return f"{out}: {len(placed)} frames; found {found}"

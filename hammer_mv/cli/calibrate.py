"""``hammer-mv calibrate VIDEO -o setup.toml``: learn a session's colour models and marker sizes."""

from __future__ import annotations

import argparse
import itertools
from pathlib import Path

from hammer_mv.cli.track import parse_rois


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``calibrate`` subcommand to ``subparsers`` (an argparse subparsers action)."""
    p = subparsers.add_parser(
        "calibrate", help="learn the colour models and marker sizes of a setup from one clip",
        description="Learn each marker's colour (hue, saturation and value ranges of its own "
        "pixels) and the markers' sizes from the first frames of VIDEO (the hand at rest, every "
        "marker in view), and write a setup file that track, recognize and batch take with "
        "--setup. Markers are found automatically; give --roi where that fails.")
    p.add_argument("video", type=Path, metavar="VIDEO", help="one clip of the session")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="SETUP.toml",
                   help="setup file to write")
    p.add_argument("--roi", nargs=5, action="append", default=[],
                   metavar=("MARKER", "X", "Y", "W", "H"),
                   help="MARKER lies inside this first-frame rectangle (px); repeatable")
    p.add_argument("--object-diameter", type=float, default=None, metavar="M",
                   help="the object's real diameter, m (default 0.1): it sets the scale "
                        "against which marker sizes are measured")
    p.add_argument("--setup", type=Path, metavar="SETUP.toml",
                   help="start from this setup (its colour models and parameters)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Calibrate from ``args.video`` and write ``args.output``; print a summary."""
    import dataclasses

    from hammer_mv.cli.checks import options
    from perception.errors import InputError
    from perception.io.atomic import check_output
    from perception.io.video import FrameSource
    from perception.tracking.setup import TrackingSetup, calibrate, load_setup, write_setup

    check_output(args.output, [p for p in (args.video, args.setup) if p is not None])
    base = load_setup(args.setup) if args.setup else TrackingSetup()
    params = base.params
    if args.object_diameter is not None:  # TrackerParams declares its range
        with options({"object_diameter": "--object-diameter"}):
            params = dataclasses.replace(params, object_diameter=args.object_diameter)
    rois = parse_rois(args.roi, base.markers.names)
    with FrameSource(args.video, hash=False) as src:
        frames = [f for _, _, f in itertools.islice(src, max(params.init_frames, 1))]
    try:
        setup = calibrate(frames, rois=rois, markers=base.markers, params=params,
                          source=str(args.video))
    except InputError as exc:
        raise InputError(exc.problem, args.video) from None
    write_setup(args.output, setup)
    p = setup.params
    if not args.quiet:
        print(f"{args.output}: markers {', '.join(setup.markers.names)}; marker diameter "
              f"{p.marker_diameter * 1000:.1f} mm, band {p.band_size[0] * 1000:.0f} x "
              f"{p.band_size[1] * 1000:.0f} mm (object {p.object_diameter * 1000:.0f} mm)")
    return 0

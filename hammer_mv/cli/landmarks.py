"""``hammer-mv landmarks``: the field's kinematics of every movement in some files, as a table."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hammer_mv.cli.flags import FPS_HELP


def register(sub) -> None:
    """Add the ``landmarks`` subcommand to ``sub`` (an argparse subparsers action).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The top-level parser's subparsers.
    """
    from hammer_mv.cli.options import add_mocap_options

    p = sub.add_parser("landmarks", help="measure reach-to-grasp landmarks, no models (CSV)",
                       description="Measure the landmarks of every movement in each INPUT "
                       "(motion-capture recordings: every reach; tracks, pose files or "
                       "videos: the movement) by the field's definitions: onset and end where "
                       "the transport speed crosses a share of its peak (or an absolute speed), "
                       "after a zero-lag low-pass filter. Writes one CSV row per movement, "
                       "and one per trial of a recording that gives none, with its status and "
                       "reason (docs/mocap.md lists the columns and their units). Exit status "
                       "1 when a trial could not be measured.")
    p.add_argument("inputs", type=Path, nargs="+", metavar="INPUT",
                   help="motion-capture recordings, tracks or pose files, or videos")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="TABLE.csv",
                   help="the table to write")
    g = p.add_argument_group("definitions")
    g.add_argument("--threshold", type=float, default=0.05, metavar="SHARE",
                   help="onset and end where the speed crosses this share of its peak "
                        "(default 0.05)")
    g.add_argument("--speed", type=float, default=None, metavar="M/S",
                   help="an absolute speed bound instead of the share")
    g.add_argument("--hold", type=float, default=0.0, metavar="S",
                   help="the speed must stay beyond the bound this long (default 0)")
    g.add_argument("--cutoff", type=float, default=10.0, metavar="HZ",
                   help="zero-lag Butterworth low-pass cutoff (default 10 Hz; 0: none)")
    g = p.add_argument_group("scale of pixel tracks")
    g.add_argument("--px-per-m", type=float, default=None, metavar="X",
                   help="image scale of tracks, pose files and videos, px/m")
    g.add_argument("--object-diameter", type=float, default=None, metavar="M",
                   help="the object's real diameter, m, to scale tracks by its apparent one")
    g.add_argument("--fps", type=float, default=None, metavar="F", help=FPS_HELP)
    add_mocap_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv landmarks`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    import pandas as pd

    from hammer_mv.cli.checks import options
    from hammer_mv.cli.options import mocap_import
    from perception.errors import InputError
    from perception.io.atomic import check_output, write_text
    from perception.landmarks import LandmarkParams
    from perception.measure import measure
    from perception.recordings import trial_summary

    with options({"threshold": "--threshold", "speed": "--speed", "hold": "--hold",
                  "cutoff": "--cutoff"}):
        params = LandmarkParams(threshold=args.threshold, speed=args.speed, hold=args.hold,
                                cutoff=args.cutoff or None)
    mocap = mocap_import(args).with_landmarks(params)  # one rule bounds and measures
    pose = None
    if args.fps is not None:
        from perception.io.pose import PoseImport

        with options({"fps": "--fps"}):
            pose = PoseImport(fps=args.fps)
    from perception.io.names import output_folder, output_stem
    from perception.pipeline import TRACKS_SUFFIX, clip_name

    check_output(args.output, args.inputs)  # never over a recording it reads
    if args.output.suffix.lower() != ".csv":
        raise InputError("the table written is CSV: name an output ending in .csv", args.output,
                         field="--output")
    inputs = []  # a file given twice is measured once: its rows twice would count double
    for path in args.inputs:
        same = next((p for p in inputs if p.exists() and path.exists() and p.samefile(path)),
                    None)
        if same is not None:
            print(f"{path}: given more than once (as {same}): measured once", file=sys.stderr)
            continue
        inputs.append(path)
    tables, trials = [], 0
    for path in inputs:
        if not path.is_file():
            raise InputError("input not found (or not a file)", path)
        # a video's tracks go beside the table, never beside the user's video
        tracks_out = None
        if clip_name(path)[1] == "video":
            tracks_out = (output_folder(args.output.parent, "tracks")
                          / f"{output_stem(clip_name(path)[0])}{TRACKS_SUFFIX}")
        found = measure(path, params=params, mocap=mocap, px_per_m=args.px_per_m,
                        object_diameter=args.object_diameter, pose=pose, tracks_out=tracks_out)
        tables.append(found.table)
        trials += found.trials
    table = pd.concat(tables, ignore_index=True)
    write_text(args.output, table.to_csv(index=False))
    missed = table[table["reason"].fillna("") != ""]
    if not args.quiet:
        done = int((table["status"] == "complete").sum())
        print(f"{len(table)} movement(s), {done} complete -> {args.output}", file=sys.stdout)
        print(trial_summary(trials, len(table) - len(missed), len(missed)), file=sys.stdout)
    for name, reason in zip(missed["trial"], missed["reason"]):  # always: none dropped
        print(f"{name}: not scored: {reason}", file=sys.stderr)
    return 1 if len(missed) else 0

"""``hammer-mv landmarks``: the field's kinematics of every movement in some files, as a table."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hammer_mv.cli.flags import Setting, add_settings, flag_text
from hammer_mv.cli.options import add_mocap_options, add_pose_options, mocap_import, pose_import
from perception.landmarks import LandmarkParams
from perception.observation import ObserveParams

#: The field's definitions of a movement, fields of LandmarkParams.
DEFINITIONS = (
    Setting(LandmarkParams, "threshold", "onset and end where the speed crosses this share of "
            "its peak (default {default})", metavar="SHARE"),
    Setting(LandmarkParams, "speed", "an absolute speed bound instead of the share",
            metavar="M/S"),
    Setting(LandmarkParams, "hold", "the speed must stay beyond the bound this long (default "
            "{default})", metavar="S"),
    Setting(LandmarkParams, "cutoff", "zero-lag Butterworth low-pass cutoff (default {default} "
            "Hz; 0: none)", metavar="HZ"),
)
#: The scale of pixel tracks: none by default (the file's own, or refused as unknown).
SCALE = (
    Setting(ObserveParams, "px_per_m", "image scale of tracks, pose files and videos, px/m",
            metavar="X"),
    Setting(ObserveParams, "object_diameter", "the object's real diameter, m, to scale tracks "
            "by its apparent one", default=None, metavar="M"),
)


def register(sub) -> None:
    """Add the ``landmarks`` subcommand to ``sub`` (an argparse subparsers action).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The top-level parser's subparsers.
    """
    p = sub.add_parser("landmarks", help="measure reach-to-grasp landmarks, no models (CSV)",
                       description="Measure the landmarks of every movement in each INPUT "
                       "(motion-capture recordings: every reach; tracks, pose files or "
                       "videos: the movement; a folder or manifest.csv: its clips, as batch "
                       "finds them) by the field's definitions: onset and end where "
                       "the transport speed crosses a share of its peak (or an absolute speed), "
                       "after a zero-lag low-pass filter. Writes batch's landmarks.csv: one "
                       "row per landmark per movement in ms, mm, mm/s, %% of the movement, with "
                       "its unit, clock and flag (ok, or why it is doubtful), and rows for a "
                       "trial that gives none, with its status and reason (docs/glossary.md "
                       "lists the columns). Exit status 1 when a trial could not be measured.")
    # kept as typed (a Path would make "udp://host" "udp:/host"): their kinds are read first
    p.add_argument("inputs", nargs="+", metavar="INPUT",
                   help="motion-capture recordings, tracks or pose files, videos, folders "
                        "of them, or a batch manifest.csv")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="TABLE.csv",
                   help="the table to write")
    p.add_argument("--wide", action="store_true",
                   help="one row per movement, a column per landmark, in the same units "
                        "(their units and clocks in TABLE.units.json beside it)")
    add_settings(p.add_argument_group("definitions"), DEFINITIONS)
    add_settings(p.add_argument_group("scale of pixel tracks"), SCALE)
    # a pose file's keypoints, individual, rate and object size (--object-diameter-px scales
    # a tracks file without its object's size too), as recognize reads them
    add_pose_options(p)
    add_mocap_options(p)
    p.set_defaults(func=run)


def landmark_settings(args: argparse.Namespace):
    """The definitions, motion-capture and pose settings of parsed ``args``, each checked by
    the class that declares it (an error names the field; the command line its flag).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of ``landmarks``.

    Returns
    -------
    params : LandmarkParams
    mocap : MocapImport
        Bounded by ``params`` too: one rule bounds and measures.
    pose : PoseImport or None
        None without a pose option (``--keypoints``, ``--fps``, ``--pose-config``, ...).
    """
    params = LandmarkParams(threshold=args.threshold, speed=args.speed, hold=args.hold,
                            cutoff=args.cutoff or None)
    # the scale is measure_inputs' arguments: checked by the classes that declare it
    ObserveParams(**{k: v for k, v in (("object_diameter", args.object_diameter),
                                       ("px_per_m", args.px_per_m)) if v is not None})
    mocap = mocap_import(args).with_landmarks(params)
    return params, mocap, pose_import(args)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv landmarks`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from perception.errors import InputError
    from perception.io.atomic import check_output, write_text
    from perception.measure import measure_inputs
    from perception.recordings import trial_summary
    from perception.report.tables import tidy_landmarks, wide_landmarks, write_units

    params, mocap, pose = landmark_settings(args)
    from perception.io.names import output_folder, output_stem
    from perception.pipeline import TRACKS_SUFFIX, clip_name
    from perception.sources import check_command

    for spec in args.inputs:  # a camera or a stream: watch's
        check_command(spec, "landmarks")
    args.inputs = [Path(spec) for spec in args.inputs]
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
        if not path.exists():
            raise InputError("input not found", path)
        inputs.append(path)

    def tracks_out(path: Path) -> Path | None:
        # a video's tracks go beside the table, never beside the user's video
        if clip_name(path)[1] != "video":
            return None
        return (output_folder(args.output.parent, "tracks")
                / f"{output_stem(clip_name(path)[0])}{TRACKS_SUFFIX}")

    bar = progress_bar(args.quiet)
    try:
        found = measure_inputs(inputs, params=params, mocap=mocap, px_per_m=args.px_per_m,
                               object_diameter=args.object_diameter,
                               object_diameter_px=args.object_diameter_px, pose=pose,
                               tracks_out=tracks_out, progress=bar)
    finally:
        if bar is not None:
            bar.close()
    from hammer_mv.cli.batch import no_clips, skipped_line

    if found.skipped and not args.quiet:  # as batch says them: none passed over silently
        print(skipped_line("landmarks", found.skipped, "-v logs each"), file=sys.stderr)
    movements = found.movements
    if not movements and not found.trials:  # folders of nothing: as batch, no empty table
        raise no_clips(found.skipped, inputs[0] if len(inputs) == 1 else None)
    if args.wide:
        table = wide_landmarks(movements)
        write_text(args.output, table.to_csv(index=False))
        write_units(args.output, table.columns)
    else:
        write_text(args.output, tidy_landmarks(movements).to_csv(index=False))
    missed = [m for m in movements if m.landmarks is None]
    flagged = [m for m in movements if m.landmarks is not None and m.flagged]
    if not args.quiet:
        done = sum(1 for m in movements
                   if m.landmarks is not None and m.status == "complete" and not m.flagged)
        line = f"{len(movements)} movement(s), {done} complete"
        if flagged:
            line += f", {len(flagged)} with a flagged landmark"
        print(f"{line} -> {args.output}", file=sys.stdout)
        print(trial_summary(found.trials, len(movements) - len(missed), len(missed)),
              file=sys.stdout)
    for m in missed:  # always: none dropped; by the clip, as the table and a batch name it
        print(f"{m.clip}: not scored: {flag_text(m.reason)}", file=sys.stderr)
    return 1 if missed else 0


class _Bar:
    """tqdm bars on stderr that follow ``(done, total, what)`` reports: a bar per stage (a
    large table's rows checked, its trials read on each pass, the movements measured)."""

    #: The unit counted, by the report's first word.
    UNITS = {"checking": "row", "reading": "trial", "measuring": "movement"}

    def __init__(self):
        self.bar = None
        self.what = None

    def __call__(self, done: int, total: int, what: str) -> None:
        if self.bar is None or what != self.what or done < self.bar.n:  # a new stage or pass
            from tqdm import tqdm

            self.close()  # a bar of its own: tqdm's pace (miniters) is the last stage's
            self.bar = tqdm(total=total, desc=what, file=sys.stderr, leave=False,
                            dynamic_ncols=True, unit=self.UNITS.get(what.split()[0], "it"))
            self.what = what
        self.bar.total = total
        self.bar.update(done - self.bar.n)

    def close(self) -> None:
        """Clear the bar drawn last."""
        if self.bar is not None:
            self.bar.close()


def progress_bar(quiet: bool) -> _Bar | None:
    """A progress bar for ``measure_inputs``' ``progress``, or None: with ``--quiet``,
    when stderr is not a terminal, or on CI (``CI=true``).

    Parameters
    ----------
    quiet : bool
        ``--quiet``.
    """
    import os

    if quiet or not sys.stderr.isatty() or os.environ.get("CI", "").lower() in ("true", "1"):
        return None
    return _Bar()

"""``hammer-mv batch``: recognise many clips in parallel and write a report."""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

from hammer_mv.cli.checks import cap_jobs, output_folder
from hammer_mv.cli.options import add_recognition_options, load_repertoire, recognition_settings
from hammer_mv.cli.recognize import add_figure_options
from perception.batch import find_clips, run_batch


def register(sub) -> None:
    """Add the ``batch`` subcommand to ``sub`` (an argparse subparsers action).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The top-level parser's subparsers.
    """
    p = sub.add_parser("batch", help="recognise a folder of clips (or a synth manifest)",
                       description="Track and recognise every clip of INPUT (a folder of "
                       "videos / .tracks.h5 files, or a manifest.csv from hammer-mv synth) in "
                       "parallel; write REPORT_DIR/report.html, summary.csv, statistics and "
                       "per-clip reports. Rerunning skips clips whose report is current. "
                       "Exits 1 if any clip failed (each failure is in the report).")
    p.add_argument("input", type=Path, metavar="INPUT",
                   help="folder of videos, .tracks.h5 or pose files, or a manifest.csv")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="REPORT_DIR",
                   help="report folder (report.html, summary.csv, per-clip reports)")
    p.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="worker processes working on clips, one thread each (1: in this "
                   "process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a dask.distributed scheduler, e.g. tcp://host:8786")
    add_figure_options(p)
    add_recognition_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv batch`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from perception.errors import InputError

    # local processes only: a scheduler's workers are its own
    jobs = (args.jobs if args.scheduler and args.jobs >= 1
            else cap_jobs(args.jobs, "batch", quiet=args.quiet))
    output_folder(args.output)
    found = find_clips(args.input)
    items = found.items
    if found.skipped and not args.quiet:
        names = ", ".join(f"{name} ({why})" for name, why in found.skipped[:3])
        more = f" and {len(found.skipped) - 3} more" if len(found.skipped) > 3 else ""
        print(f"hammer-mv batch: skipped {len(found.skipped)} file(s) that are not clips: "
              f"{names}{more}", file=sys.stderr)
    if not items:
        raise InputError("no clips found", args.input)
    rep, rep_id = load_repertoire(args)
    summary = run_batch(items, args.output, rep, recognition_settings(args), jobs=jobs,
                        scheduler=args.scheduler, repertoire_id=rep_id, quiet=args.quiet,
                        skipped=found.skipped, figure_format=args.figure_format,
                        dpi=args.dpi)
    failed = int((summary["status"] != "ok").sum())
    reused = int(summary["reused"].sum())
    if not args.quiet:
        print(f"{len(summary)} clips: {len(summary) - failed - reused} recognised, "
              f"{reused} reused (their reports were current), {failed} failed -> "
              f"{args.output / 'report.html'}")
    if failed:
        print(f"hammer-mv batch: {failed} clip(s) failed ({failure_reasons(summary, items)}); "
              f"see {args.output / 'summary.csv'}", file=sys.stderr)
        return 1
    return 0


def failure_reasons(summary, items) -> str:
    """The most common reason clips failed, with its count: ``"3: <reason>, 1 other"``.

    A clip's error begins with its file's name, which is left out so that
    clips failing for the same reason count together.

    Parameters
    ----------
    summary : pandas.DataFrame
        The batch summary (``clip``, ``status``, ``error``).
    items : list of BatchItem
        The clips (their paths).
    """
    paths = {item.clip: str(item.path.absolute()) for item in items}  # as run_batch has them
    reasons = Counter()
    for clip, status, error in zip(summary["clip"], summary["status"], summary["error"]):
        if status == "ok":
            continue
        reason = str(error or "").strip() or "unknown error"
        if clip in paths:
            reason = reason.removeprefix(f"{paths[clip]}: ")
        reasons[reason.splitlines()[0]] += 1
    reason, count = reasons.most_common(1)[0]
    others = sum(reasons.values()) - count
    return f"{count}: {reason}" + (f"; {others} other" if others else "")

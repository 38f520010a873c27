"""``hammer-mv batch``: recognise many clips in parallel and write a report."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hammer_mv.cli.options import add_recognition_options, load_repertoire, recognition_settings
from perception.batch import discover, run_batch
from perception.workers import start_early


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
                   help="local processes working on clips (this one and N-1 workers)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a dask.distributed scheduler, e.g. tcp://host:8786")
    add_recognition_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv batch`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    if args.jobs < 1:
        raise ValueError(f"--jobs: expected at least 1, got {args.jobs}")
    items = discover(args.input)
    if not items:
        raise ValueError(f"{args.input}: no clips found")
    if args.jobs > 1 and len(items) > 1 and not args.scheduler:
        start_early()  # the workers' fork server imports while the repertoire loads
    rep, rep_id = load_repertoire(args)
    summary = run_batch(items, args.output, rep, recognition_settings(args), jobs=args.jobs,
                        scheduler=args.scheduler, repertoire_id=rep_id, quiet=args.quiet)
    failed = int((summary["status"] != "ok").sum())
    reused = int(summary["reused"].sum())
    if not args.quiet:
        print(f"{len(summary)} clips: {len(summary) - failed - reused} recognised, "
              f"{reused} reused (their reports were current), {failed} failed -> "
              f"{args.output / 'report.html'}")
    if failed:
        print(f"hammer-mv batch: {failed} clip(s) failed; see the report", file=sys.stderr)
        return 1
    return 0

"""``hammer-mv batch``: recognise many clips in parallel and write a report."""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

from hammer_mv.cli.checks import cap_jobs, writable_folder
from hammer_mv.cli.flags import field_flag, flag_text
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
                       "videos, .tracks.h5 files, pose files and motion-capture recordings, "
                       "not its subfolders; or a manifest.csv naming them, as hammer-mv synth "
                       "writes one) in parallel; write REPORT_DIR/report.html, summary.csv, "
                       "statistics and per-clip reports. Files that are not clips are skipped "
                       "and listed. Rerunning skips clips whose report is current. "
                       "A motion-capture recording gives a row per reach and per trial not "
                       "scored, with its status and reason. Exits 1 if any clip failed or a "
                       "trial could not be scored (each is in the report, with why).")
    # kept as typed (a Path would make "udp://host" "udp:/host"): its kind is read first
    p.add_argument("input", metavar="INPUT",
                   help="folder of videos, .tracks.h5, pose files or motion-capture "
                   "recordings, or a manifest.csv")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="REPORT_DIR",
                   help="report folder (report.html, summary.csv, per-clip reports)")
    p.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="worker processes working on clips, one thread each (1: in this "
                   "process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a dask.distributed scheduler, e.g. tcp://host:8786")
    field_flag("jobs", "--jobs")
    field_flag("scheduler", "--scheduler")
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
    from perception.recognition.result import warnings_summary
    from perception.recordings import trial_summary

    # local processes only: a scheduler's workers are its own
    jobs = (args.jobs if args.scheduler and args.jobs >= 1
            else cap_jobs(args.jobs, "batch", quiet=args.quiet))
    from perception.sources import check_command

    check_command(args.input, "batch")  # a camera or a stream: watch's
    args.input = Path(args.input)
    writable_folder(args.output)  # a read-only one is said of itself, before any work
    _not_over_inputs(args.input, args.output)
    found = find_clips(args.input)
    items = found.items
    if found.skipped and not args.quiet:
        print(skipped_line("batch", found.skipped, "batch.json lists them"), file=sys.stderr)
    if not items:
        raise no_clips(found.skipped, args.input)
    rep, rep_id = load_repertoire(args)
    summary = run_batch(items, args.output, rep, recognition_settings(args), jobs=jobs,
                        scheduler=args.scheduler, repertoire_id=rep_id, quiet=args.quiet,
                        skipped=found.skipped, figure_format=args.figure_format,
                        dpi=args.dpi)
    failed = int((summary["status"] == "failed").sum())
    unscored = summary[(summary["status"] != "ok") & (summary["status"] != "failed")]
    reused = int(summary["reused"].sum())
    scored = int((summary["status"] == "ok").sum())
    if not args.quiet:
        print(f"{len(summary)} clips: {scored - reused} recognised, "
              f"{reused} reused (their reports were current), {failed} failed, "
              f"{len(unscored)} not scored -> {args.output / 'report.html'}")
        print(trial_summary(summary.attrs.get("trials", len(summary)), scored,
                            len(summary) - scored))
        for line in warnings_summary(_warnings(summary), "clips"):
            print(f"hammer-mv batch: warning: {flag_text(line)}", file=sys.stderr)
    why = unscored["reason"] if "reason" in unscored else unscored["error"]
    for clip, reason in zip(unscored["clip"], why):  # always: nothing dropped without a word
        print(f"{clip}: not scored: {flag_text(str(reason))}", file=sys.stderr)
    if failed:
        print(f"hammer-mv batch: {failed} clip(s) failed ({failure_reasons(summary, items)}); "
              f"see {args.output / 'summary.csv'}", file=sys.stderr)
    return 1 if failed or len(unscored) else 0


def no_clips(skipped: list[tuple[str, str]], where) -> Exception:
    """The error of an input that holds no clip: the first file skipped, and why."""
    from perception.errors import InputError

    first = f" ({len(skipped)} file(s) skipped; {skipped[0][0]}: {skipped[0][1]})" \
        if skipped else ""
    return InputError(f"no clips found{first}", where)


def skipped_line(command: str, skipped: list[tuple[str, str]], rest: str) -> str:
    """The one line that names the files of an input folder a command did not read, and
    why: the first three, then how many more (``rest`` says where they are listed)."""
    names = ", ".join(f"{name} ({why})" for name, why in skipped[:3])
    more = f" and {len(skipped) - 3} more ({rest})" if len(skipped) > 3 else ""
    return (f"hammer-mv {command}: skipped {len(skipped)} file(s) that are not clips: "
            f"{names}{more}")


def _warnings(summary) -> list[tuple[str, list[dict]]]:
    """Each scored clip's warnings (its report's ``warning_values``), as ``run_batch``
    gives them in the summary's ``attrs`` (none for a summary made otherwise)."""
    kept = summary.attrs.get("warnings")
    return [] if kept is None else [(clip, list(values)) for clip, values in kept.by_clip]


def _not_over_inputs(source: Path, out: Path) -> None:
    """Refuse a report folder that is the input folder when the batch report would
    write over a file of the user's there (a recording named ``summary.csv``)."""
    import os

    from perception.discovery import REPORT_SET
    from perception.errors import InputError

    try:
        same = source.is_dir() and out.is_dir() and os.path.samefile(source, out)
    except OSError:
        return
    if not same or (out / "batch.json").is_file():  # a report folder, its own input
        return
    clash = next((name for name in REPORT_SET if (out / name).is_file()), None)
    if clash is not None:
        raise InputError(f"the batch report would write over {clash}, a file of the input "
                         "folder: choose another output folder", out, field="--output")


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
        if status != "failed":
            continue
        reason = str(error or "").strip() or "unknown error"
        if clip in paths:
            reason = reason.removeprefix(f"{paths[clip]}: ")
        reasons[reason.splitlines()[0]] += 1
    reason, count = reasons.most_common(1)[0]
    others = sum(reasons.values()) - count
    return f"{count}: {flag_text(reason)}" + (f"; {others} other" if others else "")

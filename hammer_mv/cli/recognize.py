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


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv recognize`` with parsed ``args``; return the exit status.

    Prints one line (the clip, its verdict and winner, the report) unless ``--quiet``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    """
    from hammer_mv.cli.checks import output_folder
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
    from perception.sources import check_command

    kind = check_command(args.input, "recognize")  # a camera or a stream: watch's
    path = args.input = Path(args.input)
    output_folder(args.output)  # before any tracking
    if not path.exists():
        raise InputError("input not found", path)
    if path.is_dir():
        raise InputError("expected a video, tracks file, pose file or motion-capture "
                         "recording, got a folder (use hammer-mv batch)", path)
    if kind is not None and kind.name == "mocap":
        return _run_mocap(args, path)
    from perception.recordings import unknown_layout

    if (why := unknown_layout(path)) is not None:
        raise InputError(why, path)
    clip, kind = clip_name(path)
    if kind == "unknown":
        what = "video, tracks file, pose file or motion-capture recording"
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
            print(f"{clip}: warning: {warning}", file=sys.stderr)
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


#: Columns of ``<recording>.trials.csv``, the accounting of a recording's trials.
TRIALS_COLUMNS = ("trial", "status", "reason", "verdict", "verdict_detail", "verdict_reason",
                  "winner", "winner_note", "onset_time", "end_time", "report", "source")


def _run_mocap(args: argparse.Namespace, path: Path) -> int:
    """``recognize`` of a motion-capture file: every reach in it, one report each, and
    ``<recording>.trials.csv`` accounting for every trial (exit 1 when one is not scored)."""
    import dataclasses
    import traceback

    from hammer_mv.cli.flags import flag_text
    from hammer_mv.cli.options import load_repertoire, mocap_import, recognition_settings
    from perception.errors import HammerMVError
    from perception.factors import entry_columns
    from perception.io.atomic import check_output, write_csv
    from perception.pipeline import clip_fingerprint
    from perception.reaches import Unscored
    from perception.recognition.result import warnings_summary
    from perception.recordings import read_recording, recognize_reach, trial_summary
    from perception.report.clip import remove_stale_reports, write_clip_report
    from perception.report.tables import write_units

    settings = recognition_settings(args)
    options = settings.mocap or mocap_import(args)
    recording = read_recording(path, options)
    rep, rep_id = load_repertoire(args)
    args.output.mkdir(parents=True, exist_ok=True)
    table = check_output(_trials_table(args.output, path), [path])
    rows, missed, kept, warned, k = [], [], [], [], 0
    for entry in recording.entries:
        if isinstance(entry, Unscored):
            rows.append({**_row(entry.name, entry.status, entry.reason, entry.onset_time,
                                entry.end_time, path), **entry_columns(entry)})
            missed.append((entry.name, entry.reason))
            continue
        reach = dataclasses.replace(entry, name=_own_clip(args.output, entry.name, path))
        onset, end = float(reach.time[reach.onset]), float(reach.time[reach.end])
        fingerprint = clip_fingerprint(path, settings, f"{rep_id}#reach{k}")
        k += 1
        try:
            rec, info = recognize_reach(reach, rep, settings, options)
            extra = {"fingerprint": fingerprint, "condition": None, "input": str(path),
                     "mocap": info}
            paths = write_clip_report(rec, args.output, extra=extra,
                                      figures=not args.no_figures,
                                      figure_format=args.figure_format, dpi=args.dpi)
        except OSError:
            raise  # the output folder's (full, read-only): the user's to fix, for every reach
        except HammerMVError as exc:  # this reach's (a scene that cannot be planned, ...)
            why = f"failed: {flag_text(exc.problem)}"
        except Exception as exc:  # noqa: BLE001 - a bug on one reach must not take the rest
            traceback.print_exc()
            why = (f"failed: unexpected {type(exc).__name__} (a bug in hammer-mv; its "
                   "traceback is above)")
        else:
            kept.append(reach.name)
            rows.append({**_row(reach.name, "ok", "", onset, end, path, rec=rec,
                                report=paths["json"].name), **entry_columns(entry)})
            warned.append((reach.name, [w.to_dict() for w in rec.validation_warnings]))
            if not args.quiet:
                print(f"{verdict_line(rec)} -> {paths['json']}")
            continue
        rows.append({**_row(reach.name, "failed", why, onset, end, path),
                     **entry_columns(entry)})
        missed.append((reach.name, why))
    # reports of this recording's trials that are not scored now (or no longer in it)
    remove_stale_reports(args.output, path, kept)
    # the trial's factors and numbers after its name, as summary.csv has them
    more = list(dict.fromkeys(c for r in rows for c in r if c not in TRIALS_COLUMNS))
    columns = [TRIALS_COLUMNS[0], *more, *TRIALS_COLUMNS[1:]]
    write_csv(table, _trials_table_cells(rows, columns))
    write_units(table, columns)
    if not args.quiet:
        print(f"{trial_summary(len(recording.trials), len(kept), len(missed))} -> {table}")
        # one line per kind of warning for the recording; each reach's are in its report
        for line in warnings_summary(warned, "reaches"):
            print(f"{path.name}: warning: {line}", file=sys.stderr)
    for name, why in missed:  # always: nothing is dropped without a word
        print(f"{name}: not scored: {why}", file=sys.stderr)
    return 1 if missed else 0


def _trials_table_cells(rows: list[dict], columns: list[str]):
    """``<recording>.trials.csv``'s cells as :func:`~perception.io.atomic.write_csv` writes
    them: each column's text as pandas writes its DataFrame of ``rows`` (``reach_number``
    as integers: a whole trial without a reach has none, not 1.0), here without pandas
    for the columns of text and numbers a recording gives (its import would be a third of
    a ``recognize``'s start-up); otherwise that DataFrame."""
    cells = {c: _column_cells([r.get(c) for r in rows], integers=c == "reach_number")
             for c in columns}
    if all(v is not None for v in cells.values()):
        return cells
    import pandas as pd

    trials = pd.DataFrame(rows, columns=columns)
    if "reach_number" in trials:
        trials = trials.astype({"reach_number": "Int64"})
    return trials


def _column_cells(values: list, integers: bool = False) -> list[str] | None:
    """A column's cells as pandas writes them to csv, or None where only pandas knows.

    Missing (None, NaN) is empty; a column of text and missing cells is the text; of
    integers, the integers; of numbers with a float or a missing cell, floats as numpy
    writes them (pandas' float64); ``integers`` (pandas' Int64): integral numbers.
    """
    import numpy as np

    missing = [v is None or (isinstance(v, float) and v != v) for v in values]
    present = [v for v, m in zip(values, missing) if not m]
    if all(isinstance(v, str) for v in present):
        return ["" if m else v for v, m in zip(values, missing)]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) < 2 ** 53
               for v in present):
        return None
    if integers:
        if not all(float(v).is_integer() for v in present):
            return None
        return ["" if m else str(int(v)) for v, m in zip(values, missing)]
    if all(type(v) is int for v in present) and not any(missing):
        return [str(v) for v in values]
    floats = np.array([np.nan if m else v for v, m in zip(values, missing)], dtype=np.float64)
    return ["" if m else t for t, m in zip(floats.astype(str), missing)]


def _row(name: str, status: str, reason: str, onset: float, end: float, path: Path, *,
         rec=None, report: str = "") -> dict:
    """One row of ``<recording>.trials.csv``."""
    return {"trial": name, "status": status, "reason": reason,
            "verdict": rec.verdict if rec is not None else None,
            "verdict_detail": rec.verdict_detail if rec is not None else None,
            "verdict_reason": rec.verdict_reason if rec is not None else None,
            "winner": rec.winner if rec is not None else None,
            "winner_note": rec.winner_note if rec is not None else None,
            # ms on the recording's clock, as every landmark file (docs/glossary.md)
            "onset_time": onset * 1e3, "end_time": end * 1e3, "report": report,
            "source": str(path)}


def _same_file(a, b: Path) -> bool:
    """Whether ``a`` (a path as a report recorded it) names the file ``b``."""
    import os

    try:
        return os.path.samefile(a, b)
    except (OSError, TypeError, ValueError):
        return False


def _trials_table(out: Path, path: Path) -> Path:
    """``out/<stem>.trials.csv``, or ``out/<file name>.trials.csv`` when the first is
    another recording's (``P01.tsv`` and ``P01.csv`` into one folder)."""
    from perception.io.names import output_stem

    first = out / f"{output_stem(path.stem)}.trials.csv"
    if first.is_file():
        import pandas as pd

        try:
            sources = pd.read_csv(first, usecols=["source"])["source"].dropna().unique()
        except (OSError, ValueError):
            sources = []
        if len(sources) and not any(_same_file(s, path) for s in sources):
            return out / f"{output_stem(path.name)}.trials.csv"
    return first


def _own_clip(out: Path, name: str, path: Path) -> str:
    """``name``, or the input's full file name in its place (``P01.tsv-trial3``,
    ``P01.mp4``) when ``out`` holds a report of that name made from another input: two
    recordings' reports never overwrite each other (a video and a table of one stem)."""
    import json

    from perception.report.clip import clip_outputs

    report = clip_outputs(out, name)["json"]
    if not report.is_file():
        return name
    try:
        source = json.loads(report.read_text()).get("input")
    except (OSError, ValueError, AttributeError):
        return name
    if source is None or _same_file(source, path):
        return name
    tail = name[len(path.stem):] if name.startswith(path.stem) else f"-{name}"
    return f"{path.name}{tail}"

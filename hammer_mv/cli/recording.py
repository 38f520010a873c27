"""A motion-capture recording scored reach by reach: the loop ``recognize`` and ``watch`` share.

Every trial leaves a report, or a row of ``<recording>.trials.csv`` and a
line on stderr saying why not (docs/mocap.md); what differs between the
commands is only how a reach is scored (offline, or its rows replayed to the
online recogniser) and what is said of it.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import traceback
from collections.abc import Callable
from pathlib import Path

#: Why a reach is not scored after Ctrl-C (its row in ``<recording>.trials.csv``).
INTERRUPTED = "interrupted (Ctrl-C) before it was scored"
#: Columns of ``<recording>.trials.csv``, the accounting of a recording's trials.
TRIALS_COLUMNS = ("trial", "status", "reason", "verdict", "verdict_detail", "verdict_reason",
                  "winner", "winner_note", "onset_time", "end_time", "report", "source")


def score_recording(args: argparse.Namespace, path: Path, score: Callable, *,
                    name: Callable | None = None,
                    stopped: Callable[[], str | None] = lambda: None) -> int:
    """Score every reach of the recording ``path`` and account for every trial; the exit
    status (1 when a trial or reach is not scored).

    Each reach's report is ``recognize``'s; ``<recording>.trials.csv`` in
    ``args.output`` has a row per reach and per trial not scored, with its
    status and reason, and each of those is named on stderr. A reach that
    fails (its scene cannot be planned, a bug) costs only its own row.

    Parameters
    ----------
    args : argparse.Namespace
        The command's (``output``, ``no_figures``, ``quiet``, the recognition options,
        ``figure_format`` and ``dpi`` where it has them).
    path : Path
        The recording.
    score : callable
        ``score(reach, settings, options, repertoire) -> (Recognition, extra, say)``:
        the reach's recognition, what its report adds (``mocap``, ``online``) and
        ``say(rec, paths)``, which prints its line.
    name : callable, optional
        ``name(entry) -> str``: a reach's or trial's report name (default: its own).
    stopped : callable, optional
        Why the reaches left are not scored (a signal), or None to go on.
    """
    from hammer_mv.cli.checks import writable_folder
    from hammer_mv.cli.flags import flag_text
    from hammer_mv.cli.options import load_repertoire, mocap_import, recognition_settings
    from perception.errors import HammerMVError
    from perception.factors import entry_columns
    from perception.io.atomic import check_output, write_csv
    from perception.pipeline import clip_fingerprint
    from perception.reaches import Unscored
    from perception.recognition.result import warnings_summary
    from perception.recordings import read_recording, trial_summary
    from perception.report.clip import clip_outputs, remove_stale_reports, write_clip_report
    from perception.report.tables import write_units

    name = name or (lambda entry: entry.name)
    settings = recognition_settings(args)
    options = settings.mocap or mocap_import(args)
    recording = read_recording(path, options)
    out = writable_folder(args.output)
    out.mkdir(parents=True, exist_ok=True)
    entries = [dataclasses.replace(e, name=name(e)) for e in recording.entries]
    table = check_output(_trials_table(out, path), [path])
    inputs = [f for f in (getattr(args, "repertoire", None), path) if f is not None]
    for entry in entries:  # every output refused before the first reach is scored
        if not isinstance(entry, Unscored):
            for target in clip_outputs(out, entry.name).values():
                check_output(target, inputs)
    rep, rep_id = load_repertoire(args)
    figures = {"figures": not args.no_figures,
               **{k: getattr(args, k) for k in ("figure_format", "dpi") if hasattr(args, k)}}
    rows, missed, kept, warned, k = [], [], [], [], -1
    interrupted = False  # Ctrl-C in recognize: the reaches left are accounted for, then 130
    for entry in entries:
        if isinstance(entry, Unscored):
            rows.append({**_row(entry.name, entry.status, entry.reason, entry.onset_time,
                                entry.end_time, path), **entry_columns(entry)})
            missed.append((entry.name, entry.reason))
            continue
        k += 1  # the reach's number in the recording, in its fingerprint
        onset, end = float(entry.time[entry.onset]), float(entry.time[entry.end])
        if (why := stopped() or (INTERRUPTED if interrupted else None)) is None:
            try:
                rec, extra, say = score(entry, settings, options, rep)
                extra = {"fingerprint": clip_fingerprint(path, settings, f"{rep_id}#reach{k}"),
                         "condition": None, "input": str(path), **extra}
                paths = write_clip_report(rec, out, extra=extra, **figures)
            except KeyboardInterrupt:  # this reach's report is not written (atomic)
                interrupted, why = True, INTERRUPTED
            except OSError:
                raise  # the output folder's (full, read-only): the user's, for every reach
            except HammerMVError as exc:  # this reach's (a scene that cannot be planned, ...)
                why = f"failed: {flag_text(exc.problem)}"
            except Exception as exc:  # noqa: BLE001 - a bug on one reach must not take the rest
                traceback.print_exc()
                why = (f"failed: unexpected {type(exc).__name__} (a bug in hammer-mv; its "
                       "traceback is above)")
            else:
                kept.append(entry.name)
                rows.append({**_row(entry.name, "ok", "", onset, end, path, rec=rec,
                                    report=paths["json"].name), **entry_columns(entry)})
                warned.append((entry.name, [w.to_dict() for w in rec.validation_warnings]))
                if not args.quiet:
                    say(rec, paths)
                continue
        rows.append({**_row(entry.name, "failed" if why.startswith("failed") else "not scored",
                            why, onset, end, path), **entry_columns(entry)})
        missed.append((entry.name, why))
    if stopped() is None and not interrupted:  # reports of trials not scored now (or no
        remove_stale_reports(out, path, kept)  # longer in the recording)
    # the trial's factors and numbers after its name, as summary.csv has them
    more = list(dict.fromkeys(c for r in rows for c in r if c not in TRIALS_COLUMNS))
    columns = [TRIALS_COLUMNS[0], *more, *TRIALS_COLUMNS[1:]]
    write_csv(table, _trials_table_cells(rows, columns))
    write_units(table, columns)
    if not args.quiet:
        print(f"{trial_summary(len(recording.trials), len(kept), len(missed))} -> {table}",
              flush=True)
        # one line per kind of warning for the recording; each reach's are in its report
        for line in warnings_summary(warned, "reaches"):
            print(f"{path.name}: warning: {flag_text(line)}", file=sys.stderr)
    for entry_name, why in missed:  # always: nothing is dropped without a word
        print(f"{entry_name}: not scored: {why}", file=sys.stderr)
    if interrupted:  # the command's own end of an interruption (status 130)
        raise KeyboardInterrupt
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


def same_file(a, b: Path) -> bool:
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
        if len(sources) and not any(same_file(s, path) for s in sources):
            return out / f"{output_stem(path.name)}.trials.csv"
    return first

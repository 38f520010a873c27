"""Batch recognition: many clips, in parallel, resumable, failures recorded.

A batch input is a folder of videos and/or tracks files, or a synth
``manifest.csv`` (which also gives each clip's condition). Each clip is
tracked (videos), observed, scored against the repertoire and reported on
its own (:func:`process_clip`); a failure is recorded with its message and
the batch goes on. Rerunning skips clips whose report is complete and
current: the report records a fingerprint of its input and settings.

Clips run in local processes (``jobs``) or on a dask.distributed cluster
(``scheduler``); each clip's result does not depend on where it ran.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import os
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import perception.workers as workers
from perception.batch_clip import (
    ClipResult,
    ModelRows,
    RunTiming,
    _guarded,
    _numbers,
    _remove_outputs,
    process_clip,
)
from perception.boundary import expect
from perception.discovery import (
    ERRORS_LOG,
    REPORT_SET,
    BatchItem,
    Discovery,
    discover,
    expand_recordings,
    find_clips,
    recording_items,
    stream_recordings,
)
from perception.errors import InputError
from perception.io.atomic import write_json, write_text
from perception.io.names import output_folder
from perception.pipeline import RecognitionSettings
from perception.provenance import code_digest
from perception.recognition.repertoire import PlanCache, Repertoire
from perception.report.clip import (  # remove_stale_reports: also perception.batch's
    ClipSummary,
    remove_stale_reports,
    remove_stale_trials,
)
from perception.report.figures import DPI, FIGURE_FORMATS
from perception.report.tracking import tracking_columns

if TYPE_CHECKING:
    import pandas as pd

    from perception.reach_data import Reach

__all__ = ["REPORT_SET", "BatchItem", "ClipResult", "ClipWarnings", "Discovery", "RunTiming",
           "count_trials", "discover", "expand_recordings", "find_clips", "process_clip",
           "remove_stale_reports", "run_batch", "summary_table"]

log = logging.getLogger(__name__)

@dataclass(frozen=True)
class _Work:
    """A batch item as handed to a worker: with a recording's reach, read once by the
    batch's own process (every worker reading the whole file cost each of 16 workers
    the 4 s a 600-trial table takes to read)."""

    item: BatchItem
    reach: Reach | None = None


@dataclass(frozen=True)
class _Job:
    """What every clip of one batch shares (sent to each worker once, when it starts)."""

    out: Path
    settings: RecognitionSettings
    repertoire_id: str
    figure_format: str = "png"
    dpi: int = DPI

    @property
    def plan_cache(self) -> PlanCache:
        """Plans of the batch's scenes, beside its report, shared by every process."""
        return PlanCache(self.out / PLANS_FOLDER)

    def run(self, work: _Work, repertoire: Repertoire) -> ClipResult:
        start, cpu = time.perf_counter(), time.process_time()
        result = _guarded(work.item, self.out, repertoire=repertoire, settings=self.settings,
                          repertoire_id=self.repertoire_id, plan_cache=self.plan_cache,
                          figure_format=self.figure_format, dpi=self.dpi, reach=work.reach)
        return dataclasses.replace(result, timing=RunTiming(
            os.getpid(), start, time.perf_counter(), time.process_time() - cpu))

    def lost(self, work: _Work, message: str) -> ClipResult:
        """A clip whose worker process died running it: failed, its outputs removed."""
        item = work.item
        log.error("%s: %s", item.clip, message)
        _remove_outputs(item, self.out)
        return ClipResult(item.clip, item.condition, "failed", f"{item.path}: {message}",
                          self.settings.hammer.rule, factors=item.factors,
                          reason=f"{item.path}: {message}", **_numbers(item))


#: Folder of the plan cache inside a report folder.
PLANS_FOLDER = ".plans"


def _file_size(item: BatchItem | _Work) -> int:
    """A clip's expected cost, for handing out the largest first (0 if unreadable: a
    missing file fails at once)."""
    if isinstance(item, _Work):
        if item.reach is not None:  # its samples, as bytes of a table's row
            return len(item.reach.time) * 100
        item = item.item
    try:
        return item.path.stat().st_size
    except OSError:
        return 0


def _run_local(items: list[_Work], repertoire: Repertoire, job: _Job,
               jobs: int) -> Iterator[ClipResult]:
    """Every item here (``jobs`` 1) or in ``jobs`` worker processes (largest first).

    Each worker gets the repertoire once, when it starts (and keeps the
    models it re-plans for a scene between clips).
    """
    left, used = len(items), min(jobs, len(items))
    size = _file_size if jobs > 1 else None  # one process: in name order
    for result in workers.run_pool(items, job, jobs, shared=repertoire, size=size):
        yield result
        left -= 1
        if used > 1 and left == used - 1:  # a worker has nothing more to do
            _prepare_report()


def _take_back(found: list[BatchItem], late: list[tuple[BatchItem, list[str]]],
               done: list[ClipResult], job: _Job, repertoire: Repertoire) -> list[BatchItem]:
    """The items of a streamed batch, each recording that failed at its end (a marker
    never seen) as one failed item in place of the trials handed out for it, as a
    batch that reads every recording first gives it; their outputs removed."""
    for item, names in late:
        gone = set(names)
        for given in (i for i in found if i.clip in gone):
            _remove_outputs(given, job.out)
        found = [i for i in found if i.clip not in gone] + [item]
        done[:] = [r for r in done if r.clip not in gone]
        done.append(job.run(_Work(item), repertoire))  # reads it: fails with its error
    return found


def _prepare_report() -> None:
    """Import what the batch report needs (pandas, scipy.special, matplotlib: about
    1 s) on the core a worker has left while the others finish the last clips:
    this process would otherwise wait idle, then import them."""
    import matplotlib.figure  # noqa: F401 - the chapter 5 figures' (0.4 s)
    import scipy.special  # noqa: F401

    import perception.report.batch  # noqa: F401 - pandas


def _run_dask(items: Iterable[_Work], repertoire: Repertoire, job: _Job,
              scheduler: str) -> Iterator[ClipResult]:
    """Every item on a dask.distributed cluster (:mod:`perception.cluster`), submitted
    as ``items`` gives them (a stream of recordings' reaches is scored while it is
    read); this process imports the report's libraries once a worker is idle."""
    try:
        from perception.cluster import run_on_cluster
    except ImportError as exc:  # dask is the optional "cluster" extra
        raise InputError(f"needs dask.distributed ({exc}): pip install 'hammer-mv[cluster]'",
                         field="scheduler") from None
    return run_on_cluster(items, job.run, repertoire, scheduler, at_tail=_prepare_report,
                          lost=job.lost)


def _model_value(s: ClipSummary, name: str, values: np.ndarray) -> float:
    """``values`` (one per model of ``s``) of the model ``name``; NaN if it has none."""
    return float(values[s.names.index(name)]) if name in s.names else float("nan")


#: Per-clip columns of ``summary.csv`` after ``clip, condition, winner, rule``:
#: (column, value of a scored clip's :class:`ClipSummary`). Another step may
#: append its own (the column is empty for failed clips).
CLIP_COLUMNS: list[tuple[str, Callable[[ClipSummary], object]]] = [
    ("verdict", lambda s: s.verdict),
    ("familiarity", lambda s: s.familiarity),
    ("margin", lambda s: s.margin),
    ("winner_log_likelihood", lambda s: _model_value(s, s.winner, s.final_log_likelihood)),
]


def summary_table(results: list[ClipResult], reference: str | None = None) -> pd.DataFrame:
    """The batch summary, one row per clip (``summary.csv``).

    Columns: ``clip, condition``, the design's other factors (:attr:`ClipResult.factors`:
    the manifest's columns, a long table's factor columns, a file name's; one named
    like a column here gets ``manifest_`` before it), ``trial_number`` and
    ``reach_number`` where a recording was read (its trial's own id, the reach's
    number within it, from 1), ``winner, rule``, the
    :data:`CLIP_COLUMNS`
    (``verdict, familiarity, margin, winner_log_likelihood``),
    ``reference_model`` and ``reference_confidence`` (its final thesis-rule
    confidence, m), ``verdict_detail`` (the kind of an ``abnormal`` verdict),
    ``verdict_rule`` (the rule that gave the verdict),
    the observed landmarks (``movement_time`` s, ``peak_speed`` m/s,
    ``peak_speed_time``, ``mga`` m, ``mga_time``, ``aperture_peaks``:
    :data:`~perception.report.clip.KINEMATICS_COLUMNS`), ``conf_<model>``
    (final thesis-rule confidence of each model of the first scored clip,
    m), the tracking quality
    (``track_<marker>``, ``minlik_<marker>``, ``reacquisitions``,
    ``ambiguous_frames``), ``status`` (``ok``, ``failed``, or a recording's
    trial that gives no reach: ``no reach``, ``starts in motion``, ...),
    ``reused`` (the report was already current), ``error`` (a failure's),
    ``reason`` (why a row has no result: the error, or the trial's reason);
    beside each column whose name R
    cannot take unquoted, its alias (``conf_grasp_0_5s``:
    :func:`~perception.report.tables.with_r_aliases`).

    Parameters
    ----------
    results : list of ClipResult
        The clips, in table order.
    reference : str, optional
        The reference grasp model (default:
        :func:`~perception.report.conditions.reference_model` of the scored clips).
    """
    import pandas as pd

    from perception.report.clip import KINEMATICS_COLUMNS
    from perception.report.conditions import reference_model
    from perception.report.tables import with_r_aliases

    scored = [r for r in results if r.summary is not None]
    names = scored[0].summary.names if scored else []
    if reference is None:
        reference = reference_model([r.summary for r in scored], [r.condition for r in scored])
    factors = list(dict.fromkeys(f for r in results for f, _ in r.factors))
    numbered = any(getattr(r, "trial_number", None) is not None for r in results)
    own = ("clip", "condition", *(("trial_number", "reach_number") if numbered else ()))
    # a list a column, not a dict a row (3 kB a row: a study's largest peak while its
    # report began); a column a row first names comes after those seen, as from rows
    columns: dict[str, list] = {}
    for k, r in enumerate(results):
        entry = {"winner": r.winner, "rule": r.rule}
        s = r.summary
        for column, value in CLIP_COLUMNS:
            entry[column] = value(s) if s is not None else None
        entry["reference_model"] = reference if s is not None else None
        entry["reference_confidence"] = (_model_value(s, reference, s.confidence[:, -1])
                                         if s is not None and reference else float("nan"))
        entry["verdict_detail"] = s.verdict_detail if s is not None else None
        entry["verdict_rule"] = s.verdict_rule if s is not None else None
        for column in KINEMATICS_COLUMNS:
            entry[column] = s.landmark(column) if s is not None else float("nan")
        for n in names:
            entry[f"conf_{n}"] = (_model_value(s, n, s.confidence[:, -1]) if s is not None
                                  else float("nan"))
        entry.update(tracking_columns(s.tracking if s is not None else None))
        entry["status"] = "ok" if r.scored else r.status
        entry["reused"] = r.status == "reused"
        entry["error"] = r.error
        entry["reason"] = r.reason
        given = dict(r.factors)
        numbers = ({"trial_number": r.trial_number, "reach_number": r.reach_number}
                   if numbered else {})
        row = {"clip": r.clip, "condition": r.condition, **{
            f"manifest_{f}" if f in entry or f in own else f: given.get(f)
            for f in factors}, **numbers, **entry}
        for column, value in row.items():
            if column not in columns:  # missing in the rows before: NaN, as from rows
                columns[column] = [np.nan] * k
            columns[column].append(value)
        for values in columns.values():
            if len(values) == k:
                values.append(np.nan)
    table = pd.DataFrame(columns) if results else pd.DataFrame([])
    for count in ("aperture_peaks", "reach_number"):  # 1, not 1.0 (empty where unknown)
        if count in table:
            table[count] = table[count].astype("Int64")
    return with_r_aliases(table)


def run_batch(
    items: Iterable[BatchItem],
    out: str | os.PathLike,
    repertoire: Repertoire,
    settings: RecognitionSettings | None = None,
    *,
    jobs: int = 1,
    scheduler: str | None = None,
    repertoire_id: str = "",
    quiet: bool = False,
    skipped: Iterable[tuple[str, str]] = (),
    figure_format: str = "png",
    dpi: int = DPI,
) -> pd.DataFrame:
    """Process every clip and write the batch report.

    Parameters
    ----------
    items : iterable of BatchItem
        Clips (see :func:`discover`).
    out : str or os.PathLike
        Report folder.
    repertoire : Repertoire
        Models to score against.
    settings : RecognitionSettings, optional
        Observation and engine settings.
    jobs : int
        Worker processes working on clips, one OpenCV, FFmpeg, planning and
        BLAS thread each (:mod:`perception.workers`; 1: in this process;
        ignored with ``scheduler``), and then on a large study's statistics
        (:func:`~perception.report.statistics.landmark_statistics`). Scripts
        that use ``jobs > 1`` need the usual ``if __name__ == "__main__":``
        guard of multiprocessing.
    scheduler : str, optional
        Address of a dask.distributed scheduler (``tcp://host:8786``) to run on.
    repertoire_id : str
        Identity of the repertoire for the resume fingerprints.
    quiet : bool
        No progress bar (there is none anyway when stderr is not a terminal).
    skipped : iterable of (str, str)
        Files of the input that are not clips, with why (:attr:`Discovery.skipped`),
        listed in ``batch.json`` and ``report.html``.
    figure_format : str
        Format of every figure, the clips' and the batch's: ``png``, ``svg`` or ``pdf``.
    dpi : int
        Their resolution, dots per inch.

    Returns
    -------
    pandas.DataFrame
        The summary (see :func:`summary_table`; with ``verdict_reason`` and
        ``winner_note``, as ``summary.csv``), a row per clip: per reach of a
        recording and per trial or movement of it that gives none (its status
        and reason); ``attrs["trials"]`` the trials read (:func:`count_trials`);
        ``attrs["timing"]`` where the run's time went: ``read`` (finding the
        clips, reading recordings), ``clips`` (from the first clip handed out
        to the last result), ``report`` (the batch's report), s, and ``runs``,
        a row per summary row: the process that ran it, its start and end
        (``time.perf_counter()``) and its CPU time (:class:`RunTiming`);
        ``attrs["warnings"]`` each scored clip's warnings (:class:`ClipWarnings`).
        This process keeps a clip's every-model curves on disk while the
        clips run (:class:`~perception.batch_clip.ModelRows`): what it holds a
        clip does not grow with the repertoire.
        Reports of a recording's trials not scored in this run (no longer in
        the file, or no reach now) are removed from ``out``. The report files
        (:data:`REPORT_SET`) come from one run: the last run's are removed
        first, and this run's again if one of them cannot be written.
    """
    if not isinstance(repertoire, Repertoire):  # not an AttributeError from a worker
        raise TypeError(f"expected a Repertoire (Repertoire.load or Repertoire.build), "
                        f"got {type(repertoire).__name__}")
    if settings is not None and not isinstance(settings, RecognitionSettings):
        raise TypeError(f"expected RecognitionSettings, got {type(settings).__name__}")
    settings = RecognitionSettings() if settings is None else settings
    if isinstance(items, (str, os.PathLike)):  # not an AttributeError from its characters
        raise TypeError(f"run_batch(items=): expected BatchItems, got the path {str(items)!r}: "
                        f"give discover({str(items)!r})")
    items = list(items)
    for item in items:
        expect(item, BatchItem, "run_batch(items=)", hint="discover")
    if not items:  # as the command line says it, not a KeyError from an empty summary
        raise InputError("no clips found: the batch was given none", field="items")
    if jobs < 1:
        raise InputError(f"expected at least 1, got {jobs}", field="jobs")
    if figure_format not in FIGURE_FORMATS:
        raise InputError(f"expected one of {', '.join(FIGURE_FORMATS)}, got {figure_format!r}",
                         field="figure_format")
    t0 = time.perf_counter()
    # absolute: a worker, a dask one above all, may run in another folder
    items = [dataclasses.replace(i, path=Path(i.path).absolute()) for i in items]
    out = Path(out).absolute()
    out.mkdir(parents=True, exist_ok=True)
    for sub in ("tracks", PLANS_FOLDER):  # a link leading out of the report: refused now
        output_folder(out, sub)
    # Recordings for workers, local or dask's, are read while the workers score what
    # has been read (a 600-trial table took 4.3 s to read before the first reach went out).
    streamed = (scheduler is not None or jobs > 1) and any(i.kind == "mocap" for i in items)
    late: list[tuple[BatchItem, list[str]]] = []  # recordings that failed at their end
    if streamed:
        found: list[BatchItem] = []

        def work() -> Iterator[_Work]:
            for item, reach in stream_recordings(items, settings, late):
                found.append(item)
                yield _Work(item, reach)
            if scheduler is None:  # while the workers finish the last clips (dask: _run_dask)
                _prepare_report()
    else:
        pairs = recording_items(items, settings)
        items = [item for item, _ in pairs]
    # each worker one decoding and one planning thread: the parallelism is the workers'
    parallel = scheduler is not None or streamed or min(jobs, len(items)) > 1
    job = _Job(out, dataclasses.replace(settings, decoder_threads=1, planning_threads=1)
               if parallel else settings, repertoire_id, figure_format, dpi)
    t1 = time.perf_counter()
    if scheduler:  # largest first, unless streamed: the cluster's last clips are its shortest
        results = _run_dask(work() if streamed else sorted(
            (_Work(*pair) for pair in pairs), key=_file_size, reverse=True),
            repertoire, job, scheduler)
    elif streamed:
        results = workers.run_pool(work(), job, jobs, shared=repertoire)
    else:
        results = _run_local([_Work(*pair) for pair in pairs], repertoire, job, jobs)
    with ModelRows(out) as rows:  # each clip's summary on disk, a compact one here
        # with a scheduler `jobs` is the cluster's: the report's statistics fit here, alone;
        # the results' list is _finish's alone (it lets go of them before the report)
        return _finish(_collected(results, rows, streamed, len(items), quiet), rows, items,
                       found if streamed else None, late, job, repertoire, settings, skipped,
                       t0=t0, t1=t1, jobs=1 if scheduler else jobs)


def _collected(results: Iterable[ClipResult], rows: ModelRows, streamed: bool, n: int,
               quiet: bool) -> list[ClipResult]:
    """Every result as it comes (a progress bar on a terminal), its per-model curves
    kept in ``rows``: what the batch holds a clip does not grow with the models."""
    from tqdm import tqdm

    done: list[ClipResult] = []
    with tqdm(total=None if streamed else n, unit="clip", file=sys.stderr,
              desc="batch", disable=quiet or not sys.stderr.isatty()) as bar:
        for result in results:
            done.append(rows.keep(result))
            bar.update()
    return done


def _finish(done: list[ClipResult], rows: ModelRows, items: list[BatchItem],
            found: list[BatchItem] | None, late: list, job: _Job, repertoire: Repertoire,
            settings: RecognitionSettings, skipped, *, t0: float, t1: float,
            jobs: int) -> pd.DataFrame:
    """The batch's report from its results (:func:`run_batch`'s last steps)."""
    from perception.report.batch import with_verdict_reasons, write_batch_report
    from perception.report.conditions import reference_model

    out, figure_format, dpi = job.out, job.figure_format, job.dpi
    streamed = found is not None
    if streamed:
        items = _take_back(found, late, done, job, repertoire)
    done.sort(key=lambda r: r.clip)
    t2 = time.perf_counter()
    scored_now = {r.clip for r in done if r.scored}
    remove_stale_trials(out, {path: clips & scored_now  # reports of trials no longer in them
                              for path, clips in _recordings(items).items()})
    scored = [r for r in done if r.summary is not None]
    # the one model whose curves the report reads (summary_table would find the same)
    reference = reference_model([r.summary for r in scored], [r.condition for r in scored])
    summary = summary_table(done, reference)
    summary.attrs["trials"] = count_trials(items)
    bugs = [f"== {r.clip} ({r.error})\n{r.traceback}" for r in done if r.traceback]
    clips, runs = len(done), _runs(done)
    not_scored = [{"clip": r.clip, "status": r.status, "reason": r.reason}
                  for r in done if not r.scored]
    warnings = ClipWarnings(tuple((r.clip, tuple(r.summary.warning_values)) for r in scored))
    kept = rows.summaries((r.summary for r in scored), reference)
    # the caller's table is summary.csv's (the report would add these columns to its copy)
    summary = with_verdict_reasons(summary, kept)
    # the results, read: the report reads each clip back from disk, the summary's rows
    # hold the rest (the caller keeps no reference to the list)
    del scored
    done.clear()
    _remove_report(out)  # the last run's set: a kill or a full disk below leaves no mix
    try:
        skipped = list(skipped)  # the page and batch.json both list them
        write_batch_report(summary, kept, out, models=repertoire.models,
                           figure_format=figure_format, dpi=dpi, jobs=jobs, skipped=skipped)
        if bugs:
            write_text(out / ERRORS_LOG, "\n".join(bugs))
        write_json(out / "batch.json", {
            "clips": clips, "trials": summary.attrs["trials"],
            "ok": int((summary["status"] == "ok").sum()),
            "failed": int((summary["status"] == "failed").sum()),
            "not_scored": not_scored,
            "skipped": [{"file": n, "reason": why} for n, why in skipped],
            "settings": settings.fingerprint(), "repertoire": job.repertoire_id,
            "code": code_digest()})
    except BaseException:  # none of the set rather than part of it
        _remove_report(out)
        raise
    # set last: pandas copies attrs deeply with every frame made from this one
    summary.attrs["timing"] = {"read": t1 - t0, "clips": t2 - t1,
                               "report": time.perf_counter() - t2, "runs": runs}
    summary.attrs["warnings"] = warnings
    return summary


@dataclass(frozen=True)
class ClipWarnings:
    """Each scored clip's warnings (its report's ``warning_values``), in the summary's
    order: ``attrs["warnings"]`` of :func:`run_batch`'s summary.

    The command line said them by reading every clip's report back (0.8 ms
    a clip on a quiet machine, 6 on a busy one: 8 s to a minute of a
    10,000-trial study, after the report). Read-only,
    and shared rather than copied by the deep copy pandas makes of a frame's
    ``attrs`` for every frame made from it.

    Attributes
    ----------
    by_clip : tuple of (str, tuple of dict)
        Each scored clip and its warnings (``{"kind", "value"}``).
    """

    by_clip: tuple[tuple[str, tuple[dict, ...]], ...]

    def __deepcopy__(self, _memo) -> ClipWarnings:
        return self


def _runs(done: list[ClipResult]) -> np.ndarray:
    """Each result's :class:`RunTiming` as a row (process, start, end, cpu; NaN for a
    clip no worker ran), in ``done``'s order."""
    return np.array([dataclasses.astuple(r.timing) if r.timing else (np.nan,) * 4
                     for r in done], dtype=float).reshape(len(done), 4)


def count_trials(items: Iterable[BatchItem]) -> int:
    """Trials among ``items``: each trial of a recording once, each other clip as one.

    Parameters
    ----------
    items : iterable of BatchItem
        Clips after :func:`expand_recordings`.
    """
    return len({(str(i.path), i.trial) if i.trial is not None else (str(i.path), i.clip)
                for i in items})


def _recordings(items: Iterable[BatchItem]) -> dict[Path, set[str]]:
    """The motion-capture recordings among ``items``, with their clips' names."""
    out: dict[Path, set[str]] = {}
    for i in items:
        if i.kind == "mocap":
            out.setdefault(Path(i.path), set()).add(i.clip)
    return out


def _remove_report(out: Path) -> None:
    """Remove the batch report set (:data:`REPORT_SET`) from ``out``, as far as it can."""
    from perception.report.tables import TABLES  # in REPORT_SET too, once discovery lists them

    for name in dict.fromkeys((*REPORT_SET, *TABLES)):
        with contextlib.suppress(OSError):
            (out / name).unlink(missing_ok=True)

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
import hashlib
import json
import logging
import multiprocessing
import os
import sys
import tempfile
from collections import deque
from collections.abc import Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from perception import __version__
from perception.io.atomic import write_json
from perception.errors import InputError
from perception.recognition.engine import HammerParams, recognize
from perception.observe import ObserveParams, observe
from perception.recognition.repertoire import Repertoire
from perception.report import ClipSummary, clip_outputs, write_batch_report, write_clip_report

__all__ = ["BatchItem", "BatchSettings", "clip_name", "discover", "process_clip", "run_batch",
           "VIDEO_SUFFIXES"]

log = logging.getLogger(__name__)

VIDEO_SUFFIXES = (".mp4", ".avi", ".mkv", ".mov", ".m4v")
TRACKS_SUFFIX = ".tracks.h5"
#: Files that sit beside clips and are not inputs: ground truth, the synth
#: manifest, and what a batch writes (so a report folder can be its own input).
COMPANION_SUFFIXES = (".truth.h5", ".recognition.json", ".confidence.csv", ".confidence.png",
                      ".paths.png")
#: Which file stands for a clip found more than once (a tracks file spares tracking).
_PREFERENCE = {"tracks": 2, "video": 1, "unknown": 0}
COMPANION_NAMES = ("manifest.csv", "README.md", "recipe.toml", "summary.csv", "statistics.csv",
                   "condition_profiles.csv", "condition_profiles.png", "report.html",
                   "batch.json", "repertoire.h5")


@dataclass(frozen=True)
class BatchItem:
    """One clip of a batch.

    Attributes
    ----------
    clip : str
        Clip name (file stem).
    path : Path
        Video or tracks file.
    kind : str
        ``video``, ``tracks`` or ``unknown`` (recorded as a failure).
    condition : str or None
        Stimulus condition, when a manifest gives it.
    """

    clip: str
    path: Path
    kind: str
    condition: str | None = None


@dataclass(frozen=True)
class BatchSettings:
    """Everything that decides a clip's result (part of its fingerprint).

    Parameters
    ----------
    observe : ObserveParams
        Tracks -> observation settings.
    hammer : HammerParams
        Rule and weights.
    quiet : bool
        No progress bars.
    """

    observe: ObserveParams = field(default_factory=ObserveParams)
    hammer: HammerParams = field(default_factory=HammerParams)
    quiet: bool = False

    def fingerprint(self) -> dict:
        """JSON-able settings that change results."""
        return {"observe": dataclasses.asdict(self.observe),
                "hammer": dataclasses.asdict(self.hammer)}


def clip_name(path: Path) -> tuple[str, str]:
    """Clip name and input kind (``video``, ``tracks`` or ``unknown``) of a file.

    Parameters
    ----------
    path : Path
        The file.
    """
    name = path.name
    if name.endswith(TRACKS_SUFFIX):
        return name[: -len(TRACKS_SUFFIX)], "tracks"
    if path.suffix.lower() in VIDEO_SUFFIXES:
        return path.stem, "video"
    return path.stem, "unknown"


def discover(source: str | os.PathLike) -> list[BatchItem]:
    """List the clips of a batch input.

    Parameters
    ----------
    source : str or os.PathLike
        A folder, or a ``manifest.csv`` with columns ``clip``, ``condition`` and
        ``video`` (path relative to the manifest) as written by ``hammer-mv synth``.

    Returns
    -------
    list of BatchItem
        Sorted by clip name. A clip with both a video and a tracks file uses the
        tracks file. Other files become ``unknown`` items (reported as failed).

    Raises
    ------
    InputError
        If the source does not exist, or a manifest is unreadable.
    """
    source = Path(source)
    if not source.exists():
        raise InputError("batch input not found", source)
    if source.is_file():
        if source.suffix.lower() != ".csv":
            raise InputError("batch input must be a folder or a manifest.csv", source)
        try:
            man = pd.read_csv(source)
        except (OSError, ValueError, pd.errors.ParserError) as exc:
            raise InputError(f"unreadable manifest: {exc}", source) from None
        if "clip" not in man.columns or "video" not in man.columns:
            raise InputError("manifest needs columns clip and video", source)
        items = []
        for row in man.itertuples(index=False):
            path = (source.parent / str(row.video)).resolve()
            cond = getattr(row, "condition", None)
            cond = None if cond is None or pd.isna(cond) else str(cond)
            items.append(BatchItem(str(row.clip), path, clip_name(path)[1], cond))
        return sorted(items, key=lambda i: i.clip)
    found: dict[str, BatchItem] = {}
    conditions = {}
    manifest = source / "manifest.csv"
    if manifest.is_file():
        conditions = {i.clip: i.condition for i in discover(manifest)}
    for path in sorted(source.iterdir()):
        if path.name.startswith(".") or path.is_dir() or path.name in COMPANION_NAMES:
            continue
        if path.name.endswith(COMPANION_SUFFIXES):
            continue
        clip, kind = clip_name(path)
        prev = found.get(clip)
        if prev is None or _PREFERENCE[kind] > _PREFERENCE[prev.kind]:
            found[clip] = BatchItem(clip, path, kind, conditions.get(clip))
    return sorted(found.values(), key=lambda i: i.clip)


def _input_fingerprint(path: Path) -> dict:
    st = path.stat()
    return {"path": str(path.resolve()), "size": st.st_size, "mtime_ns": st.st_mtime_ns}


def _fingerprint(item: BatchItem, settings: BatchSettings, repertoire_id: str) -> str:
    payload = json.dumps({"input": _input_fingerprint(item.path), "settings":
                          settings.fingerprint(), "repertoire": repertoire_id,
                          "software": __version__}, sort_keys=True)
    return hashlib.sha256(payload.encode()).hexdigest()[:16]


def _current_report(item: BatchItem, out: Path, fingerprint: str) -> dict | None:
    """The clip's finished report if it was made from this input and these settings."""
    p = clip_outputs(out, item.clip)
    if not all(path.exists() for path in p.values()):
        return None
    try:
        data = json.loads(p["json"].read_text())
    except (OSError, ValueError):
        return None
    return data if data.get("fingerprint") == fingerprint else None


def process_clip(item: BatchItem, out: Path, repertoire: Repertoire,
                 settings: BatchSettings, repertoire_id: str = "") -> dict:
    """Track (if a video), observe, recognise and report one clip.

    Parameters
    ----------
    item : BatchItem
        The clip.
    out : Path
        Report folder; tracks of videos go to ``out/tracks/``.
    repertoire : Repertoire
        Models to score against.
    settings : BatchSettings
        Observation and engine settings.
    repertoire_id : str
        Identity of the repertoire, part of the report's fingerprint.

    Returns
    -------
    dict
        A summary row: clip, condition, status (``ok``, ``skipped`` — report
        already current — or ``failed``), error, winner, rule, and the report JSON
        under ``report`` (absent on failure).
    """
    row = {"clip": item.clip, "condition": item.condition, "status": "failed",
           "error": "", "winner": None, "rule": settings.hammer.rule}
    try:
        fp = _fingerprint(item, settings, repertoire_id)
        done = _current_report(item, out, fp)
        if done is not None:
            return {**row, "status": "skipped", "winner": done["winner"], "report": done}
        if item.kind == "unknown":
            raise InputError("not a video or tracks file", item.path)
        from perception.io.tracks import Tracks

        if item.kind == "video":
            from perception.tracking.tracker import track_video

            tracks_file = track_video(item.path, out / "tracks" / f"{item.clip}{TRACKS_SUFFIX}",
                                      progress=not settings.quiet and sys.stderr.isatty())
        else:
            tracks_file = item.path
        tracks = Tracks.load(tracks_file)
        try:
            obs = observe(tracks, settings.observe, clip=item.clip)
        except InputError as exc:  # name the file the user gave, not the clip
            raise InputError(exc.problem, item.path) from None
        try:
            rec = recognize(obs, repertoire, settings.hammer)
        except ValueError as exc:  # the scene the first frames describe cannot be planned
            raise InputError(f"cannot plan the models for this clip's scene (distance "
                             f"{obs.start_distance:.3f} m; check the scale: --px-per-m, "
                             f"--object-diameter): {exc}", item.path) from None
        write_clip_report(rec, out, extra={"fingerprint": fp, "condition": item.condition,
                                           "input": str(item.path)})
        # the summary is built from the written report, as for a resumed clip,
        # so fresh and reused clips go through the same JSON
        report = json.loads(clip_outputs(out, item.clip)["json"].read_text())
        return {**row, "status": "ok", "winner": rec.winner, "report": report}
    except (InputError, ValueError, OSError) as exc:
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        if isinstance(exc, OSError) and not isinstance(exc, InputError):
            msg = f"{item.path}: {msg}"
        log.info("%s failed: %s", item.clip, msg)
        _remove_outputs(item, out)
        return {**row, "error": msg}


def _remove_outputs(item: BatchItem, out: Path) -> None:
    """A clip that fails now must not keep a report from an earlier run."""
    for path in clip_outputs(out, item.clip).values():
        path.unlink(missing_ok=True)


def _guarded(item: BatchItem, out: Path, **kwargs) -> dict:
    """:func:`process_clip` that records an unexpected error instead of raising it.

    A batch goes on past any clip; the error (a bug, not bad input) is logged
    with its traceback and reported with its type.
    """
    try:
        return process_clip(item, out, **kwargs)
    except Exception as exc:  # noqa: BLE001 - one clip must not end the batch
        log.exception("%s: unexpected error", item.clip)
        _remove_outputs(item, out)
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        return {"clip": item.clip, "condition": item.condition, "status": "failed",
                "error": f"{item.path}: unexpected {type(exc).__name__}: {first}",
                "winner": None, "rule": kwargs["settings"].hammer.rule}


def _limit_threads() -> None:
    """One thread per worker process: parallelism comes from the processes."""
    import cv2

    cv2.setNumThreads(1)


@contextlib.contextmanager
def _one_thread():
    """OpenCV single-threaded in this process while it works beside its workers:
    its thread pool would otherwise take the cores the workers run on."""
    import cv2

    before = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        yield
    finally:
        cv2.setNumThreads(before)


def _init_worker(repertoire_file: str) -> None:
    """Worker setup: one thread, and the repertoire read once per process.

    The repertoire comes as a file, not pickled in the start-up arguments: a
    spawning parent blocks writing those into the worker's pipe until the
    worker has started and imported everything (about a second).
    """
    _limit_threads()
    _WORKER["repertoire"] = Repertoire.load(repertoire_file)


def _work_in_worker(item: BatchItem, out: Path, settings: BatchSettings,
                    repertoire_id: str) -> dict:
    # the worker's own repertoire keeps its re-planned models between clips
    return _guarded(item, out, repertoire=_WORKER["repertoire"], settings=settings,
                    repertoire_id=repertoire_id)


#: State of a worker process (set by its initializer; empty in the main process).
_WORKER: dict = {}


def _run_local(items: list[BatchItem], out: Path, repertoire: Repertoire,
               settings: BatchSettings, repertoire_id: str, jobs: int) -> Iterator[dict]:
    """Every item in this process and ``jobs - 1`` worker processes.

    The calling process takes items from the same queue as its workers: it is
    warm (modules imported) while a worker spends about a second starting, so
    a short batch gains from the second process too.
    """
    pending = deque(items)

    def here(item):
        return _guarded(item, out, repertoire=repertoire, settings=settings,
                        repertoire_id=repertoire_id)

    if jobs == 1 or len(items) <= 1:
        while pending:
            yield here(pending.popleft())
        return
    # spawn, not fork: a parent that has already rendered or planned holds
    # OpenCV/BLAS thread pools, and forking those deadlocks the workers
    ctx = multiprocessing.get_context("spawn")
    with tempfile.TemporaryDirectory(prefix=".repertoire-", dir=out) as tmp, _one_thread():
        rep_file = repertoire.save(Path(tmp) / "repertoire.h5")
        yield from _parallel(pending, here, jobs, ctx, rep_file, out, settings, repertoire_id)


def _parallel(pending, here, jobs, ctx, rep_file, out, settings, repertoire_id):
    """The caller's share of the clips and the workers', until all are done."""
    with ProcessPoolExecutor(max_workers=jobs - 1, initializer=_init_worker,
                             initargs=(str(rep_file),), mp_context=ctx) as pool:
        running: dict = {}

        def feed():
            # a few clips queued per worker, so it never waits for this process
            while pending and len(running) < 4 * (jobs - 1):
                item = pending.popleft()
                running[pool.submit(_work_in_worker, item, out, settings, repertoire_id)] = item

        def collect():
            for f in [f for f in running if f.done()]:
                del running[f]
                yield f.result()

        feed()
        while pending:
            yield here(pending.popleft())
            yield from collect()
            feed()
        # The queue is empty: take back clips no worker has started, rather than
        # wait for them.
        for f in list(running):
            if f.cancel():
                yield here(running.pop(f))
            yield from collect()
        for f in as_completed(list(running)):
            yield f.result()


def run_batch(
    items: Iterable[BatchItem],
    out: str | os.PathLike,
    repertoire: Repertoire,
    settings: BatchSettings | None = None,
    *,
    jobs: int = 1,
    scheduler: str | None = None,
    repertoire_id: str = "",
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
    settings : BatchSettings, optional
        Observation and engine settings.
    jobs : int
        Local processes working on clips: this one and ``jobs - 1`` spawned
        workers (ignored with ``scheduler``). Scripts that use ``jobs > 1``
        need the usual ``if __name__ == "__main__":`` guard of multiprocessing.
    scheduler : str, optional
        Address of a dask.distributed scheduler (``tcp://host:8786``) to run on.
    repertoire_id : str
        Identity of the repertoire for the resume fingerprints.

    Returns
    -------
    pandas.DataFrame
        The summary: clip, condition, winner, conf_<model> per model, status, error.
    """
    from tqdm import tqdm

    settings = BatchSettings() if settings is None else settings
    if jobs < 1:
        raise ValueError(f"--jobs: expected at least 1, got {jobs}")
    items = list(items)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    bar = tqdm(total=len(items), unit="clip", file=sys.stderr, desc="batch",
               disable=settings.quiet or not sys.stderr.isatty())
    rows: list[dict] = []
    if scheduler:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed

        with Client(scheduler) as client:
            rep = client.scatter(repertoire, broadcast=True)
            futures = [client.submit(_guarded, it, out, repertoire=rep, settings=settings,
                                     repertoire_id=repertoire_id, pure=False) for it in items]
            for fut in dask_completed(futures):
                rows.append(fut.result())
                bar.update()
    else:
        for row in _run_local(items, out, repertoire, settings, repertoire_id, jobs):
            rows.append(row)
            bar.update()
    bar.close()
    rows.sort(key=lambda r: r["clip"])
    summaries = {r["clip"]: ClipSummary.from_dict(r["report"]) for r in rows if "report" in r}
    names = next((s.names for s in summaries.values()), [])
    table = []
    for r in rows:
        rec = summaries.get(r["clip"])
        entry = {"clip": r["clip"], "condition": r["condition"], "winner": r["winner"],
                 "rule": r["rule"]}
        for n in names:
            entry[f"conf_{n}"] = (float(rec.confidence[rec.names.index(n), -1])
                                  if rec is not None and n in rec.names else float("nan"))
        entry["status"] = "ok" if r["status"] in ("ok", "skipped") else "failed"
        entry["reused"] = r["status"] == "skipped"
        entry["error"] = r["error"]
        table.append(entry)
    summary = pd.DataFrame(table)
    write_batch_report(summary, summaries, out)
    write_json(out / "batch.json", {"clips": len(rows),
                                    "ok": int((summary["status"] == "ok").sum()),
                                    "failed": int((summary["status"] != "ok").sum()),
                                    "settings": settings.fingerprint(),
                                    "repertoire": repertoire_id})
    return summary

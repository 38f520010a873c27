"""One clip of a batch: recognised, reported, and how it went (:class:`ClipResult`).

:func:`process_clip` is what each worker of a batch (:mod:`perception.batch`)
runs for a clip: the pipeline (:mod:`perception.pipeline`) and the clip's
report, or the reason it has none; a report already current for the same
input, settings, repertoire and code is reused.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import tempfile
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np

from perception.discovery import BatchItem
from perception.errors import HammerMVError
from perception.io.files import input_file
from perception.io.frame_sample import FrameSample
from perception.io.names import output_folder, output_stem
from perception.pipeline import (
    TRACKS_SUFFIX,
    RecognitionSettings,
    clip_fingerprint,
    load_clip,
    recognize_tracks,
)
from perception.recognition.repertoire import PlanCache, Repertoire
from perception.report.clip import ClipSummary, clip_outputs, remove_output, write_clip_report
from perception.report.figures import DPI, FIGURE_FORMATS
from perception.report.tracking import write_tracking_report

if TYPE_CHECKING:
    from perception.reach_data import Reach

__all__ = ["ClipResult", "ModelRows", "RunTiming", "process_clip"]

log = logging.getLogger("perception.batch")


def _recognized(item: BatchItem, out: Path, repertoire: Repertoire,
                settings: RecognitionSettings, fp: str, progress: bool,
                plan_cache: PlanCache | None, reach: Reach | None = None):
    """The recognition of one item and its report's extra entries."""
    if item.kind == "mocap":
        import dataclasses

        from perception.recordings import cached_reaches, recognize_reach

        if reach is None:
            reach = cached_reaches(item.path, settings.mocap)[item.reach or 0]
        if reach.name != item.clip:  # made safe or unique (expand_recordings)
            reach = dataclasses.replace(reach, name=item.clip)
        rec, info = recognize_reach(reach, repertoire, settings, settings.mocap,
                                    plan_cache=plan_cache)
        return rec, {"fingerprint": fp, "condition": item.condition, "input": str(item.path),
                     "mocap": info}
    frames = FrameSample()
    tracks_out = output_folder(out, "tracks") / f"{output_stem(item.clip)}{TRACKS_SUFFIX}"
    tracks = load_clip(item.path, tracks_out=tracks_out,
                       progress=progress, setup=settings.tracking, pose=settings.pose,
                       frames=frames, **settings.video_options())
    rec = recognize_tracks(tracks, repertoire, settings, clip=item.clip, source=item.path,
                           plan_cache=plan_cache)
    tracking = write_tracking_report(tracks, out, item.clip, frames=frames)
    return rec, {"fingerprint": fp, "condition": item.condition, "input": str(item.path),
                 "tracking": tracking}


def _current_report(item: BatchItem, out: Path, fingerprint: str,
                    figure_format: str = "png") -> dict | None:
    """The clip's finished report if it was made from this input and these settings
    (its figures in ``figure_format``)."""
    p = clip_outputs(out, item.clip, figure_format)
    if not all(path.exists() for path in p.values()):
        return None
    try:
        data = json.loads(p["json"].read_text())
    except (OSError, ValueError):
        return None
    return data if data.get("fingerprint") == fingerprint else None


@dataclass(frozen=True)
class RunTiming:
    """Where and when one clip of a batch ran: what a profile of a batch reads
    (``tools/bench_recognition.py``: each worker's start-up, its idle time between
    clips, the clips' own cost).

    Attributes
    ----------
    process : int
        The process that ran it (its id).
    start, end : float
        ``time.perf_counter()`` there when it began and ended, s (one clock
        for every process of a machine on Linux and macOS).
    cpu : float
        CPU time that process spent on it, s.
    """

    process: int
    start: float
    end: float
    cpu: float


@dataclass(frozen=True)
class ClipResult:
    """How one clip of a batch went.

    Attributes
    ----------
    clip : str
        Clip name.
    condition : str or None
        Its stimulus condition, if known.
    status : str
        ``ok``, ``reused`` (its report was already current), ``failed``, or
        the status of a recording's trial or movement that gives no reach to
        score (``no reach``, ``starts in motion``, ...: :attr:`BatchItem.unscored`).
    error : str
        One line saying why it failed (empty otherwise).
    rule : str
        Rule that picks the winner.
    summary : ClipSummary or None
        The scored clip (None if it failed).
    traceback : str
        The traceback of a failure that is a bug, not bad input (empty otherwise).
    factors : tuple of (str, str)
        The manifest's other columns for this clip (:attr:`BatchItem.factors`).
    reason : str
        Why it has no result, in a sentence (a failure's error, or a trial's
        reason: ``no reach: the hand never moved``); empty for a scored clip.
    trial_number : str or None
        A recording's trial's own id (:attr:`BatchItem.trial_number`).
    reach_number : int or None
        Which reach of its trial, from 1 (:attr:`BatchItem.reach_number`).
    timing : RunTiming or None
        Where and when it ran (None for a clip a worker did not run).
    """

    clip: str
    condition: str | None
    status: str
    error: str = ""
    rule: str = "likelihood"
    summary: ClipSummary | None = None
    traceback: str = ""
    factors: tuple[tuple[str, str], ...] = ()
    reason: str = ""
    trial_number: str | None = None
    reach_number: int | None = None
    timing: RunTiming | None = None

    @property
    def scored(self) -> bool:
        """Whether the clip has a result (``ok`` or ``reused``)."""
        return self.status in ("ok", "reused")

    @property
    def winner(self) -> str | None:
        """The winning model, if the clip was scored."""
        return None if self.summary is None else self.summary.winner


class ModelRows:
    """The batch's clips' every-model curves, kept on disk while the batch runs.

    A clip's :class:`ClipSummary` holds its confidence and transport term
    for every model of the repertoire (16 by default: 12 kB of a mocap
    trial's 20 kB), but the batch report reads every model's final value
    and the curves of one, the reference model, known only once every clip
    is in. :meth:`keep` writes a result's curves to a temporary file beside
    the report and keeps the final values; :meth:`restored` reads back the
    reference model's. What the batch holds a clip is then its scalars, its
    own curves (time, aperture, the kinematic traces) and two rows of
    ``(1, N)``: the same at any number of models and the report's numbers the
    same, bit for bit (float64 written and read as it was).

    Use it as a context manager: the file goes when it closes (at once on
    POSIX: it is never linked into the folder).

    Parameters
    ----------
    folder : Path
        Where the temporary file goes (the report folder: a disk, where
        ``/tmp`` may be memory).
    """

    def __init__(self, folder: Path):
        self._file: BinaryIO = tempfile.TemporaryFile(dir=folder, prefix=".batch-rows-")
        #: clip: (offset of its confidence, its shape, its transport's shape)
        self._where: dict[str, tuple[int, tuple[int, ...], tuple[int, ...]]] = {}
        #: the model lists seen, each kept once (every clip's are alike: 2 kB a clip)
        self._lists: dict[tuple[str, ...], list[str]] = {}

    def __enter__(self) -> ModelRows:
        return self

    def __exit__(self, *exc) -> None:
        self._file.close()

    def keep(self, result: ClipResult) -> ClipResult:
        """``result`` with its summary's per-model curves written here and dropped.

        The kept summary's ``confidence`` is its final column, ``(M, 1)``,
        its ``transport`` ``(M, 0)``, and its ``traces`` arrays (a reused
        report's are lists of floats: 32 bytes a value, not 8); a result
        without a summary is returned as it is.

        Parameters
        ----------
        result : ClipResult
            A clip's result, as a worker returned it.
        """
        s = result.summary
        if s is None:
            return result
        confidence = np.ascontiguousarray(s.confidence, dtype=float)
        transport = np.ascontiguousarray(s.transport, dtype=float)
        if confidence.ndim != 2 or transport.ndim != 2:  # no models: nothing to keep apart
            return result
        self._file.seek(0, 2)
        self._where[s.clip] = self._file.tell(), confidence.shape, transport.shape
        self._file.write(confidence.tobytes())
        self._file.write(transport.tobytes())
        traces = ({k: np.asarray(v, dtype=float) for k, v in s.traces.items()}
                  if isinstance(s.traces, dict) else s.traces)
        return dataclasses.replace(result, summary=dataclasses.replace(
            s, confidence=confidence[:, -1:].copy(),
            transport=np.zeros((len(s.names), 0)), traces=traces,
            names=self._shared(s.names), kinds=self._shared(s.kinds)))

    def _shared(self, values: list[str]) -> list[str]:
        """``values``, as the first equal list kept (read, never changed, by the report)."""
        return self._lists.setdefault(tuple(values), list(values))

    def restored(self, summary: ClipSummary, model: str | None) -> ClipSummary:
        """A kept summary with the curves of ``model`` alone, read back.

        ``names``, ``kinds`` and the per-model arrays hold ``model`` only: what
        the batch report reads of a clip once the reference model is known.
        Without ``model``, or for a clip that has no such model, every
        model's curves come back (the report then fails or reads as it would
        have).

        Parameters
        ----------
        summary : ClipSummary
            A summary :meth:`keep` returned.
        model : str or None
            The reference model.
        """
        if summary.clip not in self._where:  # not kept here: as it is
            return summary
        offset, shape, transport_shape = self._where[summary.clip]
        n = shape[0] * shape[1]
        if model is None or model not in summary.names:
            return dataclasses.replace(
                summary, confidence=self._read(offset, shape),
                transport=self._read(offset + 8 * n, transport_shape))
        i = summary.names.index(model)
        row = self._read(offset + 8 * i * shape[1], (1, shape[1]))
        width = transport_shape[1]
        transport = (self._read(offset + 8 * (n + i * width), (1, width))
                     if transport_shape[0] > i else np.zeros((1, 0)))
        pick = slice(i, i + 1)

        def one(values: np.ndarray) -> np.ndarray:  # an array a model, if it is one
            return values[pick] if len(values) == len(summary.names) else values

        return dataclasses.replace(
            summary, names=[model], kinds=summary.kinds[pick], confidence=row,
            transport=transport, final_log_likelihood=one(summary.final_log_likelihood),
            familiarities=one(summary.familiarities))

    def _read(self, offset: int, shape: tuple[int, ...]) -> np.ndarray:
        self._file.seek(offset)
        count = int(np.prod(shape))
        return np.frombuffer(self._file.read(8 * count), dtype=float).reshape(shape).copy()


def process_clip(item: BatchItem, out: Path, repertoire: Repertoire,
                 settings: RecognitionSettings, repertoire_id: str = "", *,
                 progress: bool = False, plan_cache: PlanCache | None = None,
                 figure_format: str = "png", dpi: int = DPI,
                 reach: Reach | None = None) -> ClipResult:
    """Recognise one clip through the pipeline (:mod:`perception.pipeline`) and report it.

    Parameters
    ----------
    item : BatchItem
        The clip.
    out : Path
        Report folder; tracks of videos go to ``out/tracks/``.
    repertoire : Repertoire
        Models to score against.
    settings : RecognitionSettings
        Observation and engine settings.
    repertoire_id : str
        Identity of the repertoire, part of the report's fingerprint.
    progress : bool
        Show a progress bar while tracking a video.
    plan_cache : PlanCache, optional
        Models re-planned for a scene, shared with the batch's other processes.
    figure_format : str
        The clip's figures' format, ``png``, ``svg`` or ``pdf`` (a report with
        its figures in another format is not current: they are drawn again).
    dpi : int
        Their resolution, dots per inch.
    reach : Reach, optional
        A recording's reach ``item`` names, read by the caller: the file is
        then not read here (a batch reads each recording once, not once per
        worker process).

    Returns
    -------
    ClipResult
        ``reused`` with the summary of the existing report when it is current
        for this input, settings and repertoire; ``failed`` with the error of
        a bad clip (its stale outputs removed).
    """
    base = dict(clip=item.clip, condition=item.condition, rule=settings.hammer.rule,
                factors=item.factors, **_numbers(item))
    if item.unscored is not None:  # a trial that gives no reach: its row says why
        _remove_outputs(item, out)  # an earlier run's report of it is not current
        status, reason = item.unscored
        return ClipResult(**base, status=status, reason=reason)
    try:
        # before hashing: a FIFO or device would never end
        input_file(item.path, "clip", empty=False)
        fp = clip_fingerprint(item.path, settings, repertoire_id + (
            f"#reach{item.reach}" if item.reach is not None else ""))
        done = _current_report(item, out, fp, figure_format)
        if done is not None:
            return ClipResult(**base, status="reused", summary=ClipSummary.from_dict(done))
        rec, extra = _recognized(item, out, repertoire, settings, fp, progress, plan_cache,
                                 reach)
        write_clip_report(rec, out, extra=extra, figure_format=figure_format, dpi=dpi)
        return ClipResult(**base, status="ok", summary=ClipSummary.from_recognition(rec, extra))
    except (HammerMVError, OSError) as exc:  # the clip's fault; anything else is a bug
        msg = _first_line(exc)
        if isinstance(exc, OSError) and item.path.name not in msg:
            msg = f"{item.path}: {msg}"
        log.info("%s failed: %s", item.clip, msg)
        _remove_outputs(item, out)
        return ClipResult(**base, status="failed", error=msg, reason=msg)


def _numbers(item: BatchItem) -> dict:
    """A recording's item's trial and reach numbers, for its :class:`ClipResult`."""
    return {"trial_number": getattr(item, "trial_number", None),
            "reach_number": getattr(item, "reach_number", None)}


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _remove_outputs(item: BatchItem, out: Path) -> None:
    """A clip that fails now must not keep a report from an earlier run.

    Never raises: it runs while a failure is being recorded (a name too long
    for the file system, a read-only folder) and must not end the batch.
    """
    try:
        paths = list(dict.fromkeys(p for fmt in FIGURE_FORMATS
                                   for p in clip_outputs(out, item.clip, fmt).values()))
    except (OSError, ValueError) as exc:
        log.warning("%s: cannot list its outputs to remove them: %s", item.clip, exc)
        return
    for path in paths:
        try:
            remove_output(path)
        except OSError as exc:
            log.warning("%s: %s", item.clip, exc)


def _guarded(item: BatchItem, out: Path, **kwargs) -> ClipResult:
    """:func:`process_clip` that records an unexpected error instead of raising it.

    A batch goes on past any clip; the error (a bug, not bad input) is logged
    with its traceback, reported with its type and kept with its traceback
    (``errors.log`` in the report folder).
    """
    try:
        return process_clip(item, out, **kwargs)
    except Exception as exc:  # noqa: BLE001 - one clip must not end the batch
        log.exception("%s: unexpected error (a bug in hammer-mv)", item.clip)
        _remove_outputs(item, out)
        msg = (f"{item.path}: unexpected {type(exc).__name__} (a bug in hammer-mv; "
               f"see errors.log): {_first_line(exc)}")
        return ClipResult(item.clip, item.condition, "failed", msg,
                          kwargs["settings"].hammer.rule, traceback=traceback.format_exc(),
                          factors=item.factors, reason=msg, **_numbers(item))

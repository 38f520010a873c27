"""One clip of a batch: recognised, reported, and how it went (:class:`ClipResult`).

:func:`process_clip` is what each worker of a batch (:mod:`perception.batch`)
runs for a clip: the pipeline (:mod:`perception.pipeline`) and the clip's
report, or the reason it has none; a report already current for the same
input, settings, repertoire and code is reused.
"""

from __future__ import annotations

import array
import dataclasses
import json
import logging
import math
import pickle
import tempfile
import traceback
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO, NamedTuple

import numpy as np

from perception.discovery import BatchItem, batch_file
from perception.errors import HammerMVError
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
from perception.report.clip import (
    KINEMATICS_COLUMNS,
    ClipSummary,
    PerModel,
    clip_outputs,
    measured_traces,
    remove_output,
    write_clip_report,
)
from perception.report.figures import DPI, FIGURE_FORMATS
from perception.report.tracking import write_tracking_report

if TYPE_CHECKING:
    from perception.reach_data import Reach

__all__ = ["ClipCurves", "ClipResult", "KeptSummaries", "ModelRows", "RunTiming",
           "process_clip"]

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
                    figure_format: str = "png", dpi: int = DPI) -> dict | None:
    """The clip's finished report if it was made from this input and these settings
    (its figures in ``figure_format``, PNG at ``dpi``)."""
    p = clip_outputs(out, item.clip, figure_format)
    if not all(path.exists() for path in p.values()):
        return None
    try:
        data = json.loads(p["json"].read_text())
    except (OSError, ValueError):
        return None
    if data.get("fingerprint") != fingerprint:
        return None
    if figure_format == "png" and not all(_png_dpi(path) == dpi for key, path in p.items()
                                          if key not in ("json", "csv")):
        return None  # a rerun at another --dpi draws its figures again: none left mixed
    return data


def _png_dpi(path: Path) -> int | None:
    """The resolution a PNG records (its pHYs chunk, read from the header alone), None if
    it records none or cannot be read."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            found = im.info.get("dpi")
    except (OSError, UnidentifiedImageError):
        return None
    return round(found[0]) if found else None


@dataclass(frozen=True, slots=True)
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


@dataclass(frozen=True, slots=True)
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
    """The batch's clips' summaries, kept on disk while the batch runs and its report
    is written.

    A clip's :class:`ClipSummary` holds its confidence and transport term
    for every model of the repertoire (16 by default), its kinematic traces,
    landmarks, notes and sentences: 21 kB of Python objects a motion-capture
    trial, which a study of 10,000 trials cannot hold. :meth:`keep` writes a
    result's summary to a temporary file beside the report (the per-model
    curves, time and aperture as float64 rows, the rest pickled) and keeps a
    compact summary: the scalars and landmarks ``summary.csv`` reads, one
    final value a model (its confidence and log-likelihood) and the warnings.
    :meth:`restored` reads a clip back, with the curves of one model (the
    reference model, known only once every clip is in), and :meth:`summaries`
    gives the report every scored clip that way, one at a time
    (:meth:`KeptSummaries.curves`: its time, aperture and that model's curves
    alone, without unpickling the rest). The report's numbers are the same,
    bit for bit (float64 written and read as it was).

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
        #: clip: its row of :attr:`_places`
        self._where: dict[str, int] = {}
        #: a clip's place in the file, :data:`_PLACE` numbers a clip (80 bytes, where a
        #: tuple of them was 300)
        self._places = array.array("q")
        #: a model count's empty transport, shared by the compact summaries
        self._no_transport: dict[int, np.ndarray] = {}
        #: the (names, kinds) pairs of the clips kept, each once
        self._models: dict[tuple[int, int], int] = {}
        self._model_lists: list[tuple[list[str], list[str]]] = []
        #: the model lists seen, each kept once (every clip's are alike: 2 kB a clip)
        self._lists: dict[tuple[str, ...], list[str]] = {}
        #: short texts every clip repeats (condition, verdict, factors, ...), each kept
        #: once: a result unpickled from a worker brings its own copy of each
        self._texts: dict = {}

    def __enter__(self) -> ModelRows:
        return self

    def __exit__(self, *exc) -> None:
        self._file.close()

    def keep(self, result: ClipResult) -> ClipResult:
        """``result`` with its summary written here and a compact one in its place.

        The compact summary holds what ``summary.csv`` and the choice of the
        reference model read: the scalars, ``confidence`` as its final column
        ``(M, 1)`` (``transport`` ``(M, 0)``), ``final_log_likelihood``, the
        landmarks of :data:`~perception.report.clip.KINEMATICS_COLUMNS`, the
        tracking quality and the warnings' values; no curve, trace, note or
        sentence (:meth:`restored` gives them back). A result without a
        summary is returned as it is, its repeated texts shared.

        Parameters
        ----------
        result : ClipResult
            A clip's result, as a worker returned it.
        """
        s = result.summary
        shared = dataclasses.replace(
            result, condition=self._text(result.condition), rule=self._text(result.rule),
            status=self._text(result.status), factors=self._text(result.factors))
        if s is None:
            return shared
        confidence = np.ascontiguousarray(s.confidence, dtype=float)
        transport = np.ascontiguousarray(s.transport, dtype=float)
        time = np.ascontiguousarray(s.time, dtype=float)
        aperture = np.ascontiguousarray(s.aperture, dtype=float)
        if confidence.ndim != 2 or transport.ndim != 2 or time.ndim != 1 or aperture.ndim != 1:
            return shared  # no models (or no time): nothing to keep apart
        names, kinds = self._shared(s.names), self._shared(s.kinds)
        traces = ({k: np.asarray(v, dtype=float) for k, v in s.traces.items()}
                  if isinstance(s.traces, dict) else s.traces)
        self._file.seek(0, 2)
        offset = self._file.tell()
        for values in (confidence, transport, time, aperture):
            self._file.write(values.tobytes())
        # the curves and model names are set again on every read (None: no array to
        # rebuild for them, a dozen reads a clip)
        rest = pickle.dumps(dataclasses.replace(
            s, confidence=None, transport=None, time=None, aperture=None, traces=traces,
            names=None, kinds=None), protocol=pickle.HIGHEST_PROTOCOL)
        self._where[s.clip] = len(self._places) // len(_PLACE)
        pair = self._models.setdefault((id(names), id(kinds)), len(self._model_lists))
        if pair == len(self._model_lists):
            self._model_lists.append((names, kinds))
        self._places.extend((offset, *confidence.shape, *transport.shape, len(time),
                             len(aperture), self._file.tell(), len(rest), pair))
        self._file.write(rest)
        observed = (s.kinematics or {}).get("observed") or {}
        m = len(names)
        if m not in self._no_transport:
            self._no_transport[m] = _read_only(np.zeros((m, 0)))
        compact = ClipSummary(
            result.clip if s.clip == result.clip else s.clip, _NO_VALUES, names, kinds,
            confidence[:, -1:].copy(), np.asarray(s.final_log_likelihood, dtype=float),
            self._text(s.winner),
            self._text(s.rule), verdict=self._text(s.verdict), familiarity=s.familiarity,
            margin=s.margin, familiarities=_NO_VALUES,
            reference_model=self._text(s.reference_model),
            transport=self._no_transport[m], aperture=_NO_VALUES,
            extras={"tracking": s.tracking} if s.tracking is not None else {},
            verdict_detail=self._text(s.verdict_detail),
            kinematics={"observed": {k: observed[k] for k in KINEMATICS_COLUMNS
                                     if k in observed}},
            verdict_rule=self._text(s.verdict_rule),
            warning_values=[{k: self._text(v) if isinstance(v, str) else v
                             for k, v in w.items()} for w in s.warning_values],
            transport_point=self._text(s.transport_point), time_origin=s.time_origin)
        return dataclasses.replace(shared, summary=compact)

    def _shared(self, values: list[str]) -> list[str]:
        """``values``, as the first equal list kept (read, never changed, by the report)."""
        return self._lists.setdefault(tuple(values), list(values))

    def _text(self, value):
        """``value`` (a text or a tuple of texts), as the first equal one kept; anything
        else as it is."""
        if not isinstance(value, str | tuple):
            return value
        try:
            return self._texts.setdefault(value, value)
        except TypeError:  # a tuple of something not hashable
            return value

    def restored(self, summary: ClipSummary, model: str | None) -> ClipSummary:
        """A kept summary as it was, with the curves of ``model`` alone, read back.

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
        return self._restored(summary.clip, model)

    def _restored(self, clip: str, model: str | None) -> ClipSummary:
        place = self._place(clip)
        names, kinds = self._model_lists[place.models]
        # the clip's arrays and its pickle lie end to end: one read
        block = self._block(place, place.rest + place.length)
        whole = pickle.loads(memoryview(block)[place.rest - place.offset:])
        time, aperture = _array(block, place, place.time, place.steps), _array(
            block, place, place.aperture, place.samples)
        if model is None or model not in names:
            return _filled(whole, names=names, kinds=kinds, time=time, aperture=aperture,
                           confidence=_array(block, place, place.offset, place.rows,
                                             place.width),
                           transport=_array(block, place, place.transport, place.transport_rows,
                                            place.transport_width))
        i = names.index(model)
        pick = slice(i, i + 1)

        def one(values: np.ndarray) -> np.ndarray:  # an array a model, if it is one
            return values[pick] if len(values) == len(names) else values

        return _filled(whole, names=[model], kinds=kinds[pick], time=time, aperture=aperture,
                       confidence=_row(block, place, i), transport=_transport_row(block, place, i),
                       final_log_likelihood=one(whole.final_log_likelihood),
                       familiarities=one(whole.familiarities))

    def _curves(self, clip: str, model: str | None) -> ClipCurves | None:
        """``clip``'s time, aperture and ``model``'s curves alone, read back without the
        rest of its summary (None: no such model, or a clip not kept here)."""
        if clip not in self._where:
            return None
        place = self._place(clip)
        names = self._model_lists[place.models][0]
        if model is None or model not in names:
            return None
        i = names.index(model)
        block = self._block(place, place.rest)  # its arrays, not its pickle
        return ClipCurves(clip, _array(block, place, place.time, place.steps), [model],
                          _row(block, place, i), _transport_row(block, place, i),
                          _array(block, place, place.aperture, place.samples))

    def _place(self, clip: str) -> _Place:
        k = self._where[clip] * len(_PLACE)
        return _Place(*self._places[k:k + len(_PLACE)])

    def _block(self, place: _Place, end: int) -> bytes:
        """The file's bytes from ``place``'s first array up to ``end``."""
        self._file.seek(place.offset)
        return self._file.read(end - place.offset)

    def summaries(self, summaries: Iterable[ClipSummary], model: str | None) -> KeptSummaries:
        """Every one of ``summaries`` by clip, each read back (:meth:`restored`) when
        it is asked for and not kept: what the batch report reads.

        Parameters
        ----------
        summaries : iterable of ClipSummary
            Summaries :meth:`keep` returned.
        model : str or None
            The reference model.
        """
        # a summary not kept here (a recording's that failed at its end) is held as it is
        return KeptSummaries(self, {s.clip: None if s.clip in self._where else s
                                    for s in summaries}, model)


def _array(block: bytes, place: _Place, offset: int, *shape: int) -> np.ndarray:
    """The float64 array of ``shape`` at ``offset`` in the file, from ``block`` (the bytes
    from ``place``'s first array on), a copy of its own."""
    return np.frombuffer(block, dtype=float, count=math.prod(shape),
                         offset=offset - place.offset).reshape(shape).copy()


def _row(block: bytes, place: _Place, i: int) -> np.ndarray:
    """Model ``i``'s confidence, ``(1, N)``, from ``block`` (:func:`_array`)."""
    return _array(block, place, place.offset + 8 * i * place.width, 1, place.width)


def _transport_row(block: bytes, place: _Place, i: int) -> np.ndarray:
    """Model ``i``'s transport term, ``(1, N)`` (``(1, 0)`` where it has none)."""
    if place.transport_rows <= i:
        return np.zeros((1, 0))
    return _array(block, place, place.transport + 8 * i * place.transport_width, 1,
                  place.transport_width)


def _filled(summary: ClipSummary, **fields) -> ClipSummary:
    """``summary``, just unpickled and seen by no one else, with ``fields`` set: what
    :func:`dataclasses.replace` gives, without building a second summary through
    ``__init__`` (35 µs of a read-back's 150, read back a dozen times a clip)."""
    for name, value in fields.items():
        object.__setattr__(summary, name, value)  # frozen to its readers, not to its maker
    return summary


def _read_only(values: np.ndarray) -> np.ndarray:
    values.flags.writeable = False
    return values


#: What a compact summary holds in place of its time, aperture and familiarities: shared,
#: never written to.
_NO_VALUES = _read_only(np.zeros(0))


class _Place(NamedTuple):
    """A clip's place in :class:`ModelRows`' file: its confidence's offset and shape, its
    transport's shape (after it), its time's and aperture's lengths (after that), the
    offset and length of the rest, pickled, and which of the model lists is its."""

    offset: int
    rows: int
    width: int
    transport_rows: int
    transport_width: int
    steps: int
    samples: int
    rest: int
    length: int
    models: int

    @property
    def transport(self) -> int:
        """Where its transport term starts."""
        return self.offset + 8 * self.rows * self.width

    @property
    def time(self) -> int:
        """Where its time starts."""
        return self.transport + 8 * self.transport_rows * self.transport_width

    @property
    def aperture(self) -> int:
        """Where its aperture starts."""
        return self.time + 8 * self.steps


#: The numbers of a :class:`_Place`, as :class:`ModelRows` keeps them (one array of them).
_PLACE = _Place._fields


@dataclass(frozen=True, eq=False)
class ClipCurves(PerModel):
    """A clip's time, grip aperture and one model's curves: what the batch report's
    profiles and confidence figures read of a clip (:meth:`KeptSummaries.curves`), read
    back without the rest of its :class:`ClipSummary`.

    Attributes
    ----------
    clip : str
        Clip name.
    time : (N,) array
        Time since onset, s.
    names : list of str
        The one model.
    confidence : (1, N) array
        Its thesis-rule confidence, m (weighted).
    transport : (1, N) array
        Its transport term's share (``(1, 0)`` where the clip has none), m.
    aperture : (N,) array
        Observed grip aperture, m.
    """

    clip: str
    time: np.ndarray
    names: list[str]
    confidence: np.ndarray
    transport: np.ndarray
    aperture: np.ndarray


class KeptSummaries(Mapping):
    """Scored clips by name, each read back from a :class:`ModelRows` when asked for:
    a mapping of :class:`ClipSummary` that holds none of them (:meth:`ModelRows.summaries`).

    Each look-up reads the clip's summary from disk (about 30 µs): a report
    reads each clip a few times rather than holding every one.

    Parameters
    ----------
    rows : ModelRows
        Where the clips were kept.
    clips : dict of str to ClipSummary or None
        The clips, in order: None for one kept in ``rows``, else its summary
        (one not kept there, held as it is).
    model : str or None
        The reference model (:meth:`ModelRows.restored`).
    curves : bool
        Read each clip kept in ``rows`` as its time, aperture and ``model``'s
        curves alone (:class:`ClipCurves`; :meth:`curves`).
    """

    def __init__(self, rows: ModelRows, clips: dict[str, ClipSummary | None],
                 model: str | None, *, curves: bool = False):
        self._rows, self._clips, self._model, self._curves = rows, clips, model, curves

    def __getitem__(self, clip: str) -> ClipSummary | ClipCurves:
        held = self._clips[clip]
        if held is not None:
            return held
        curves = self._rows._curves(clip, self._model) if self._curves else None
        return self._rows._restored(clip, self._model) if curves is None else curves

    def curves(self, model: str | None) -> KeptSummaries:
        """The same clips, each read as its time, aperture and ``model``'s curves alone
        (:class:`ClipCurves`, about a fifth of a whole read's time) where ``model`` is
        the one they were kept for; else as here.

        Parameters
        ----------
        model : str or None
            The model whose curves are read (the report's reference model).
        """
        return KeptSummaries(self._rows, self._clips, self._model,
                             curves=model is not None and model == self._model)

    def __contains__(self, clip) -> bool:
        return clip in self._clips

    def __iter__(self) -> Iterator[str]:
        return iter(self._clips)

    def __len__(self) -> int:
        return len(self._clips)


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
        batch_file(item.path)  # before hashing: a FIFO or device would never end
        fp = clip_fingerprint(item.path, settings, repertoire_id + (
            f"#reach{item.reach}" if item.reach is not None else ""))
        done = _current_report(item, out, fp, figure_format, dpi)
        if done is not None:
            return ClipResult(**base, status="reused", summary=ClipSummary.from_dict(done))
        rec, extra = _recognized(item, out, repertoire, settings, fp, progress, plan_cache,
                                 reach)
        traces = measured_traces(rec)  # once, for the figure, the JSON and the summary
        write_clip_report(rec, out, extra=extra, figure_format=figure_format, dpi=dpi,
                          traces=traces)
        return ClipResult(**base, status="ok",
                          summary=ClipSummary.from_recognition(rec, extra, traces=traces))
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

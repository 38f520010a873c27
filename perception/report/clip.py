"""One clip's report: ``<clip>.recognition.json``, the per-step CSV and three figures.

:class:`ClipSummary` is what a batch keeps of a scored clip: built from the
:class:`~perception.recognition.result.Recognition` in memory for a clip
scored now, or from its JSON for a clip a rerun reuses. Keys a caller adds
to the JSON (``write_clip_report(extra=...)``: the batch's fingerprint,
condition and input, or a tracking summary) come back in
:attr:`ClipSummary.extras`.
"""

from __future__ import annotations

import bisect
import contextlib
import json
import logging
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

from perception.io.atomic import write_csv, write_json
from perception.io.names import output_stem, printable
from perception.recognition.result import Recognition
from perception.report.figures import DPI, FIGURE_FORMATS

__all__ = ["KINEMATICS_COLUMNS", "ClipSummary", "PerModel", "clip_figures", "clip_outputs",
           "clip_traces", "measured_traces", "remove_output", "remove_stale_reports",
           "remove_stale_trials", "write_clip_report"]

log = logging.getLogger(__name__)

#: Keys of ``<clip>.recognition.json`` that :meth:`Recognition.to_dict` writes;
#: any other key is an extra (see :attr:`ClipSummary.extras`).
RECOGNITION_KEYS = frozenset({
    "clip", "models", "winner", "rule", "verdict", "familiarity", "margin",
    "familiarity_threshold", "reference_model", "time", "confidence", "transport_confidence",
    "aperture", "verdict_detail", "verdict_rule", "verdict_rules", "verdict_reason", "warnings",
    "notes", "kinematics", "shape", "passes", "mirrored", "traces", "warning_values",
    "winner_note", "verdict_model", "transport_point", "time_origin"})

#: The observed landmarks a batch's ``summary.csv`` shows, one column each
#: (:attr:`ClipSummary.kinematics`; units in docs/recognition.md §9).
KINEMATICS_COLUMNS = ("movement_time", "peak_speed", "peak_speed_time", "mga", "mga_time",
                      "aperture_peaks")

#: The clip's own figures (keys of :func:`clip_outputs`, named ``_png`` whatever their
#: format), in the order a report shows them.
FIGURE_KEYS = ("confidence_png", "paths_png", "kinematics_png")

#: A clip's (time, transport speed, grip aperture) over the whole clip (:func:`measured_traces`).
Traces = tuple[np.ndarray, np.ndarray, np.ndarray]


def clip_traces(rec: Recognition, traces: Traces | None = None) -> dict[str, np.ndarray]:
    """The curves the clip's landmarks are measured on: the report's ``traces``.

    ``time`` (s, on the landmarks' clock), ``wrist_speed`` (m/s) and
    ``aperture`` (m, marker to marker) over the whole clip
    (:func:`measured_traces`), to the µm.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    traces : tuple of array, optional
        Its :func:`measured_traces`, if already made.
    """
    traces = measured_traces(rec) if traces is None else traces
    return dict(zip(("time", "wrist_speed", "aperture"), (np.round(x, 6) for x in traces)))


def measured_traces(rec: Recognition) -> Traces:
    """The clip's time, transport speed and grip aperture as its landmarks were measured
    (:func:`~perception.report.kinematics.kinematic_traces` by its rules' landmark
    filter): what the kinematics figure draws and, rounded, the report's ``traces``.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    from perception.report.kinematics import kinematic_traces

    return kinematic_traces(rec.observation, rec.rules.landmarks)


def _floats(values, n: int | None = None) -> np.ndarray:
    """JSON numbers (None for NaN) as a float array; NaN of length ``n`` if absent."""
    if values is None:
        return np.full(n or 0, np.nan)
    return np.array([np.nan if v is None else v for v in values], dtype=float)


class PerModel:
    """A clip's per-model arrays, a row per model of ``names``: what the batch report reads
    of a :class:`ClipSummary` and of a :class:`~perception.batch_clip.ClipCurves` alike."""

    names: list[str]

    def index(self, model: str) -> int:
        """Row of ``model`` in the per-model arrays.

        Parameters
        ----------
        model : str
            Model name.
        """
        return self.names.index(model)


@dataclass(frozen=True, eq=False)
class ClipSummary(PerModel):
    """What a batch keeps of one scored clip (rebuilt from its JSON on resume).

    Attributes
    ----------
    clip : str
        Clip name.
    time : (N,) array
        Time since onset, s.
    names, kinds : list of str
        Models and their kinds.
    confidence : (M, N) array
        Thesis-rule confidence, m (weighted).
    final_log_likelihood : (M,) array
        Likelihood-rule score at the end.
    winner : str
        The winning model.
    rule : str
        Rule that picked the winner.
    verdict : str or None
        ``normal``, ``abnormal``, ``reach`` or ``unfamiliar``.
    verdict_detail : str or None
        The kind of an ``abnormal`` verdict (``delayed-opening``,
        ``re-opening``, ``no-opening``, ``other``); None for any other.
    verdict_rule : str or None
        The rule that gave the verdict
        (:data:`~perception.recognition.result.VERDICT_RULES`; None in
        reports written before it was recorded).
    familiarity : float
        The best model's familiarity, 0..1.
    margin : float
        Log-likelihood of the best model minus the runner-up's.
    familiarities : (M,) array
        Every model's familiarity.
    reference_model : str or None
        The grasp model with the highest log-likelihood.
    transport : (M, N) array
        The transport term's share of the confidence (cumulative ``dC_r``), m.
    aperture : (N,) array
        Observed grip aperture, m.
    kinematics : dict or None
        The JSON's ``kinematics``: the ``observed`` landmarks, the
        ``reference`` model's own and its name (None in reports written
        before they existed).
    traces : dict or None
        The JSON's ``traces`` (:func:`clip_traces`; lists, None for NaN, in
        a summary read from a report; None in reports written before them).
    extras : dict
        The JSON's other keys (``fingerprint``, ``condition``, ``input``,
        ``tracking``, …).
    verdict_reason : str or None
        Why the verdict was given, with each measured value against its
        rule's threshold (:attr:`Recognition.verdict_reason`; None in reports
        written before every verdict had one and it was not given).
    winner_note : str or None
        What the winner is where its kind contradicts the verdict
        (:attr:`Recognition.winner_note`); None where they agree.
    warnings : list of str
        Where the clip lies outside what the verdict was validated on, in words.
    warning_values : list of dict
        The same as ``{"kind", "value"}``
        (:meth:`~perception.recognition.result.ValidationWarning.to_dict`).
    transport_point : str
        Whose speed ``traces["wrist_speed"]`` is: ``wrist``, or ``grip
        midpoint`` where no wrist was recorded
        (:attr:`Recognition.transport_point`).
    time_origin : float
        The recording's clock at the observation clock's zero, s (NaN: not
        known; :attr:`Recognition.time_origin`).
    """

    clip: str
    time: np.ndarray
    names: list[str]
    kinds: list[str]
    confidence: np.ndarray
    final_log_likelihood: np.ndarray
    winner: str
    rule: str
    verdict: str | None = None
    familiarity: float = float("nan")
    margin: float = float("nan")
    familiarities: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reference_model: str | None = None
    transport: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    aperture: np.ndarray = field(default_factory=lambda: np.zeros(0))
    extras: dict = field(default_factory=dict)
    verdict_detail: str | None = None
    kinematics: dict | None = None
    verdict_rule: str | None = None
    traces: dict | None = None
    verdict_reason: str | None = None
    winner_note: str | None = None
    warnings: list = field(default_factory=list)
    warning_values: list = field(default_factory=list)
    transport_point: str = "wrist"
    time_origin: float = float("nan")

    @property
    def tracking(self) -> dict | None:
        """The clip's tracking quality (the JSON's ``tracking`` key), if recorded."""
        return self.extras.get("tracking")

    def landmark(self, name: str) -> float | int | None:
        """One observed landmark (the JSON's ``kinematics.observed``): NaN if unknown.

        ``aperture_peaks`` is None where it is not known.

        Parameters
        ----------
        name : str
            A landmark, e.g. ``mga`` (see :class:`perception.landmarks.Landmarks`).
        """
        value = ((self.kinematics or {}).get("observed") or {}).get(name)
        if name == "aperture_peaks":
            return None if value is None else int(value)
        return float("nan") if value is None else float(value)

    @property
    def grip(self) -> np.ndarray:
        """(M, N) the grip term's share of the confidence (cumulative ``dC_g``), m."""
        return self.confidence - self.transport

    @classmethod
    def from_dict(cls, d: dict) -> ClipSummary:
        """From the content of a ``<clip>.recognition.json``.

        Parameters
        ----------
        d : dict
            The parsed JSON (reports written before the verdict existed lack
            its keys; they read as NaN / None).
        """
        names = [m["name"] for m in d["models"]]
        n = len(d["time"])
        transport = d.get("transport_confidence") or {}
        return cls(
            clip=d["clip"],
            time=np.asarray(d["time"], dtype=float),
            names=names,
            kinds=[m["kind"] for m in d["models"]],
            confidence=np.array([d["confidence"][k] for k in names], dtype=float),
            final_log_likelihood=_floats([m.get("final_log_likelihood") for m in d["models"]]),
            winner=d["winner"],
            rule=d["rule"],
            verdict=d.get("verdict"),
            familiarity=float(_floats([d.get("familiarity")])[0]),
            margin=float(_floats([d.get("margin")])[0]),
            familiarities=_floats([m.get("familiarity") for m in d["models"]]),
            reference_model=d.get("reference_model"),
            transport=np.array([_floats(transport.get(k), n) for k in names]).reshape(
                len(names), n),
            aperture=_floats(d.get("aperture"), n),
            extras={k: v for k, v in d.items() if k not in RECOGNITION_KEYS},
            verdict_detail=d.get("verdict_detail"),
            kinematics=d.get("kinematics"),
            verdict_rule=d.get("verdict_rule"),
            traces=d.get("traces"),
            verdict_reason=d.get("verdict_reason"),
            winner_note=d.get("winner_note"),
            warnings=list(d.get("warnings") or []),
            warning_values=list(d.get("warning_values") or []),
            transport_point=d.get("transport_point") or "wrist",
            time_origin=float(_floats([d.get("time_origin")])[0]),
        )

    @classmethod
    def from_recognition(cls, rec: Recognition, extras: dict | None = None, *,
                         traces: Traces | None = None) -> ClipSummary:
        """From a :class:`~perception.recognition.result.Recognition`.

        Parameters
        ----------
        rec : Recognition
            A scored clip.
        extras : dict, optional
            Keys added to its JSON (see :func:`write_clip_report`).
        traces : tuple of array, optional
            Its :func:`measured_traces`, if already made (its report's).
        """
        d = rec.decision
        return cls(clip=rec.clip, time=rec.time, names=list(rec.names), kinds=list(rec.kinds),
                   confidence=rec.confidence, final_log_likelihood=rec.log_likelihood[:, -1],
                   winner=rec.winner, rule=rec.rule, verdict=d.verdict,
                   familiarity=d.familiarity, margin=d.margin, familiarities=rec.familiarity,
                   reference_model=rec.reference_model,
                   transport=np.cumsum(rec.dC_r, axis=1), aperture=rec.scored_movement.g,
                   extras=dict(extras or {}), verdict_detail=rec.verdict_detail,
                   kinematics=rec.kinematics, verdict_rule=rec.verdict_rule,
                   traces=clip_traces(rec, traces), verdict_reason=rec.verdict_reason,
                   winner_note=rec.winner_note, warnings=rec.warnings,
                   warning_values=[w.to_dict() for w in rec.validation_warnings],
                   transport_point=rec.transport_point, time_origin=rec.time_origin)



def clip_outputs(out: Path, clip: str, figure_format: str = "png") -> dict[str, Path]:
    """Paths of the files :func:`write_clip_report` writes for ``clip`` in ``out``.

    They are named by the clip's :func:`~perception.io.names.output_stem`:
    the clip name itself unless it holds bytes that are not UTF-8, a
    separator or a control character, or is too long for a file name.

    Parameters
    ----------
    out : Path
        Report folder.
    clip : str
        Clip name.
    figure_format : str
        The figures' format, their suffix (:data:`~perception.report.figures.FIGURE_FORMATS`).
    """
    stem = output_stem(clip)
    return {
        "json": out / f"{stem}.recognition.json",
        "csv": out / f"{stem}.confidence.csv",
        **{key: out / _figure_name(stem, key, figure_format) for key in FIGURE_KEYS},
    }


def _figure_name(stem: str, key: str, figure_format: str) -> str:
    """The file name of a clip's figure ``key`` (one of :data:`FIGURE_KEYS`)."""
    return f"{stem}.{key[:-4]}.{figure_format}"


def clip_figures(out: Path, clip: str, names: Sequence[str] | None = None) -> list[Path]:
    """Every figure of ``clip`` in ``out``: its three own, then any other ``<clip>.<name>.png``.

    The own figures are found in whichever format they were written (PNG,
    SVG or PDF). A figure another step adds beside the clip's report (one
    ``<name>``, no dots; PNG or SVG) is shown with the clip in ``report.html``.

    Parameters
    ----------
    out : Path
        Report folder.
    clip : str
        Clip name.
    names : sequence of str, optional
        The file names in ``out``, sorted: a batch report lists its folder
        once for all its clips, rather than once per clip (default: listed here).
    """
    if names is None:
        names = sorted(os.listdir(out)) if out.is_dir() else []
    stem = output_stem(clip)
    # names, not paths: a batch report of 6,000 clips built 300,000 paths here (1.8 s)
    own = [_figure_name(stem, k, f) for k in FIGURE_KEYS for f in FIGURE_FORMATS]
    prefix = f"{stem}."
    mine = []
    # the names starting with the prefix are one run of the sorted list
    for name in names[bisect.bisect_left(names, prefix):]:
        if not name.startswith(prefix):
            break
        mine.append(name)
    others = [n for n in mine if n not in own and n.endswith((".png", ".svg"))
              and n[len(prefix):].count(".") == 1
              and printable(n) == n]  # not a file name that is not UTF-8 text
    return [out / n for n in own if n in mine] + [out / n for n in others]


def remove_output(path: Path) -> None:
    """Remove an output that would be stale, if there is one.

    A read-only folder refuses even to remove a file that is not there
    (``EROFS``): only an existing file is removed, and a failure is one
    :class:`OSError` naming it.

    Parameters
    ----------
    path : Path
        The output.
    """
    if not os.path.lexists(path):
        return
    try:
        path.unlink()
    except FileNotFoundError:
        pass
    except OSError as exc:
        raise OSError(exc.errno, f"cannot remove {path}: {exc.strerror or exc}") from None


def remove_stale_reports(out: str | os.PathLike, source: str | os.PathLike,
                         keep: Iterable[str]) -> list[str]:
    """Remove the reports in ``out`` of a recording's reaches that are not in ``keep``.

    A rerun after a table lost a trial (or a trial that no longer gives a
    reach) must not leave that trial's report and figures looking current.
    Only reaches' reports (those with a ``mocap`` entry) made from ``source``
    itself (the same file) are touched, and only in ``out``.
    :func:`remove_stale_trials` does it for several recordings at once.

    Parameters
    ----------
    out : str or os.PathLike
        The report folder.
    source : str or os.PathLike
        The recording.
    keep : iterable of str
        The clips scored now.

    Returns
    -------
    list of str
        The stems of the reports removed.
    """
    return remove_stale_trials(out, {source: keep})


def remove_stale_trials(out: str | os.PathLike,
                        scored: Mapping[str | os.PathLike, Iterable[str]]) -> list[str]:
    """:func:`remove_stale_reports` for every recording of ``scored`` in one pass over ``out``.

    A report whose clip is scored now is current whichever recording it came
    from (clip names are unique in a batch); every other one is read once,
    and removed if it was made from one of the recordings. One pass for a
    batch: a pass a recording read every other recording's reports, and a
    study of P files of T trials made P x P x T reads.

    Parameters
    ----------
    out : str or os.PathLike
        The report folder.
    scored : mapping of recording to iterable of str
        Each recording, with the clips scored from it now.

    Returns
    -------
    list of str
        The stems of the reports removed.
    """
    out = Path(out)
    keep_stems = {output_stem(c) for clips in scored.values() for c in clips}
    recordings = {}  # the recordings' files by identity: samefile without a stat a pair
    for source in scored:
        with contextlib.suppress(OSError):
            st = os.stat(source)
            recordings[(st.st_dev, st.st_ino)] = Path(source)
    removed = []
    suffix = ".recognition.json"
    for report in sorted(out.glob(f"*{suffix}")) if recordings else ():
        stem = report.name[:-len(suffix)]
        if stem in keep_stems:
            continue
        try:
            data = json.loads(report.read_text())
            made_from = data.get("input") if isinstance(data, dict) and "mocap" in data else None
            st = os.stat(made_from) if isinstance(made_from, str) else None
        except (OSError, ValueError):
            continue
        source = recordings.get((st.st_dev, st.st_ino)) if st is not None else None
        if source is None:
            continue
        log.info("%s: removed: its trial is not scored from %s now", report, source)
        for path in dict.fromkeys(p for fmt in FIGURE_FORMATS
                                  for p in clip_outputs(out, stem, fmt).values()):
            with contextlib.suppress(OSError):
                remove_output(path)
        removed.append(stem)
    return removed


def write_clip_report(rec: Recognition, out: Path, *, extra: dict | None = None,
                      figures: bool = True, figure_format: str = "png",
                      dpi: int = DPI, traces: Traces | None = None) -> dict[str, Path]:
    """Write ``<clip>.recognition.json``, the per-step CSV and the three figures.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    out : Path
        Report folder (created if missing).
    extra : dict, optional
        More keys for the JSON (e.g. the batch's input fingerprint).
    figures : bool
        Draw the figures (matplotlib, imported here: see
        :mod:`perception.report.figures`): the confidence, the paths and the
        kinematics (:func:`~perception.report.kinematics.kinematics_figure`);
        without them, figures of an earlier run are removed, since they would
        show another result (as are, with them, those in other formats).
    figure_format : str
        ``png``, ``svg`` or ``pdf`` (:func:`~perception.report.figures.write_figure`).
    dpi : int
        The figures' resolution, dots per inch.
    traces : tuple of array, optional
        The clip's :func:`measured_traces`, if already made (a batch makes them once
        for the report and the clip's :class:`ClipSummary`).

    Returns
    -------
    dict of Path
        The files written (see :func:`clip_outputs`).
    """
    from perception.boundary import expect

    expect(rec, Recognition, "write_clip_report(rec=)", hint="recognize_clip's result")
    paths = clip_outputs(Path(out), rec.clip, figure_format)
    traces = measured_traces(rec) if traces is None else traces  # the figure's, the JSON's
    with contextlib.ExitStack() as stack:
        if figures:
            from perception.report.figures import (
                FigureFiles,
                confidence_figure,
                paths_figure,
            )
            from perception.report.kinematics import kinematics_figure

            # each on this process's kept figure of its kind, drawn before the next clip's;
            # a PNG encoded while the next figure is drawn, the last while the CSV and JSON are made
            files = stack.enter_context(FigureFiles(figure_format, dpi))
            for key, draw in (("confidence_png", confidence_figure), ("paths_png", paths_figure),
                              ("kinematics_png", partial(kinematics_figure, traces=traces))):
                files.write(draw(rec, reuse=True), paths[key].with_suffix(""))
        for fmt in FIGURE_FORMATS:
            if not figures or fmt != figure_format:
                for key in FIGURE_KEYS:
                    remove_output(clip_outputs(Path(out), rec.clip, fmt)[key])
        # Python's numbers, not NumPy's: the same text (str of a float64 is repr of the
        # float), without formatting each cell through NumPy's own (a fifth of the CSV's time)
        write_csv(paths["csv"], {k: v.tolist() if isinstance(v, np.ndarray) else v
                                 for k, v in rec.columns().items()})
        report = {**rec.to_dict(), "traces": clip_traces(rec, traces), **(extra or {})}
    # the JSON last, once every figure is written: its presence marks the report complete
    write_json(paths["json"], report)
    return paths

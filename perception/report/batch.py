"""The batch report: ``summary.csv``, the chapter 5 figures and statistics, ``report.html``.

Every clip is read on one *reference* grasp model
(:func:`~perception.report.conditions.reference_model`): the aperture
profiles against the model's own (Fig. 5.4d), its confidence on one clip per
condition (Fig. 5.8a) and on all clips (Fig. 5.8b), mean ± SD per condition
(Fig. 5.8c) and the statistics of its final confidence. The page escapes
every name it shows and quotes every link, so any clip name is safe in it;
a name with bytes that are not UTF-8 (or control characters) is shown, in
the page and in ``summary.csv``, with them escaped
(:func:`~perception.io.names.printable`).
"""

from __future__ import annotations

import gc
import html
import os
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

import numpy as np
import pandas as pd

from perception.io import atomic
from perception.io.atomic import write_csv
from perception.io.names import printable
from perception.report.clip import ClipSummary, clip_figures, clip_outputs
from perception.report.conditions import (
    aperture_profiles,
    condition_profiles,
    condition_statistics,
    model_aperture,
    reference_model,
    typical_clips,
)
from perception.report.figures import (
    DPI,
    aperture_figure,
    condition_figure,
    confidence_all_figure,
    confidence_single_figure,
    write_figure,
)
from perception.report.paper import (
    LANDMARKS,
    condition_kinematics_figure,
    kinematic_profiles,
    landmark_strip_figure,
    transport_name,
)
from perception.report.statistics import (
    PARTICIPANT_COLUMNS,
    fitted_in_workers,
    landmark_statistics,
    participant_column,
    participant_means,
)
from perception.report.tables import (
    LANDMARK_UNITS,
    TABLES,
    in_lab_units,
    r_aliases,
    records,
    write_landmark_table,
    write_units,
)

__all__ = ["BatchReport", "write_batch_report"]

#: The chapter 5 figures of a batch: file name without its format's suffix, thesis figure,
#: caption.
FIGURES = (
    ("aperture_profiles", "Fig. 5.4(d)",
     "grip aperture per condition, mean ± SD over normalised movement time, against the "
     "reference model's own (dashed)"),
    ("confidence_single", "Fig. 5.8(a)",
     "the reference model's confidence on one clip per condition (the clip with the "
     "condition's median final confidence)"),
    ("confidence_all", "Fig. 5.8(b)", "the reference model's confidence on every clip"),
    ("condition_profiles", "Fig. 5.8(c)",
     "mean ± SD confidence per condition at select points, with its transport and grip terms"),
)

#: The figures drawn across the page.
WIDE = ("condition_profiles", "kinematic_profiles", "landmark_strips")

_CSS = """
body{font-family:system-ui,sans-serif;max-width:1240px;margin:1.5em auto;padding:0 12px;
     line-height:1.4;color:#222}
h1{font-size:1.6em} h2{margin-top:1.6em;border-bottom:1px solid #ccc} h3{margin-bottom:.2em}
table.t{border-collapse:collapse;font-size:90%;margin:.5em 0}
table.t td,table.t th{padding:3px 9px;border-bottom:1px solid #ddd;text-align:left;
     white-space:nowrap}
table.t td.n,table.t th.n{text-align:right}
.scroll{max-width:100%;overflow-x:auto}
figure{margin:0} figure img,.clip img{width:100%;height:auto;border:1px solid #eee}
.clip img.thumb{width:480px;max-width:100%}
.grid{display:grid;grid-template-columns:1fr 1fr;gap:14px} .grid figure.wide{grid-column:1/-1}
figcaption,.note{font-size:90%;color:#555}
.v-normal{color:#1b6e20;font-weight:bold} .v-reach{color:#1f4e99;font-weight:bold}
.v-abnormal{color:#b3261e;font-weight:bold} .v-failed{color:#777}
.v-unfamiliar{color:#8a5a00;font-weight:bold}
"""


@dataclass(frozen=True)
class BatchReport:
    """Paths of a batch report.

    Attributes
    ----------
    folder : Path
        Report folder.
    summary : Path
        ``summary.csv``.
    html : Path
        ``report.html``.
    """

    folder: Path
    summary: Path
    html: Path


class _Clips(Sequence):
    """The scored clips' summaries in table order, each looked up in ``recognitions``
    when it is read (a batch's are read back from disk, one at a time: none is kept)."""

    def __init__(self, recognitions: Mapping[str, ClipSummary], names: list[str]):
        self._recognitions, self.names = recognitions, names

    def __getitem__(self, i):
        if isinstance(i, slice):
            return _Clips(self._recognitions, self.names[i])
        return self._recognitions[self.names[i]]

    def __iter__(self) -> Iterator[ClipSummary]:
        return (self._recognitions[name] for name in self.names)

    def __len__(self) -> int:
        return len(self.names)

    def curves(self, model: str) -> _Clips:
        """The same clips, each read as its time, aperture and ``model``'s curves alone
        where the mapping can (a batch's: :meth:`~perception.batch_clip.KeptSummaries.curves`,
        without unpickling the rest); else as here."""
        curves = getattr(self._recognitions, "curves", None)
        return self if curves is None else _Clips(curves(model), self.names)


def _e(value) -> str:
    """A cell's text, escaped; empty for None and NaN."""
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return ""
    return html.escape(printable(str(value)))


def _link(path: str, text: str) -> str:
    return f'<a href="{html.escape(quote(path), quote=True)}">{_e(text)}</a>'


def _image(name: str, alt: str, cls: str = "", lazy: bool = False) -> str:
    """A figure file as an image that links to itself; a PDF (no ``<img>`` shows one) as a link."""
    if name.endswith(".pdf"):
        return _link(name, f"{name} (PDF)")
    src = html.escape(quote(name), quote=True)
    attrs = (f" class={cls}" if cls else "") + f' src="{src}"' + (' loading="lazy"' if lazy else "")
    return f'<a href="{src}"><img{attrs} alt="{_e(alt)}"></a>'


def _table(headers: Sequence[str], rows: Iterable[Sequence[str]], numeric: set[int] = frozenset(),
           cls: str = "t") -> str:
    """An HTML table from escaped cell strings; ``numeric`` columns are right-aligned."""
    return "".join(_table_parts(headers, rows, numeric, cls))


def _table_parts(headers: Sequence[str], rows: Iterable[Sequence[str]],
                 numeric: set[int] = frozenset(), cls: str = "t") -> Iterator[str]:
    """:func:`_table`'s text, a row at a time (a page written as it is made)."""
    def row(cells, tag):
        return "<tr>" + "".join(
            f'<{tag}{" class=n" if i in numeric else ""}>{c}</{tag}>'
            for i, c in enumerate(cells)) + "</tr>"
    yield (f'<table class="{cls}"><thead>{row([html.escape(h) for h in headers], "th")}'
           "</thead><tbody>")
    yield from (row(r, "td") for r in rows)
    yield "</tbody></table>"


def _printable_table(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with its text cells :func:`~perception.io.names.printable` (valid UTF-8)."""
    def cell(v):
        return printable(v) if isinstance(v, str) else v

    shown = table.copy()
    for c in table.columns:
        if not (pd.api.types.is_numeric_dtype(table[c]) or pd.api.types.is_bool_dtype(table[c])):
            # printable() escapes character by character: a column whose text, run
            # together, needs none needs none cell by cell (2.3 million cells, 3 s, at
            # 10,000 trials)
            text = "".join(v for v in table[c].tolist() if isinstance(v, str))
            if printable(text) != text:
                shown[c] = table[c].map(cell)
    return shown


#: Rows of ``summary.csv`` made into text at once (:func:`write_summary_csv`).
SUMMARY_CHUNK = 1000


def write_summary_csv(path: Path, summary: pd.DataFrame, chunk: int = SUMMARY_CHUNK) -> Path:
    """Write ``summary.csv`` atomically, ``chunk`` rows at a time: ``summary`` in lab
    units (:func:`~perception.report.tables.in_lab_units`), its text valid UTF-8.

    The same bytes as the whole table converted and written at once, without
    its two whole copies (the units' and the escaping's: 1 kB a trial each).

    Parameters
    ----------
    path : Path
        The CSV file.
    summary : pandas.DataFrame
        :func:`perception.batch.summary_table`'s table (SI units).
    chunk : int
        Rows converted and written at a time.
    """
    return atomic.write_csv_chunks(
        path, (_printable_table(in_lab_units(summary.iloc[start:start + chunk]))
               for start in range(0, max(len(summary), 1), chunk)))


def _num(value, fmt: str) -> str:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return ""
    return format(v, fmt) if np.isfinite(v) else ""


def with_verdict_reasons(summary: pd.DataFrame, recognitions: dict[str, ClipSummary]
                         ) -> pd.DataFrame:
    """``summary`` with ``verdict_reason`` and ``winner_note`` after ``verdict_rule``.

    Each scored clip's :attr:`ClipSummary.verdict_reason` (the rule that
    fired, with the measured value against its threshold) and
    :attr:`ClipSummary.winner_note` (what the winner is where its kind
    contradicts the verdict); empty for clips without a result. Columns the
    summary already has are kept as they are.

    Parameters
    ----------
    summary : pandas.DataFrame
        One row per clip (:func:`perception.batch.summary_table`).
    recognitions : dict of ClipSummary
        Scored clips by name.
    """
    where = (list(summary.columns).index("verdict_rule") + 1 if "verdict_rule" in summary
             else len(summary.columns))
    wanted = [c for c in ("verdict_reason", "winner_note") if c not in summary]
    values: dict[str, list] = {c: [] for c in wanted}
    if wanted:
        for c, ok in zip(summary["clip"], summary["status"]):
            # one read a clip: a batch's summaries are read back from disk one at a time
            rec = recognitions[c] if ok == "ok" and c in recognitions else None
            for column in wanted:
                values[column].append(getattr(rec, column) if rec is not None else None)
    summary = summary.copy(deep=False)  # copied on write: the columns are shared
    for column in wanted:
        summary.insert(where, column, values[column])
        where += 1
    return summary


def _verdict_cell(verdict, status: str, detail=None) -> str:
    if status != "ok":  # failed, or a trial that gives no reach (its status)
        return f'<span class="v-failed">{_e(status) or "failed"}</span>'
    v = _e(verdict) or "—"
    # the kind of an abnormal verdict (a float NaN where summary.csv has none)
    # on a line of its own: the main table must fit a 1280 px window
    kind = f"<br><small>{_e(detail)}</small>" if isinstance(detail, str) and detail else ""
    return f'<span class="v-{v}">{v}</span>{kind}' if verdict else v


def _main_table(summary: pd.DataFrame, anchors: dict[str, str], reference: str | None
                ) -> Iterator[str]:
    headers = ["clip", "condition", "verdict", "familiarity (0–1)", "margin (log-lik.)",
               "winner", "winner log-lik.", f"C of {reference or 'reference'} (cm)", "status"]
    rows = (_main_row(r, anchors) for r in summary.itertuples(index=False))
    return _table_parts(headers, rows, numeric={3, 4, 6, 7}, cls="t main")


def _main_row(r, anchors: dict[str, str]) -> list[str]:
    """One clip's row of the main table."""
    def get(name):  # a summary written by other code may lack columns
        return getattr(r, name, None)

    clip = _e(r.clip)
    if r.clip in anchors:
        clip = f'<a href="#{anchors[r.clip]}">{clip}</a>'
    ref = get("reference_confidence")
    return [clip, _e(r.condition), _verdict_cell(get("verdict"), r.status, get("verdict_detail")),
            _num(get("familiarity"), ".2f"), _num(get("margin"), ".1f"), _e(r.winner),
            _num(get("winner_log_likelihood"), ".1f"),
            _num(ref * 100 if ref is not None else None, ".2f"), _e(r.status)]


def _models_table(summary: pd.DataFrame) -> Iterator[str]:
    aliases = r_aliases(summary.columns)
    cols = [c for c in summary.columns if c.startswith("conf_") and c not in aliases]
    if not cols:
        return
    rows = ([_e(r["clip"])] + [_num(r[c] * 100, ".2f") for c in cols]
            # dicts, not iterrows' Series a row: 1 s of a 6,000-clip report a table
            for r in records(summary[summary["status"] == "ok"]))
    yield ("<details><summary>Final thesis-rule confidence C of every model (cm, "
           'weighted; <code>conf_&lt;model&gt;</code> in summary.csv, m)</summary>'
           '<div class="scroll">')
    yield from _table_parts(["clip"] + [c[len("conf_"):] for c in cols], rows,
                            numeric=set(range(1, len(cols) + 1)))
    yield "</div></details>"


#: summary.csv columns the main table or the per-model table shows.
_SHOWN = {"clip", "condition", "winner", "rule", "verdict", "verdict_detail", "familiarity",
          "margin", "winner_log_likelihood", "reference_model", "reference_confidence", "status",
          "reused", "error", "reason", "verdict_reason", "winner_note"}


def _other_columns_table(summary: pd.DataFrame) -> Iterator[str]:
    """summary.csv's other columns (the tracking quality, …), folded away: its values, in its
    units (the landmarks' ms, mm, %, not the in-memory table's SI ones), each named."""
    cols = [c for c in summary.columns if c not in _SHOWN | r_aliases(summary.columns)
            and not c.startswith("conf_")]
    if not cols:
        return
    def number(v):  # 3 digits, whole ms and mm/s without an exponent (1442, not 1.44e+03)
        return _num(v, ".0f" if abs(v) >= 1000 else ".3g")

    rows = ([_e(r["clip"])] + [number(r[c]) if isinstance(r[c], int | float | np.number)
                               and not isinstance(r[c], bool) else _e(r[c]) for c in cols]
            for r in records(in_lab_units(summary[summary["status"] == "ok"])))
    headers = [f"{c} ({LANDMARK_UNITS[c]})" if c in LANDMARK_UNITS else c for c in cols]
    yield ("<details><summary>Tracking quality and other columns of summary.csv</summary>"
           '<div class="scroll">')
    yield from _table_parts(["clip", *headers], rows, numeric=set(range(1, len(cols) + 1)))
    yield "</div></details>"


def _verdict_counts(ok: pd.DataFrame) -> str:
    if not len(ok) or "verdict" not in ok:
        return ""
    cond = ok["condition"].where(ok["condition"].notna(), "unlabelled")
    counts = pd.crosstab(cond, ok["verdict"].fillna("none"))
    rows = [[_e(c)] + [str(int(counts.loc[c, v])) for v in counts.columns] for c in counts.index]
    return "<h2>Verdicts per condition</h2>" + _table(
        ["condition", *[str(v) for v in counts.columns]], rows,
        numeric=set(range(1, len(counts.columns) + 1)))


def _clip_section(rec: ClipSummary, out: Path, anchor: str, condition,
                  names: list[str]) -> str:
    files = clip_outputs(out, rec.clip)
    links = " · ".join(_link(files[k].name, label) for k, label in
                       (("json", "recognition.json"), ("csv", "confidence.csv")))
    # a winner whose kind contradicts the verdict is named for what it is
    winner = ("closest model" if rec.winner_note else "winner")
    line = (f"verdict {_verdict_cell(rec.verdict, 'ok', rec.verdict_detail)}"
            f" (familiarity {_num(rec.familiarity, '.2f')}, margin {_num(rec.margin, '.1f')})"
            f"; {winner} {_e(rec.winner)} ({_e(rec.rule)} rule); condition "
            f"{_e(condition) or 'unlabelled'}; files: {links}")
    if rec.verdict_reason:
        line += f"<br>why: {_e(rec.verdict_reason)}"
    if rec.winner_note:
        line += f"<br>{_e(rec.winner_note)}"
    if rec.warnings:
        line += "<br>warnings: " + "; ".join(_e(w) for w in rec.warnings)
    # each figure links to itself at full size; the kinematics one shows as a thumbnail
    thumb = files["kinematics_png"].with_suffix("").name
    figs = "".join(_image(p.name, p.name, "thumb" if p.with_suffix("").name == thumb else "",
                          lazy=True) for p in clip_figures(out, rec.clip, names))
    return f'<div class="clip"><h3 id="{anchor}">{_e(rec.clip)}</h3><p>{line}</p>{figs}</div>'


def _written(fig, stem: Path, fmt: str, dpi: int) -> None:
    """:func:`~perception.report.figures.write_figure`, then the figure's memory freed.

    A figure is a cycle of objects (figure, canvas, axes, artists) that only
    the garbage collector frees, and its full collection comes seldom: a
    study's figure of every clip's curve (1 kB a trial) and the tables made
    before it stayed on: the report's peak grew 10.6 kB a trial without
    these collections, 2.7 kB with them (tracemalloc, 100 and 400 trials).
    """
    write_figure(fig, stem, fmt, dpi)
    del fig
    gc.collect()


def _chapter5(recs: _Clips, conds: list[str], reference: str, models, out: Path,
              fmt: str, dpi: int) -> None:
    """The four chapter 5 figures (matplotlib) and their tables."""
    model = next((m for m in models or () if m.name == reference), None)
    own = model_aperture(model) if model is not None else None
    # six passes over the clips, each reading a clip's time, aperture and the reference
    # model's curves alone: a whole clip read back is mostly unpickling the rest
    recs = recs.curves(reference)
    ap = aperture_profiles(recs, conds)
    if own is not None:
        ap = pd.concat([ap, own.assign(condition=f"model:{reference}", n=1)],
                       ignore_index=True)[["condition", "phase", "mean", "sd", "n"]]
    write_csv(out / "aperture_profiles.csv", ap)
    observed = ap[~ap["condition"].astype(str).str.startswith("model:")]
    _written(aperture_figure(observed, own, reference), out / "aperture_profiles", fmt, dpi)
    single, single_conds = typical_clips(recs, conds, reference)
    _written(confidence_single_figure(single, single_conds, reference),
                 out / "confidence_single", fmt, dpi)
    _written(confidence_all_figure(recs, conds, reference), out / "confidence_all", fmt, dpi)
    prof = condition_profiles(recs, conds, reference)
    write_csv(out / "condition_profiles.csv", prof)
    _written(condition_figure(prof, reference), out / "condition_profiles", fmt, dpi)


def _grid(figures: Sequence[tuple[str, str]], fmt: str) -> str:
    """Figures (file stem, caption) in a grid, each a link to itself at full size."""
    return "<div class=grid>" + "".join(
        f'<figure{" class=wide" if stem in WIDE else ""}>{_image(f"{stem}.{fmt}", stem)}'
        f"<figcaption>{html.escape(caption)} (click for full size)</figcaption></figure>"
        for stem, caption in figures) + "</div>"


def _figures_html(reference: str, fmt: str) -> str:
    """The chapter 5 figures, their thesis figure numbers in their captions."""
    return (f"<h2>Chapter 5, read on the reference grasp model {_e(reference)}</h2>"
            + _grid([(stem, f"{fig}: {caption}") for stem, fig, caption in FIGURES], fmt))


def _kinematics(recs: list[ClipSummary], conds: list[str], landmarks: pd.DataFrame, out: Path,
                fmt: str, dpi: int) -> str:
    """The kinematics per condition: its table, its two figures and their HTML."""
    # each a pass over the clips, read back from disk: made once, the table and its figure
    profiles, point = kinematic_profiles(recs, conds), transport_name(recs)
    write_csv(out / "kinematic_profiles.csv", profiles)
    _written(condition_kinematics_figure(recs, conds, profiles=profiles, point=point),
             out / "kinematic_profiles", fmt, dpi)
    _written(landmark_strip_figure(landmarks), out / "landmark_strips", fmt, dpi)
    return "<h2>Kinematics per condition</h2>" + _grid([
        ("kinematic_profiles", f"{point} speed (mm/s) and grip aperture (mm) "
         "per condition, mean ± SD, from each trial's onset to its end "
         "(kinematic_profiles.csv)"),
        ("landmark_strips", "each landmark of every trial, per condition (coloured by "
         "participant where the manifest names them), with the condition's mean ± SD")], fmt)


def _statistics_html(stats_df: pd.DataFrame) -> str:
    def n(r):  # clips per group, and a warning where a group is too small
        per = getattr(r, "n_per_group", None)
        note = getattr(r, "note", None)
        text = _e(per) if isinstance(per, str) and per else str(int(r.n))
        return text + (f"<br><small>{_e(note)}</small>" if isinstance(note, str) and note else "")

    rows = [[_e(r.test), _e(r.groups), n(r), _e(r.statistic_type),
             _num(r.statistic, ".3g"), _e(r.df), _num(r.p_value, ".3g"),
             _num(r.mean_difference * 100, ".2f"), _e(r.effect_size_type),
             _num(r.effect_size, ".2f")] for r in stats_df.itertuples(index=False)]
    return _table(["test", "groups", "n", "statistic", "value", "df", "p", "mean difference (cm)",
                   "effect size", "value"], rows, numeric={2, 4, 6, 7, 9})


#: The columns of ``landmarks.csv`` :func:`~perception.report.paper.landmark_strip_figure`
#: reads, with the participant's and the condition.
STRIP_COLUMNS = ("landmark", "value", "status")


def _measures(columns: list[str], kept: dict[str, list], summary: pd.DataFrame
              ) -> pd.DataFrame:
    """What :func:`~perception.report.statistics.landmark_statistics` and
    :func:`~perception.report.statistics.participant_means` read of
    :func:`~perception.report.statistics.measure_table` (``measure, unit``, the
    participant, ``condition, value``), the same table, from ``landmarks.csv``'s
    ``kept`` columns: its other columns were 2 kB a trial."""
    who = participant_column(columns)
    first: dict[str, int] = {}
    for i, clip in enumerate(kept["clip"]):
        first.setdefault(clip, i)
    rows = list(first.values())
    ok = summary[summary["status"] == "ok"].set_index("clip")["reference_confidence"]
    table = {"measure": kept["landmark"] + ["reference_confidence"] * len(rows),
             "unit": kept["unit"] + ["mm"] * len(rows)}
    for c in ([who] if who else []) + ["condition"]:
        table[c] = kept[c] + [kept[c][i] for i in rows]
    table["value"] = np.concatenate([np.frombuffer(kept["value"], dtype=float),
                                     ok.reindex(list(first)).to_numpy(float) * 1e3])
    return pd.DataFrame(table)


def _strip_rows(kept: dict[str, list]) -> pd.DataFrame:
    """The rows of ``landmarks.csv``'s ``kept`` columns that the strips figure draws
    (:data:`~perception.report.paper.LANDMARKS`)."""
    drawn = {name for name, *_ in LANDMARKS}
    rows = [i for i, name in enumerate(kept["landmark"]) if name in drawn]
    values = np.frombuffer(kept["value"], dtype=float)
    return pd.DataFrame({c: values[rows] if c == "value" else [kept[c][i] for i in rows]
                         for c in kept if c != "unit"})


def _statistics_soon(measures: pd.DataFrame, jobs: int) -> Callable[[], pd.DataFrame]:
    """:func:`~perception.report.statistics.landmark_statistics` of ``measures``, to be
    asked for: fitted in worker processes while this process draws the figures where
    it would use them (a 10,000-trial study's mixed models: minutes, one process),
    else here, now."""
    if not fitted_in_workers(measures, jobs):
        table = landmark_statistics(measures)
        return lambda: table
    import threading
    from concurrent.futures import Future

    done: Future = Future()

    def fit() -> None:
        try:
            done.set_result(landmark_statistics(measures, jobs))
        except BaseException as exc:  # noqa: BLE001 - raised where it is asked for
            done.set_exception(exc)

    # a daemon thread (an executor's is joined at exit): a report that fails meanwhile
    # exits after the fits under way, not after every fit
    threading.Thread(target=fit, name="statistics", daemon=True).start()
    return done.result


def write_batch_report(summary: pd.DataFrame, recognitions: dict[str, ClipSummary],
                       out: Path, *, profile_model: str | None = None,
                       title: str = "hammer-mv recognition report",
                       models: Sequence | None = None, figure_format: str = "png",
                       dpi: int = DPI, jobs: int = 1,
                       skipped: Iterable[tuple[str, str]] = ()) -> BatchReport:
    """Write ``summary.csv``, the chapter 5 figures and statistics, the tidy tables
    (``landmarks.csv``, ``participant_means.csv``, ``landmark_statistics.csv``) and
    ``report.html``.

    Parameters
    ----------
    summary : pandas.DataFrame
        One row per clip (:func:`perception.batch.summary_table`).
    recognitions : dict of ClipSummary
        Scored clips by name (failed clips absent).
    out : Path
        Report folder.
    profile_model : str, optional
        The reference grasp model (default: the summary's ``reference_model``,
        else the grasp model that best explains the ``normal`` clips — highest
        mean log-likelihood among grasp models — or all clips without labels).
    title : str
        Heading of the HTML page.
    models : sequence of MotorModel, optional
        The repertoire's models: the reference model's own aperture is drawn
        from it in Fig. 5.4(d).
    figure_format : str
        Format of the figures: ``png``, ``svg`` or ``pdf``
        (:func:`~perception.report.figures.write_figure`; ``report.html``
        links a PDF rather than showing it).
    dpi : int
        Their resolution, dots per inch.
    jobs : int
        Worker processes that may fit the statistics' measures side by side
        (:func:`~perception.report.statistics.landmark_statistics`).
    skipped : iterable of (str, str)
        The input folder's files that are not clips, with why
        (:attr:`perception.discovery.Discovery.skipped`): listed on the page.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary = with_verdict_reasons(summary, recognitions)
    # the landmark columns in the landmark tables' units (ms, mm, mm/s, %), said beside it
    write_summary_csv(out / "summary.csv", summary)
    write_units(out / "summary.csv", summary.columns)
    # landmarks.csv written a chunk of movements at a time; kept of it, what the
    # statistics and the strips figure read (the whole table was 2 kB a trial)
    columns, kept = write_landmark_table(
        summary, recognitions, out / TABLES[0], shown=_printable_table,
        keep=("clip", "condition", *PARTICIPANT_COLUMNS, *STRIP_COLUMNS, "unit"))
    measures = _measures(columns, kept, summary)
    statistics = _statistics_soon(measures, jobs)
    write_csv(out / TABLES[1], _printable_table(participant_means(measures)))
    landmarks = _strip_rows(kept)
    del kept
    ok = summary[summary["status"] == "ok"]
    recs = _Clips(recognitions, [c for c in ok["clip"] if c in recognitions])
    condition_of = ok.set_index("clip")["condition"]
    conds = [c if isinstance(c, str) else "unlabelled" for c in condition_of.loc[recs.names]]
    if profile_model is None and "reference_model" in ok and ok["reference_model"].notna().any():
        profile_model = str(ok["reference_model"].dropna().iloc[0])
    if recs and profile_model is None:
        profile_model = reference_model(recs, [condition_of.get(c) for c in recs.names])
    scored, counts = len(ok), _verdict_counts(ok)
    del ok  # a copy of the summary's scored rows: 1 kB a trial
    sections, stats_df = [], pd.DataFrame()
    if recs:
        sections.append(_kinematics(recs, conds, landmarks, out, figure_format, dpi))
    del landmarks  # written and drawn
    if recs and profile_model:
        _chapter5(recs, conds, profile_model, models, out, figure_format, dpi)
        stats_df = condition_statistics(summary, profile_model)
        write_csv(out / "statistics.csv", stats_df)
        sections.append(_figures_html(profile_model, figure_format))
        if len(stats_df):
            sections.append("<h2>Statistics of the reference model's final confidence</h2>"
                            + _statistics_html(stats_df))
    anchors = {clip: f"clip-{i}" for i, clip in enumerate(recs.names)}
    failed = summary[summary["status"] != "ok"]
    if len(failed):  # failures and trials that give no reach, each with why
        why = failed["reason"] if "reason" in failed else failed["error"]
        why = why.where(why.notna() & (why.astype(str) != ""), failed["error"])
        sections.append(f"<h2>Not scored ({len(failed)})</h2>" + _table(
            ["clip", "status", "reason"],
            [[_e(c), _e(st), _e(w)] for c, st, w in zip(failed["clip"], failed["status"], why)]))
    skipped = list(skipped)
    if skipped:  # every file of the input is on the page: a row, or a line saying why not
        sections.append(f"<h2>Files not read ({len(skipped)})</h2>" + _table(
            ["file", "reason"], [[_e(name), _e(why)] for name, why in skipped]))
    names = sorted(os.listdir(out))  # once, not once per clip
    clips = (_clip_section(rec, out, anchors[rec.clip], condition_of.get(rec.clip), names)
             for rec in recs)
    tables = [_link(n, n) for n in ("summary.csv", *(["statistics.csv"] if len(stats_df)
                                                      else []), *TABLES)]
    body = [
        f"<h1>{_e(title)}</h1>",
        f"<p>{len(summary)} clips: {scored} scored, {len(failed)} not scored"
        + (f"; {len(skipped)} file(s) of the input not read (below)" if skipped else "")
        + ". Tables: "
        + ", ".join(tables) + '. <span class="note">' + _HOW_TO_READ + "</span></p>",
        counts,
        "<h2>Summary</h2>", _main_table(summary, anchors, profile_model), _models_table(summary),
        _other_columns_table(summary),
        *sections, "<h2>Clips</h2>", *clips,
    ]
    # the page written as it is made, a table row and a clip at a time (the whole of it
    # was 35 kB a trial at its peak), and renamed into place once complete (through the
    # module, as write_csv and write_text call it: the one place a write can fail)
    with atomic.atomic_path(out / "report.html") as tmp, open(
            tmp, "w", encoding="utf-8", errors="backslashreplace", newline="") as page:
        page.write("<!doctype html><html><head><meta charset='utf-8'>"
                   "<meta name='viewport' content='width=device-width, initial-scale=1'>"
                   f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>")
        for k, part in enumerate(body):
            if k:
                page.write("\n")
            if isinstance(part, str):
                page.write(part)
            else:  # a table or a clip's section, a row at a time
                page.writelines(part)
        page.write("</body></html>\n")
        write_csv(out / TABLES[2], _printable_table(statistics()))
    return BatchReport(folder=out, summary=out / "summary.csv", html=out / "report.html")


_HOW_TO_READ = (
    "How to read it: the <b>verdict</b> judges the movement's coordination, brought to the "
    "repertoire's speed, distance and frame rate: <i>normal</i> or <i>reach</i> when the "
    "model that explains it best (highest log-likelihood) fits it better than the worst 5 % "
    "of its own demonstrations (<b>familiarity</b>, 0–1); <i>abnormal</i> when it does not, "
    "or when the grip opens late or twice (the kind is given below it); <i>unfamiliar</i> "
    "when even its transport is no human reach. The <b>margin</b> is the best model's "
    "log-likelihood minus the runner-up's. C is the thesis-rule confidence in cm "
    "(weighted; the files hold metres).")

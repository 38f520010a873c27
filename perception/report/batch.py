"""The batch report: ``summary.csv``, condition profiles and statistics, ``report.html``."""

from __future__ import annotations

import html
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from perception.io.atomic import save_figure, write_csv, write_text
from perception.report.clip import ClipSummary, clip_outputs
from perception.report.conditions import (
    condition_profiles,
    condition_statistics,
    default_profile_model,
)
from perception.report.figures import condition_figure

__all__ = ["BatchReport", "write_batch_report"]


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


def _table_html(df: pd.DataFrame) -> str:
    return df.to_html(index=False, float_format=lambda v: f"{v:.4g}", na_rep="",
                      classes="t", border=0, escape=True)


def write_batch_report(summary: pd.DataFrame, recognitions: dict[str, ClipSummary],
                       out: Path, *, profile_model: str | None = None,
                       title: str = "hammer-mv recognition report") -> BatchReport:
    """Write ``summary.csv``, condition profiles and statistics, and ``report.html``.

    Parameters
    ----------
    summary : pandas.DataFrame
        One row per clip: clip, condition, winner, conf_<model>..., status, error.
    recognitions : dict of ClipSummary
        Scored clips by name (failed clips absent).
    out : Path
        Report folder.
    profile_model : str, optional
        Model for the per-condition profiles and statistics (default: the grasp
        model that best explains the ``normal`` clips — highest mean
        log-likelihood among grasp models — or all clips without labels).
    title : str
        Heading of the HTML page.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "summary.csv", summary)
    sections = []
    ok = summary[summary["status"] == "ok"]
    recs = [recognitions[c] for c in ok["clip"] if c in recognitions]
    condition_of = ok.set_index("clip")["condition"]
    if recs and profile_model is None:
        normal = [r for r in recs if condition_of.get(r.clip) == "normal"]
        profile_model = default_profile_model(normal or recs)
    stats_df = pd.DataFrame()
    if recs and profile_model:
        conds = [c if isinstance(c, str) else "unlabelled"
                 for c in condition_of.loc[[r.clip for r in recs]]]
        prof = condition_profiles(recs, conds, profile_model)
        write_csv(out / "condition_profiles.csv", prof)
        save_figure(out / "condition_profiles.png", condition_figure(prof, profile_model))
        stats_df = condition_statistics(summary, profile_model)
        write_csv(out / "statistics.csv", stats_df)
        sections.append(f"<h2>Confidence of {html.escape(profile_model)} by condition</h2>"
                        '<img src="condition_profiles.png" alt="condition profiles">')
        if len(stats_df):
            sections.append("<h2>Statistics of final confidence</h2>" + _table_html(stats_df))
    counts = ok.groupby(["condition", "winner"], dropna=False).size().reset_index(name="clips")
    if len(counts):
        sections.append("<h2>Winners (likelihood rule unless stated)</h2>" + _table_html(counts))
    failed = summary[summary["status"] != "ok"]
    if len(failed):
        sections.append(f"<h2>Failed clips ({len(failed)})</h2>"
                        + _table_html(failed[["clip", "status", "error"]]))
    clips = []
    for rec in recs:
        p = clip_outputs(out, rec.clip)
        clips.append(
            f"<h3>{html.escape(rec.clip)} — winner {html.escape(rec.winner)} ({rec.rule})</h3>"
            f'<img src="{p["confidence_png"].name}" width="49%">'
            f'<img src="{p["paths_png"].name}" width="49%">'
            + (f'<img src="{rec.clip}.tracking.png" width="98%" alt="tracked markers">'
               if (out / f"{rec.clip}.tracking.png").exists() else ""))
    body = "\n".join([
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{len(summary)} clips: {len(ok)} scored, {len(failed)} failed. "
        'Tables: <a href="summary.csv">summary.csv</a>'
        + (', <a href="statistics.csv">statistics.csv</a>' if len(stats_df) else "")
        + ".</p>",
        *sections,
        "<h2>Summary</h2>", _table_html(summary),
        "<h2>Clips</h2>", *clips,
    ])
    page = ("<!doctype html><html><head><meta charset='utf-8'>"
            f"<title>{html.escape(title)}</title><style>"
            "body{font-family:sans-serif;max-width:1200px;margin:2em auto;}"
            "table.t{border-collapse:collapse;font-size:85%;}"
            "table.t td,table.t th{padding:2px 8px;border-bottom:1px solid #ddd;}"
            "img{max-width:100%;}</style></head><body>"
            f"{body}</body></html>\n")
    write_text(out / "report.html", page)
    return BatchReport(folder=out, summary=out / "summary.csv", html=out / "report.html")

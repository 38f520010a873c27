"""Recognition reports: per clip (JSON, CSV, figures) and per batch (tables, statistics, HTML).

Figures follow thesis chapter 5: confidence profiles (Fig. 5.8), predicted
against observed digit paths and grip aperture (Figs. 5.5-5.7), and mean
± SD confidence per stimulus condition (Fig. 5.8c).
"""

from __future__ import annotations

import html
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from minvar.figures import new_figure

from perception.io.atomic import save_figure, write_csv, write_json, write_text
from perception.recognition.engine import Recognition

__all__ = [
    "ClipSummary",
    "write_clip_report",
    "clip_outputs",
    "confidence_figure",
    "paths_figure",
    "condition_profiles",
    "condition_figure",
    "condition_statistics",
    "BatchReport",
    "write_batch_report",
    "PROFILE_POINTS",
]

log = logging.getLogger(__name__)

#: Samples of normalised movement time for per-condition mean profiles.
PROFILE_POINTS = 101


@dataclass(frozen=True, eq=False)
class ClipSummary:
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
        Thesis-rule confidence.
    final_log_likelihood : (M,) array
        Likelihood-rule score at the end.
    winner : str
        The winning model.
    rule : str
        Rule that picked the winner.
    """

    clip: str
    time: np.ndarray
    names: list[str]
    kinds: list[str]
    confidence: np.ndarray
    final_log_likelihood: np.ndarray
    winner: str
    rule: str

    @classmethod
    def from_dict(cls, d: dict) -> ClipSummary:
        """From the content of a ``<clip>.recognition.json``.

        Parameters
        ----------
        d : dict
            The parsed JSON.
        """
        names = [m["name"] for m in d["models"]]
        return cls(
            clip=d["clip"],
            time=np.asarray(d["time"], dtype=float),
            names=names,
            kinds=[m["kind"] for m in d["models"]],
            confidence=np.array([d["confidence"][n] for n in names], dtype=float),
            final_log_likelihood=np.array([m.get("final_log_likelihood", np.nan)
                                           for m in d["models"]], dtype=float),
            winner=d["winner"],
            rule=d["rule"],
        )

    @classmethod
    def from_recognition(cls, rec: Recognition) -> ClipSummary:
        """From a :class:`~perception.recognition.engine.Recognition`.

        Parameters
        ----------
        rec : Recognition
            A scored clip.
        """
        return cls(clip=rec.clip, time=rec.time, names=list(rec.names), kinds=list(rec.kinds),
                   confidence=rec.confidence, final_log_likelihood=rec.log_likelihood[:, -1],
                   winner=rec.winner, rule=rec.rule)


def clip_outputs(out: Path, clip: str) -> dict[str, Path]:
    """Paths of the files :func:`write_clip_report` writes for ``clip`` in ``out``.

    Parameters
    ----------
    out : Path
        Report folder.
    clip : str
        Clip name.
    """
    return {
        "json": out / f"{clip}.recognition.json",
        "csv": out / f"{clip}.confidence.csv",
        "confidence_png": out / f"{clip}.confidence.png",
        "paths_png": out / f"{clip}.paths.png",
    }


def confidence_figure(rec: Recognition) -> Figure:
    """Confidence profiles of every model (thesis rule) and the log-likelihood.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    fig, ax = new_figure(1, 2, size=(11, 4))
    styles = {"grasp": "-", "reach": "--"}
    for name, kind, c, ll in zip(rec.names, rec.kinds, rec.confidence, rec.log_likelihood):
        ax[0, 0].plot(rec.time, c * 100, styles.get(kind, "-"), label=name, lw=1.2)
        ax[0, 1].plot(rec.time, ll, styles.get(kind, "-"), label=name, lw=1.2)
    ax[0, 0].set_title("thesis rule: confidence C (eqs. 5.6-5.8)")
    ax[0, 0].set_ylabel("C (cm, weighted)")
    ax[0, 1].set_title(f"likelihood rule: cumulative log-likelihood (winner {rec.winner})")
    ax[0, 1].set_ylabel("log-likelihood")
    for a in ax[0]:
        a.set_xlabel("time since onset (s)")
        a.axhline(0, color="0.7", lw=0.6)
    ax[0, 0].legend(fontsize=7, ncol=2)
    fig.suptitle(rec.clip)
    return fig


def paths_figure(rec: Recognition, model: str | None = None) -> Figure:
    """Predicted against observed digit paths and grip aperture (thesis Figs. 5.5-5.7).

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    model : str, optional
        Model whose predictions are drawn (default: the winner).
    """
    model = model or rec.winner
    i = rec.names.index(model)
    obs = rec.observation
    fig, ax = new_figure(1, 2, size=(11, 4.5))
    a = ax[0, 0]
    a.plot(*obs.finger.T, "g-", lw=1.5, label="finger observed")
    a.plot(*obs.thumb.T, "r-", lw=1.5, label="thumb observed")
    a.plot(*obs.wrist.T, "b-", lw=1.5, label="wrist observed")
    a.plot(*rec.predicted["finger"][i].T, "g:", lw=1.5, label="finger predicted")
    a.plot(*rec.predicted["thumb"][i].T, "r:", lw=1.5, label="thumb predicted")
    a.plot(*rec.predicted["wrist"][i].T, "b:", lw=1.5, label="wrist predicted")
    circle = np.linspace(0, 2 * np.pi, 100)
    rad = obs.object_diameter / 2
    a.plot(rad * np.cos(circle), rad * np.sin(circle), "y-", lw=2, label="object")
    a.set_aspect("equal", adjustable="datalim")
    a.set_xlabel("x (m)")
    a.set_ylabel("y (m), toward the object")
    a.set_title(f"paths: observed vs {model}")
    a.legend(fontsize=7)
    b = ax[0, 1]
    b.plot(rec.time, obs.g * 100, "k-", label="observed")
    b.plot(rec.time, rec.predicted_g[i] * 100, "k:", label=f"predicted ({model})")
    b.set_xlabel("time since onset (s)")
    b.set_ylabel("grip aperture (cm)")
    b.set_title("grip aperture")
    b.legend(fontsize=8)
    fig.suptitle(rec.clip)
    return fig


def write_clip_report(rec: Recognition, out: Path, *, extra: dict | None = None
                      ) -> dict[str, Path]:
    """Write ``<clip>.recognition.json``, the per-step CSV and the two figures.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    out : Path
        Report folder (created if missing).
    extra : dict, optional
        More keys for the JSON (e.g. the batch's input fingerprint).

    Returns
    -------
    dict of Path
        The files written (see :func:`clip_outputs`).
    """
    paths = clip_outputs(Path(out), rec.clip)
    save_figure(paths["confidence_png"], confidence_figure(rec))
    save_figure(paths["paths_png"], paths_figure(rec))
    write_csv(paths["csv"], rec.to_pandas())
    # the JSON last: its presence marks the clip's report complete
    write_json(paths["json"], {**rec.to_dict(), **(extra or {})})
    return paths


def condition_profiles(recognitions: list[ClipSummary], conditions: list[str],
                       model: str) -> pd.DataFrame:
    """Mean ± SD confidence of one model per condition over normalised movement time.

    Parameters
    ----------
    recognitions : list of ClipSummary
        Scored clips.
    conditions : list of str
        Condition of each clip (e.g. normal, delayed, open-close-open).
    model : str
        Model whose confidence is profiled.

    Returns
    -------
    pandas.DataFrame
        Columns: condition, phase (0..1), mean, sd, n.
    """
    phase = np.linspace(0, 1, PROFILE_POINTS)
    curves: dict[str, list[np.ndarray]] = {}
    for rec, cond in zip(recognitions, conditions):
        i = rec.names.index(model)
        t = rec.time / rec.time[-1] if rec.time[-1] > 0 else rec.time
        curves.setdefault(cond, []).append(np.interp(phase, t, rec.confidence[i]))
    rows = []
    for cond, cs in curves.items():
        arr = np.array(cs)
        sd = arr.std(axis=0, ddof=1) if len(arr) > 1 else np.zeros(len(phase))
        rows.append(pd.DataFrame({"condition": cond, "phase": phase, "mean": arr.mean(0),
                                  "sd": sd, "n": len(arr)}))
    return pd.concat(rows, ignore_index=True)


def condition_figure(profiles: pd.DataFrame, model: str) -> Figure:
    """Mean ± SD confidence profile per condition (thesis Fig. 5.8c).

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`condition_profiles`.
    model : str
        The model profiled (for the title).
    """
    fig, ax = new_figure(1, 1, size=(6.5, 4.5))
    a = ax[0, 0]
    for cond, g in profiles.groupby("condition", sort=False):
        line, = a.plot(g["phase"] * 100, g["mean"] * 100, lw=1.8,
                       label=f"{cond} (n={int(g['n'].iloc[0])})")
        a.fill_between(g["phase"] * 100, (g["mean"] - g["sd"]) * 100,
                       (g["mean"] + g["sd"]) * 100, color=line.get_color(), alpha=0.2)
    a.set_xlabel("movement time (%)")
    a.set_ylabel("confidence C (cm, weighted)")
    a.set_title(f"mean ± SD confidence of {model}")
    a.axhline(0, color="0.7", lw=0.6)
    a.legend(fontsize=8)
    return fig


def condition_statistics(summary: pd.DataFrame, model: str) -> pd.DataFrame:
    """Compare final confidence of ``model`` between conditions.

    One-way ANOVA across all conditions and Welch t-tests for each pair.

    Parameters
    ----------
    summary : pandas.DataFrame
        Batch summary with ``condition``, ``status`` and ``conf_<model>`` columns.
    model : str
        Model compared.

    Returns
    -------
    pandas.DataFrame
        Columns: model, test, groups, n, statistic, p_value, mean_difference.
    """
    from scipy import stats  # slow to import; only the batch report needs it

    col = f"conf_{model}"
    ok = summary[(summary["status"] == "ok") & summary["condition"].notna()]
    groups = {c: g[col].to_numpy(float) for c, g in ok.groupby("condition", sort=False)}
    rows = []
    testable = {c: v for c, v in groups.items() if len(v) >= 2}
    if len(testable) >= 2:
        f, p = stats.f_oneway(*testable.values())
        rows.append({"test": "one-way ANOVA", "groups": " / ".join(testable),
                     "n": sum(len(v) for v in testable.values()), "statistic": float(f),
                     "p_value": float(p), "mean_difference": np.nan})
    names = list(testable)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            t, p = stats.ttest_ind(testable[a], testable[b], equal_var=False)
            rows.append({"test": "Welch t-test", "groups": f"{a} vs {b}",
                         "n": len(testable[a]) + len(testable[b]), "statistic": float(t),
                         "p_value": float(p),
                         "mean_difference": float(testable[a].mean() - testable[b].mean())})
    return pd.DataFrame(rows, columns=["test", "groups", "n", "statistic", "p_value",
                                       "mean_difference"]).assign(model=model)[
        ["model", "test", "groups", "n", "statistic", "p_value", "mean_difference"]]


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
        profile_model = _default_profile_model(normal or recs)
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
            f'<img src="{p["paths_png"].name}" width="49%">')
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


def _default_profile_model(recs: list[ClipSummary]) -> str | None:
    """The grasp model with the highest mean final log-likelihood over ``recs``."""
    if not recs:
        return None
    names, kinds = recs[0].names, recs[0].kinds
    grasp = [i for i, k in enumerate(kinds) if k == "grasp"] or list(range(len(names)))
    ll = np.array([[r.final_log_likelihood[i] for i in grasp] for r in recs
                   if r.names == names])
    return names[grasp[int(np.argmax(np.nanmean(ll, axis=0)))]] if len(ll) else names[0]

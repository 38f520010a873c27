"""Statistics that respect a lab's design: per-participant means and mixed models.

Trials of one participant are not independent: where the manifest names
participants, each measure (every landmark of ``landmarks.csv`` and the
reference model's final confidence) is tested with a linear mixed model,
``value ~ condition`` with the participant as a random intercept
(statsmodels ``MixedLM``, REML), as labs do with lme4 or afex; without
participants, with the plain one-way ANOVA and Welch t-tests
(:func:`~perception.report.conditions.plain_tests`). ``method`` says which.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from perception.report.conditions import plain_tests

__all__ = ["PARTICIPANT_COLUMNS", "landmark_statistics", "measure_table",
           "participant_column", "participant_means"]

#: Manifest columns that name the participant, first found wins.
PARTICIPANT_COLUMNS = ("participant", "subject")

_STAT_COLUMNS = ["measure", "unit", "method", "term", "estimate", "se", "statistic_type",
                 "statistic", "df1", "df2", "p_value", "n", "n_participants", "note"]


def participant_column(columns) -> str | None:
    """The column of ``columns`` that names the participant (:data:`PARTICIPANT_COLUMNS`)."""
    return next((c for c in PARTICIPANT_COLUMNS if c in columns), None)


def measure_table(landmarks: pd.DataFrame, summary: pd.DataFrame) -> pd.DataFrame:
    """``landmarks.csv`` with its ``landmark`` as ``measure``, and the reference model's
    final confidence (``reference_confidence``, mm) of each scored clip.

    Parameters
    ----------
    landmarks : pandas.DataFrame
        :func:`~perception.report.tables.landmark_table`.
    summary : pandas.DataFrame
        :func:`perception.batch.summary_table`.
    """
    keys = [c for c in landmarks.columns if c not in ("landmark", "value", "unit")]
    ok = summary[summary["status"] == "ok"].set_index("clip")
    conf = (landmarks.drop_duplicates("clip")[keys]
            .assign(measure="reference_confidence", unit="mm",
                    value=lambda d: ok["reference_confidence"].reindex(d["clip"]).to_numpy(
                        float) * 1e3))
    return pd.concat([landmarks.rename(columns={"landmark": "measure"}), conf],
                     ignore_index=True)


def participant_means(data: pd.DataFrame) -> pd.DataFrame:
    """Mean, SD and trials (``n``) of each measure per participant and condition.

    Parameters
    ----------
    data : pandas.DataFrame
        :func:`measure_table`. Without a participant column the cells are the
        conditions alone; the manifest's other columns are averaged over.

    Returns
    -------
    pandas.DataFrame
        Columns ``measure``, ``unit``, the participant column, ``condition``,
        ``n`` (trials with a value), ``mean``, ``sd`` (in ``unit``).
    """
    who = participant_column(data.columns)
    keys = ["measure", "unit", *([who] if who else []), "condition"]
    cells = data.dropna(subset=["value"]).groupby(keys, sort=False, dropna=False)["value"]
    return cells.agg(n="count", mean="mean", sd="std").reset_index()


def landmark_statistics(data: pd.DataFrame) -> pd.DataFrame:
    """Each measure compared between conditions, one row per measure and term.

    A mixed model (``method`` ``mixedlm``) where at least 2 participants
    have 2 trials or more of a measure with a condition and a value; the
    plain tests (``one_way_anova``, ``welch_t_test``) otherwise, ``note``
    saying why.

    Parameters
    ----------
    data : pandas.DataFrame
        :func:`measure_table`.

    Returns
    -------
    pandas.DataFrame
        Columns ``measure``, ``unit``, ``method``, ``term``, ``estimate``,
        ``se``, ``statistic_type`` (``z``, ``F``, ``t``), ``statistic``, ``df1``,
        ``df2``, ``p_value``, ``n`` (trials), ``n_participants``, ``note``.
    """
    who = participant_column(data.columns)
    rows = []
    for (measure, unit), d in data.groupby(["measure", "unit"], sort=False):
        d = d[d["condition"].notna() & np.isfinite(d["value"].to_numpy(float))]
        if who is not None:
            d = d[d[who].notna() & (d[who].astype(str) != "")]
        why = _plain_because(d, who)
        found = _mixed_model(d, who) if why is None else []
        if isinstance(found, str):
            why, found = f"mixed model failed: {found}", []
        if why is not None:
            groups = {c: g["value"].to_numpy(float)
                      for c, g in d.groupby("condition", sort=False)}
            found = [{"method": "one_way_anova" if r["statistic_type"] == "F"
                      else "welch_t_test", "term": r["groups"], "estimate": r["mean_difference"],
                      **{k: r[k] for k in ("se", "statistic_type", "statistic", "df1", "df2",
                                           "p_value", "n")},
                      "n_participants": d[who].nunique() if who else None,
                      "note": "; ".join(filter(None, [why, r["note"]]))}
                     for r in plain_tests(groups)]
        rows += [{"measure": measure, "unit": unit, **r} for r in found]
    table = pd.DataFrame(rows, columns=_STAT_COLUMNS)
    return table.astype({"n": "Int64", "n_participants": "Int64"})


def _plain_because(d: pd.DataFrame, who: str | None) -> str | None:
    """Why a measure's trials ``d`` get the plain tests (None: a mixed model)."""
    if who is None:
        return "no participant column in the manifest"
    if (d.groupby(who).size() >= 2).sum() < 2:
        return "fewer than 2 participants with 2 trials or more"
    if d["condition"].nunique() < 2:
        return "fewer than 2 conditions"
    return "the same value in every trial" if d["value"].nunique() < 2 else None


def _mixed_model(d: pd.DataFrame, who: str) -> list[dict] | str:
    """``value ~ condition``, the participant a random intercept (REML; the reference
    condition ``normal`` where there is one): its rows, or why it failed."""
    import statsmodels.formula.api as smf

    levels = sorted(d["condition"].unique(), key=lambda c: (c != "normal", c))
    d = d.assign(condition=pd.Categorical(d["condition"], levels))
    with warnings.catch_warnings():  # a fit on the boundary says so in note
        warnings.simplefilter("ignore")
        try:
            fit = smf.mixedlm("value ~ condition", d, groups=d[who]).fit(reml=True)
        except (np.linalg.LinAlgError, ValueError) as exc:
            return str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    common = {"method": "mixedlm", "n": int(fit.nobs), "n_participants": d[who].nunique(),
              "df1": np.nan, "df2": np.nan,
              "note": "" if fit.converged else "did not converge (statsmodels)"}
    rows = [{**common, "term": term, "estimate": fit.fe_params[term], "se": fit.bse[term],
             "statistic_type": "z", "statistic": fit.tvalues[term],
             "p_value": fit.pvalues[term]} for term in fit.fe_params.index]
    for term, value in (("participant_variance", fit.cov_re.iloc[0, 0]),
                        ("residual_variance", fit.scale)):
        rows.append({**common, "term": term, "estimate": float(value), "se": np.nan,
                     "statistic_type": "", "statistic": np.nan, "p_value": np.nan})
    return rows

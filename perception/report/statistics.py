"""Statistics that respect a lab's design, and say when they cannot.

Trials of one participant are not independent: where the manifest names
participants, each measure (every landmark of ``landmarks.csv`` and the
reference model's final confidence) is tested with a linear mixed model,
``value ~ condition`` with the participant as a random intercept
(statsmodels ``MixedLM``, REML), as labs do with lme4 or afex.

A mixed model is only printed when the data support it. It is refused
below :data:`MIN_PARTICIPANTS`, and a fit is rejected, whatever
statsmodels' ``converged`` flag says, on any of :func:`mixed_fit_problems`
(a warning of statsmodels, a non-finite log-likelihood, a singular or
boundary fit, a zero, non-finite or absurd standard error, a fixed-effects
covariance that is not positive definite). The fallbacks, in order:

1. ``ols_cluster_robust``: ordinary least squares ``value ~ condition``
   with participant-clustered standard errors (CR1, t with G - 1 degrees
   of freedom), when the mixed model's fit is rejected (there are
   :data:`MIN_PARTICIPANTS` participants or more), unless its own standard
   errors or covariance fail the same checks;
2. ``cell_means``: each condition's mean of the participants' means, no
   test: with fewer participants, fewer than 2 conditions, one value in
   every trial, or when the robust fit fails too.

Without participants the trials are taken as independent: the plain
one-way ANOVA and Welch t-tests
(:func:`~perception.report.conditions.plain_tests`). ``method`` names the
model each row comes from and ``note`` why it is not the mixed model.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from perception.report.conditions import plain_tests

__all__ = ["ABSURD_SE_FACTOR", "BOUNDARY_VARIANCE_RATIO", "MIN_PARTICIPANTS",
           "PARALLEL_TRIALS", "PARTICIPANT_COLUMNS", "fitted_in_workers", "landmark_statistics",
           "measure_table", "mixed_fit_problems", "participant_column", "participant_means"]

#: Manifest columns that name the participant, first found wins.
PARTICIPANT_COLUMNS = ("participant", "subject")

#: Fewest participants for a random intercept (and for participant-clustered
#: errors). A variance is estimated from its levels: with fewer than 5 or 6
#: the random effect's variance is unreliable and often estimated as zero
#: (Bolker et al. 2009, Trends Ecol. Evol. 24:127, "Generalized linear mixed
#: models: a practical guide"; Gelman & Hill 2007, §12.9), and a clustered
#: standard error with G clusters has G - 1 degrees of freedom (Cameron &
#: Miller 2015, J. Human Resources 50:317).
MIN_PARTICIPANTS = 5

#: A participant variance below this share of the residual variance is a
#: boundary (singular) fit: the random intercept is not supported. lme4's
#: ``isSingular`` tests the SD ratio against 1e-4, but statsmodels' optimizer
#: stops short of the boundary (0.5-0.9 % on simulated data without any
#: participant variance); below 1 % the random intercept changes the fixed
#: effects little, so the fallback costs nothing.
BOUNDARY_VARIANCE_RATIO = 0.01

#: A standard error over this many times the SD of the measure's own values
#: is absurd (a mean's SE is at most that SD: one trial): a degenerate fit.
ABSURD_SE_FACTOR = 10.0

#: An SE under this share of the values' SD is zero to rounding: nothing varies
#: where the model looks (e.g. participant-clustered errors with one participant
#: per condition).
_ZERO_SE = 1e-9

_STAT_COLUMNS = ["measure", "unit", "method", "term", "estimate", "se", "statistic_type",
                 "statistic", "df1", "df2", "p_value", "n", "n_participants", "note"]

#: statsmodels' messages that are no failure of their own: an optimizer failed and
#: the next is tried (the last one's outcome counts), and "boundary", which tests
#: the participant variance against 0.01 in the data's own unit² (a variance of
#: 0.005 s² is no boundary); :data:`BOUNDARY_VARIANCE_RATIO` is the scale-free test.
_NOT_FAILURES = ("Retrying MixedLM optimization",
                 "Maximum Likelihood optimization failed to converge",
                 "The MLE may be on the boundary")


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
    # a landmark's own clock and flag are not the clip's: the confidence gets its own
    keys = [c for c in landmarks.columns
            if c not in ("landmark", "value", "unit", "clock", "flag")]
    ok = summary[summary["status"] == "ok"].set_index("clip")
    conf = (landmarks.drop_duplicates("clip")[keys]
            .assign(measure="reference_confidence", unit="mm",
                    value=lambda d: ok["reference_confidence"].reindex(d["clip"]).to_numpy(
                        float) * 1e3, clock="",
                    flag=lambda d: np.where(d["value"].isna(), "not scored", "ok")))
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


#: Trials of a measure from which :func:`landmark_statistics` fits the measures in
#: worker processes when it is given more than one: 1,200 trials of 40 participants
#: (19 measures) took 11 s in one process, 7 s in two with their start-up
#: (statsmodels' imports, about a second); 10,000 of 100, 29 s in one.
PARALLEL_TRIALS = 500


def landmark_statistics(data: pd.DataFrame, jobs: int = 1) -> pd.DataFrame:
    """Each measure compared between conditions, one row per measure and term.

    A mixed model (``method`` ``mixedlm``) where :data:`MIN_PARTICIPANTS`
    participants or more have a measure with a condition and a value, and
    its fit passes :func:`mixed_fit_problems`; else the fallbacks of the
    module's docstring (``ols_cluster_robust``, ``cell_means``), or without
    a participant column the plain tests (``one_way_anova``,
    ``welch_t_test``); ``note`` says why, and nothing reaches the console.

    Parameters
    ----------
    data : pandas.DataFrame
        :func:`measure_table`.
    jobs : int
        Worker processes that may fit the measures side by side
        (:mod:`perception.workers`: one BLAS thread each, as the command's
        own process has), where a measure has :data:`PARALLEL_TRIALS` trials
        or more and a participant column (mixed models); the rows are the
        same, in the same order.

    Returns
    -------
    pandas.DataFrame
        Columns ``measure``, ``unit``, ``method``, ``term``, ``estimate``,
        ``se``, ``statistic_type`` (``z``, ``t``, ``F``), ``statistic``, ``df1``,
        ``df2``, ``p_value``, ``n`` (trials), ``n_participants``, ``note``.
    """
    who = participant_column(data.columns)
    measures = []
    for (measure, unit), d in data.groupby(["measure", "unit"], sort=False):
        d = d[d["condition"].notna() & np.isfinite(d["value"].to_numpy(float))]
        if who is not None:
            d = d[d[who].notna() & (d[who].astype(str) != "")]
        measures.append((len(measures), measure, unit, d))
    job = _MeasureJob(who)
    if fitted_in_workers(data, jobs):
        from perception.workers import run_pool

        found = dict(run_pool(measures, job, min(jobs, len(measures)),
                              size=lambda item: len(item[3])))
    else:
        found = dict(job.run(m, None) for m in measures)
    rows = [r for k in range(len(measures)) for r in found[k]]
    table = pd.DataFrame(rows, columns=_STAT_COLUMNS)
    return table.astype({"n": "Int64", "n_participants": "Int64"})


def fitted_in_workers(data: pd.DataFrame, jobs: int) -> bool:
    """Whether :func:`landmark_statistics` fits ``data``'s measures in worker processes
    with ``jobs``: more than one measure, one of :data:`PARALLEL_TRIALS` trials or more,
    a participant column (mixed models: the plain tests cost too little).

    Parameters
    ----------
    data : pandas.DataFrame
        :func:`measure_table`.
    jobs : int
        Worker processes allowed.
    """
    if jobs <= 1 or participant_column(data.columns) is None or not len(data):
        return False
    trials = data.groupby(["measure", "unit"], sort=False).size()
    return len(trials) > 1 and int(trials.max()) >= PARALLEL_TRIALS


class _MeasureJob:
    """One measure's rows, for :func:`~perception.workers.run_pool` (picklable)."""

    def __init__(self, who: str | None):
        self.who = who

    def lost(self, item, message: str) -> tuple[int, list[dict]]:
        """A measure whose worker died (killed, out of memory), fitted here: the same rows,
        not a batch without its report."""
        return self.run(item, None)

    def run(self, item: tuple[int, str, str, pd.DataFrame], shared) -> tuple[int, list[dict]]:
        """``(its place, its rows)`` of the measure ``item`` (place, measure, unit, trials)."""
        k, measure, unit, d = item
        return k, [{"measure": measure, "unit": unit, **r} for r in _measure_rows(d, self.who)]


def _measure_rows(d: pd.DataFrame, who: str | None) -> list[dict]:
    """One measure's rows: the first model of the order that its trials ``d`` support."""
    if who is None:
        return _plain_rows(d, "no participant column in the manifest")
    levels = sorted(d["condition"].unique(), key=lambda c: (c != "normal", c))
    d = d.assign(condition=pd.Categorical(d["condition"], levels))
    n_who = d[who].nunique()
    why = ("fewer than 2 conditions" if d["condition"].nunique() < 2
           else "the same value in every trial" if d["value"].nunique() < 2
           else f"{n_who} participants: a random effect needs at least {MIN_PARTICIPANTS}"
           if n_who < MIN_PARTICIPANTS else None)
    if why is not None:
        return _cell_mean_rows(d, who, why)
    found, problems = _mixed_model(d, who)
    if not problems:
        return found
    why = f"mixed model rejected: {'; '.join(problems)}"
    found, problems = _cluster_robust(d, who)
    if not problems:
        return [{**r, "note": why} for r in found]
    return _cell_mean_rows(d, who, f"{why}; cluster-robust fit rejected: {'; '.join(problems)}")


def _plain_rows(d: pd.DataFrame, why: str) -> list[dict]:
    """The one-way ANOVA and Welch t-tests of ``d``'s trials, taken as independent."""
    groups = {c: g["value"].to_numpy(float) for c, g in d.groupby("condition", sort=False)}
    return [{"method": "one_way_anova" if r["statistic_type"] == "F" else "welch_t_test",
             "term": r["groups"], "estimate": r["mean_difference"],
             **{k: r[k] for k in ("se", "statistic_type", "statistic", "df1", "df2",
                                  "p_value", "n")},
             "n_participants": None, "note": "; ".join(filter(None, [why, r["note"]]))}
            for r in plain_tests(groups)]


def _cell_mean_rows(d: pd.DataFrame, who: str, why: str) -> list[dict]:
    """Each condition's mean of its participants' means (each participant counts once):
    a description, no test."""
    rows = []
    for cond, g in d.groupby("condition", observed=True):  # the reference first
        rows.append({"method": "cell_means", "term": f"mean[{cond}]",
                     "estimate": float(g.groupby(who)["value"].mean().mean()), "se": np.nan,
                     "statistic_type": "", "statistic": np.nan, "df1": np.nan, "df2": np.nan,
                     "p_value": np.nan, "n": len(g), "n_participants": g[who].nunique(),
                     "note": f"{why}; cell means only, no test"})
    return rows


def _fit_quietly(fit):
    """``fit()``'s result and the warnings it raised, none of them reaching the console."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            return fit(), caught
        except (np.linalg.LinAlgError, ValueError) as exc:
            return (str(exc).splitlines()[0] if str(exc) else type(exc).__name__), caught


def _mixed_model(d: pd.DataFrame, who: str) -> tuple[list[dict], list[str]]:
    """``value ~ condition``, the participant a random intercept (REML; the reference
    condition ``normal`` where there is one): its rows and what is wrong with its fit."""
    import statsmodels.formula.api as smf

    fit, caught = _fit_quietly(
        lambda: smf.mixedlm("value ~ condition", d, groups=d[who]).fit(reml=True))
    if isinstance(fit, str):
        return [], [f"fit failed: {fit}"]
    problems = mixed_fit_problems(fit, caught, float(d["value"].std()))
    common = {"method": "mixedlm", "n": int(fit.nobs), "n_participants": d[who].nunique(),
              "df1": np.nan, "df2": np.nan, "note": ""}
    rows = [{**common, "term": term, "estimate": fit.fe_params[term], "se": fit.bse[term],
             "statistic_type": "z", "statistic": fit.tvalues[term],
             "p_value": fit.pvalues[term]} for term in fit.fe_params.index]
    for term, value in (("participant_variance", fit.cov_re.iloc[0, 0]),
                        ("residual_variance", fit.scale)):
        rows.append({**common, "term": term, "estimate": float(value), "se": np.nan,
                     "statistic_type": "", "statistic": np.nan, "p_value": np.nan})
    return rows, problems


def mixed_fit_problems(fit, caught: list[warnings.WarningMessage], sd: float) -> list[str]:
    """What is wrong with a random-intercept ``MixedLM`` fit, in words (empty: nothing).

    statsmodels can say "converged" of a degenerate fit (an infinite
    log-likelihood, a standard error of 1e9), so each is checked here.

    Parameters
    ----------
    fit : statsmodels.regression.mixed_linear_model.MixedLMResults
        The fit.
    caught : list of warnings.WarningMessage
        The warnings raised while fitting: any ``ConvergenceWarning``,
        ``HessianInversionWarning``, ``SingularMatrixWarning`` or one that
        says "singular" or "boundary" is a problem, except those of
        ``_NOT_FAILURES`` (a retry; statsmodels' boundary test, which is in the
        data's unit: :data:`BOUNDARY_VARIANCE_RATIO` replaces it).
    sd : float
        The SD of the values fitted, the yardstick of :data:`ABSURD_SE_FACTOR`.
    """
    problems = _warning_problems(caught)
    if not fit.converged:
        problems.append("did not converge (statsmodels)")
    if not np.isfinite(fit.llf):
        problems.append(f"log-likelihood {fit.llf}")
    ratio = float(fit.cov_re.iloc[0, 0]) / fit.scale if fit.scale > 0 else np.nan
    if not ratio >= BOUNDARY_VARIANCE_RATIO:
        problems.append(f"participant variance {ratio:.2%} of the residual variance "
                        f"(under {BOUNDARY_VARIANCE_RATIO:.0%}: a singular, boundary fit)")
    fe = fit.fe_params.index
    problems += _se_problems(fit.bse[fe], sd)
    problems += _covariance_problems(np.asarray(fit.cov_params().loc[fe, fe], float))
    return list(dict.fromkeys(problems))


def _warning_problems(caught: list[warnings.WarningMessage]) -> list[str]:
    """statsmodels' warnings of a failed fit, as one problem (none: an empty list)."""
    from statsmodels.tools.sm_exceptions import (
        ConvergenceWarning,
        HessianInversionWarning,
        SingularMatrixWarning,
    )

    bad = (ConvergenceWarning, HessianInversionWarning, SingularMatrixWarning)
    found = []
    for w in caught:
        text = str(w.message).strip().splitlines()[0] if str(w.message).strip() else ""
        if text.startswith(_NOT_FAILURES):
            continue
        if issubclass(w.category, bad) or any(k in text.lower()
                                              for k in ("singular", "boundary")):
            found.append(text.rstrip(".") or w.category.__name__)
    found = list(dict.fromkeys(found))
    return [f"statsmodels warned: {'; '.join(found)}"] if found else []


def _se_problems(se: pd.Series, sd: float) -> list[str]:
    """Standard errors that are not finite, zero (to rounding), or absurd against ``sd``."""
    zero = [f"{t} {v:.3g}" for t, v in se.items() if not (np.isfinite(v) and v > _ZERO_SE * sd)]
    huge = [f"{t} {v:.3g}" for t, v in se.items() if np.isfinite(v) and v > ABSURD_SE_FACTOR * sd]
    return ([f"SE not finite or zero ({', '.join(zero)})"] if zero else []) + (
        [f"SE over {ABSURD_SE_FACTOR:g} times the SD of the values, {sd:.3g} "
         f"({', '.join(huge)})"] if huge else [])


def _covariance_problems(cov: np.ndarray) -> list[str]:
    """A fixed-effects covariance (the inverse Hessian) that is not positive definite."""
    if not np.isfinite(cov).all():
        return ["covariance of the fixed effects is not finite (Hessian not invertible)"]
    eig = np.linalg.eigvalsh((cov + cov.T) / 2)
    if eig.min() <= _ZERO_SE * eig.max():
        return ["covariance of the fixed effects is not positive definite"]
    return []


def _cluster_robust(d: pd.DataFrame, who: str) -> tuple[list[dict], list[str]]:
    """OLS ``value ~ condition`` with participant-clustered standard errors (CR1,
    statsmodels' small-sample factor, t with G - 1 degrees of freedom)."""
    import statsmodels.formula.api as smf

    groups = pd.factorize(d[who])[0]
    fit, caught = _fit_quietly(lambda: smf.ols("value ~ condition", d).fit(
        cov_type="cluster", cov_kwds={"groups": groups}, use_t=True))
    if isinstance(fit, str):
        return [], [f"fit failed: {fit}"]
    params = fit.params.index
    problems = _warning_problems(caught)
    problems += _se_problems(fit.bse, float(d["value"].std()))
    problems += _covariance_problems(np.asarray(fit.cov_params().loc[params, params], float))
    n_who = int(groups.max()) + 1
    rows = [{"method": "ols_cluster_robust", "term": term, "estimate": fit.params[term],
             "se": fit.bse[term], "statistic_type": "t", "statistic": fit.tvalues[term],
             "df1": float(fit.df_resid_inference), "df2": np.nan,
             "p_value": fit.pvalues[term], "n": int(fit.nobs), "n_participants": n_who}
            for term in params]
    return rows, problems

"""Comparing stimulus conditions over a batch: mean profiles and statistics."""

from __future__ import annotations

import numpy as np
import pandas as pd

from perception.report.clip import ClipSummary

__all__ = ["PROFILE_POINTS", "condition_profiles", "condition_statistics", "default_profile_model"]

#: Samples of normalised movement time for per-condition mean profiles.
PROFILE_POINTS = 101


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


def default_profile_model(recs: list[ClipSummary]) -> str | None:
    """The grasp model with the highest mean final log-likelihood over ``recs``.

    Parameters
    ----------
    recs : list of ClipSummary
        Scored clips (those with other model lists are ignored).
    """
    if not recs:
        return None
    names, kinds = recs[0].names, recs[0].kinds
    grasp = [i for i, k in enumerate(kinds) if k == "grasp"] or list(range(len(names)))
    ll = np.array([[r.final_log_likelihood[i] for i in grasp] for r in recs
                   if r.names == names])
    return names[grasp[int(np.argmax(np.nanmean(ll, axis=0)))]] if len(ll) else names[0]

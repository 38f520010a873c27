"""Comparing stimulus conditions over a batch: the reference model, profiles and statistics.

The *reference* (profile) model is one grasp model for the whole batch: the
one that explains the ``normal`` clips best (highest mean final
log-likelihood), or all clips when none is labelled — the thesis's "normal
grasp model" that chapter 5 reads every stimulus on.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np
import pandas as pd

from perception.report.clip import ClipSummary

__all__ = ["PROFILE_POINTS", "aperture_profiles", "condition_profiles", "condition_statistics",
           "default_profile_model", "model_aperture", "plain_tests", "reference_model",
           "stacked_curves", "typical_clips"]

#: Samples of normalised movement time for per-condition mean profiles.
PROFILE_POINTS = 101


def _phase(rec: ClipSummary) -> np.ndarray:
    return rec.time / rec.time[-1] if rec.time[-1] > 0 else rec.time


def _mean_sd(curves: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    arr = np.asarray(curves)
    sd = np.nanstd(arr, axis=0, ddof=1) if len(arr) > 1 else np.zeros(arr.shape[1])
    return np.nanmean(arr, axis=0), sd


def stacked_curves(recognitions: Iterable, conditions: Sequence[str],
                   curve: Callable[[object], np.ndarray | None], points: int = PROFILE_POINTS
                   ) -> tuple[dict[str, np.ndarray], list[str]]:
    """Each condition's curves, one pass over ``recognitions``, in one array a condition.

    What a profile's mean ± SD reads, built without a list of arrays (and
    its copy): a batch's clips are read back one at a time, and a curve a
    clip held at once was 0.9 kB a trial and curve.

    Parameters
    ----------
    recognitions : iterable
        The clips, in order (read once).
    conditions : sequence of str
        Their conditions.
    curve : callable
        A clip's curve, ``(points,)``, or None to leave the clip out.
    points : int
        Samples of a curve.

    Returns
    -------
    curves : dict of str to array
        ``(k, points)`` for each condition, in the order the conditions come (``k``
        0 where every clip of it was left out), rows in the clips' order.
    order : list of str
        The conditions in the order their first curve came.
    """
    conditions = list(conditions)
    counts = dict.fromkeys(conditions, 0)
    for cond in conditions:
        counts[cond] += 1
    arrays = {cond: np.empty((n, points)) for cond, n in counts.items()}
    filled = dict.fromkeys(counts, 0)
    order: list[str] = []
    for rec, cond in zip(recognitions, conditions):
        values = curve(rec)
        if values is None:
            continue
        if not filled[cond]:
            order.append(cond)
        arrays[cond][filled[cond]] = values
        filled[cond] += 1
    return {cond: a[:filled[cond]] for cond, a in arrays.items()}, order


def condition_profiles(recognitions: Sequence[ClipSummary], conditions: list[str],
                       model: str) -> pd.DataFrame:
    """Mean ± SD confidence of one model per condition over normalised movement time.

    Parameters
    ----------
    recognitions : sequence of ClipSummary
        Scored clips (read once a curve: total, transport, grip).
    conditions : list of str
        Condition of each clip (e.g. normal, delayed, open-close-open).
    model : str
        Model whose confidence is profiled.

    Returns
    -------
    pandas.DataFrame
        Columns: condition, phase (0..1), mean, sd, n (the total confidence,
        m), and transport_mean, transport_sd, grip_mean, grip_sd (its two terms).
    """
    phase = np.linspace(0, 1, PROFILE_POINTS)

    def total(rec: ClipSummary) -> np.ndarray:
        return np.interp(phase, _phase(rec), rec.confidence[rec.index(model)])

    def transport(rec: ClipSummary) -> np.ndarray:
        return (np.interp(phase, _phase(rec), rec.transport[rec.index(model)])
                if rec.transport.size else np.full(len(phase), np.nan))

    def grip(rec: ClipSummary) -> np.ndarray:
        return total(rec) - transport(rec)

    # a curve at a time over every clip: one curve a clip held, not three
    conditions = list(conditions)[:len(recognitions)]
    tables: dict[str, dict] = {}
    for prefix, curve in (("", total), ("transport_", transport), ("grip_", grip)):
        curves, _ = stacked_curves(recognitions, conditions, curve)
        for cond, cs in curves.items():
            table = tables.setdefault(cond, {"condition": cond, "phase": phase})
            table[f"{prefix}mean"], table[f"{prefix}sd"] = _mean_sd(cs)
            table.setdefault("n", len(cs))
        del curves
    rows = [pd.DataFrame(table) for table in tables.values()]
    return pd.concat(rows, ignore_index=True)[
        ["condition", "phase", "mean", "sd", "n", "transport_mean", "transport_sd", "grip_mean",
         "grip_sd"]]


def aperture_profiles(recognitions: Sequence[ClipSummary], conditions: list[str]
                      ) -> pd.DataFrame:
    """Mean ± SD observed grip aperture per condition over normalised movement time.

    Parameters
    ----------
    recognitions : sequence of ClipSummary
        Scored clips (read once).
    conditions : list of str
        Condition of each clip.

    Returns
    -------
    pandas.DataFrame
        Columns: condition, phase (0..1), mean, sd (m), n.
    """
    phase = np.linspace(0, 1, PROFILE_POINTS)

    def curve(rec: ClipSummary) -> np.ndarray | None:
        g = rec.aperture
        ok = np.isfinite(g)
        return np.interp(phase, _phase(rec)[ok], g[ok]) if ok.sum() >= 2 else None

    curves, order = stacked_curves(recognitions, conditions, curve)
    rows = []
    for cond in order:
        mean, sd = _mean_sd(curves[cond])
        rows.append(pd.DataFrame({"condition": cond, "phase": phase, "mean": mean, "sd": sd,
                                  "n": len(curves[cond])}))
    return (pd.concat(rows, ignore_index=True) if rows
            else pd.DataFrame(columns=["condition", "phase", "mean", "sd", "n"]))


def _hedges_g(a: np.ndarray, b: np.ndarray) -> float:
    """Hedges' g of a - b (pooled SD, small-sample correction); scipy.stats has none."""
    na, nb = len(a), len(b)
    pooled = np.sqrt(((na - 1) * a.var(ddof=1) + (nb - 1) * b.var(ddof=1)) / (na + nb - 2))
    if not pooled > 0:
        return float("nan")
    return float((a.mean() - b.mean()) / pooled * (1 - 3 / (4 * (na + nb) - 9)))


def _eta_squared(groups: Sequence[np.ndarray]) -> float:
    """Share of the variance between groups (one-way ANOVA's eta squared)."""
    everything = np.concatenate(groups)
    total = ((everything - everything.mean()) ** 2).sum()
    between = sum(len(g) * (g.mean() - everything.mean()) ** 2 for g in groups)
    return float(between / total) if total > 0 else float("nan")


#: Fewer clips than this in a group: its test is flagged in ``note``.
_FEW_CLIPS = 3

_STAT_COLUMNS = ["model", "test", "groups", "n", "statistic_type", "statistic", "df",
                 "p_value", "mean_difference", "effect_size_type", "effect_size",
                 "n_per_group", "note"]


def _sizes(groups: dict[str, np.ndarray]) -> dict:
    """The ``n_per_group`` and ``note`` cells of a test of ``groups``."""
    few = min(len(v) for v in groups.values()) < _FEW_CLIPS
    return {"n_per_group": ", ".join(f"{c}={len(v)}" for c, v in groups.items()),
            "note": f"a group has fewer than {_FEW_CLIPS} clips" if few else ""}


def condition_statistics(summary: pd.DataFrame, model: str) -> pd.DataFrame:
    """Compare final confidence of ``model`` between conditions.

    One-way ANOVA (``scipy.stats.f_oneway``) across all conditions with at
    least 2 scored clips and a Welch t-test (``scipy.stats.ttest_ind`` with
    ``equal_var=False``) for each pair of them (:func:`plain_tests`).

    Parameters
    ----------
    summary : pandas.DataFrame
        Batch summary with ``condition``, ``status`` and ``conf_<model>`` columns.
    model : str
        Model compared.

    Returns
    -------
    pandas.DataFrame
        Columns: model, test, groups, n, statistic_type (``F`` or ``t``),
        statistic, df (``k-1, n-k`` for F; Welch's for t), p_value,
        mean_difference (t-tests, m), effect_size_type (``eta^2`` or
        ``Hedges' g``), effect_size, n_per_group (``a=10, b=3``) and note
        (``a group has fewer than 3 clips``, or empty).
    """
    col = f"conf_{model}"
    ok = summary[(summary["status"] == "ok") & summary["condition"].notna()]
    groups = {c: g[col].to_numpy(float) for c, g in ok.groupby("condition", sort=False)}
    return pd.DataFrame(plain_tests(groups), columns=_STAT_COLUMNS[1:]).assign(model=model)[
        _STAT_COLUMNS]


def plain_tests(groups: dict[str, np.ndarray]) -> list[dict]:
    """The one-way ANOVA across the groups of 2 or more values and a Welch t-test per pair.

    Parameters
    ----------
    groups : dict of str to array
        The values of each condition.

    Returns
    -------
    list of dict
        One per test: the :func:`condition_statistics` columns, and ``se``
        (of a t-test's mean difference), ``df1``, ``df2`` (F's; t's in ``df1``).
    """
    import warnings

    from scipy import stats  # here: a second of import, only for batches with conditions

    testable = {c: v for c, v in groups.items() if len(v) >= 2}
    rows = []
    with warnings.catch_warnings():
        # a constant group gives NaN or inf, as the table shows; no warning on stderr
        warnings.simplefilter("ignore", RuntimeWarning)
        if len(testable) >= 2:
            r = stats.f_oneway(*testable.values())
            k, n = len(testable), sum(len(v) for v in testable.values())
            rows.append({"test": "one-way ANOVA", "groups": " / ".join(testable), "n": n,
                         "statistic_type": "F", "statistic": float(r.statistic),
                         "df": f"{k - 1}, {n - k}", "df1": k - 1, "df2": n - k,
                         "p_value": float(r.pvalue), "mean_difference": np.nan,
                         "se": np.nan, "effect_size_type": "eta^2",
                         "effect_size": _eta_squared(list(testable.values())),
                         **_sizes(testable)})
        names = list(testable)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                x, y = testable[a], testable[b]
                r = stats.ttest_ind(x, y, equal_var=False)
                rows.append({"test": "Welch t-test", "groups": f"{a} vs {b}",
                             "n": len(x) + len(y), "statistic_type": "t",
                             "statistic": float(r.statistic), "df": f"{r.df:.1f}",
                             "df1": float(r.df), "df2": np.nan, "p_value": float(r.pvalue),
                             "mean_difference": float(x.mean() - y.mean()),
                             "se": float(np.sqrt(x.var(ddof=1) / len(x)
                                                 + y.var(ddof=1) / len(y))),
                             "effect_size_type": "Hedges' g", "effect_size": _hedges_g(x, y),
                             **_sizes({a: x, b: y})})
    return rows


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


def reference_model(recs: list[ClipSummary], conditions: Sequence[str | None]) -> str | None:
    """The batch's reference grasp model: the best over its ``normal`` clips, or over all.

    Parameters
    ----------
    recs : list of ClipSummary
        Scored clips.
    conditions : sequence of str or None
        Their conditions.
    """
    normal = [r for r, c in zip(recs, conditions) if c == "normal"]
    return default_profile_model(normal or list(recs))


def typical_clips(recs: Sequence[ClipSummary], conditions: Sequence[str], model: str
                  ) -> tuple[list[ClipSummary], list[str]]:
    """One clip per condition: the one whose final confidence is the condition's median.

    Parameters
    ----------
    recs : sequence of ClipSummary
        Scored clips (each read once, the chosen ones again).
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose final confidence ranks them.
    """
    # each clip's final value read once, the chosen clips looked up again: a batch's
    # summaries are read back from disk, and a condition's group of them was every clip
    finals = [float(r.confidence[r.index(model), -1]) for r in recs]
    chosen, conds = [], []
    for cond in dict.fromkeys(conditions):
        group = [i for i, c in enumerate(conditions) if c == cond and i < len(finals)]
        final = np.array([finals[i] for i in group])
        chosen.append(recs[group[int(np.argsort(final)[(len(final) - 1) // 2])]])
        conds.append(cond)
    return chosen, conds


def model_aperture(model, *, trials: int = 100, cv: float = 0.01, seed: int = 0) -> pd.DataFrame:
    """A model's own grip aperture over its movement: mean ± SD of noisy executions.

    Parameters
    ----------
    model : MotorModel
        The model.
    trials : int
        Executions.
    cv : float
        Coefficient of variation of the command noise (the thesis's 1 %).
    seed : int
        Seed of the noise.

    Returns
    -------
    pandas.DataFrame
        Columns: phase (0..1 of the planned movement time), mean, sd (m).
    """
    from perception.recognition.rollout import rollout

    run = rollout([model], model.arm.horizon, trials=trials, cv=cv,
                  rng=np.random.default_rng(seed))
    g = run.aperture[0]
    phase = np.linspace(0, 1, PROFILE_POINTS)
    t = run.time / run.time[-1]
    curves = np.array([np.interp(phase, t, trial) for trial in g])
    return pd.DataFrame({"phase": phase, "mean": curves.mean(0), "sd": curves.std(0, ddof=1)})

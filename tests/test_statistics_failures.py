"""Statistics that know when they fail (issue 44, item 4): a degenerate mixed model is
flagged and replaced by a model the data support, with the reason in ``note``; a sound one
is statsmodels' own numbers."""

import warnings

import numpy as np
import pandas as pd
import pytest
import statsmodels.formula.api as smf

from perception.report.statistics import (
    ABSURD_SE_FACTOR,
    MIN_PARTICIPANTS,
    landmark_statistics,
    mixed_fit_problems,
)


def _design(n_participants: int, seed: int, *, participant_sd: float = 0.0,
            trials: int = 15) -> pd.DataFrame:
    """Movement times (ms) of ``n_participants`` x 2 conditions x ``trials``; the cell
    means of the issue (1324 and 1352 ms), a trial SD of 80 ms."""
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n_participants):
        offset = rng.normal(0, participant_sd) if participant_sd else 0.0
        for cond, mean in (("normal", 1324.0), ("delayed", 1352.0)):
            rows += [{"clip": f"p{i}-{cond}-{t}", "condition": cond, "participant": f"p{i}",
                      "measure": "movement_time", "unit": "ms",
                      "value": round(mean + offset + rng.normal(0, 80), 1)}
                     for t in range(trials)]
    return pd.DataFrame(rows)


def _by_hand(d: pd.DataFrame):
    """statsmodels run directly, warnings recorded, as a user would by hand."""
    d = d.assign(condition=pd.Categorical(d["condition"], ["normal", "delayed"]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = smf.mixedlm("value ~ condition", d, groups=d["participant"]).fit(reml=True)
    return fit, caught


def _quiet(data: pd.DataFrame) -> pd.DataFrame:
    """landmark_statistics, asserting that no warning reaches the console."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        table = landmark_statistics(data)
    assert [str(w.message) for w in caught] == []
    return table


def test_the_issue_degenerate_fit_is_caught_although_statsmodels_says_converged():
    # the fault of the issue: 2 participants x 2 conditions, "Converged: Yes", an
    # infinite log-likelihood, an intercept of ~1e-15 ms with an SE of ~1e9
    d = _design(2, seed=1)
    fit, caught = _by_hand(d)
    assert fit.converged and fit.llf == np.inf
    assert abs(fit.fe_params["Intercept"]) < 1e-10 and fit.bse["Intercept"] > 1e8
    problems = mixed_fit_problems(fit, caught, float(d["value"].std()))
    text = "; ".join(problems)
    assert "log-likelihood inf" in text
    assert "singular, boundary fit" in text
    assert f"SE over {ABSURD_SE_FACTOR:g} times the SD of the values" in text
    assert "statsmodels warned:" in text and "singular" in text


def test_two_participants_get_cell_means_with_the_reason():
    d = _design(2, seed=1)
    table = _quiet(d)
    assert list(table["method"]) == ["cell_means", "cell_means"]
    assert list(table["term"]) == ["mean[normal]", "mean[delayed]"]
    assert (table["note"] == f"2 participants: a random effect needs at least "
                             f"{MIN_PARTICIPANTS}; cell means only, no test").all()
    assert table["p_value"].isna().all() and table["se"].isna().all()
    # each participant counts once: the mean of the participants' cell means
    expected = d.groupby(["condition", "participant"])["value"].mean().groupby("condition").mean()
    np.testing.assert_allclose(table["estimate"], expected[["normal", "delayed"]], rtol=1e-12)
    assert list(table["n"]) == [30, 30] and list(table["n_participants"]) == [2, 2]
    # between 1300 and 1400 ms, not the 4.9e-15 of the degenerate fit
    assert ((table["estimate"] > 1300) & (table["estimate"] < 1400)).all()


def test_fewer_than_the_minimum_refuse_the_random_effect():
    table = _quiet(_design(MIN_PARTICIPANTS - 1, seed=2, participant_sd=100, trials=4))
    assert set(table["method"]) == {"cell_means"}
    assert table["note"].str.startswith(f"{MIN_PARTICIPANTS - 1} participants: a random "
                                        f"effect needs at least {MIN_PARTICIPANTS}").all()


def test_six_participants_fit_and_are_statsmodels_own_numbers():
    d = _design(6, seed=4, participant_sd=60, trials=5)
    fit, caught = _by_hand(d)
    assert mixed_fit_problems(fit, caught, float(d["value"].std())) == []
    rows = _quiet(d).set_index("term")
    assert list(rows.index) == ["Intercept", "condition[T.delayed]", "participant_variance",
                                "residual_variance"]
    assert (rows["method"] == "mixedlm").all() and (rows["note"] == "").all()
    fixed = rows.iloc[:2]
    for column, expected in (("estimate", fit.fe_params), ("se", fit.bse.iloc[:2]),
                             ("statistic", fit.tvalues.iloc[:2]),
                             ("p_value", fit.pvalues.iloc[:2])):
        np.testing.assert_allclose(fixed[column].to_numpy(float), expected.to_numpy(float),
                                   rtol=1e-6, atol=0, err_msg=column)
    np.testing.assert_allclose(rows.loc["participant_variance", "estimate"],
                               fit.cov_re.iloc[0, 0], rtol=1e-6)
    np.testing.assert_allclose(rows.loc["residual_variance", "estimate"], fit.scale, rtol=1e-6)
    assert (rows["n"] == 60).all() and (rows["n_participants"] == 6).all()
    assert (fixed["statistic_type"] == "z").all()


def test_a_boundary_fit_statsmodels_accepts_falls_back_to_cluster_robust_ols():
    # no participant variance in the data: statsmodels converges without a warning on a
    # participant variance under 1 % of the residual's
    d = _design(6, seed=15, trials=5)
    fit, caught = _by_hand(d)
    assert fit.converged and not [w for w in caught if "singular" in str(w.message)]
    assert fit.cov_re.iloc[0, 0] / fit.scale < 0.01
    rows = _quiet(d).set_index("term")
    assert (rows["method"] == "ols_cluster_robust").all()
    assert rows["note"].str.match(r"mixed model rejected: participant variance 0\.\d+% of "
                                  r"the residual variance \(under 1%: a singular, boundary "
                                  r"fit\)$").all()
    cat = d.assign(condition=pd.Categorical(d["condition"], ["normal", "delayed"]))
    ols = smf.ols("value ~ condition", cat).fit(
        cov_type="cluster", cov_kwds={"groups": pd.factorize(cat["participant"])[0]},
        use_t=True)
    for column, expected in (("estimate", ols.params), ("se", ols.bse),
                             ("statistic", ols.tvalues), ("p_value", ols.pvalues)):
        np.testing.assert_allclose(rows[column].to_numpy(float), expected.to_numpy(float),
                                   rtol=1e-9, err_msg=column)
    assert (rows["df1"] == 5).all() and (rows["statistic_type"] == "t").all()
    # the clustered SE is not the naive one that takes 60 trials as independent
    naive = smf.ols("value ~ condition", cat).fit()
    assert not np.allclose(rows["se"].to_numpy(float), naive.bse.to_numpy(float))


def test_when_the_robust_fit_fails_too_only_cell_means_remain():
    # one participant per condition: the participant is the condition, so neither a
    # random intercept nor participant-clustered errors can be estimated
    rng = np.random.default_rng(0)
    d = pd.DataFrame([{"clip": f"c{c}-{t}", "condition": f"c{c}", "participant": f"p{c}",
                       "measure": "mga", "unit": "mm", "value": 100 + c + rng.normal(0, 2)}
                      for c in range(MIN_PARTICIPANTS) for t in range(3)])
    table = _quiet(d)
    assert set(table["method"]) == {"cell_means"} and len(table) == MIN_PARTICIPANTS
    note = table["note"].iloc[0]
    assert note.startswith("mixed model rejected: ")
    assert "; cluster-robust fit rejected: SE not finite or zero (" in note
    assert note.endswith("; cell means only, no test")
    assert table["p_value"].isna().all()


@pytest.mark.parametrize("values", [[1.0] * 4, [np.nan] * 4])
def test_degenerate_values_never_reach_a_fit(values):
    d = _design(6, seed=3, trials=2)
    d = d.assign(value=np.resize(values, len(d)))
    table = _quiet(d)
    assert "mixedlm" not in set(table["method"])

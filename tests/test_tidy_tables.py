"""Tidy batch tables (issue 34): the manifest's columns everywhere, R-safe names, the long
landmarks.csv, per-participant means and mixed models, checked against statsmodels itself."""

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _demos import default_repertoire, demo_tracks
from _reports import disk_full_at
from scipy import stats

from perception.batch import discover, run_batch
from perception.report.statistics import landmark_statistics
from perception.report.tables import LANDMARK_UNITS, TABLES, r_name

SAFE = re.compile(r"^[a-z][a-z0-9_]*$")
#: 3 participants x 2 conditions x 2 trials; each participant moves at their own speed
PARTICIPANTS = {"p1": 0.9, "p2": 1.0, "p3": 1.15}


@pytest.fixture(scope="module")
def batch(tmp_path_factory):
    src = tmp_path_factory.mktemp("src")
    rows, seed = [], 0
    for who, duration in PARTICIPANTS.items():
        for cond in ("normal", "delayed"):
            for trial in (1, 2):
                name = f"{who}-{cond}-{trial}"
                demo_tracks(cond, seed, duration=duration)[0].save(src / f"{name}.tracks.h5")
                seed += 1
                rows.append({"clip": name, "condition": cond, "video": f"{name}.tracks.h5",
                             "participant": who, "session": f"s{trial}",
                             "Age group": "young" if who != "p3" else "old"})
    pd.DataFrame(rows).to_csv(src / "manifest.csv", index=False)
    out = tmp_path_factory.mktemp("report")
    summary = run_batch(discover(src / "manifest.csv"), out, default_repertoire(), quiet=True)
    return src, out, summary


def test_the_manifest_columns_reach_the_summary_and_every_table(batch):
    src, out, summary = batch
    manifest = pd.read_csv(src / "manifest.csv", dtype=str).set_index("clip")
    s = pd.read_csv(out / "summary.csv", dtype={"session": str})
    assert list(s.columns[:7]) == ["clip", "condition", "participant", "session", "Age group",
                                   "age_group", "winner"]
    s = s.set_index("clip")
    assert (s["participant"] == manifest.loc[s.index, "participant"]).all()
    landmarks = pd.read_csv(out / "landmarks.csv")
    assert list(landmarks.columns) == ["clip", "condition", "participant", "session",
                                       "age_group", "landmark", "value", "unit"]
    by_clip = landmarks.drop_duplicates("clip").set_index("clip")
    assert (by_clip["age_group"] == manifest["Age group"].loc[by_clip.index]).all()
    means = pd.read_csv(out / "participant_means.csv")
    assert list(means.columns) == ["measure", "unit", "participant", "condition", "n", "mean",
                                   "sd"]


def test_a_resumed_batch_keeps_the_manifest_columns(batch, tmp_path):
    src, out, summary = batch
    again = tmp_path / "again"
    shutil.copytree(out, again)
    rerun = run_batch(discover(src / "manifest.csv"), again, default_repertoire(), quiet=True)
    assert rerun["reused"].all()
    pd.testing.assert_frame_equal(rerun.drop(columns="reused"), summary.drop(columns="reused"))
    for name in TABLES:
        assert (again / name).read_bytes() == (out / name).read_bytes(), name


def test_landmarks_csv_is_long_in_lab_units(batch):
    _, out, summary = batch
    table = pd.read_csv(out / "landmarks.csv")
    assert len(table) == len(summary) * len(LANDMARK_UNITS)
    wide = table.pivot(index="clip", columns="landmark", values="value")
    si = summary.set_index("clip")
    for name, scale in (("movement_time", 1e3), ("peak_speed", 1e3), ("mga", 1e3),
                        ("peak_speed_time", 100), ("mga_time", 100), ("aperture_peaks", 1)):
        np.testing.assert_allclose(wide[name], si.loc[wide.index, name].astype(float) * scale,
                                   rtol=1e-12)
    observed = json.loads((out / "p2-normal-1.recognition.json").read_text())[
        "kinematics"]["observed"]
    row = wide.loc["p2-normal-1"]
    assert row["time_to_mga"] == pytest.approx(observed["mga_seconds"] * 1e3, rel=1e-12)
    assert row["opening"] == pytest.approx(observed["opening"] * 1e3, rel=1e-12)
    assert row["closing_time"] == pytest.approx(observed["closing_time"] * 1e3, rel=1e-12)
    units = table.drop_duplicates("landmark").set_index("landmark")["unit"]
    assert units.to_dict() == LANDMARK_UNITS
    assert set(LANDMARK_UNITS.values()) == {"ms", "mm", "mm/s", "%", "count"}


def test_every_name_loads_unquoted_and_the_summary_has_aliases(batch):
    _, out, summary = batch
    for name in TABLES:
        table = pd.read_csv(out / name)
        assert all(SAFE.match(c) for c in table.columns), (name, list(table.columns))
    assert all(SAFE.match(n) for n in pd.read_csv(out / "landmarks.csv")["landmark"])
    assert all(SAFE.match(n) for n in pd.read_csv(out / "landmark_statistics.csv")["measure"])
    cols = list(summary.columns)
    for c in cols:
        if not SAFE.match(c):  # e.g. conf_grasp-0.5s: its alias beside it, the same values
            alias = cols[cols.index(c) + 1]
            assert alias == r_name(c) and SAFE.match(alias)
            pd.testing.assert_series_equal(summary[alias], summary[c], check_names=False)
    assert "conf_grasp-0.5s" in cols and "conf_grasp_0_5s" in cols


@pytest.mark.skipif(shutil.which("Rscript") is None, reason="R is not installed")
def test_r_reads_every_table_as_it_is(batch):
    _, out, _ = batch
    for name in ("summary.csv", *TABLES):
        script = (f"d <- read.csv('{out / name}'); cat(nrow(d), '\\n'); "
                  "cat(names(d), sep='\\n'); "
                  "if (!is.null(d$value)) stopifnot(is.numeric(d$value))")
        r = subprocess.run(["Rscript", "-e", script], capture_output=True, text=True,
                           check=True)
        rows, *names = r.stdout.split("\n")
        table = pd.read_csv(out / name)
        assert int(rows) == len(table), name
        safe = [c for c in table.columns if SAFE.match(c)]
        assert [n for n in names if n in safe] == safe, name  # R kept them as they are
        if name != "summary.csv":
            assert names[:len(table.columns)] == list(table.columns), name


def _measure(out: Path, measure: str) -> pd.DataFrame:
    landmarks = pd.read_csv(out / "landmarks.csv")
    if measure == "reference_confidence":
        s = pd.read_csv(out / "summary.csv").set_index("clip")
        d = landmarks.drop_duplicates("clip").assign(
            value=lambda d: s.loc[d["clip"], "reference_confidence"].to_numpy() * 1e3)
    else:
        d = landmarks[landmarks["landmark"] == measure]
    return d.dropna(subset=["value"]).reset_index(drop=True)


@pytest.mark.filterwarnings("ignore::statsmodels.tools.sm_exceptions.ConvergenceWarning")
def test_mixed_models_are_statsmodels_own_numbers(batch):
    import statsmodels.formula.api as smf

    _, out, _ = batch
    table = pd.read_csv(out / "landmark_statistics.csv", keep_default_na=False,
                        na_values=[""])
    mixed = table[table["method"] == "mixedlm"]
    assert {"movement_time", "mga", "mga_time", "reference_confidence"} <= set(mixed["measure"])
    for measure in ("movement_time", "mga", "opening_time", "reference_confidence"):
        d = _measure(out, measure)
        fit = smf.mixedlm("value ~ C(condition, Treatment('normal'))", d,
                          groups=d["participant"]).fit(reml=True)
        rows = mixed[mixed["measure"] == measure].set_index("term")
        assert list(rows.index) == ["Intercept", "condition[T.delayed]",
                                    "participant_variance", "residual_variance"]
        fixed = rows.iloc[:2]
        for column, expected in (("estimate", fit.fe_params), ("se", fit.bse.iloc[:2]),
                                 ("statistic", fit.tvalues.iloc[:2]),
                                 ("p_value", fit.pvalues.iloc[:2])):
            np.testing.assert_allclose(fixed[column], expected, rtol=1e-9, atol=1e-300,
                                       err_msg=f"{measure} {column}")
        np.testing.assert_allclose(rows.loc["participant_variance", "estimate"],
                                   fit.cov_re.iloc[0, 0], rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(rows.loc["residual_variance", "estimate"], fit.scale,
                                   rtol=1e-9)
        assert (rows["n"] == 12).all() and (rows["n_participants"] == 3).all()
        assert (fixed["statistic_type"] == "z").all()
    # the participants' own speeds are in the movement time's participant variance
    mt = mixed[(mixed["measure"] == "movement_time")].set_index("term")
    assert mt.loc["participant_variance", "estimate"] > mt.loc["residual_variance", "estimate"]


def test_participant_means_give_n_per_cell(batch):
    _, out, _ = batch
    means = pd.read_csv(out / "participant_means.csv")
    landmarks = pd.read_csv(out / "landmarks.csv").dropna(subset=["value"])
    mga = means[means["measure"] == "mga"].set_index(["participant", "condition"])
    expected = landmarks[landmarks["landmark"] == "mga"].groupby(
        ["participant", "condition"])["value"].agg(["count", "mean", "std"])
    assert len(mga) == 6 and (mga["n"] == 2).all()
    np.testing.assert_allclose(mga.loc[expected.index, "mean"], expected["mean"], rtol=1e-12)
    np.testing.assert_allclose(mga.loc[expected.index, "sd"], expected["std"], rtol=1e-12)
    assert set(means["measure"]) == {*LANDMARK_UNITS, "reference_confidence"}


def test_statistics_csv_is_kept(batch):
    _, out, _ = batch
    assert list(pd.read_csv(out / "statistics.csv").columns) == [
        "model", "test", "groups", "n", "statistic_type", "statistic", "df", "p_value",
        "mean_difference", "effect_size_type", "effect_size", "n_per_group", "note"]


def _trials(participants):
    rng = np.random.default_rng(3)
    rows = [{"clip": f"c{i}", "condition": cond, "participant": who, "measure": "mga",
             "unit": "mm", "value": rng.normal(100 + 5 * (cond == "delayed"), 2)}
            for i, (who, cond) in enumerate(participants)]
    return pd.DataFrame(rows)


def test_without_participants_the_plain_tests_say_why():
    design = [(w, c) for w in ("a", "b") for c in ("normal", "delayed") for _ in range(3)]
    data = _trials(design)
    # no participant column: one-way ANOVA and Welch, scipy's own numbers
    plain = landmark_statistics(data.drop(columns="participant"))
    assert list(plain["method"]) == ["one_way_anova", "welch_t_test"]
    assert (plain["note"] == "no participant column in the manifest").all()
    x, y = (data.loc[data["condition"] == c, "value"].to_numpy() for c in ("normal", "delayed"))
    welch = stats.ttest_ind(x, y, equal_var=False)
    t = plain.iloc[1]
    assert (t["statistic"], t["p_value"], t["df1"]) == pytest.approx(
        (welch.statistic, welch.pvalue, welch.df), rel=1e-12)
    assert t["estimate"] == pytest.approx(x.mean() - y.mean())
    assert t["estimate"] / t["se"] == pytest.approx(welch.statistic, rel=1e-12)
    anova = plain.iloc[0]
    assert (anova["df1"], anova["df2"]) == (1, 10)
    # one participant with 2 trials or more: not enough for a mixed model
    one = landmark_statistics(_trials([("a", "normal"), ("a", "delayed"), ("b", "normal")]))
    assert set(one["method"]) == {"welch_t_test", "one_way_anova"} or one.empty
    lone = landmark_statistics(_trials([("a", "normal"), ("a", "normal"), ("a", "delayed"),
                                        ("a", "delayed"), ("b", "normal")]))
    assert (lone["note"].str.startswith("fewer than 2 participants with 2 trials")).all()
    assert len(lone) == 2
    # two participants with two trials: the mixed model
    assert set(landmark_statistics(data)["method"]) == {"mixedlm"}
    flat = landmark_statistics(data.assign(value=1.0))
    assert (flat["method"] != "mixedlm").all()
    assert (flat["note"] == "the same value in every trial").all()


@pytest.mark.parametrize("fails", ["landmarks.csv", "landmark_statistics.csv"])
def test_the_tables_are_part_of_the_one_run_set(batch, tmp_path, monkeypatch, fails):
    src, out, _ = batch
    again = tmp_path / "again"
    shutil.copytree(out, again)
    disk_full_at(monkeypatch, fails)
    with pytest.raises(OSError, match="No space left"):
        run_batch(discover(src / "manifest.csv"), again, default_repertoire(), quiet=True)
    left = {"summary.csv", "statistics.csv", *TABLES} & {p.name for p in again.iterdir()}
    assert not left


def test_every_column_landmark_and_method_is_documented(batch):
    _, out, summary = batch
    doc = (Path(__file__).resolve().parents[1] / "docs" / "recognition.md").read_text()
    section = doc[doc.index("## 9. Batch outputs"):doc.index("## 10.")]
    spans = set(re.findall(r"`([^`]+)`", section))
    names = {*TABLES, *LANDMARK_UNITS, "reference_confidence", "mixedlm", "one_way_anova",
             "welch_t_test", "participant_variance", "residual_variance"}
    for name in TABLES:
        names |= {c for c in pd.read_csv(out / name).columns
                  if c not in ("participant", "session", "age_group")} | {"participant"}
    assert sorted(names - spans) == []
    assert set(LANDMARK_UNITS.values()) <= spans

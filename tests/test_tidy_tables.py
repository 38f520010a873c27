"""Tidy batch tables (issue 34): the manifest's columns everywhere, R-safe names, the long
landmarks.csv, per-participant means, and the statistics a design supports (issue 44)."""

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
from perception.report.statistics import MIN_PARTICIPANTS, landmark_statistics
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
    assert list(landmarks.columns) == ["clip", "trial", "condition", "participant", "session",
                                       "age_group", "trial_number", "reach_number",
                                       "landmark", "value", "unit", "clock", "flag", "status",
                                       "reason"]
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


def test_three_participants_get_cell_means_not_a_mixed_model(batch):
    # a random intercept needs MIN_PARTICIPANTS (the mixed model matching statsmodels run
    # by hand, and each fallback, are in test_statistics_failures.py)
    _, out, _ = batch
    table = pd.read_csv(out / "landmark_statistics.csv", keep_default_na=False,
                        na_values=[""])
    means = pd.read_csv(out / "participant_means.csv")
    assert {"movement_time", "mga", "mga_time", "reference_confidence"} <= set(table["measure"])
    assert set(table["method"]) == {"cell_means"}
    few = f"3 participants: a random effect needs at least {MIN_PARTICIPANTS}"
    assert set(table["note"]) <= {f"{few}; cell means only, no test",
                                  "the same value in every trial; cell means only, no test"}
    assert table["p_value"].isna().all()
    for measure in ("movement_time", "mga", "opening_time", "reference_confidence"):
        d = _measure(out, measure)
        rows = table[table["measure"] == measure].set_index("term")
        assert list(rows.index) == ["mean[normal]", "mean[delayed]"]
        assert rows["note"].str.startswith(few).all()
        # each participant counts once: the mean of participant_means.csv's means
        cells = means[means["measure"] == measure].groupby("condition")["mean"].mean()
        np.testing.assert_allclose(rows["estimate"], cells[["normal", "delayed"]], rtol=1e-9,
                                   err_msg=measure)
        assert list(rows["n"]) == [(d["condition"] == c).sum() for c in ("normal", "delayed")]
        assert (rows["n_participants"] == 3).all()


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
    # named participants, fewer than MIN_PARTICIPANTS: cell means, no test, and why
    for few_design in ([("a", "normal"), ("a", "delayed"), ("b", "normal")], design):
        few = landmark_statistics(_trials(few_design))
        assert set(few["method"]) == {"cell_means"}
        assert (few["note"] == f"2 participants: a random effect needs at least "
                               f"{MIN_PARTICIPANTS}; cell means only, no test").all()
    # enough participants, each at their own level: the mixed model
    many = _trials([(w, c) for w in "abcdef" for c in ("normal", "delayed") for _ in range(3)])
    levels = dict(zip("abcdef", (0, 3, -2, 5, -4, 1)))
    many["value"] += many["participant"].map(levels)
    assert set(landmark_statistics(many)["method"]) == {"mixedlm"}
    flat = landmark_statistics(many.assign(value=1.0))
    assert (flat["method"] != "mixedlm").all()
    assert (flat["method"] == "cell_means").all()
    assert (flat["note"] == "the same value in every trial; cell means only, no test").all()


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
             "welch_t_test", "participant_variance", "residual_variance",
             "ols_cluster_robust", "cell_means", "MIN_PARTICIPANTS"}
    for name in TABLES:
        names |= {c for c in pd.read_csv(out / name).columns
                  if c not in ("participant", "session", "age_group")} | {"participant"}
    assert sorted(names - spans) == []
    assert set(LANDMARK_UNITS.values()) <= spans


def test_summary_csv_is_in_the_landmark_tables_units_and_says_so(batch):
    # one unit convention for every landmark file (issue 44): summary.csv was SI (shares 0-1)
    _, out, summary = batch
    written = pd.read_csv(out / "summary.csv").set_index("clip")
    ok = summary[summary["status"] == "ok"].set_index("clip")
    for column, scale in (("movement_time", 1e3), ("peak_speed", 1e3), ("peak_speed_time", 100),
                          ("mga", 1e3), ("mga_time", 100)):
        np.testing.assert_allclose(written.loc[ok.index, column], ok[column] * scale, rtol=1e-9)
    units = json.loads((out / "summary.units.json").read_text())
    assert {units[c]["unit"] for c in ("movement_time", "peak_speed_time", "mga")} == \
        {"ms", "%", "mm"}
    long = pd.read_csv(out / "landmarks.csv")
    mt = long[long["landmark"] == "movement_time"].set_index("clip")["value"]
    np.testing.assert_allclose(mt.loc[ok.index], written.loc[ok.index, "movement_time"])

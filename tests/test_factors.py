"""A design's factors (issue 44): a long table's participant and condition columns, a file
name's factors and the trial's own number reach every reach, unscored entry and batch row."""

import argparse
import logging

import numpy as np
import pandas as pd
import pytest

from hammer_mv.cli import main
from hammer_mv.cli.options import add_mocap_options, mocap_import
from perception.batch import ClipResult, summary_table
from perception.discovery import BatchItem, expand_recordings
from perception.errors import InputError
from perception.factors import DEFAULT_FACTORS, merge_factors, name_factors, name_pattern
from perception.io.mocap import read_mocap
from perception.pipeline import RecognitionSettings
from perception.reaches import Reach, Unscored
from perception.recordings import MocapImport, read_recording

RATE = 100.0
HEADER = ["trial", "participant", "condition", "block", "thumb_x", "thumb_y", "thumb_z",
          "index_x", "index_y", "index_z"]


def _reach(still: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """A 2 s trial's grip midpoint height and aperture, mm: a 0.8 s reach of 300 mm."""
    t = np.arange(0, 2.0, 1 / RATE)
    s = np.clip((t - 0.5) / 0.8, 0, 1)
    lift = 0 * s if still else 300 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    return lift, 20 + 60 * np.sin(np.pi * s)


def write_table(path, ids=("38", "39", "40", "41"), participants=("P01", "P01", "P02", "P02"),
                conditions=("near", "far", "near", "far"), blocks=(1, 1, 2, 2), still=(),
                vary_condition_in=None, header=HEADER):
    """A long table of 4 trials: text participant and condition columns, a numeric block."""
    lines = ["\t".join(header)]
    for k, tid in enumerate(ids):
        y, ap = _reach(still=k in still)
        for i in range(len(y)):
            cond = "other" if k == vary_condition_in and i > 100 else conditions[k]
            cells = [tid, participants[k], cond, str(blocks[k]), f"{-ap[i] / 2:.3f}",
                     f"{y[i]:.3f}", "0", f"{ap[i] / 2:.3f}", f"{y[i]:.3f}", "0"]
            lines.append("\t".join(cells if "trial" in header else cells[1:]))
    path.write_text("\n".join(lines) + "\n")
    return path


# --- 1. the readers keep factor columns per trial -------------------------------------

def test_text_columns_named_as_default_factors_are_each_trials_factors(tmp_path):
    trials = read_mocap(write_table(tmp_path / "t.tsv"), rate=RATE)
    assert [t.trial_number for t in trials] == ["38", "39", "40", "41"]
    assert [dict(t.factors) for t in trials] == [
        {"participant": "P01", "condition": "near", "block": "1"},
        {"participant": "P01", "condition": "far", "block": "1"},
        {"participant": "P02", "condition": "near", "block": "2"},
        {"participant": "P02", "condition": "far", "block": "2"}]
    assert not any("not numeric" in n for n in trials[0].notes)
    assert set(DEFAULT_FACTORS) >= {"participant", "condition", "session", "block"}


def test_a_default_factor_is_found_whatever_its_case(tmp_path):
    header = ["trial", "Participant", "CONDITION", *HEADER[3:]]
    trials = read_mocap(write_table(tmp_path / "t.tsv", header=header), rate=RATE)
    assert dict(trials[2].factors) == {"Participant": "P02", "CONDITION": "near", "block": "2"}


def test_a_column_named_in_factors_is_read_text_or_numbers(tmp_path):
    path = write_table(tmp_path / "t.tsv", header=["trial", "age", *HEADER[2:]],
                       participants=("21", "21", "34.5", "34.5"))
    trials = read_mocap(path, rate=RATE, factors="age,block")
    assert [t.factors["age"] for t in trials] == ["21", "21", "34.5", "34.5"]
    assert [t.factors["block"] for t in trials] == ["1", "1", "2", "2"]  # as written, not 1.0
    assert "age" not in read_mocap(path, rate=RATE)[0].factors  # not a default name


def test_a_factor_named_that_varies_within_a_trial_is_refused(tmp_path):
    path = write_table(tmp_path / "t.tsv", vary_condition_in=1)
    with pytest.raises(InputError, match=r"column 'condition' changes within a trial "
                                         r"\('far' then 'other' at data row 302, trial 2\)") as e:
        read_mocap(path, rate=RATE, factors=["condition"])
    assert e.value.field == "factors"
    assert "t.tsv" in str(e.value)


def test_a_default_factor_that_varies_within_a_trial_is_not_taken_and_said(tmp_path):
    trials = read_mocap(write_table(tmp_path / "t.tsv", vary_condition_in=1), rate=RATE)
    assert all("condition" not in t.factors for t in trials)
    assert trials[0].factors["participant"] == "P01"
    assert any("'condition' changes within a trial" in n and "not read as a factor" in n
               for n in trials[0].notes)


def test_a_factor_named_that_the_table_lacks_is_refused_naming_its_columns(tmp_path):
    with pytest.raises(InputError, match=r"no column 'subject' .*'participant', 'condition'"):
        read_mocap(write_table(tmp_path / "t.tsv"), rate=RATE, factors=("subject",))


def test_a_file_without_a_trial_column_is_trial_1(tmp_path):
    (trial,) = read_mocap(write_table(tmp_path / "t.tsv", ids=("1",), header=HEADER[1:]),
                          rate=RATE)
    assert trial.trial_number == "1"
    assert dict(trial.factors) == {"participant": "P01", "condition": "near", "block": "1"}


def test_factors_of_a_layout_without_columns_are_refused(tmp_path):
    path = tmp_path / "h.txt"
    path.write_text("1 2 3 4 5 6\n1 2 3 4 5 6\n")
    with pytest.raises(InputError, match="no columns to read factors from") as e:
        read_mocap(path, rate=RATE, columns="thumb,index", factors="participant")
    assert e.value.field == "factors"


def test_a_trial_keeps_its_factors_through_pickling(tmp_path):
    import pickle

    (trial, *_) = read_mocap(write_table(tmp_path / "t.tsv"), rate=RATE)
    back = pickle.loads(pickle.dumps(trial))
    assert dict(back.factors) == dict(trial.factors) and back.trial_number == "38"


# --- 2. reaches and unscored entries carry them ------------------------------------------

def test_each_reach_and_unscored_entry_carries_factors_and_numbers(tmp_path):
    rec = read_recording(write_table(tmp_path / "t.tsv", still=(1,)), MocapImport(rate=RATE))
    assert len(rec.trials) == 4 and len(rec.entries) == 4
    by_trial = {e.trial_number: e for e in rec.entries}
    assert isinstance(by_trial["39"], Unscored) and by_trial["39"].status == "no reach"
    assert dict(by_trial["39"].factors) == {"participant": "P01", "condition": "far",
                                            "block": "1"}
    assert by_trial["39"].reach_number is None
    reach = by_trial["40"]
    assert isinstance(reach, Reach) and reach.reach_number == 1
    assert dict(reach.factors) == {"participant": "P02", "condition": "near", "block": "2"}
    assert reach.name == "t-trial40"  # the name stays as it was


# --- 3. factors from a file's name --------------------------------------------------------

def test_name_factors_are_the_named_groups_searched_in_the_stem(caplog):
    pattern = r"(?P<participant>P\d+)_(?P<condition>[a-z]+)"
    assert name_factors(pattern, "/data/P07_fast.tsv") == {"participant": "P07",
                                                           "condition": "fast"}
    assert name_factors(None, "P07_fast.tsv") == {}
    with caplog.at_level(logging.WARNING, logger="perception.factors"):
        assert name_factors(pattern, "pilot.tsv") is None
    assert "does not match the file name 'pilot'" in caplog.text


@pytest.mark.parametrize("bad, said", [("(?P<p>", "not a regular expression"),
                                       (r"P\d+", "no named group")])
def test_a_bad_name_pattern_is_refused_naming_the_flag(bad, said):
    with pytest.raises(InputError, match=said) as e:
        name_pattern(bad)
    assert e.value.field == "factors_from_name"
    with pytest.raises(InputError) as e:
        MocapImport(factors_from_name=bad)
    assert e.value.field.endswith("factors_from_name")


def test_a_file_the_pattern_misses_keeps_its_rows_without_name_factors(tmp_path):
    rec = read_recording(write_table(tmp_path / "pilot.tsv"),
                         MocapImport(rate=RATE, factors_from_name=r"(?P<session>S\d+)"))
    assert len(rec.entries) == 4
    assert all("session" not in e.factors for e in rec.entries)


def test_name_factors_join_the_columns_on_every_row(tmp_path):
    rec = read_recording(write_table(tmp_path / "P01_S2.tsv", participants=("P01",) * 4),
                         MocapImport(rate=RATE, factors_from_name=r"(?P<participant>P\d+)_"
                                                                  r"(?P<session>S\d)"))
    assert [dict(e.factors)["session"] for e in rec.entries] == ["S2"] * 4
    assert all(e.factors["participant"] == "P01" for e in rec.entries)


# --- 4. merging ---------------------------------------------------------------------------

def test_a_factor_two_sources_disagree_on_is_refused_naming_both(tmp_path):
    assert merge_factors([("a", {"x": "1"}), ("b", {"x": "1", "y": "2"})]) == {"x": "1",
                                                                               "y": "2"}
    path = write_table(tmp_path / "P09_x.tsv")
    with pytest.raises(InputError, match=r"factor 'participant' is 'P01' in the table's "
                                         r"columns and 'P09' in the file name"):
        read_recording(path, MocapImport(rate=RATE,
                                         factors_from_name=r"(?P<participant>P\d+)"))


def test_a_manifest_that_disagrees_with_a_trials_column_is_refused(tmp_path):
    path = write_table(tmp_path / "t.tsv")
    settings = RecognitionSettings(mocap=MocapImport(rate=RATE))
    with pytest.raises(InputError, match=r"'condition' is 'near' in the manifest and 'far' "
                                         r"in t.tsv's trial columns"):
        expand_recordings([BatchItem("t", path, "mocap", "near")], settings)
    same = write_table(tmp_path / "same.tsv", conditions=("near",) * 4)
    agree = expand_recordings([BatchItem("same", same, "mocap", "near")], settings)
    assert [i.condition for i in agree] == ["near"] * 4


def test_a_recordings_items_carry_condition_factors_and_numbers(tmp_path):
    path = write_table(tmp_path / "t.tsv", still=(3,))
    items = expand_recordings([BatchItem("t", path, "mocap", factors=(("site", "lyon"),))],
                              RecognitionSettings(mocap=MocapImport(rate=RATE)))
    assert [i.condition for i in items] == ["near", "far", "near", "far"]
    assert [dict(i.factors) for i in items][2] == {"site": "lyon", "participant": "P02",
                                                   "block": "2"}
    assert [(i.trial_number, i.reach_number) for i in items] == [
        ("38", 1), ("39", 1), ("40", 1), ("41", None)]
    assert items[3].unscored is not None


def test_summary_puts_factors_and_numbers_between_condition_and_winner():
    results = [ClipResult("t-trial38", "near", "no reach", factors=(("participant", "P01"),),
                          trial_number="38", reach_number=None),
               ClipResult("t-trial39", "far", "failed", factors=(("participant", "P02"),),
                          trial_number="39", reach_number=2)]
    table = summary_table(results)
    cols = list(table.columns)
    assert cols[:cols.index("winner")] == ["clip", "condition", "participant", "trial_number",
                                           "reach_number"]
    assert table["trial_number"].tolist() == ["38", "39"]
    assert str(table["reach_number"].dtype) == "Int64"
    from perception.report.tables import factor_columns

    assert factor_columns(table) == ["participant", "trial_number", "reach_number"]


# --- 6. the flags -------------------------------------------------------------------------

def test_the_flags_reach_mocap_import():
    p = argparse.ArgumentParser()
    add_mocap_options(p)
    args = p.parse_args(["--factors", "participant, block",
                         "--factors-from-name", r"(?P<site>[A-Z]+)_"])
    options = mocap_import(args)
    assert options.factors == ("participant", "block")
    assert options.factors_from_name == r"(?P<site>[A-Z]+)_"
    assert options.read_options()["factors"] == ("participant", "block")


@pytest.mark.parametrize("flag, value, said", [
    ("--factors-from-name", "(", "--factors-from-name: expected a regular expression"),
    ("--factors-from-name", "P1", "--factors-from-name: expected a regular expression with "
                                  "a named group"),
    ("--factors", "a,a", "--factors: expected each column named once")])
def test_a_bad_flag_is_one_line_and_exit_2(tmp_path, capsys, flag, value, said):
    path = write_table(tmp_path / "t.tsv")
    assert main(["landmarks", str(path), "--rate", "100", flag, value,
                 "-o", str(tmp_path / "l.csv")]) == 2
    assert said in capsys.readouterr().err


# --- 5. end to end: batch -----------------------------------------------------------------

def test_batch_of_a_long_table_carries_its_factors_on_every_row(tmp_path):
    src = tmp_path / "in"
    src.mkdir()
    write_table(src / "P01_lab.tsv", participants=("P01",) * 4)
    out = tmp_path / "out"
    assert main(["batch", str(src), "-o", str(out), "--rate", "100", "--quiet",
                 "--factors-from-name", r"(?P<participant>P\d+)_(?P<site>[a-z]+)"]) == 0
    summary = pd.read_csv(out / "summary.csv", dtype={"trial_number": str})
    assert len(summary) == 4  # 4 trials in, 4 rows out
    cols = list(summary.columns)
    assert cols[:cols.index("winner")] == ["clip", "condition", "participant", "block", "site",
                                           "trial_number", "reach_number"]
    assert summary["participant"].tolist() == ["P01"] * 4
    assert summary["condition"].tolist() == ["near", "far", "near", "far"]
    assert summary["trial_number"].tolist() == ["38", "39", "40", "41"]
    assert summary["reach_number"].tolist() == [1] * 4
    assert summary["site"].tolist() == ["lab"] * 4
    landmarks = pd.read_csv(out / "landmarks.csv", dtype={"trial_number": str})
    assert {"participant", "site", "trial_number"} <= set(landmarks.columns)
    assert set(landmarks["trial_number"]) == {"38", "39", "40", "41"}
    means = pd.read_csv(out / "participant_means.csv")
    assert "participant" in means.columns and set(means["participant"]) == {"P01"}
    # a factor renamed labels the rows afresh and scores nothing again
    assert main(["batch", str(src), "-o", str(out), "--rate", "100", "--quiet",
                 "--factors-from-name", r"(?P<subject>P\d+)_(?P<site>[a-z]+)"]) == 0
    again = pd.read_csv(out / "summary.csv", dtype={"trial_number": str})
    assert again["reused"].all() and again["subject"].tolist() == ["P01"] * 4
    assert again["verdict"].tolist() == summary["verdict"].tolist()

"""Every trial of a recording accounted for: a result, or a row saying why not (issue 41).

A table of three trials is written from the real Optotrak trials
(tests/data/mocap/): two real grasps with, between them, a trial in which
the hand never moves. Each command must give the still trial a row with its
status and reason, print "N trials, M reaches scored, K not scored", list it,
go on to the trial after it, and exit 1. Trials in = rows out.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _cli import hammer_here
from _demos import default_repertoire

import hammer_mv.cli as cli
from perception.errors import InputError, PlanningError
from perception.landmarks import LandmarkParams, movement_landmarks, observed_landmarks
from perception.reaches import Reach, Unscored
from perception.recordings import MocapImport, read_recording

DATA = Path(__file__).parent / "data" / "mocap"
RATE = 85.0
STILL = "table-trial9"


def write_table(path: Path, trials=(0, 9, 1)) -> Path:
    """A long table of the real trials 0 and 1 and a still trial 9 (the hand at rest)."""
    real = pd.read_csv(DATA / "optotrak-trials.tsv", sep="\t")
    cols = ["trialN", *[f"{m}{a}raw" for m in ("index", "thumb") for a in "XYZ"]]
    real = real[cols]
    parts = []
    for t in trials:
        if t == 9:
            rest = real[real["trialN"] == 0].iloc[[5]]
            still = pd.concat([rest] * 200, ignore_index=True)
            jitter = np.random.default_rng(0).normal(0, 0.05, (200, 6))  # 0.05 mm noise
            still.iloc[:, 1:] = still.iloc[:, 1:].to_numpy() + jitter
            still["trialN"] = 9
            parts.append(still)
        else:
            parts.append(real[real["trialN"] == t])
    pd.concat(parts, ignore_index=True).to_csv(path, sep="\t", index=False, float_format="%.3f")
    return path


def hammer(*args, timeout=300):
    """``hammer-mv *args`` as a subprocess: for what the process shows (exit status 2 in one
    line); the lines and files of a command are tested in-process (:func:`hammer_here`)."""
    return subprocess.run([sys.executable, "-m", "hammer_mv", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    return write_table(tmp_path_factory.mktemp("rec") / "table.tsv")


def test_a_recording_gives_every_trial_a_reach_or_a_reason(table):
    rec = read_recording(table, MocapImport(rate=RATE))
    assert rec.trials == ("table-trial0", STILL, "table-trial1")
    kinds = [(type(e).__name__, e.name) for e in rec.entries]
    # file order: the still trial between the two reaches, the last trial still read
    assert kinds == [("Reach", "table-trial0"), ("Unscored", STILL), ("Reach", "table-trial1")]
    still = rec.unscored[0]
    assert still.status and still.reason and still.source == str(table)


def test_one_trial_whose_finder_fails_does_not_stop_the_trials_after_it(table, monkeypatch):
    import perception.recordings as recordings

    real = recordings.trial_reaches

    def flaky(trial, markers, params):
        if trial.name == "table-trial0":
            raise IndexError("index -253 is out of bounds")   # the crash
        return real(trial, markers, params)

    monkeypatch.setattr(recordings, "trial_reaches", flaky)
    rec = read_recording(table, MocapImport(rate=RATE))
    assert [e.name for e in rec.entries] == ["table-trial0", STILL, "table-trial1"]
    failed = rec.entries[0]
    assert isinstance(failed, Unscored) and failed.status == "failed"
    assert "IndexError" in failed.reason and "index -253" in failed.reason
    assert isinstance(rec.entries[2], Reach)


def test_a_missing_marker_is_still_the_whole_files_mistake(table):
    from perception.reaches import MarkerMap

    with pytest.raises(InputError, match="pinky"):
        read_recording(table, MocapImport(rate=RATE, markers=MarkerMap("thumb", "pinky")))


def test_recognize_writes_a_row_for_the_still_trial_lists_it_and_exits_1(table, tmp_path,
                                                                          capsys):
    out = tmp_path / "out"
    res = hammer_here(capsys, "recognize", table, "--rate", RATE, "-o", out, "--no-figures")
    assert res.returncode == 1, res.stderr
    assert "3 trials, 2 reaches scored, 1 not scored" in res.stdout
    listed = [line for line in res.stderr.splitlines() if "not scored" in line]
    assert len(listed) == 1 and listed[0].startswith(f"{STILL}: not scored: ")
    assert "Traceback" not in res.stderr
    # both real trials, the one after the still trial too, have their report
    assert sorted(p.name for p in out.glob("*.recognition.json")) == [
        "table-trial0.recognition.json", "table-trial1.recognition.json"]
    rows = pd.read_csv(out / "table.trials.csv", keep_default_na=False)
    assert list(rows["trial"]) == ["table-trial0", STILL, "table-trial1"]   # trials in = rows out
    assert list(rows["status"] == "ok") == [True, False, True]
    still = rows[rows["trial"] == STILL].iloc[0]
    assert still["reason"] and still["verdict"] == "" and still["report"] == ""
    scored = rows[rows["status"] == "ok"]
    assert (scored["verdict"] != "").all()
    assert list(scored["report"]) == ["table-trial0.recognition.json",
                                      "table-trial1.recognition.json"]


def test_recognize_quiet_still_lists_what_was_not_scored(table, tmp_path, capsys):
    res = hammer_here(capsys, "recognize", table, "--rate", RATE, "-o", tmp_path / "out",
                      "--no-figures", "--quiet")
    assert res.returncode == 1 and res.stdout == ""
    assert f"{STILL}: not scored: " in res.stderr


def test_recognize_exits_0_when_every_trial_is_scored(tmp_path, capsys):
    table = write_table(tmp_path / "good.tsv", trials=(0, 1))
    res = hammer_here(capsys, "recognize", table, "--rate", RATE, "-o", tmp_path / "out",
                      "--no-figures")
    assert res.returncode == 0, res.stderr
    assert "2 trials, 2 reaches scored, 0 not scored" in res.stdout
    assert "not scored:" not in res.stderr


def test_a_reach_that_cannot_be_planned_does_not_take_the_following_ones(table, tmp_path,
                                                                         monkeypatch, capsys):
    import perception.recordings as recordings

    real = recordings.recognize_reach

    def unplannable(reach, *args, **kwargs):
        if reach.name == "table-trial0":
            raise PlanningError("the scene cannot be planned for (a stand-in)")
        return real(reach, *args, **kwargs)

    monkeypatch.setattr(recordings, "recognize_reach", unplannable)
    out = tmp_path / "out"
    code = cli.main(["recognize", str(table), "--rate", str(RATE), "-o", str(out),
                     "--no-figures"])
    err = capsys.readouterr().err
    assert code == 1
    assert "table-trial0: not scored: failed: the scene cannot be planned" in err
    rows = pd.read_csv(out / "table.trials.csv", keep_default_na=False)
    status = dict(zip(rows["trial"], rows["status"]))
    assert (status["table-trial0"], status["table-trial1"]) == ("failed", "ok")
    assert (out / "table-trial1.recognition.json").is_file()
    assert not (out / "table-trial0.recognition.json").exists()


def test_landmarks_writes_the_still_trial_with_its_status_reason_and_nan(table, tmp_path, capsys):
    out = tmp_path / "lm.csv"
    res = hammer_here(capsys, "landmarks", table, "--rate", RATE, "-o", out, "--wide")
    assert res.returncode == 1, res.stderr
    assert "3 trials, 2 reaches scored, 1 not scored" in res.stdout
    assert f"{STILL}: not scored: " in res.stderr
    rows = pd.read_csv(out)
    assert list(rows["trial"]) == ["table-trial0", STILL, "table-trial1"]
    still = rows.iloc[1]
    assert isinstance(still["reason"], str) and still["reason"]
    assert still["status"] != "complete"
    assert math.isnan(still["movement_time"]) and math.isnan(still["mga"])
    assert rows.loc[[0, 2], "movement_time"].between(1000, 2500).all()  # ms
    assert rows.loc[[0, 2], "reason"].isna().all()
    # each scored row says which rule bounded it (the table dropped the column before)
    assert list(rows.loc[[0, 2], "bound"]) == ["5 % of peak speed"] * 2
    # the long table (the default): the still trial keeps its rows, flagged not scored
    res = hammer_here(capsys, "landmarks", table, "--rate", RATE, "-o", out)
    long = pd.read_csv(out, keep_default_na=False, na_values={"value": [""]})
    still = long[long["trial"] == STILL]
    assert len(still) and still["value"].isna().all()
    assert (still["flag"] == "not scored").all() and (still["reason"] != "").all()


def test_batch_has_a_row_for_every_trial_and_exits_1(table, tmp_path, capsys):
    folder = tmp_path / "session"
    folder.mkdir()
    (folder / "table.tsv").write_bytes(table.read_bytes())
    report = tmp_path / "report"
    res = hammer_here(capsys, "batch", folder, "-o", report, "--rate", RATE, "--quiet")
    assert res.returncode == 1, res.stderr
    assert f"{STILL}: not scored: " in res.stderr and "Traceback" not in res.stderr
    summary = pd.read_csv(report / "summary.csv", keep_default_na=False)
    assert sorted(summary["clip"]) == ["table-trial0", "table-trial1", STILL]   # in = out
    still = summary[summary["clip"] == STILL].iloc[0]
    assert still["status"] not in ("ok", "failed") and still["reason"]
    assert (summary.loc[summary["clip"] != STILL, "status"] == "ok").all()
    batch = json.loads((report / "batch.json").read_text())
    assert batch["trials"] == 3 and batch["ok"] == 2
    assert [u["clip"] for u in batch["not_scored"]] == [STILL]
    page = (report / "report.html").read_text()
    assert "Not scored (1)" in page and STILL in page


def test_batch_prints_the_trial_summary(tmp_path, capsys):
    folder = tmp_path / "session"
    folder.mkdir()
    write_table(folder / "table.tsv")
    res = hammer_here(capsys, "batch", folder, "-o", tmp_path / "report", "--rate", RATE)
    assert res.returncode == 1
    assert "3 trials, 2 reaches scored, 1 not scored" in res.stdout


# -- [verdict.landmarks] applies to motion capture as to video ----------------------------
def _rules(threshold: float):
    from perception.pipeline import RecognitionSettings
    from perception.recognition.rules import VerdictRules

    return RecognitionSettings(rules=VerdictRules(landmarks=LandmarkParams(threshold=threshold)))


def test_verdict_landmarks_threshold_sets_a_reachs_landmarks_as_a_videos(table):
    from perception.pipeline import recognize_tracks
    from perception.reaches import reach_tracks
    from perception.recordings import recognize_reach
    from perception.synthetic.demos import demo_tracks

    rep = default_repertoire()
    reach = read_recording(table, MocapImport(rate=RATE)).reaches[0]
    tracks, _ = demo_tracks("normal")
    for threshold in (0.05, 0.20):
        settings = _rules(threshold)
        params = LandmarkParams(threshold=threshold)
        rec, _ = recognize_reach(reach, rep, settings)
        # the reach: its 3D landmarks by the rules' definitions, on the report's clock
        rt = reach_tracks(reach)
        clock = rt.tracks.time - (rt.tracks.time[-1] - rec.observation.clip_time[-1])
        assert rec.landmarks[0] == movement_landmarks(clock, rt.transport, rt.aperture, params)
        # the video: its landmarks by the same rules
        video = recognize_tracks(tracks, rep, settings, clip="demo")
        assert video.landmarks[0] == observed_landmarks(video.observation, params)
        if threshold == 0.05:
            reach_5, video_5 = rec.landmarks[0], video.landmarks[0]
    # a higher bound, a shorter movement: for both sources alike
    assert rec.landmarks[0].movement_time < reach_5.movement_time - 0.05
    assert video.landmarks[0].movement_time < video_5.movement_time - 0.05


def test_verdict_rules_file_changes_the_reports_landmarks(tmp_path, capsys):
    table = write_table(tmp_path / "one.tsv", trials=(0,))
    rules = tmp_path / "rules.toml"
    rules.write_text("[verdict.landmarks]\nthreshold = 0.2\n")
    times = {}
    for name, extra in (("default", []), ("rules", ["--verdict-rules", rules])):
        out = tmp_path / name
        res = hammer_here(capsys, "recognize", table, "--rate", RATE, "-o", out, "--no-figures",
                          *extra)
        assert res.returncode == 0, res.stderr
        d = json.loads((out / "one-trial0.recognition.json").read_text())
        times[name] = d["kinematics"]["observed"]["movement_time"]
        if name == "rules":
            assert d["verdict_rules"]["landmarks"]["threshold"] == 0.2
    assert times["rules"] < times["default"] - 0.05


# -- MocapImport declared, and its flags ------------------------------------------------
@pytest.mark.parametrize("kwargs, field", [
    ({"rate": "85"}, "rate"), ({"rate": 0}, "rate"), ({"rate": 5000.0}, "rate"),
    ({"units": "in"}, "units"), ({"columns": ("thumb", "")}, "columns"),
    ({"columns": "thumb"}, "columns"), ({"columns": ()}, "columns"),
    ({"trial_column": 3}, "trial_column"), ({"time_column": 1}, "time_column"),
    ({"markers": "thumb"}, "markers"), ({"colums": ("a",)}, "colums"),
])
def test_mocap_import_refuses_bad_values_naming_the_field(kwargs, field):
    with pytest.raises(InputError) as err:
        MocapImport(**kwargs)
    assert err.value.location == ("MocapImport", field)


def test_mocap_import_takes_lists_and_is_a_hashable_value():
    a = MocapImport(rate=85, columns=["object", "thumb", "index"], time_column="none")
    assert a.columns == ("object", "thumb", "index") and a.rate == 85.0
    assert a == MocapImport(rate=85.0, columns=("object", "thumb", "index"), time_column="none")
    assert hash(a) == hash(MocapImport(rate=85.0, columns=("object", "thumb", "index"),
                                       time_column="none"))
    assert a.read_options()["columns"] == ("object", "thumb", "index")
    assert MocapImport().read_options()["columns"] is None


@pytest.mark.parametrize("command", ["recognize", "landmarks", "batch"])
def test_every_table_command_takes_columns_and_time_column(command):
    from hammer_mv.cli.options import mocap_import

    parser = cli.build_parser(command)
    args = parser.parse_args([command, "x.txt", "-o", "out", "--columns", "object,thumb,index",
                              "--time-column", "none", "--rate", "200"])
    options = mocap_import(args)
    assert options.columns == ("object", "thumb", "index")
    assert options.time_column == "none" and options.rate == 200.0


@pytest.mark.parametrize("flags, named", [
    (["--columns", "thumb,,index"], "--columns"), (["--rate", "-5"], "--rate"),
    (["--rate", "5000"], "--rate"), (["--object-size", "2"], "--object-size"),
    (["--object-size", "nan"], "--object-size"),
])
def test_a_bad_mocap_flag_is_one_line_naming_it(flags, named, table, tmp_path):
    res = hammer("landmarks", table, "-o", tmp_path / "lm.csv", *flags, timeout=120)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and named in res.stderr


def test_recognize_and_landmarks_find_the_same_reaches_in_a_session(tmp_path, capsys):
    # four real trials one after another, no trial column: a session. landmarks found its
    # movements while recognize refused it whole ("the wrist never leaves its rest
    # position"); both now take the same reaches, named and timed alike
    real = pd.read_csv(DATA / "optotrak-trials.tsv", sep="\t")
    cols = [f"{m}{a}raw" for m in ("index", "thumb") for a in "XYZ"]
    session = tmp_path / "session.tsv"
    real[cols].to_csv(session, sep="\t", index=False, float_format="%.3f")
    res = hammer_here(capsys, "landmarks", session, "--rate", RATE, "-o", tmp_path / "lm.csv",
                      "--wide")
    assert res.returncode == 0, res.stderr
    rows = pd.read_csv(tmp_path / "lm.csv")
    assert len(rows) >= 4 and (rows["status"] == "complete").all()
    out = tmp_path / "rec"
    res = hammer_here(capsys, "recognize", session, "--rate", RATE, "-o", out, "--no-figures")
    assert res.returncode == 0, res.stderr
    trials = pd.read_csv(out / "session.trials.csv")
    assert list(trials["trial"]) == list(rows["trial"])
    # trials.csv in s, the landmark table in ms: both on the recording's clock
    np.testing.assert_allclose(trials["onset_time"], rows["onset_time"], atol=1.5e3 / RATE)  # ms
    assert sorted(p.name for p in out.glob("*.recognition.json")) == sorted(
        f"{name}.recognition.json" for name in rows["trial"])


def test_recognize_interrupted_accounts_for_every_reach_then_exits_130(tmp_path, monkeypatch,
                                                                        capsys):
    """Ctrl-C while a recording's reaches are scored: the reports written stay, the trials
    table is written with a row for every reach (those left: not scored, interrupted), and
    the command ends as interrupted (it wrote no table: the reaches left had no word)."""
    import perception.report.clip as clip_report

    table = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"
    write, calls = clip_report.write_clip_report, []

    def interrupted_at_the_second(*args, **kw):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return write(*args, **kw)

    monkeypatch.setattr(clip_report, "write_clip_report", interrupted_at_the_second)
    out = tmp_path / "out"
    status = cli.main(["recognize", str(table), "--rate", "85", "--markers", "thumb=thumb",
                       "finger=index", "-o", str(out), "--no-figures"])
    err = capsys.readouterr().err
    assert status == 130 and "interrupted" in err
    rows = pd.read_csv(out / "optotrak-trials.trials.csv")
    assert list(rows["status"]) == ["ok", "not scored", "not scored", "not scored"]
    assert rows["reason"].iloc[1:].str.startswith("interrupted").all()
    assert len(list(out.glob("*.recognition.json"))) == 1
    for trial in rows["trial"].iloc[1:]:
        assert f"{trial}: not scored: interrupted" in err

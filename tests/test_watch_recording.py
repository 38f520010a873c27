"""``hammer-mv watch`` of a motion-capture recording (issue 46): each reach replayed row by row.

Each reach goes through the online recogniser and ends as ``recognize`` scores
it: the same report but for its ``online`` entry. Every trial is accounted
for, as ``recognize`` does it. The recordings are written here.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from test_faults_mocap_rest import _table
from test_reach_finding import _simple_reach

from hammer_mv.cli import main


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A long table of two trials: a reach to grasp, and a hand that never moves."""
    reach = _table(_simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)]))
    still = reach.copy()
    for column in still.columns[1:]:  # every marker held where it starts
        still[column] = still[column].iloc[0] + np.zeros(len(still))
    table = pd.concat([reach.assign(trial=1), still.assign(trial=2)])
    path = tmp_path_factory.mktemp("rec") / "P01.tsv"
    table[["trial", *reach.columns]].to_csv(path, sep="\t", index=False)
    return path


def _watch(path, out, *more):
    return main(["watch", str(path), "-o", str(out), "--as-fast-as-possible", "--no-figures",
                 *more])


def test_watch_of_a_recording_replays_each_reach_and_accounts_for_every_trial(
        recording, tmp_path, capsys):
    code = _watch(recording, tmp_path / "watch")
    said = capsys.readouterr()
    assert code == 1, said  # a trial is not scored
    assert "not a readable video" not in said.err
    assert "2 trials, 1 reach scored, 1 not scored" in said.out
    assert "P01-trial2: not scored: no reach: the hand never moved" in said.err
    assert "P01-trial1: settled " in said.out  # where the verdict settled, as for a file
    line = next(x for x in said.out.splitlines() if x.startswith("P01-trial1: ") and
                "winner" in x)
    assert " rows) -> " in line and line.endswith("P01-trial1.recognition.json")
    # every trial accounted for in the recording's table, as recognize writes it
    trials = pd.read_csv(tmp_path / "watch" / "P01.trials.csv")
    assert trials["trial"].tolist() == ["P01-trial1", "P01-trial2"]
    assert trials["status"].tolist()[0] == "ok" and trials["reason"].notna().tolist()[1]
    watched = json.loads((tmp_path / "watch" / "P01-trial1.recognition.json").read_text())
    assert watched["online"]["source"] == "recording"
    assert watched["online"]["frames"] > 100 and not watched["online"]["interrupted"]
    # the online path ends as recognize: the same report but for the online entry
    assert main(["recognize", str(recording), "-o", str(tmp_path / "rec"),
                 "--no-figures"]) == 1
    offline = json.loads((tmp_path / "rec" / "P01-trial1.recognition.json").read_text())
    assert (tmp_path / "rec" / "P01.trials.csv").read_bytes() == (
        tmp_path / "watch" / "P01.trials.csv").read_bytes()
    assert watched["mocap"]["trial"] == "P01-trial1"
    assert {k: v for k, v in watched.items() if k != "online"} == offline


def test_watch_of_a_recording_prints_a_line_per_row_with_live(recording, tmp_path, capsys):
    _watch(recording, tmp_path, "--live")
    out = capsys.readouterr().out
    rows = [x for x in out.splitlines() if re.match(r" *\d+\.\d{3} s  ", x)]
    watched = json.loads((tmp_path / "P01-trial1.recognition.json").read_text())
    assert len(rows) == watched["online"]["frames"]  # one per row of the one reach
    assert watched["online"]["settled_early"]  # and the rows show it as on a video
    assert any("SETTLED NORMAL" in x for x in rows)
    assert any("?" in x and "SETTLED" not in x for x in rows)  # provisional before


def test_watch_of_a_recording_names_its_reaches_by_clip(recording, tmp_path, capsys):
    _watch(recording, tmp_path, "--clip", "block1")
    said = capsys.readouterr()
    assert (tmp_path / "block1-trial1.recognition.json").is_file()
    assert "block1-trial2: not scored" in said.err


def test_watch_of_a_recording_refuses_a_labelled_video(recording, tmp_path, capsys):
    code = _watch(recording, tmp_path, "--labelled-video", str(tmp_path / "x.mp4"))
    err = capsys.readouterr().err
    assert code == 2 and "no frames to label" in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.glob("*.recognition.json"))


def test_a_signal_ends_the_replay_after_the_reach_under_way_is_reported(tmp_path, monkeypatch,
                                                                         capsys):
    import _thread
    import signal

    from perception import online

    first = _table(_simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)]))
    second = _table(_simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)], seed=1))
    path = tmp_path / "two.tsv"
    pd.concat([first.assign(trial=1), second.assign(trial=2)])[
        ["trial", *first.columns]].to_csv(path, sep="\t", index=False)
    update, calls = online.OnlineRecognizer.update, []

    def updating(self, *args, **kwargs):
        calls.append(1)
        if len(calls) == 120:  # Ctrl-C during the first reach
            _thread.interrupt_main(signal.SIGINT)
        return update(self, *args, **kwargs)

    monkeypatch.setattr(online.OnlineRecognizer, "update", updating)
    before = signal.getsignal(signal.SIGINT)
    code = _watch(path, tmp_path / "out")
    said = capsys.readouterr()
    assert code == 130, said
    report = json.loads((tmp_path / "out" / "two-trial1.recognition.json").read_text())
    assert report["online"]["interrupted"] and report["online"]["signal"] == "SIGINT"
    assert report["online"]["frames"] == 120
    assert not (tmp_path / "out" / "two-trial2.recognition.json").exists()
    assert "2 trials, 1 reach scored, 1 not scored" in said.out
    assert "two-trial2: not scored: not replayed: watch interrupted (SIGINT)" in said.err
    assert signal.getsignal(signal.SIGINT) == before

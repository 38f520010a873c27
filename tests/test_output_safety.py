"""No command writes over its inputs, and two recordings' reports never overwrite each other.

Issue 41's output-safety cases: ``landmarks T.tsv -o T.tsv`` overwrote the
recording; a video and a table of one stem (``P01.mp4``, ``P01.tsv``) left
the video unprocessed and unlisted; duplicate stems among motion-capture
files overwrote each other's reports, then a traceback; one unsafe trial id
(``x/../y``) failed a whole batch; a rerun after a table lost a trial kept
that trial's report looking current. Also: ``pc.landmarks`` turning into the
module, and a table of no known layout refused with a pose-format message.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from _cli import hammer_here

from perception.discovery import BatchItem, expand_recordings, find_clips
from perception.pipeline import RecognitionSettings
from perception.recordings import MocapImport

DATA = Path(__file__).parent / "data" / "mocap"
RATE = 85.0


def hammer(*args, timeout=300):
    """``hammer-mv *args`` as a subprocess: for what the process shows (exit status 2 in one
    line); the lines and files of a command are tested in-process (:func:`hammer_here`)."""
    return subprocess.run([sys.executable, "-m", "hammer_mv", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


def write_trials(path: Path, trials=(0,), names=None, sep="\t", trial_column=True) -> Path:
    """Real Optotrak trials (thumb and index) as a table, trial ids renamed by ``names``."""
    real = pd.read_csv(DATA / "optotrak-trials.tsv", sep="\t")
    real = real[["trialN", *[f"{m}{a}raw" for m in ("index", "thumb") for a in "XYZ"]]]
    table = real[real["trialN"].isin(trials)].copy()
    if names is not None:
        table["trialN"] = table["trialN"].map(dict(zip(trials, names)))
    if not trial_column:
        table = table.drop(columns="trialN")
    table.to_csv(path, sep=sep, index=False, float_format="%.3f")
    return path


def test_landmarks_refuses_to_write_over_its_recording(tmp_path):
    table = write_trials(tmp_path / "T.tsv")
    before = table.read_bytes()
    res = hammer("landmarks", table, "--rate", RATE, "-o", table, timeout=120)
    assert res.returncode == 2
    assert len(res.stderr.strip().splitlines()) == 1 and "input" in res.stderr
    assert table.read_bytes() == before


def test_landmarks_refuses_an_input_named_through_another_path(tmp_path, monkeypatch,
                                                                capsys):
    table = write_trials(tmp_path / "T.tsv")
    before = table.read_bytes()
    monkeypatch.chdir(tmp_path)
    res = hammer_here(capsys, "landmarks", "T.tsv", "--rate", RATE, "-o",
                      tmp_path / "." / "T.tsv")
    assert res.returncode == 2 and table.read_bytes() == before


def test_a_video_and_a_table_of_one_stem_are_both_clips(tmp_path):
    write_trials(tmp_path / "P01.tsv", trial_column=False)
    (tmp_path / "P01.mp4").write_bytes(b"")
    found = find_clips(tmp_path)
    assert {(i.clip, i.kind) for i in found.items} == {("P01.mp4", "video"),
                                                        ("P01.tsv", "mocap")}
    assert found.skipped == []


def test_two_recordings_of_one_stem_give_their_reaches_distinct_names(tmp_path):
    write_trials(tmp_path / "a.tsv", trials=(0, 1))
    write_trials(tmp_path / "a.csv", trials=(0, 1), sep=",")
    items = find_clips(tmp_path).items
    assert sorted(i.clip for i in items) == ["a.csv", "a.tsv"]
    settings = RecognitionSettings(mocap=MocapImport(rate=RATE))
    names = [i.clip for i in expand_recordings(items, settings)]
    assert sorted(names) == ["a.csv-trial0", "a.csv-trial1", "a.tsv-trial0", "a.tsv-trial1"]


def test_a_batch_of_same_stem_recordings_reports_each(tmp_path, capsys):
    folder = tmp_path / "in"
    folder.mkdir()
    write_trials(folder / "a.tsv", trial_column=False)
    write_trials(folder / "a.csv", sep=",", trial_column=False)
    report = tmp_path / "report"
    status, _, err = hammer_here(capsys, "batch", folder, "-o", report, "--rate", RATE, "--quiet")
    assert status == 0, err
    assert "Traceback" not in err
    summary = pd.read_csv(report / "summary.csv")
    assert sorted(summary["clip"]) == ["a.csv", "a.tsv"] and (summary["status"] == "ok").all()
    inputs = {json.loads((report / f"{c}.recognition.json").read_text())["input"]
              for c in summary["clip"]}
    assert {Path(p).name for p in inputs} == {"a.tsv", "a.csv"}


def test_an_unsafe_trial_id_gets_a_safe_name_and_the_rest_go_on(tmp_path):
    table = write_trials(tmp_path / "s.tsv", trials=(0, 1), names=("x/../y", "ok"))
    item = BatchItem("s", table, "mocap")
    settings = RecognitionSettings(mocap=MocapImport(rate=RATE))
    items = expand_recordings([item], settings)
    names = [i.clip for i in items]
    assert len(names) == 2 and "s-trialok" in names
    unsafe = next(n for n in names if n != "s-trialok")
    assert "/" not in unsafe and not unsafe.startswith(".") and unsafe.startswith("s-trialx_")


def test_recognize_gives_a_second_recording_of_one_stem_its_own_reports(tmp_path, capsys):
    out = tmp_path / "out"
    a = write_trials(tmp_path / "P01.tsv", trial_column=False)
    b = write_trials(tmp_path / "P01.csv", trials=(1,), sep=",", trial_column=False)
    for path in (a, b):
        status, _, err = hammer_here(capsys, "recognize", path, "--rate", RATE, "-o", out,
                                     "--no-figures")
        assert status == 0, err
    reports = {p.name: json.loads(p.read_text())["input"] for p in out.glob("*.recognition.json")}
    assert {name: Path(src).name for name, src in reports.items()} == {
        "P01.recognition.json": "P01.tsv", "P01.csv.recognition.json": "P01.csv"}
    assert sorted(p.name for p in out.glob("*.trials.csv")) == ["P01.csv.trials.csv",
                                                                "P01.trials.csv"]
    # the first recording again: its own report, not the second's renamed
    assert hammer_here(capsys, "recognize", a, "--rate", RATE, "-o", out, "--no-figures")[0] == 0
    assert len(list(out.glob("*.recognition.json"))) == 2


def test_a_rerun_after_a_trial_left_the_table_removes_its_report(tmp_path, capsys):
    folder = tmp_path / "in"
    folder.mkdir()
    table = write_trials(folder / "t.tsv", trials=(0, 1))
    report = tmp_path / "report"
    status, _, err = hammer_here(capsys, "batch", folder, "-o", report, "--rate", RATE, "--quiet")
    assert status == 0, err
    assert (report / "t-trial1.recognition.json").is_file()
    other = report / "other.recognition.json"   # another input's report: never touched
    other.write_text(json.dumps({"input": str(tmp_path / "elsewhere.tsv"), "mocap": {}}))
    write_trials(table, trials=(0,))
    status, _, err = hammer_here(capsys, "batch", folder, "-o", report, "--rate", RATE, "--quiet")
    assert status == 0, err
    assert not list(report.glob("t-trial1.*"))
    assert (report / "t-trial0.recognition.json").is_file() and other.is_file()
    assert list(pd.read_csv(report / "summary.csv")["clip"]) == ["t-trial0"]


def test_stale_trials_of_several_recordings_go_in_one_pass(tmp_path, monkeypatch):
    from perception.report import clip

    a, b = (tmp_path / "a.tsv", tmp_path / "b.tsv")
    for f in (a, b):
        f.write_text("x")
    out = tmp_path / "out"
    out.mkdir()

    def report(stem, source, mocap=True):
        (out / f"{stem}.recognition.json").write_text(
            json.dumps({"input": str(source), **({"mocap": {}} if mocap else {})}))
        (out / f"{stem}.confidence.png").write_bytes(b"png")

    for stem, source in (("a-trial0", a), ("a-trial1", a), ("b-trial0", b), ("b-trial1", b),
                         ("c-trial0", tmp_path / "c.tsv")):
        report(stem, source)
    report("a-video", a, mocap=False)  # not a reach's report: never touched
    reads = []
    loads = json.loads
    monkeypatch.setattr(clip, "json", type("J", (), {"loads": staticmethod(
        lambda text: reads.append(text) or loads(text))}))
    removed = clip.remove_stale_trials(out, {a: ["a-trial0"], b: ["b-trial0", "b-trial1"]})
    assert removed == ["a-trial1"]
    assert not list(out.glob("a-trial1.*"))
    assert {p.name.split(".")[0] for p in out.iterdir()} == {
        "a-trial0", "b-trial0", "b-trial1", "c-trial0", "a-video"}
    # the clips scored now are not read: only the three others, once each
    assert len(reads) == 3
    # the one-recording form removes only that recording's
    assert clip.remove_stale_reports(out, b, ["b-trial0"]) == ["b-trial1"]
    assert (out / "a-trial0.recognition.json").is_file()


def test_a_batch_will_not_write_its_report_over_a_recording_in_its_folder(tmp_path, capsys):
    folder = tmp_path / "in"
    folder.mkdir()
    write_trials(folder / "landmarks.csv", sep=",")
    res = hammer_here(capsys, "batch", folder, "-o", folder, "--rate", RATE)
    assert res.returncode == 2 and "landmarks.csv" in res.stderr
    # elsewhere, the file a batch report would call its own is listed, not silently left
    found = find_clips(folder)
    assert dict(found.skipped).keys() == {"landmarks.csv"}


def test_pc_landmarks_stays_the_function_after_read_reaches():
    code = ("import perception as pc\n"
            f"pc.read_reaches({str(DATA / 'optotrak-trials.tsv')!r}, pc.MocapImport(rate=85.0))\n"
            "import perception.landmarks\n"
            "print(callable(pc.landmarks), type(pc.landmarks).__name__)\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["True", "function"]


@pytest.mark.parametrize("command", ["recognize", "landmarks"])
def test_a_table_of_no_known_layout_is_told_what_was_expected(tmp_path, command):
    odd = tmp_path / "odd.csv"
    odd.write_text("a,b,c\n1,2,3\n4,5,6\n")
    out = tmp_path / ("out" if command == "recognize" else "lm.csv")
    res = hammer(command, odd, "-o", out, timeout=120)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    line = res.stderr.strip()
    assert len(line.splitlines()) == 1
    assert "expected" in line and "DeepLabCut" in line and "pose file" in line
    assert "LightningPose" not in line and "header rows do not match" not in line


def test_a_batch_lists_a_table_of_no_known_layout_with_why(tmp_path):
    (tmp_path / "odd.tsv").write_text("a\tb\tc\n1\t2\t3\n")
    (tmp_path / "odd2.csv").write_text("a,b,c\n1,2,3\n")
    (tmp_path / "notes.txt").write_text("not a video")
    skipped = dict(find_clips(tmp_path).skipped)
    for name in ("odd.tsv", "odd2.csv"):
        assert skipped[name].startswith("not a") and "expected" in skipped[name]
        assert "pose file" in skipped[name]
    assert skipped["notes.txt"] == ("not a video, tracks file, pose file or motion-capture "
                                    "recording")


def test_a_bug_reading_one_recording_does_not_end_the_batch(tmp_path, monkeypatch):
    from _demos import default_repertoire

    import perception.recordings as recordings
    from perception.batch import run_batch

    folder = tmp_path / "in"
    folder.mkdir()
    write_trials(folder / "good.tsv", trial_column=False)
    write_trials(folder / "bad.tsv", trial_column=False)
    real = recordings.iter_recording

    def buggy(path, options=None):  # read_recording reads through it too
        if Path(path).name == "bad.tsv":
            raise ValueError("Duplicate names are not allowed.")   # pandas, on a doubled column
        return real(path, options)

    monkeypatch.setattr(recordings, "iter_recording", buggy)
    recordings._cached.cache_clear()
    summary = run_batch(find_clips(folder).items, tmp_path / "report", default_repertoire(),
                        RecognitionSettings(mocap=MocapImport(rate=RATE)), quiet=True)
    status = dict(zip(summary["clip"], summary["status"]))
    assert status == {"bad": "failed", "good": "ok"}
    assert "Duplicate names" in summary.set_index("clip").loc["bad", "reason"]

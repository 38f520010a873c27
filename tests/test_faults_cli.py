"""The command line tells a user's mistake from a bug, and says what it did.

A user's mistake (:class:`~perception.errors.HammerMVError`, ``OSError``) is
one line on stderr and exit status 2; anything else (a bare ``ValueError``
included) is a bug: its traceback, a line saying so, exit status 1. Library
warnings are summarised in one line (shown with ``-v``, nothing with
``--quiet``); ``--jobs`` is capped at what the machine allows; ``--quiet``
is silent on success.
"""

from __future__ import annotations

import os
import re
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import psutil
import pytest
from _faults import one_line

import hammer_mv.cli.batch as batch_cli
import hammer_mv.cli.synth as synth_cli
from hammer_mv.cli import main
from minvar.task import ReachTask
from perception.errors import InputError, PlanningError

sys.path.insert(0, str(Path(__file__).resolve().parent))

BUG = "this is a bug in hammer-mv (not in your input); please report it with the traceback above"


def _lines(text: str) -> list[str]:
    return text.strip().splitlines()


@pytest.fixture
def recipe(tmp_path):
    path = tmp_path / "r.toml"
    path.write_text("[conditions]\nnormal = 2\n")
    return path


def _command(monkeypatch, body):
    """Make ``hammer-mv synth`` run ``body(args)`` instead of rendering."""
    monkeypatch.setattr(synth_cli, "run", body)


def _synth(recipe, *extra):
    return main(["synth", str(recipe), "-o", str(recipe.parent / "out"), *extra])


def _raise(error, warn=False):
    def body(*args):
        if warn:
            warnings.warn("noise", RuntimeWarning, stacklevel=1)
        raise error
    return body


# -- a bug against a user's mistake

@pytest.mark.parametrize("command, error", [
    ("synth", "deep inside: shapes (3,) and (4,) differ"),
    ("reach", "ReachTask.shoulder: not a user's option"),  # a field's name, yet no option's
], ids=["bare ValueError", "ValueError naming no option"])
def test_a_value_error_is_a_bug_with_its_traceback(command, error, monkeypatch, recipe, capsys):
    if command == "synth":
        _command(monkeypatch, _raise(ValueError(error)))
        assert _synth(recipe) == 1
    else:
        monkeypatch.setattr(ReachTask, "steps", _raise(ValueError(error)))
        assert main(["reach", "-o", str(recipe.parent / "out")]) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and f"ValueError: {error}" in err
    assert _lines(err)[-1] == f"hammer-mv {command}: {BUG}"
    assert "error:" not in err  # not dressed up as the user's mistake


@pytest.mark.parametrize("body, status, line", [
    (_raise(InputError("expected a number, got 'x'", "r.toml", field="[scene] duration")), 2,
     "hammer-mv synth: error: r.toml: [scene] duration: expected a number, got 'x'"),
    (_raise(PlanningError("out of the arm's reach", "clip.mp4")), 2,
     "hammer-mv synth: error: clip.mp4: out of the arm's reach"),
    (_raise(FileNotFoundError(2, "No such file or directory", "/data/missing.mp4")), 2,
     "hammer-mv synth: error: /data/missing.mp4: No such file or directory"),
    (_raise(KeyboardInterrupt), 130, "hammer-mv: interrupted"),
    (_raise(InputError("bad", "x.toml"), warn=True), 2, "hammer-mv synth: error: x.toml: bad"),
], ids=["input error names file and field", "planning error is the user's too",
        "OS error names its file", "interrupted is 130",
        "a failing command prints its error, not the warnings' summary"])
def test_a_users_mistake_is_one_line(body, status, line, monkeypatch, recipe, capsys):
    _command(monkeypatch, body)
    assert _synth(recipe) == status
    captured = capsys.readouterr()
    assert _lines(captured.err) == [line] and captured.out == ""


# -- library warnings

def _warns(args):
    np.float64(0.0) / np.float64(0.0)  # numpy: RuntimeWarning, invalid value
    warnings.warn("a library's second warning", UserWarning, stacklevel=1)
    print("done")
    return 0


@pytest.mark.parametrize("flag, shown, stderr", [
    ([], [], r"hammer-mv synth: 2 library warning\(s\) hidden \(first: RuntimeWarning: "
             r"invalid value.*; -v shows them\n"),
    (["-v"], ["RuntimeWarning", "UserWarning"], r"(?s)(?!.*hidden).*"),
    (["--quiet"], [], r""),
], ids=["summarised in one line", "shown with verbose", "silent with quiet"])
def test_library_warnings(flag, shown, stderr, monkeypatch, recipe, capsys):
    _command(monkeypatch, _warns)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("default")
        assert _synth(recipe, *flag) == 0
    captured = capsys.readouterr()
    assert captured.out == "done\n"
    assert re.fullmatch(stderr, captured.err), captured.err
    assert sorted(w.category.__name__ for w in seen) == shown  # none went past the summary


# -- --jobs

@pytest.fixture
def machine(monkeypatch):
    """A machine of 2 cores and 23.1 GiB free; returns a setter for both."""
    state = {"cores": 2, "memory": int(23.1 * 2**30)}
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(state["cores"])))
    monkeypatch.setattr(psutil, "virtual_memory", lambda: SimpleNamespace(
        available=state["memory"]))
    return state


@pytest.fixture
def fake_synthesize(monkeypatch):
    """``synthesize`` replaced by one that records its ``jobs`` and writes nothing."""
    import perception.synthetic.recipes as recipes

    calls = []

    def synthesize(recipe, out, *, seed, jobs, progress):
        calls.append(jobs)
        return pd.DataFrame({"clip": ["normal-01", "normal-02"], "condition": ["normal"] * 2})

    monkeypatch.setattr(recipes, "synthesize", synthesize)
    return calls


@pytest.mark.parametrize("cores, gib, extra, stderr", [
    (2, 23.1, ["--jobs", "1000"], "--jobs 1000 capped at 2 (2 cores, 23.1 GiB free)"),
    (16, 1.3, ["--jobs", "8"], "--jobs 8 capped at 2 (16 cores, 1.3 GiB free)"),
    (2, 23.1, ["--jobs", "2"], ""),
    (2, 23.1, ["--jobs", "1000", "--quiet"], ""),
], ids=["capped at the cores", "capped at the free memory (two workers' worth)",
        "within the machine kept silently", "capped quietly with quiet"])
def test_jobs_capped_at_the_machine(cores, gib, extra, stderr, machine, fake_synthesize, recipe,
                                    capsys):
    machine.update(cores=cores, memory=int(gib * 2**30))
    assert _synth(recipe, *extra) == 0
    assert fake_synthesize == [2]
    out, err = capsys.readouterr()
    assert err == (f"hammer-mv synth: {stderr}\n" if stderr else "")
    assert out == "" or "--quiet" not in extra


def test_the_real_machine_caps_too(fake_synthesize, recipe, capsys):
    assert _synth(recipe, "--jobs", "1000000") == 0
    (jobs,) = fake_synthesize
    line = one_line(capsys.readouterr().err)
    m = re.fullmatch(r"hammer-mv synth: --jobs 1000000 capped at (\d+) \((\d+) cores?"
                     r"(?:, ([\d.]+) GiB free)?\)", line)
    assert m and int(m[1]) == jobs and 1 <= jobs <= int(m[2]) <= (os.cpu_count() or jobs), line
    assert m[3] is None or float(m[3]) > 0


def test_batch_caps_jobs_and_names_the_commonest_failure(machine, monkeypatch, tmp_path,
                                                          capsys):
    clips = tmp_path / "clips"
    clips.mkdir()
    for name in ("a", "b", "c"):
        (clips / f"{name}.mp4").write_bytes(b"not a video")
    seen = {}

    def run_batch(items, out, rep, settings, *, jobs, **kwargs):
        seen["jobs"] = jobs
        paths = {i.clip: i.path for i in items}
        errors = {"a": f"{paths['a']}: not a readable video (FFmpeg could not open it)",
                  "b": f"{paths['b']}: not a readable video (FFmpeg could not open it)",
                  "c": f"{paths['c']}: truncated"}
        return pd.DataFrame({"clip": list(errors), "status": ["failed"] * 3,
                             "reused": [False] * 3, "error": list(errors.values())})

    monkeypatch.setattr(batch_cli, "run_batch", run_batch)
    monkeypatch.setattr(batch_cli, "load_repertoire", lambda args: (None, "rep"))
    out = tmp_path / "report"
    assert main(["batch", str(clips), "-o", str(out), "--jobs", "64"]) == 1
    assert seen["jobs"] == 2
    err = _lines(capsys.readouterr().err)
    assert err == [
        "hammer-mv batch: --jobs 64 capped at 2 (2 cores, 23.1 GiB free)",
        "hammer-mv batch: 3 clip(s) failed (2: not a readable video (FFmpeg could not open "
        f"it); 1 other); see {out / 'summary.csv'}"]


# -- recognize

def test_recognize_into_an_existing_file_fails_before_tracking(monkeypatch, tmp_path, capsys):
    import perception.pipeline as pipeline

    video = tmp_path / "a.mp4"
    video.write_bytes(b"a video")
    taken = tmp_path / "report"
    taken.write_text("not a folder")

    def never(*args, **kwargs):
        raise AssertionError("tracked before checking -o")

    monkeypatch.setattr(pipeline, "load_clip", never)
    assert main(["recognize", str(video), "-o", str(taken)]) == 2
    one_line(capsys.readouterr().err, str(taken), "--output", "not a folder")
    assert taken.read_text() == "not a folder"


@pytest.mark.parametrize("command", ["recognize", "batch"])
def test_a_read_only_output_folder_is_refused_before_any_work(command, monkeypatch, tmp_path,
                                                              capsys):
    import errno
    import tempfile

    import perception.pipeline as pipeline

    clips = tmp_path / "clips"
    clips.mkdir()
    (clips / "a.mp4").write_bytes(b"a video")
    out = tmp_path / "locked"
    out.mkdir()

    def never(*args, **kwargs):
        raise AssertionError("worked before checking -o")

    def read_only(*args, dir=None, **kwargs):  # as a read-only file system answers
        raise OSError(errno.EROFS, "Read-only file system", dir)

    monkeypatch.setattr(pipeline, "load_clip", never)
    monkeypatch.setattr(batch_cli, "run_batch", never)
    monkeypatch.setattr(batch_cli, "load_repertoire", never)
    monkeypatch.setattr(tempfile, "TemporaryFile", read_only)
    source = clips / "a.mp4" if command == "recognize" else clips
    assert main([command, str(source), "-o", str(out)]) == 2
    # the folder the user named, not a scratch file the command would have made there
    one_line(capsys.readouterr().err, str(out), "--output", "Read-only file system")


@pytest.fixture(scope="module")
def tracks_file(tmp_path_factory):
    from _demos import demo_tracks

    path = tmp_path_factory.mktemp("clip") / "n.tracks.h5"
    demo_tracks("normal", 0)[0].save(path)
    return path


def test_recognize_says_verdict_and_winner(tracks_file, tmp_path, capsys):
    import json

    out = tmp_path / "out"
    assert main(["recognize", str(tracks_file), "-o", str(out), "--no-figures"]) == 0
    line, = _lines(capsys.readouterr().out)
    report = json.loads((out / "n.recognition.json").read_text())
    verdict = report["verdict"]["verdict"] if isinstance(report.get("verdict"), dict) else \
        report.get("verdict")
    assert line.startswith(f"n: {verdict}, winner grasp-"), line
    assert line.endswith(str(out / "n.recognition.json"))


@pytest.mark.parametrize("argv, output", [
    (["reach", "--trials", "5"], "out"),
    (["grasp", "simulate", "--trials", "2"], "out"),
    (["repertoire", "build", "--durations", "1.0"], "rep.h5"),
    (["recognize", "{tracks}", "--no-figures"], "out/n.recognition.json"),
], ids=["reach", "grasp", "repertoire", "recognize"])
def test_quiet_commands_print_nothing_on_success(argv, output, tracks_file, tmp_path, capsys):
    argv = [a.format(tracks=tracks_file) for a in argv]
    assert main([*argv, "-o", str(tmp_path / output.split("/")[0]), "--quiet"]) == 0
    assert capsys.readouterr() == ("", "")
    assert (tmp_path / output).exists()


def test_synth_quiet_prints_nothing(fake_synthesize, recipe, capsys):
    assert _synth(recipe, "--quiet") == 0
    assert capsys.readouterr() == ("", "")
    assert _synth(recipe) == 0
    assert _lines(capsys.readouterr().out)[0].startswith("wrote 2 clips to ")


# -- option values checked at the boundary, named by their flag

@pytest.mark.parametrize("argv, field", [
    # (every flag of a declared field of recognize, batch, landmarks, reach, grasp simulate
    # and repertoire build: tests/test_declared_fields.py, generated; here the checks no
    # field declares, and one generated flag through main)
    (["reach", "--trials", "1"], "--trials"),
    (["repertoire", "build", "--distance", "2"], "--distance"),  # off the table: by hand
    (["repertoire", "build", "--durations", "0"], "--durations"),
    (["repertoire", "build", "--durations", "0.01"], "--durations"),  # under two model steps
    (["repertoire", "build", "--fps", "0"], "--fps"),  # a rate: SceneSpec holds its period
    (["reach", "--seed", "-1"], "--seed"),  # numpy's own ValueError, checked first
    (["grasp", "experiment", "object-size", "--seed", "-1"], "--seed"),
    (["synth", "r.toml", "--seed", "-1"], "--seed"),
    (["recognize", "{clip}", "--px-per-m", "0"], "--px-per-m"),
    *[([command, folder, "--jobs", jobs], "--jobs") for jobs in ["0", "-2"]
      for command, folder in [("synth", "{recipe}"), ("batch", "{folder}")]],
], ids=lambda v: " ".join(v) if isinstance(v, list) else None)
def test_option_values_are_named_not_tracebacks(argv, field, recipe, tmp_path, capsys):
    clip = tmp_path / "a.tracks.h5"
    clip.write_bytes(b"")
    out = tmp_path / ("r.h5" if argv[0] == "repertoire" else "x")
    argv = [a.format(clip=clip, recipe=recipe, folder=tmp_path) for a in argv]
    assert main([*argv, "-o", str(out)]) == 2
    line = one_line(capsys.readouterr().err)
    assert line.startswith(f"hammer-mv {argv[0]}: error: {field}: "), line
    assert not out.exists()


# -- planning failures are PlanningErrors at their source

def test_an_unreachable_scene_is_a_planning_error():
    from perception.recognition.models import SceneSpec
    from perception.recognition.planning import build_model, default_specs

    with pytest.raises(PlanningError, match="outside the arm's reach"):
        build_model(default_specs([1.0])[0], SceneSpec(distance=2.0))


@pytest.mark.parametrize("error", [
    PlanningError("out of the arm's reach", field="distance"),
    ValueError("operands could not be broadcast together"),
], ids=["a planning error names the clip", "a bug stays a bug"])
def test_recognize_tracks_names_the_clip_of_a_planning_error(monkeypatch, error):
    import perception.pipeline as pipeline
    from perception.recognition.models import SceneSpec
    from perception.synthetic.demos import demo_tracks

    obs = pipeline.observe(demo_tracks("normal", 0)[0], clip="c")
    monkeypatch.setattr(pipeline, "observe", lambda tracks, params, clip=None: obs)
    # no tracks at all: the start needs no settling either
    monkeypatch.setattr("perception.settling.settle_start",
                        lambda tracks, params, clip=None: (tracks, None))

    class Scenes:
        def reference(self):
            return SceneSpec(), (0.6, 1.2)

        def wrist_offset(self):
            return 0.06

        def for_scene(self, scene, **kwargs):
            raise error

    with pytest.raises(type(error)) as info:
        pipeline.recognize_tracks(None, Scenes(), source="clip.mp4")
    if isinstance(error, PlanningError):
        assert info.value.path == "clip.mp4" and info.value.field == "distance"
        assert "out of the arm's reach" in str(info.value) and "`px_per_m`" in str(info.value)
    else:
        assert not isinstance(info.value, InputError | PlanningError)


@pytest.mark.parametrize("name", ["trial.tsv", "trial.c3d", "poses.csv", "poses.h5",
                                  "clip.tracks.h5", "clip.mp4"])
def test_an_empty_recording_is_refused_as_empty_naming_the_file(tmp_path, capsys, name):
    """A 0-byte input says it is empty, whatever its reader would have made of it (the
    pose reader said its header rows did not match DeepLabCut's)."""
    from hammer_mv.cli import main

    (tmp_path / name).write_bytes(b"")
    status = main(["recognize", str(tmp_path / name), "-o", str(tmp_path / "out"),
                   "--rate", "100", "--fps", "30"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert name in err[0] and "empty file (0 bytes)" in err[0]
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_a_batch_lists_an_empty_table_as_empty(tmp_path):
    """An empty table of no kind is skipped as empty; an empty video fails as one."""
    from perception.discovery import find_clips

    (tmp_path / "trial.tsv").write_bytes(b"")
    (tmp_path / "notes.tsv").write_text("a\tb\n1\t2\n")
    found = find_clips(tmp_path)
    assert dict(found.skipped)["trial.tsv"] == "empty file (0 bytes)"
    assert "empty" not in dict(found.skipped)["notes.tsv"]


def test_landmarks_of_a_folder_names_the_files_it_skipped(tmp_path, capsys):
    """landmarks finds a folder's clips as batch does, and says what it skipped as batch
    does (it said nothing: notes, an empty table, a subfolder of recordings all dropped)."""
    from hammer_mv.cli import main

    folder = tmp_path / "in"
    (folder / "P01").mkdir(parents=True)
    (folder / "notes.txt").write_text("a few words\n")
    (folder / "trial.tsv").write_bytes(b"")
    # nothing measured: refused as batch refuses it, no empty table
    assert main(["landmarks", str(folder), "-o", str(tmp_path / "l.csv")]) == 2
    assert not (tmp_path / "l.csv").exists()
    err = capsys.readouterr().err.splitlines()
    said = [line for line in err if "landmarks: skipped" in line]
    assert len(said) == 1 and said[0].startswith("hammer-mv landmarks: skipped 3 file(s)")
    for name, why in (("notes.txt", "not a video"), ("trial.tsv", "empty file"),
                      ("P01", "a folder")):
        assert f"{folder / name} ({why}" in said[0]
    assert err[-1].startswith(f"hammer-mv landmarks: error: {folder}: no clips found (3 file")
    assert main(["landmarks", str(folder), "-o", str(tmp_path / "l.csv"), "--quiet"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "no clips found" in err[0]  # the list left to the one error


def test_landmarks_of_an_empty_table_says_it_is_empty(tmp_path, capsys):
    from hammer_mv.cli import main

    (tmp_path / "trial.tsv").write_bytes(b"")
    assert main(["landmarks", str(tmp_path / "trial.tsv"), "-o", str(tmp_path / "l.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "trial.tsv" in err[0] and "empty file (0 bytes)" in err[0]


@pytest.mark.parametrize("command", ["recognize", "landmarks", "batch"])
def test_a_file_of_no_kind_is_refused_naming_every_kind_the_command_reads(
        tmp_path, capsys, command):
    """landmarks and batch read motion-capture recordings too, and say so (they said "not
    a video, tracks or pose file", as load_clip, which reads no recording, does)."""
    from hammer_mv.cli import main

    notes = tmp_path / "in" / "notes.txt"
    notes.parent.mkdir()
    notes.write_text("a few words\nof prose\n")
    given = str(notes.parent if command == "batch" else notes)
    out = str(tmp_path / ("l.csv" if command == "landmarks" else "out"))
    assert main([command, given, "-o", out]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "not a video, tracks file, pose file or motion-capture recording" in err[-1], err
    assert "notes.txt" in err[-1]

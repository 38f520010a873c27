"""The command line tells a user's mistake from a bug, and says what it did.

A user's mistake (:class:`~perception.errors.HammerMVError`, ``OSError``) is
one line on stderr and exit status 2; anything else (a bare ``ValueError``
included) is a bug: its traceback, a line saying so, exit status 1. Library
warnings are summarised in one line (shown with ``-v``, nothing with
``--quiet``); ``--jobs`` is capped at what the machine allows; ``--quiet``
is silent on success.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import hammer_mv.cli.batch as batch_cli
import hammer_mv.cli.checks as checks
import hammer_mv.cli.synth as synth_cli
from hammer_mv.cli import main
from perception.errors import InputError, PlanningError

sys.path.insert(0, str(Path(__file__).resolve().parent))

RECIPE = "[conditions]\nnormal = 2\n"


def _lines(text: str) -> list[str]:
    return text.strip().splitlines()


@pytest.fixture
def recipe(tmp_path):
    path = tmp_path / "r.toml"
    path.write_text(RECIPE)
    return path


def _command(monkeypatch, body):
    """Make ``hammer-mv synth`` run ``body(args)`` instead of rendering."""
    monkeypatch.setattr(synth_cli, "run", body)


def _synth(recipe, *extra):
    return main(["synth", str(recipe), "-o", str(recipe.parent / "out"), *extra])


# -- a bug against a user's mistake

def test_a_bare_value_error_is_a_bug_with_its_traceback(monkeypatch, recipe, capsys):
    def body(args):
        raise ValueError("deep inside: shapes (3,) and (4,) differ")

    _command(monkeypatch, body)
    assert _synth(recipe) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err
    assert "ValueError: deep inside: shapes (3,) and (4,) differ" in err
    assert _lines(err)[-1] == ("hammer-mv synth: this is a bug in hammer-mv (not in your input); "
                               "please report it with the traceback above")
    assert "error:" not in err  # not dressed up as the user's mistake


def test_an_input_error_is_one_line_naming_file_and_field(monkeypatch, recipe, capsys):
    def body(args):
        raise InputError("expected a number, got 'x'", "r.toml", field="[scene] duration")

    _command(monkeypatch, body)
    assert _synth(recipe) == 2
    captured = capsys.readouterr()
    assert _lines(captured.err) == [
        "hammer-mv synth: error: r.toml: [scene] duration: expected a number, got 'x'"]
    assert "Traceback" not in captured.err and captured.out == ""


def test_a_planning_error_is_the_users_too(monkeypatch, recipe, capsys):
    def body(args):
        raise PlanningError("out of the arm's reach", "clip.mp4")

    _command(monkeypatch, body)
    assert _synth(recipe) == 2
    assert _lines(capsys.readouterr().err) == [
        "hammer-mv synth: error: clip.mp4: out of the arm's reach"]


def test_an_os_error_names_its_file(monkeypatch, recipe, capsys):
    def body(args):
        raise FileNotFoundError(2, "No such file or directory", "/data/missing.mp4")

    _command(monkeypatch, body)
    assert _synth(recipe) == 2
    assert _lines(capsys.readouterr().err) == [
        "hammer-mv synth: error: /data/missing.mp4: No such file or directory"]


def test_interrupted_is_130(monkeypatch, recipe, capsys):
    def body(args):
        raise KeyboardInterrupt

    _command(monkeypatch, body)
    assert _synth(recipe) == 130
    assert _lines(capsys.readouterr().err) == ["hammer-mv: interrupted"]


# -- library warnings

def _warns(args):
    np.float64(0.0) / np.float64(0.0)  # numpy: RuntimeWarning, invalid value
    warnings.warn("a library's second warning", UserWarning, stacklevel=1)
    print("done")
    return 0


def test_warnings_are_summarised_in_one_line(monkeypatch, recipe, capsys):
    _command(monkeypatch, _warns)
    with warnings.catch_warnings(record=True) as leaked:
        warnings.simplefilter("default")
        assert _synth(recipe) == 0
    captured = capsys.readouterr()
    assert captured.out == "done\n"
    lines = _lines(captured.err)
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("hammer-mv synth: 2 library warning(s) hidden (first: "
                               "RuntimeWarning: invalid value"), lines[0]
    assert lines[0].endswith("; -v shows them")
    assert leaked == []  # none went past the summary


def test_warnings_are_shown_with_verbose(monkeypatch, recipe, capsys):
    _command(monkeypatch, _warns)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("default")
        assert _synth(recipe, "-v") == 0
    assert sorted(w.category.__name__ for w in shown) == ["RuntimeWarning", "UserWarning"]
    assert "hidden" not in capsys.readouterr().err


def test_warnings_are_silent_with_quiet(monkeypatch, recipe, capsys):
    _command(monkeypatch, _warns)
    with warnings.catch_warnings(record=True) as leaked:
        warnings.simplefilter("default")
        assert _synth(recipe, "--quiet") == 0
    assert capsys.readouterr().err == "" and leaked == []


def test_a_failing_command_prints_its_error_not_the_summary(monkeypatch, recipe, capsys):
    def body(args):
        warnings.warn("noise", RuntimeWarning, stacklevel=1)
        raise InputError("bad", "x.toml")

    _command(monkeypatch, body)
    assert _synth(recipe) == 2
    assert _lines(capsys.readouterr().err) == ["hammer-mv synth: error: x.toml: bad"]


# -- --jobs

@pytest.fixture
def machine(monkeypatch):
    """A machine of 2 cores and 23.1 GiB free; returns a setter for both."""
    state = {"cores": 2, "memory": int(23.1 * 2**30)}
    monkeypatch.setattr(checks, "usable_cores", lambda: state["cores"])
    monkeypatch.setattr(checks, "free_memory", lambda: state["memory"])
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


def test_jobs_capped_at_the_cores(machine, fake_synthesize, recipe, capsys):
    assert _synth(recipe, "--jobs", "1000") == 0
    assert fake_synthesize == [2]
    err = _lines(capsys.readouterr().err)
    assert err == ["hammer-mv synth: --jobs 1000 capped at 2 (2 cores, 23.1 GiB free)"]


def test_jobs_capped_at_the_free_memory(machine, fake_synthesize, recipe, capsys):
    machine.update(cores=16, memory=int(1.3 * 2**30))  # two workers' worth
    assert _synth(recipe, "--jobs", "8") == 0
    assert fake_synthesize == [2]
    assert "--jobs 8 capped at 2 (16 cores, 1.3 GiB free)" in capsys.readouterr().err


def test_jobs_within_the_machine_are_kept_silently(machine, fake_synthesize, recipe, capsys):
    assert _synth(recipe, "--jobs", "2") == 0
    assert fake_synthesize == [2] and capsys.readouterr().err == ""


def test_jobs_capped_quietly_with_quiet(machine, fake_synthesize, recipe, capsys):
    assert _synth(recipe, "--jobs", "1000", "--quiet") == 0
    assert fake_synthesize == [2]
    assert capsys.readouterr() == ("", "")


def test_the_real_machine_caps_too():
    cores = checks.usable_cores()
    assert 1 <= cores <= (checks.os.cpu_count() or cores)
    assert 1 <= checks.cap_jobs(10**6, "batch", quiet=True) <= cores
    memory = checks.free_memory()
    assert memory is None or memory > 0


@pytest.mark.parametrize("command", ["synth", "batch"])
@pytest.mark.parametrize("jobs", ["0", "-2"])
def test_jobs_below_one_refused(command, jobs, recipe, tmp_path, capsys):
    assert main([command, str(recipe if command == "synth" else tmp_path), "-o",
                 str(tmp_path / "out"), "--jobs", jobs]) == 2
    err = _lines(capsys.readouterr().err)
    assert len(err) == 1 and err[0].startswith(f"hammer-mv {command}: error: --jobs: "), err
    assert not (tmp_path / "out").exists()


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
    err = _lines(capsys.readouterr().err)
    assert len(err) == 1 and str(taken) in err[0] and "--output" in err[0], err
    assert "not a folder" in err[0]
    assert taken.read_text() == "not a folder"


@pytest.fixture(scope="module")
def tracks_file(tmp_path_factory):
    from _demos import demo_tracks

    path = tmp_path_factory.mktemp("clip") / "n.tracks.h5"
    demo_tracks("normal", 0)[0].save(path)
    return path


def test_recognize_quiet_prints_nothing(tracks_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["recognize", str(tracks_file), "-o", str(out), "--no-figures", "--quiet"]) == 0
    assert capsys.readouterr() == ("", "")
    assert (out / "n.recognition.json").exists()


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


def test_synth_quiet_prints_nothing(fake_synthesize, recipe, capsys):
    assert _synth(recipe, "--quiet") == 0
    assert capsys.readouterr() == ("", "")
    assert _synth(recipe) == 0
    assert _lines(capsys.readouterr().out)[0].startswith("wrote 2 clips to ")


# -- option values checked at the boundary

@pytest.mark.parametrize("argv, field", [
    (["reach", "--r", "-1"], "--r"),
    (["reach", "--sigma-s", "nan"], "--sigma-s"),
    (["reach", "--trials", "1"], "--trials"),
    (["grasp", "simulate", "--dt", "0"], "--dt"),
    (["grasp", "simulate", "--execution-cv", "-1"], "--execution-cv"),
    (["repertoire", "build", "--object-size", "-1"], "--object-size"),
    (["repertoire", "build", "--distance", "2"], "--distance"),
    (["repertoire", "build", "--durations", "0"], "--durations"),
    (["reach", "--seed", "-1"], "--seed"),  # numpy's own ValueError, checked first
    (["grasp", "experiment", "object-size", "--seed", "-1"], "--seed"),
    (["synth", "r.toml", "--seed", "-1"], "--seed"),
])
def test_option_values_are_named_not_tracebacks(argv, field, tmp_path, capsys):
    out = tmp_path / ("r.h5" if argv[0] == "repertoire" else "x")
    assert main([*argv, "-o", str(out)]) == 2
    err = _lines(capsys.readouterr().err)
    assert len(err) == 1 and f": error: {field}: " in err[0], err
    assert not out.exists()


@pytest.mark.parametrize("extra, field", [
    (["--w-g", "-1"], "--w-g"), (["--filter-gain", "2"], "--filter-gain"),
    (["--px-per-m", "0"], "--px-per-m"), (["--object-diameter", "inf"], "--object-diameter"),
    (["--pcutoff", "2"], "--pcutoff"), (["--keypoints", "thumb"], "--keypoints"),
])
def test_recognition_options_are_named(extra, field, tmp_path, capsys):
    clip = tmp_path / "a.tracks.h5"
    clip.write_bytes(b"")
    assert main(["recognize", str(clip), "-o", str(tmp_path / "out"), *extra]) == 2
    err = _lines(capsys.readouterr().err)
    assert len(err) == 1 and f"hammer-mv recognize: error: {field}: " in err[0], err


def test_checks_option_leaves_a_bug_a_bug():
    with pytest.raises(InputError) as info, checks.option("--trials"):
        raise ValueError("--trials: too many")
    assert str(info.value) == "--trials: too many" and info.value.field == "--trials"
    with pytest.raises(ValueError) as info, checks.options({"w_v": "--w-v"}):
        raise ValueError("ReachTask.shoulder: not a user's option")
    assert not isinstance(info.value, InputError)


# -- planning failures are PlanningErrors at their source

def test_an_unreachable_scene_is_a_planning_error():
    from perception.recognition.models import SceneSpec
    from perception.recognition.planning import build_model, default_specs

    with pytest.raises(PlanningError, match="outside the arm's reach"):
        build_model(default_specs([1.0])[0], SceneSpec(distance=2.0))


def _reference(self):
    from perception.recognition.models import SceneSpec

    return SceneSpec(), (0.6, 1.2)


def _scene_observation(monkeypatch):
    import perception.pipeline as pipeline
    from perception.synthetic.demos import demo_tracks

    obs = pipeline.observe(demo_tracks("normal", 0)[0], clip="c")
    monkeypatch.setattr(pipeline, "observe", lambda tracks, params, clip=None: obs)
    # no tracks at all: the start needs no settling either
    monkeypatch.setattr("perception.settling.settle_start",
                        lambda tracks, params, clip=None: (tracks, None))
    return pipeline


def test_recognize_tracks_names_the_clip_of_a_planning_error(monkeypatch):
    pipeline = _scene_observation(monkeypatch)

    class Unreachable:
        reference = _reference

        def for_scene(self, scene, cache=None):
            raise PlanningError("out of the arm's reach", field="distance")

    with pytest.raises(PlanningError) as info:
        pipeline.recognize_tracks(None, Unreachable(), source="clip.mp4")
    assert info.value.path == "clip.mp4" and info.value.field == "distance"
    assert "out of the arm's reach" in str(info.value) and "--px-per-m" in str(info.value)


def test_recognize_tracks_leaves_a_bug_a_bug(monkeypatch):
    pipeline = _scene_observation(monkeypatch)

    class Broken:
        reference = _reference

        def for_scene(self, scene, cache=None):
            raise ValueError("operands could not be broadcast together")

    with pytest.raises(ValueError) as info:
        pipeline.recognize_tracks(None, Broken(), source="clip.mp4")
    assert not isinstance(info.value, InputError | PlanningError)


@pytest.mark.parametrize("argv", [
    ["reach", "--trials", "5"],
    ["grasp", "simulate", "--trials", "2"],
    ["repertoire", "build", "--durations", "1.0"],
], ids=["reach", "grasp", "repertoire"])
def test_quiet_commands_print_nothing_on_success(argv, tmp_path, capsys):
    out = tmp_path / ("rep.h5" if argv[0] == "repertoire" else "out")
    assert main([*argv, "-o", str(out), "--quiet"]) == 0
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""
    assert out.exists()

import subprocess
import sys

import pytest

from hammer_mv.cli import main
from perception.errors import InputError


def test_version(capsys):
    try:
        main(["--version"])
    except SystemExit as exc:
        assert exc.code == 0
    assert "hammer-mv" in capsys.readouterr().out


def test_bad_option_is_one_line_exit_2():
    proc = subprocess.run(
        [sys.executable, "-m", "hammer_mv", "--no-such-option"],
        capture_output=True, text=True,
    )
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1
    assert "Traceback" not in proc.stderr


# -- the flags are contracts: written down before they were generated from the fields

#: The recognition flags recognize and batch (and watch) share: (flags, dest, default).
_RECOGNITION = [
    ("--repertoire", "repertoire", None), ("--rule", "rule", "likelihood"),
    ("--w-r", "w_r", 1.0), ("--w-g", "w_g", 2.0), ("--thesis-sign", "thesis_sign", "text"),
    ("--filter-gain", "filter_gain", 0.3), ("--object-diameter", "object_diameter", 0.1),
    ("--px-per-m", "px_per_m", None), ("--mirror", "mirror", False),
    ("--verdict-rules", "verdict_rules", None), ("--keypoints", "keypoints", None),
    ("--pose-config", "pose_config", None), ("--pcutoff", "pcutoff", None),
    ("--individual", "individual", None), ("--fps", "fps", None),
    ("--object-diameter-px", "object_diameter_px", None)]
#: The motion-capture and factor flags (recognize, batch, watch, landmarks).
_MOCAP = [
    ("--markers", "markers", None), ("--rate", "rate", None), ("--columns", "columns", None),
    ("--time-column", "time_column", None), ("--units", "units", None),
    ("--trial-column", "trial_column", None), ("--object-size", "object_size", None),
    ("--factors", "factors", None), ("--factors-from-name", "factors_from_name", None)]
_FIGURES = [("--figure-format", "figure_format", "png"), ("--dpi", "dpi", 120)]
_VIDEO = [("--keep-truncated", "keep_truncated", False), ("--setup", "setup", None)]
FLAGS = {
    "recognize": [("-o --output", "output", None), ("--no-figures", "no_figures", False),
                  *_FIGURES, *_RECOGNITION, *_MOCAP, *_VIDEO],
    "batch": [("-o --output", "output", None), ("--jobs", "jobs", 1),
              ("--scheduler", "scheduler", None), *_FIGURES, *_RECOGNITION, *_MOCAP, *_VIDEO],
    "landmarks": [("-o --output", "output", None), ("--wide", "wide", False),
                  ("--threshold", "threshold", 0.05), ("--speed", "speed", None),
                  ("--hold", "hold", 0.0), ("--cutoff", "cutoff", 10.0),
                  ("--px-per-m", "px_per_m", None), ("--object-diameter", "object_diameter", None),
                  *_RECOGNITION[-6:], *_MOCAP],  # the pose options, as recognize's
    # the simulation commands (issue 42 item 6: written down before they were generated)
    "reach": [("--start", "start", (0.2, 0.2)), ("--goal", "goal", (0.4, 0.5)),
              ("--duration", "duration", 0.5), ("--via", "via", []),
              ("--trials", "trials", None), ("--seed", "seed", 0), ("--sweep", "sweep", False),
              ("--durations", "durations", [0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2]),
              ("--r", "r", 2e-4), ("--w-v", "w_v", 0.2), ("--w-f", "w_f", 0.01),
              ("--sigma-u", "sigma_u", 0.4), ("--sigma-s", "sigma_s", 0.4),
              ("-o --output", "output", None)],
    "grasp simulate": [
        ("--object-size", "object_size", 0.04), ("--distance", "distance", 0.26),
        ("--duration", "duration", 1.0), ("--viapoint-offset", "viapoint_offset", 0.01),
        ("--viapoint-height", "viapoint_height", 0.0), ("--viapoint-time", "viapoint_time", 0.7),
        ("--tip-start", "tip_start", 0.02), ("--reach-only", "reach_only", False),
        ("--execution-cv", "execution_cv", 0.01), ("--dt", "dt", 0.01),
        ("--trials", "trials", 500), ("--seed", "seed", 0), ("-o --output", "output", None)],
    "repertoire build": [
        ("-o --output", "output", None),
        ("--durations", "durations", [0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2]),
        ("--distance", "distance", 0.25), ("--object-size", "object_size", 0.1),
        ("--fps", "fps", 30.0)],
}
#: What ``--help`` shows of the simulation commands' flags: (metavar, nargs, help).
SHOWN = {
    "reach": {
        "--start": (("X", "Y"), 2, "start position, m (default: 0.2 0.2, thesis Fig. 3.4)"),
        "--goal": (("X", "Y"), 2, "goal position, m (default: 0.4 0.5)"),
        "--duration": ("S", None, "movement time, s (default: 0.5)"),
        "--via": (("X", "Y", "FRACTION"), 3,
                  "via-point at (X, Y) m, at FRACTION (0-1) of the movement; repeatable"),
        "--trials": ("N", None, "repetitions (default: 100; 200 per duration with --sweep)"),
        "--seed": ("N", None, "random seed (default: 0)"),
        "--sweep": (None, 0, "speed-accuracy sweep over --durations instead of one movement"),
        "--durations": ("S", "+", "movement times for --sweep, s (default: 0.5 ... 1.2)"),
        "--r": (None, None, "effort weight r (default: 0.0002)"),
        "--w-v": (None, None, "final velocity weight (default: 0.2)"),
        "--w-f": (None, None, "final force weight (default: 0.01)"),
        "--sigma-u": (None, None, "control-dependent noise scale (default: 0.4)"),
        "--sigma-s": (None, None, "sensory noise scale (default: 0.4)"),
        "-o --output": ("DIR", None, "folder for the figures and tables")},
    "grasp simulate": {
        "--object-size": ("M", None, "object diameter, m (default 0.04)"),
        "--distance": ("M", None, "wrist start to object centre, m (default 0.26: the wrist "
                       "travels 0.2, stopping 0.06 short of the centre)"),
        "--duration": ("S", None, "movement time, s (default 1.0)"),
        "--viapoint-offset": ("M", None, "digit via-point distance outside the object, m "
                              "(default 0.01)"),
        "--viapoint-height": ("M", None, "digit via-point height above the target line, m "
                              "(default 0)"),
        "--viapoint-time": ("F", None, "digit via-point time, fraction of the movement "
                            "(default 0.7)"),
        "--tip-start": ("M", None, "how far ahead of the wrist the closed digit tips start, m "
                        "(default 0.02: below the target line, 0.06 ahead of the wrist at the "
                        "goal)"),
        "--reach-only": (None, 0, "transport only: the digits stay closed"),
        "--execution-cv": ("CV", None, "coefficient of variation of the execution noise "
                           "(default 0.01)"),
        "--dt": ("S", None, "time step, s (default 0.01)"),
        "--trials": ("N", None, "repetitions (default 500)"),
        "--seed": ("N", None, "random seed (default 0)"),
        "-o --output": ("DIR", None, "folder for the figures and tables")},
    "repertoire build": {
        "-o --output": ("REP.h5", None, "repertoire file to write (HDF5)"),
        # (says 0.8 where the default starts at 0.5: kept as users read it)
        "--durations": ("S", "+", "movement times without CONFIG (default: 0.8 ... 1.2)"),
        "--distance": (None, None, "wrist start to object centre, m (without CONFIG)"),
        "--object-size": (None, None, "object diameter, m (without CONFIG)"),
        "--fps": (None, None, "video frame rate (without CONFIG)")},
}
#: The flags whose values are a choice.
CHOICES = {"--rule": ("likelihood", "thesis"), "--thesis-sign": ("text", "printed"),
           "--units": ("mm", "cm", "m"), "--figure-format": ("png", "svg", "pdf")}


def _parser(command):
    """The parser of ``command`` (``"grasp simulate"``: a subcommand's)."""
    import argparse

    from hammer_mv.cli import build_parser

    names = command.split()
    parser = build_parser(names[0])
    for name in names:
        (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        parser = sub.choices[name]
    return parser


@pytest.mark.parametrize("command", sorted(FLAGS))
def test_the_generated_flags_are_todays(command):
    parser = _parser(command)
    got = [(" ".join(a.option_strings), a.dest, a.default) for a in parser._actions
           if a.option_strings and a.dest not in ("help", "verbose", "quiet")]
    assert got == FLAGS[command]
    for action in parser._actions:
        if action.option_strings and action.option_strings[-1] in CHOICES:
            assert tuple(action.choices) == CHOICES[action.option_strings[-1]]


@pytest.mark.parametrize("command", sorted(SHOWN))
def test_the_simulation_flags_help_is_todays(command):
    shown = {" ".join(a.option_strings): (a.metavar, a.nargs, a.help)
             for a in _parser(command)._actions
             if a.option_strings and a.dest not in ("help", "verbose", "quiet")}
    assert shown == SHOWN[command]
    types = {" ".join(a.option_strings): a.type for a in _parser(command)._actions}
    assert {types[f] for f in SHOWN[command] if SHOWN[command][f][1] != 0
            and f not in ("-o --output", "--trials", "--seed")} == {float}


def test_a_field_and_its_flag_are_one_map():
    from hammer_mv.cli.flags import FIELD_FLAGS, OWNER_FLAGS

    _parser("recognize")
    _parser("landmarks")
    for flags, dest, _ in [*_RECOGNITION, *_MOCAP]:
        if dest in FIELD_FLAGS:  # a flag that sets a field: its flag is the field's
            assert FIELD_FLAGS[dest] == flags
    assert OWNER_FLAGS[("ObserveParams", "px_per_m")] == "--px-per-m"
    assert OWNER_FLAGS[("ReachParams", "object_size")] == "--object-size"
    assert OWNER_FLAGS[("LandmarkParams", "cutoff")] == "--cutoff"
    # the files and tables the user names are no fields
    assert "setup" not in FIELD_FLAGS and "verdict_rules" not in FIELD_FLAGS


def test_the_simulation_flags_are_the_fields_flags():
    from hammer_mv.cli.flags import OWNER_FLAGS

    for command in ("reach", "grasp simulate", "repertoire build"):
        _parser(command)
    assert OWNER_FLAGS[("ReachTask", "w_v")] == "--w-v"
    assert OWNER_FLAGS[("PointMassPlant", "sigma_s")] == "--sigma-s"
    assert OWNER_FLAGS[("GraspTask", "viapoint_time")] == "--viapoint-time"
    assert OWNER_FLAGS[("PointMassPlant", "dt")] == "--dt"
    assert OWNER_FLAGS[("SceneSpec", "object_size")] == "--object-size"
    # the flags that set no field: a count, a seed, a rate turned into a period, a list
    assert not {("ReachTask", "via_points"), ("SceneSpec", "frame_period")} & set(OWNER_FLAGS)


@pytest.mark.parametrize("error, line", [
    (InputError("no sampling rate: give it with `rate`", "t.tsv", field="rate"),
     "t.tsv: --rate: no sampling rate: give it with --rate"),
    (InputError("expected a number > 0, got -1.0", location=("ObserveParams", "px_per_m")),
     "--px-per-m: expected a number > 0, got -1.0"),
    # a file's value keeps the file's key; a field no flag sets keeps its name
    (InputError("expected a number > 0", "r.toml", field="[verdict.landmarks] cutoff",
                location=("LandmarkParams", "cutoff")),
     "r.toml: [verdict.landmarks] cutoff: expected a number > 0"),
    (InputError("`shoulder` is not a flag", field="shoulder"),
     "shoulder: `shoulder` is not a flag"),
], ids=["a field and a field in the text", "a declared class's field", "a file's key",
        "a field without a flag"])
def test_the_error_line_names_the_flag_where_the_library_names_the_field(error, line):
    from hammer_mv.cli import error_line

    _parser("recognize")
    assert error_line("recognize", error) == f"hammer-mv recognize: error: {line}"


def test_a_library_log_line_names_fields_and_the_command_line_gives_their_flags():
    """The library's warnings name its fields (```factors_from_name```, ```rois```), as
    its errors do; the command line's log handler gives them as the flags that set them,
    and leaves a handler it did not make alone."""
    import logging

    from hammer_mv.cli import _flag_words

    _parser("landmarks")
    record = logging.LogRecord("perception.factors", logging.WARNING, __file__, 1,
                               "%s: `factors_from_name` %r does not match", ("a.tsv", "P"),
                               None)
    assert _flag_words(record)
    assert record.getMessage() == "a.tsv: --factors-from-name 'P' does not match"
    record = logging.LogRecord("perception.tracking", logging.WARNING, __file__, 1,
                               "give `rois` thumb X Y W H; `no_such_field` stays", (), None)
    _flag_words(record)
    assert record.getMessage() == "give --roi thumb X Y W H; `no_such_field` stays"
    root = logging.getLogger()
    theirs = logging.NullHandler()
    root.addHandler(theirs)
    try:
        assert main([]) == 2  # no command: the help, after logging is set up
    finally:
        root.removeHandler(theirs)
    assert _flag_words not in theirs.filters


def test_a_batch_names_the_flag_of_the_field_a_clip_failed_on(tmp_path):
    """A clip's error as a batch keeps it begins with the field it names ("time_column: no
    column ..."): the failure line gives it as the flag the user typed."""
    from types import SimpleNamespace

    import pandas as pd

    from hammer_mv.cli import build_parser
    from hammer_mv.cli.batch import failure_reasons
    from hammer_mv.cli.flags import flag_text

    build_parser("batch")  # the command's flags, as its run has them
    table = tmp_path / "trials.tsv"
    summary = pd.DataFrame({"clip": ["trials"], "status": ["failed"],
                            "error": [f"{table.absolute()}: time_column: no column 'globalTime'"]})
    items = [SimpleNamespace(clip="trials", path=table)]
    assert failure_reasons(summary, items) == "1: --time-column: no column 'globalTime'"
    # a word that is no field, or a field named later, keeps its words
    assert flag_text("trial 3: no reach found") == "trial 3: no reach found"
    assert flag_text("no column 'x' (time_column)") == "no column 'x' (time_column)"
    assert flag_text("check `px_per_m`") == "check --px-per-m"

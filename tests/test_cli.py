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
                  ("--object-diameter-px", "object_diameter_px", None), ("--fps", "fps", None),
                  *_MOCAP],
}
#: The flags whose values are a choice.
CHOICES = {"--rule": ("likelihood", "thesis"), "--thesis-sign": ("text", "printed"),
           "--units": ("mm", "cm", "m"), "--figure-format": ("png", "svg", "pdf")}


def _parser(command):
    import argparse

    from hammer_mv.cli import build_parser

    top = build_parser(command)
    (sub,) = [a for a in top._actions if isinstance(a, argparse._SubParsersAction)]
    return sub.choices[command]


@pytest.mark.parametrize("command", sorted(FLAGS))
def test_the_generated_flags_are_todays(command):
    parser = _parser(command)
    got = [(" ".join(a.option_strings), a.dest, a.default) for a in parser._actions
           if a.option_strings and a.dest not in ("help", "verbose", "quiet")]
    assert got == FLAGS[command]
    for action in parser._actions:
        if action.option_strings and action.option_strings[-1] in CHOICES:
            assert tuple(action.choices) == CHOICES[action.option_strings[-1]]


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

"""The command line explains itself: help on every argument, defaults shown, common flags."""

import argparse
import re

import pytest

from hammer_mv.cli import build_parser


def _parsers(parser, path=("hammer-mv",)):
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                yield from _parsers(child, (*path, name))


PARSERS = list(_parsers(build_parser()))
LEAVES = [(path, p) for path, p in PARSERS
          if not any(isinstance(a, argparse._SubParsersAction) for a in p._actions)]


def _arguments(parser):
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction | argparse._VersionAction
                      | argparse._SubParsersAction):
            continue
        yield action


@pytest.mark.parametrize("path, parser", PARSERS, ids=[" ".join(p) for p, _ in PARSERS])
def test_every_argument_has_help(path, parser):
    missing = [a.dest for a in _arguments(parser) if not (a.help or "").strip()]
    assert not missing, f"{' '.join(path)}: arguments without help: {missing}"


@pytest.mark.parametrize("path, parser", PARSERS, ids=[" ".join(p) for p, _ in PARSERS])
def test_defaults_are_shown(path, parser):
    text = parser.format_help()
    for action in _arguments(parser):
        if (action.option_strings and action.default not in (None, argparse.SUPPRESS)
                and not isinstance(action.default, bool)):
            helped = parser._get_formatter()._get_help_string(action)
            assert "default" in helped, f"{' '.join(path)} {action.option_strings[0]}"
    assert "usage:" in text


@pytest.mark.parametrize("path, parser", LEAVES, ids=[" ".join(p) for p, _ in LEAVES])
def test_verbose_and_quiet_after_the_command(path, parser):
    flags = {s for a in parser._actions for s in a.option_strings}
    assert {"-v", "--verbose", "--quiet"} <= flags, " ".join(path)


def test_a_flag_means_the_same_before_and_after_the_command(tmp_path):
    parser = build_parser()
    before = parser.parse_args(["-v", "--quiet", "tracks", "info", "x.tracks.h5"])
    after = parser.parse_args(["tracks", "info", "x.tracks.h5", "-v", "--quiet"])
    neither = parser.parse_args(["tracks", "info", "x.tracks.h5"])
    assert before.verbose and before.quiet and after.verbose and after.quiet
    assert not neither.verbose and not neither.quiet


def test_the_top_level_help_explains_the_pipeline():
    text = build_parser().format_help()
    assert "video" in text and "tracks" in text and "recognize" in text and "example" in text
    for name in ("synth", "track", "tracks", "recognize", "batch", "calibrate", "reach", "grasp",
                 "repertoire"):
        assert f"    {name}" in text


def test_batch_help_names_every_kind_it_reads_and_that_subfolders_are_not():
    # it named videos, tracks and pose files: a lab with motion-capture tables could not
    # tell from --help that batch takes them, nor that P01/, P02/ are not read
    batch = dict(PARSERS)[("hammer-mv", "batch")]
    text = re.sub(r"-\s+", "-", " ".join(batch.format_help().split()))  # wrapped at hyphens
    assert "motion-capture recordings, or a manifest.csv" in text
    assert "not its subfolders" in text and "skipped and listed" in text

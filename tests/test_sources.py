"""The kinds of input in one registry (perception/sources.py, issue 42 item 1): what each input
is, and every command refusing, up front and in one line, a kind it does not take."""

from __future__ import annotations

from pathlib import Path

import pytest

from hammer_mv.cli import main
from perception.errors import InputError
from perception.sources import KINDS, check_command, clip_name, input_kind

DATA = Path(__file__).parent / "data" / "mocap"
COMMANDS = ("recognize", "landmarks", "batch", "watch")


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    """An input of every kind, by kind (files that need to exist are written)."""
    d = tmp_path_factory.mktemp("kinds")
    pose = d / "trial01DLC_resnet50_hands.csv"
    pose.write_text("scorer,a\nbodyparts,thumb\ncoords,x\n0,1.0\n")
    return {"camera": "0", "stream": "udp://127.0.0.1:5000", "tracks": str(d / "c.tracks.h5"),
            "video": str(d / "c.MP4"), "mocap": str(DATA / "optotrak-trials.tsv"),
            "pose": str(pose)}


def test_every_kind_is_recognised_in_its_order(examples):
    for name, spec in examples.items():
        assert input_kind(spec).name == name, spec
    assert [k.name for k in KINDS] == ["camera", "stream", "tracks", "video", "mocap", "pose"]
    assert input_kind("notes.json") is None
    # a tracks file is not read as a pose file (.h5), a table of a known layout not as one
    assert clip_name(examples["tracks"]) == ("c", "tracks")
    assert clip_name(examples["pose"]) == ("trial01", "pose")
    assert clip_name(examples["mocap"]) == ("optotrak-trials", "mocap")
    assert clip_name("udp://127.0.0.1:5000") == ("stream", "stream")
    assert clip_name("notes.json") == ("notes", "unknown")


CASES = [(command, name) for command in COMMANDS for name in
         ("camera", "stream", "tracks", "video", "mocap", "pose")
         if not next(k for k in KINDS if k.name == name).takes(command)]


def test_the_refused_cases_are_what_the_commands_cannot_read():
    assert sorted(CASES) == sorted([("batch", "camera"), ("batch", "stream"),
                                    ("landmarks", "camera"), ("landmarks", "stream"),
                                    ("recognize", "camera"), ("recognize", "stream"),
                                    ("watch", "tracks")])


@pytest.mark.parametrize("command, name", CASES)
def test_a_kind_a_command_cannot_take_is_refused_up_front_in_one_line(examples, tmp_path,
                                                                      capsys, command, name):
    spec = examples[name]
    with pytest.raises(InputError) as err:
        check_command(spec, command)
    assert f"{command} takes" in err.value.problem
    out = tmp_path / ("t.csv" if command == "landmarks" else "out")
    rc = main([command, spec, "-o", str(out)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(lines) == 1, lines
    # the input as typed (a URL keeps its "//"), what it is, what the command takes instead
    assert lines[0].startswith(f"hammer-mv {command}: error: {spec}: ")
    assert next(k for k in KINDS if k.name == name).what in lines[0]
    assert "hammer-mv watch" in lines[0] or "hammer-mv recognize" in lines[0]
    assert not out.exists()  # refused before anything was written

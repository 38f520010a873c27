"""``hammer-mv`` run in the test's own process, its console read as a subprocess's."""

from __future__ import annotations

import contextlib
import os
from typing import NamedTuple


class Ran(NamedTuple):
    """What a command gave: as :class:`subprocess.CompletedProcess` names it."""

    returncode: int
    stdout: str
    stderr: str


@contextlib.contextmanager
def _environment_kept():
    """``os.environ`` put back as it was once the command ends.

    ``main()`` sets OpenCV's and FFmpeg's log levels for its process
    (``os.environ.setdefault``); left set, they pass to every later subprocess
    of the test process, and a test that a subprocess prints no FFmpeg chatter
    would pass without ``main()``'s own settings.
    """
    saved = dict(os.environ)
    try:
        yield
    finally:
        if dict(os.environ) != saved:
            os.environ.clear()
            os.environ.update(saved)


def main_here(*args) -> int:
    """``hammer-mv *args`` run in this process: its exit status, the console left to pytest
    (for a fixture, which ``capsys`` does not reach)."""
    from hammer_mv.cli import main

    with _environment_kept():
        return main([str(a) for a in args])


def hammer_here(capsys, *args) -> Ran:
    """``hammer-mv *args`` run in this process (``capsys`` pytest's fixture).

    For the tests of the lines and files a command writes: a subprocess adds the CLI's
    imports and a repertoire's planning (seconds of CPU) to each run. How a process
    exits (exit status 2 in one line, hangs, crashes, signals) stays in subprocesses.
    """
    capsys.readouterr()
    status = main_here(*args)
    out, err = capsys.readouterr()
    return Ran(status, out, err)

"""``hammer-mv`` run in the test's own process, its console read as a subprocess's."""

from __future__ import annotations

from typing import NamedTuple


class Ran(NamedTuple):
    """What a command gave: as :class:`subprocess.CompletedProcess` names it."""

    returncode: int
    stdout: str
    stderr: str


def main_here(*args) -> int:
    """``hammer-mv *args`` run in this process: its exit status, the console left to pytest
    (for a fixture, which ``capsys`` does not reach)."""
    from hammer_mv.cli import main

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

"""Checks shared by tests/test_faults*.py: one error line, a named InputError, a FIFO read."""

from __future__ import annotations

import os
import threading

import pytest

from perception.errors import InputError


def one_line(stderr: str, *pieces: str) -> str:
    """The only line of ``stderr`` (no traceback, no warning), checked to hold every piece."""
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr[-2000:]
    for piece in pieces:
        assert piece in lines[0], lines[0]
    return lines[0]


def refused(call, *args, path=None, field=..., match=None) -> InputError:
    """The InputError of ``call(*args)``, checked to name ``path`` and ``field`` (where given)."""
    with pytest.raises(InputError, match=match) as err:
        call(*args)
    if path is not None:
        assert err.value.path == str(path), str(err.value)
    if field is not ...:
        assert err.value.field == field, str(err.value)
    return err.value


def error_within(call, path, seconds=60.0):
    """``call(path)``'s exception (None if it returned); fails if it reads past ``seconds``.

    A reader that opens a FIFO with no writer blocks for ever, one that refuses it
    returns: ``seconds`` only bounds that wait (a hang, not a speed: a busy machine takes
    longer to refuse, never for ever).
    """
    box = {}

    def run():
        try:
            call(path)
        except BaseException as exc:  # noqa: BLE001 - handed to the test thread
            box["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))  # unblock the reader so it ends
        pytest.fail(f"{call} still reading the FIFO {path} after {seconds} s")
    return box.get("error")

"""Checks of option values at the command line's boundary.

A value the user typed that a library refuses with a bare ``ValueError``
would show a traceback (bare ``ValueError``\\ s are bugs: see
:mod:`perception.errors`). The commands check such values here, or wrap the
one call that checks them in :func:`option`, and raise
:class:`~perception.errors.InputError` naming the option.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager, suppress
from pathlib import Path

from perception.errors import HammerMVError, InputError

__all__ = ["WORKER_BYTES", "cap_jobs", "check_seed", "free_memory", "option", "options",
           "output_folder", "usable_cores", "writable_folder"]

#: Memory one worker process may need (a clip's frames, tracks and models), bytes.
WORKER_BYTES = 600 * 2**20


@contextmanager
def option(field: str) -> Iterator[None]:
    """A ``ValueError`` raised inside becomes an :class:`InputError` naming ``field``.

    Wrap only a call that checks the option's value (a limit check, a
    constructor's validation), never a computation: a ``ValueError`` from
    deeper down is a bug.

    Parameters
    ----------
    field : str
        The option, as typed (``"--trials"``).
    """
    try:
        yield
    except HammerMVError as exc:
        if exc.path is not None or exc.field == field:
            raise
        # a library's own name for the value ("ViaPoint.position") after the option's
        problem = exc.problem if exc.field is None else f"{exc.field}: {exc.problem}"
        raise type(exc)(problem.removeprefix(f"{field}: "), field=field) from None
    except ValueError as exc:
        raise InputError(str(exc).removeprefix(f"{field}: "), field=field) from None


#: ``Owner.attribute[i]: message`` of the minvar and perception validators.
_ATTRIBUTE = re.compile(r"^\s*(?:[A-Za-z_][\w.]*\.)?([A-Za-z_]\w*)(?:\[\d+\])?: (.*)$", re.S)


@contextmanager
def options(fields: Mapping[str, str]) -> Iterator[None]:
    """Like :func:`option` for a constructor taking several options.

    The ``ValueError``'s message names the attribute at fault
    (``"ReachTask.w_v: expected ..."``) or the option itself
    (``"--pcutoff: expected ..."``); ``fields`` maps attribute names to the
    options that set them. An error about an attribute no option sets is
    not the user's: it propagates unchanged (a bug).

    Parameters
    ----------
    fields : mapping of str to str
        Attribute name -> option (``{"w_v": "--w-v"}``).
    """
    try:
        yield
    except HammerMVError as exc:
        if exc.path is None and exc.field:  # field="ReachTask.w_v" (or "w_v")
            attribute = exc.field.rsplit(".", 1)[-1]
            if attribute in fields:
                raise type(exc)(exc.problem, field=fields[attribute]) from None
        if exc.path is None and exc.field is None:
            renamed = _renamed(exc.problem, fields)
            if renamed is not None:
                raise type(exc)(renamed[0], field=renamed[1]) from None
        raise
    except ValueError as exc:
        renamed = _renamed(str(exc), fields)
        if renamed is None:
            raise
        raise InputError(renamed[0], field=renamed[1]) from None


def _renamed(message: str, fields: Mapping[str, str]) -> tuple[str, str | None] | None:
    """(problem, option) for :func:`options`, or None if the message names no option."""
    flag = next((f for f in fields.values() if message.startswith((f"{f}: ", f"{f} "))), None)
    if flag is not None:  # the message names the flag itself
        if message.startswith(f"{flag}: "):
            return message.removeprefix(f"{flag}: "), flag
        return message, None  # "--flag VALUE: ..."
    match = _ATTRIBUTE.match(message)
    if match is None or match.group(1) not in fields:
        return None
    field = fields[match.group(1)]
    return match.group(2).removeprefix(f"{field}: "), field


def check_seed(seed: int, field: str = "--seed") -> int:
    """``seed`` if numpy can seed with it (an integer >= 0), else an InputError."""
    if seed < 0:
        raise InputError(f"expected an integer >= 0, got {seed}", field=field)
    return seed


def output_folder(path: Path, field: str = "--output") -> Path:
    """``path``, refused at once if it exists and is not a folder.

    Parameters
    ----------
    path : Path
        The output folder the user named.
    field : str
        Its option.
    """
    if path.exists() and not path.is_dir():
        raise InputError("exists and is not a folder (expected an output folder)", path,
                         field=field)
    return path


def writable_folder(path: Path, field: str = "--output") -> Path:
    """``path`` (the output folder ``field`` names), refused at once unless it is or can be
    made a folder this process writes in: its nearest folder that exists is tried."""
    output_folder(path, field)
    nearest = path
    while not nearest.exists() and nearest.parent != nearest:
        nearest = nearest.parent
    try:
        tempfile.TemporaryFile(dir=nearest).close()
    except OSError as exc:
        raise InputError(f"cannot write here: {exc.strerror or exc}", path, field=field) from None
    return path


def usable_cores() -> int:
    """CPU cores this process may run on (its affinity mask where there is one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # not on every platform
        return os.cpu_count() or 1


def free_memory() -> int | None:
    """Memory available to new processes, bytes (psutil's ``available``), or None if unknown."""
    import psutil

    with suppress(OSError, RuntimeError):
        return int(psutil.virtual_memory().available)
    return None


def cap_jobs(requested: int, command: str, *, quiet: bool = False) -> int:
    """``--jobs`` checked and capped at what the machine allows.

    At most one process per usable core and one per :data:`WORKER_BYTES` of
    free memory (no memory cap where it cannot be read). A cap is told in one
    line on stderr unless ``quiet``.

    Parameters
    ----------
    requested : int
        The ``--jobs`` the user gave.
    command : str
        The command, for the message (``"batch"``).
    quiet : bool
        Say nothing when capping.

    Raises
    ------
    InputError
        ``requested`` is below 1.
    """
    if requested < 1:
        raise InputError(f"expected at least 1 process, got {requested}", field="--jobs")
    cores = usable_cores()
    memory = free_memory()
    limit = cores if memory is None else min(cores, max(1, memory // WORKER_BYTES))
    if requested <= limit:
        return requested
    if not quiet:
        free = "" if memory is None else f", {memory / 2**30:.1f} GiB free"
        print(f"hammer-mv {command}: --jobs {requested} capped at {limit} "
              f"({cores} core{'s' if cores != 1 else ''}{free})", file=sys.stderr)
    return limit

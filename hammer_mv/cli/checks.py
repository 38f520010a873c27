"""Checks of option values at the command line's boundary.

A value the user typed that a library refuses must not show a traceback
(bare ``ValueError``\\ s are bugs: see :mod:`perception.errors`). The
commands check such values here, or wrap the call that checks them in
:func:`options`, which renames the error's structured location to the flag
through a table.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager, suppress
from pathlib import Path

from minvar.errors import LocatedError
from perception.errors import HammerMVError, InputError

__all__ = ["WORKER_BYTES", "cap_jobs", "check_seed", "free_memory", "options",
           "output_folder", "usable_cores", "writable_folder"]

#: Memory one worker process may need (a clip's frames, tracks and models), bytes.
WORKER_BYTES = 600 * 2**20


@contextmanager
def options(flags: Mapping[str, str] | str) -> Iterator[None]:
    """An error about a value the user typed, raised inside, names the flag that gave it.

    Wrap only calls that check values (constructors, limit checks), never a
    computation: a bare ``ValueError`` from deeper down is a bug.

    Parameters
    ----------
    flags : mapping of str to str, or str
        Attribute -> flag (``{"w_v": "--w-v"}``), read off the error's
        structured ``location`` (:mod:`minvar.validation`); an error about an
        attribute no flag sets propagates unchanged. A single flag names
        every error raised inside.
    """
    try:
        yield
    except ValueError as exc:
        error = exc if isinstance(exc, LocatedError) else None
        if isinstance(flags, str):
            if error is None:  # a check function's own words, about this one value
                raise InputError(str(exc), field=flags) from None
            if error.path is not None and isinstance(error, HammerMVError):
                raise
            # a library's own name for the value ("ViaPoint.position") after the flag
            named = error.field not in (None, flags)
            raise _user(error)(f"{error.field}: {error.problem}" if named else error.problem,
                               error.path, field=flags) from None
        flag = flags.get(error.location[-1]) if error is not None and error.location else None
        if flag is None:
            raise
        raise _user(error)(error.problem, field=flag, location=error.location) from None


def _user(error: LocatedError) -> type[HammerMVError]:
    """The user's error class for ``error`` (minvar's ParameterError is an InputError here)."""
    return type(error) if isinstance(error, HammerMVError) else InputError


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

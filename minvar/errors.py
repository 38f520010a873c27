"""Errors about a value that say where it is: the file, the field, and the field as data.

Kept apart from :mod:`minvar.validation` (which loads pydantic and numpy) so
that a command line can tell these errors apart without loading either.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Iterable

__all__ = ["LocatedError", "ParameterError", "suggest"]


class LocatedError(Exception):
    """An error about a value, saying where it is: the file, the field, and the field as data.

    Parameters
    ----------
    message : str
        What is wrong, phrased for the user.
    path : str or os.PathLike, optional
        The file the problem is in; prefixed to the message.
    field : str, optional
        The field (option, TOML key, HDF5 dataset or attribute) the problem
        is in; named after the file. Default: ``location`` joined by dots.
    location : tuple of str, optional
        Where the problem is, as data: ``("ReachTask", "w_v")`` for a
        parameter class's field. A reader of a file or the command line
        renames it to the key or flag the user wrote (through a table).
    """

    def __init__(self, message: str, path: str | os.PathLike | None = None, *,
                 field: str | None = None, location: tuple[str, ...] = ()):
        self.path = None if path is None else os.fspath(path)
        self.location = tuple(location)
        self.field = field if field is not None or not location else ".".join(location)
        self.problem = message
        super().__init__(": ".join([p for p in (self.path, self.field) if p] + [message]))

    def at(self, path: str | os.PathLike | None) -> LocatedError:
        """The same error (its kind, field and location) said of ``path``: the file the
        user gave, where the problem was found in one made from it.

        Parameters
        ----------
        path : str or os.PathLike, optional
            The file to name.
        """
        return type(self)(self.problem, path, field=self.field, location=self.location)

    def __reduce__(self):
        # rebuilt in the parent process when a worker raises it
        return _rebuild, (type(self), self.problem, self.path, self.field, self.location)


def _rebuild(cls, problem, path, field, location=()):
    return cls(problem, path, field=field, location=location)


class ParameterError(LocatedError, ValueError):
    """A parameter out of its declared type or range (``ReachTask.w_v: expected ...``).

    Takes ``message``, ``path``, ``field`` and ``location`` as :class:`LocatedError` does.
    """


def suggest(name: str, valid: Iterable[str]) -> str:
    """``" (did you mean 'x'?)"`` for the valid name nearest ``name``, or ``""``.

    Parameters
    ----------
    name : str
        What was written.
    valid : iterable of str
        What may be written there.
    """
    close = difflib.get_close_matches(str(name), [str(v) for v in valid], n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""

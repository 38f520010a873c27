"""Errors that are the user's to fix, told apart from bugs.

Every error hammer-mv raises on purpose derives from :class:`HammerMVError`
and also from the builtin a caller would expect (``except ValueError`` still
catches a bad file). The CLI prints a ``HammerMVError`` (or an ``OSError``
from the user's files) as one line and exits with status 2; anything else —
a bare ``ValueError`` from deep inside included — is a bug and shows its
traceback.
"""

from __future__ import annotations

import os

__all__ = ["HammerMVError", "InputError", "PlanningError", "TrackingError"]


class HammerMVError(Exception):
    """Base of the errors a user can fix: a bad file, option or scene.

    Parameters
    ----------
    message : str
        What is wrong, phrased for the user.
    path : str or os.PathLike, optional
        The file the problem is in; prefixed to the message.
    field : str, optional
        The field (option, TOML key, HDF5 dataset or attribute) the problem
        is in; named after the file.
    """

    def __init__(self, message: str, path: str | os.PathLike | None = None, *,
                 field: str | None = None):
        self.path = None if path is None else os.fspath(path)
        self.field = field
        self.problem = message
        where = [p for p in (self.path, field) if p]
        super().__init__(": ".join([*where, message]))

    def __reduce__(self):
        # rebuilt in the parent process when a worker raises it
        return _rebuild, (type(self), self.problem, self.path, self.field)


def _rebuild(cls, problem, path, field):
    return cls(problem, path, field=field)


class InputError(HammerMVError, ValueError):
    """Bad input the user can fix: a missing or corrupt file, an impossible option.

    Takes ``message``, ``path`` and ``field`` as :class:`HammerMVError` does.
    """


class TrackingError(InputError):
    """A video that cannot be tracked: markers never found, too few frames, a broken stream.

    Takes ``message``, ``path`` and ``field`` as :class:`HammerMVError` does.
    """


class PlanningError(HammerMVError, ValueError):
    """A scene the models cannot be planned for (out of the arm's reach, a bad scale).

    Takes ``message``, ``path`` and ``field`` as :class:`HammerMVError` does.
    """

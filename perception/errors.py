"""Errors that are the user's to fix, told apart from bugs.

Every error hammer-mv raises on purpose derives from :class:`HammerMVError`
and also from the builtin a caller would expect (``except ValueError`` still
catches a bad file). The CLI prints a ``HammerMVError`` (or an ``OSError``
from the user's files) as one line and exits with status 2; anything else —
a bare ``ValueError`` from deep inside included — is a bug and shows its
traceback.
"""

from __future__ import annotations

from minvar.errors import LocatedError

__all__ = ["HammerMVError", "InputError", "PlanningError", "TrackingError"]


class HammerMVError(LocatedError):
    """Base of the errors a user can fix: a bad file, option or scene.

    Takes ``message``, ``path``, ``field`` and ``location`` as
    :class:`minvar.errors.LocatedError` does.
    """


class InputError(HammerMVError, ValueError):
    """Bad input the user can fix: a missing or corrupt file, an impossible option.

    Takes ``message``, ``path``, ``field`` and ``location`` as :class:`HammerMVError` does.
    """


class TrackingError(InputError):
    """A video that cannot be tracked: markers never found, too few frames, a broken stream.

    Takes ``message``, ``path``, ``field`` and ``location`` as :class:`HammerMVError` does.
    """


class PlanningError(HammerMVError, ValueError):
    """A scene the models cannot be planned for (out of the arm's reach, a bad scale).

    Takes ``message``, ``path``, ``field`` and ``location`` as :class:`HammerMVError` does.
    """

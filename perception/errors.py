"""The one error type for a user's mistakes (bad files, bad options)."""

from __future__ import annotations

import os


class InputError(ValueError):
    """Bad input the user can fix: a missing or corrupt file, an impossible option.

    The CLI prints it as one line and exits with status 2.

    Parameters
    ----------
    message : str
        What is wrong, phrased for the user.
    path : str or os.PathLike, optional
        The file the problem is in; prefixed to the message.
    """

    def __init__(self, message: str, path: str | os.PathLike | None = None):
        self.path = None if path is None else os.fspath(path)
        self.problem = message
        super().__init__(f"{self.path}: {message}" if self.path else message)

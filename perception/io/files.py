"""Input files are regular files, checked before anything opens them.

Opening a FIFO blocks until someone writes to it, and reading ``/dev/zero``
or ``/dev/urandom`` never ends: hashing or decoding such an "input" hangs a
command for ever. Every file a user names (clips, setups, colour files,
repertoires, manifests) goes through :func:`input_file` first, which only
``stat``\\ s it (following symbolic links, so a link to a device is refused too).
"""

from __future__ import annotations

import hashlib
import os
import stat
from pathlib import Path

from perception.errors import InputError

__all__ = ["input_file", "is_regular_file", "sha256_file"]


def is_regular_file(path: str | os.PathLike) -> bool:
    """Whether ``path`` is (or links to) a regular file; never opens it."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):  # ValueError: a NUL in the name
        return False


def input_file(path: str | os.PathLike, what: str = "file", *, empty: bool = True) -> Path:
    """``path`` as a Path if it is a regular file that can be read.

    Parameters
    ----------
    path : str or os.PathLike
        The file the user named.
    what : str
        What the file is meant to be, for the message (``"video"``, ``"setup file"``).
    empty : bool
        Whether an empty file can be one (a setup file of defaults can; a
        recording cannot, and its reader's own complaint would not say why).

    Raises
    ------
    InputError
        Missing, a folder, not a regular file (a FIFO, device or socket, or
        a symbolic link to one), or empty where ``empty`` is false.
    """
    p = Path(path)
    try:
        mode = os.stat(p).st_mode
    except FileNotFoundError:
        raise InputError(f"{what} not found", p) from None
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read the {what}: {getattr(exc, 'strerror', None) or exc}",
                         p) from None
    if stat.S_ISDIR(mode):
        raise InputError(f"is a folder, not a {what}", p)
    if not stat.S_ISREG(mode):
        raise InputError(f"is not a regular file (a FIFO, device or socket); expected a {what}",
                         p)
    if not empty and os.stat(p).st_size == 0:
        raise InputError(f"empty file (0 bytes); expected a {what}", p)
    return p


def sha256_file(path: str | os.PathLike) -> str:
    """Hex SHA-256 of the file at ``path``, read in pieces (memory stays flat).

    Here, not with the video readers, so that fingerprinting a table or a
    pose file never loads OpenCV.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    """
    with open(path, "rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()

"""TOML files read strictly: a misspelt table or key is an error that names the nearest valid one.

A recipe with ``[scence]`` or a repertoire config with ``[[models]]`` must
not pass silently and build something else: every reader of a TOML file
checks each table it reads with :func:`check_keys`.
"""

from __future__ import annotations

import difflib
import os
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from perception.errors import InputError

__all__ = ["check_keys", "read_toml", "suggest"]


def suggest(name: str, valid: Iterable[str]) -> str:
    """``" (did you mean 'x'?)"`` for the valid name nearest ``name``, or ``""``.

    Parameters
    ----------
    name : str
        What was written.
    valid : iterable of str
        What may be written there.
    """
    close = difflib.get_close_matches(name, list(valid), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check_keys(table: Mapping[str, Any], valid: Iterable[str], where: str) -> None:
    """Refuse keys of ``table`` that are not in ``valid``, naming the nearest valid one.

    Parameters
    ----------
    table : mapping
        A table read from TOML.
    valid : iterable of str
        Its allowed keys.
    where : str
        The table's name in the file, for the message (``"[scene]"``, ``"the
        top level"``).

    Raises
    ------
    ValueError
        For the first unknown key (the caller adds the file's name).
    """
    valid = list(valid)
    for key in table:
        if key not in valid:
            raise ValueError(f"{where}: unknown key {key!r}{suggest(key, valid)}; "
                             f"expected one of {', '.join(valid)}")


def read_toml(path: str | os.PathLike, what: str) -> dict[str, Any]:
    """The tables of a TOML file, with one-line errors for a missing or malformed file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for messages ("recipe", "repertoire config").

    Raises
    ------
    InputError
        The file is missing, unreadable, not UTF-8 or not valid TOML.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{what} not found", path)
    if not path.is_file():
        raise InputError(f"{what} is not a regular file", path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the {what}: {exc}", path) from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML: {exc}", path) from None

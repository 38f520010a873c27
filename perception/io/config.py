"""TOML files read strictly: a misspelt table or key is an error that names the nearest valid one.

A recipe with ``[scence]`` or a repertoire config with ``[[models]]`` must
not pass silently and build something else. Every reader of a TOML file
builds each table into a declared class (:mod:`perception.validation`)
with :func:`from_table`, or checks its keys with :func:`check_keys`. Every
problem is an :class:`~perception.errors.InputError` naming the file and
the field (``[tracker] search_scale``).
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Iterable, Mapping
from typing import Any

from minvar.errors import suggest
from perception.errors import HammerMVError, InputError
from perception.io.files import input_file

__all__ = ["check_keys", "from_table", "read_toml", "renamed", "sub_table", "suggest"]


def check_keys(table: Mapping[str, Any], valid: Iterable[str], where: str,
               path: str | os.PathLike | None = None) -> None:
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
    path : str or os.PathLike, optional
        The file, named in the message.

    Raises
    ------
    InputError
        For the first unknown key (an InputError is a ValueError).
    """
    valid = list(valid)
    for key in table:
        if key not in valid:
            raise InputError(f"unknown key {key!r}{suggest(key, valid)}; "
                             f"expected one of {', '.join(valid)}", path, field=where)


def sub_table(data: Any, name: str | None, where: str,
              path: str | os.PathLike | None = None) -> Mapping[str, Any]:
    """``data[name]`` if it is a table (``{}`` when absent); ``data`` itself if ``name`` is None.

    Parameters
    ----------
    data : mapping
        The parsed file (or an enclosing table).
    name : str or None
        The table's key.
    where : str
        The field named in the message (``"[setup]"``).
    path : str or os.PathLike, optional
        The file, named in the message.

    Raises
    ------
    InputError
        It is something else (``setup = []``), naming ``where``.
    """
    value = data if name is None else data.get(name, {})
    if not isinstance(value, Mapping):
        raise InputError(f"expected a table, got {type(value).__name__} {value!r}"[:120],
                         path, field=where)
    return value


def from_table(cls: type, table: Any, where: str, path: str | os.PathLike | None = None,
               **given: Any) -> Any:
    """``cls(**table, **given)`` for a table read from a file, errors naming ``[where] key``.

    Parameters
    ----------
    cls : type
        A :func:`perception.validation.declared` class.
    table : mapping
        The table as read (anything else is refused as "expected a table").
    where : str
        The table's name in the file (``"[tracker]"``).
    path : str or os.PathLike, optional
        The file.
    **given
        Fields the table does not hold (set by the reader).

    Raises
    ------
    InputError
        Not a table, an unknown key (with the nearest valid one: the class
        refuses it), or a bad value, naming the file and ``[where] key``.
    """
    table = sub_table(table, None, where, path)
    # an unknown key is the class's to refuse (extra="forbid"), one the reader sets is ours
    valid = [k for k in cls.__dataclass_fields__ if k not in given]
    for key in table:
        if key in given:
            raise InputError(f"unknown key {key!r}; expected one of {', '.join(valid)}", path,
                             field=f"{where} {key}")
    try:
        return cls(**table, **given)
    except HammerMVError as exc:
        raise renamed(exc, lambda attribute: f"{where} {attribute}", path) from None


def renamed(exc: HammerMVError, name: Any, path: str | os.PathLike | None = None) -> Exception:
    """``exc`` with its field renamed to ``name(attribute)`` (the key or flag the user wrote).

    An error with a file already, or without a ``location``, or whose
    attribute ``name`` maps to None, is returned as it is.

    Parameters
    ----------
    exc : HammerMVError
        Raised by a declared class (``location == (Owner, attribute)``).
    name : callable or mapping
        Attribute -> key or flag (``{"w_v": "--w-v"}``, or a function).
    path : str or os.PathLike, optional
        The file the value came from.
    """
    if exc.path is not None or len(exc.location) < 2:
        return exc
    attribute = exc.location[-1]
    field = name(attribute) if callable(name) else name.get(attribute)
    if field is None:
        return exc
    return type(exc)(exc.problem, path, field=field, location=exc.location)


def read_toml(path: str | os.PathLike, what: str) -> dict[str, Any]:
    """The tables of a TOML file, with one-line errors for a missing or malformed file.

    Parameters
    ----------
    path : str or os.PathLike
        The file; it must be a regular file (a FIFO would hang the read).
    what : str
        What the file is, for messages ("recipe", "repertoire config").

    Raises
    ------
    InputError
        The file is missing, not a regular file, unreadable, not UTF-8 or
        not valid TOML.
    """
    path = input_file(path, what)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the {what}: {exc}", path) from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML: {exc}", path) from None

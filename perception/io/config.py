"""TOML files read strictly: a misspelt table or key is an error that names the nearest valid one.

A recipe with ``[scence]`` or a repertoire config with ``[[models]]`` must
not pass silently and build something else: every reader of a TOML file
checks each table it reads with :func:`check_keys`, and each value against
a declared type and range (:class:`Spec`, :func:`check_table`): a number is
finite and within its documented range, an integer fits the C ``int`` that
OpenCV takes, a table is a table. Every problem is an
:class:`~perception.errors.InputError` naming the file and the field
(``[tracker] search_scale``).
"""

from __future__ import annotations

import contextlib
import difflib
import math
import numbers
import os
import tomllib
from collections.abc import Iterable, Mapping
from typing import Any, NamedTuple

from perception.errors import InputError
from perception.io.files import input_file

__all__ = ["INT32_MAX", "Spec", "check_fields", "check_keys", "check_table", "check_value",
           "document_ranges", "read_toml", "sub_table", "suggest"]

#: Largest integer OpenCV takes (a C ``int``).
INT32_MAX = 2**31 - 1


class Spec(NamedTuple):
    """The type and range of one value in a file.

    Parameters
    ----------
    kind : type or str
        ``int``, ``float`` (an integer is accepted too), ``str``, ``bool``,
        ``"colour"`` (a marker name or three integers 0..255) or ``"any"``
        (checked elsewhere).
    lo, hi : float, optional
        Inclusive bounds of a number (or of each element of a list); an
        integer is always within int32, a float always finite.
    lo_open : bool
        ``lo`` itself is excluded (``> 0`` rather than ``>= 0``).
    hi_open : bool
        ``hi`` itself is excluded.
    size : int, optional
        A list of exactly this many values (``0``: any number of them);
        ``None``: one value.
    choices : tuple, optional
        The strings allowed (a ``"colour"``'s marker names).
    note : str
        Said after the range (a unit: ``"m"``, ``"frames/s"``).
    """

    kind: Any
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    size: int | None = None
    choices: tuple | None = None
    note: str = ""

    def describe(self) -> str:
        """What is expected, in words (``"a number > 0 and <= 1"``)."""
        if self.kind == "any":
            one = "any value"
        elif self.kind == "colour":
            names = f" ({', '.join(self.choices)})" if self.choices else ""
            one = f"a marker name{names} or [b, g, r] with integers 0..255"
        elif self.kind is bool:
            one = "true or false"
        elif self.kind is str:
            one = ("one of " + ", ".join(repr(c) for c in self.choices)) if self.choices \
                else "a string"
        else:
            one = "an integer" if self.kind is int else "a number"
            lo, hi = self.bounds()
            if lo is not None and hi is not None and not (self.lo_open or self.hi_open):
                one += f" {_num(lo)}..{_num(hi)}"
            else:
                parts = []
                if lo is not None:
                    parts.append(f"{'>' if self.lo_open else '>='} {_num(lo)}")
                if hi is not None:
                    parts.append(f"{'<' if self.hi_open else '<='} {_num(hi)}")
                one += (" " + " and ".join(parts)) if parts else ""
        note = f" ({self.note})" if self.note else ""
        if self.size is None:
            return one + note
        many = "a list of " + (f"{self.size} values" if self.size else "values")
        return f"{many}, each {one}{note}"

    def bounds(self) -> tuple[float | None, float | None]:
        """``(lo, hi)``, integers' clipped to int32."""
        lo, hi = self.lo, self.hi
        if self.kind is int:
            lo = -INT32_MAX - 1 if lo is None else max(lo, -INT32_MAX - 1)
            hi = INT32_MAX if hi is None else min(hi, INT32_MAX)
        return lo, hi


def _num(x: float) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _one_ok(value: Any, spec: Spec) -> bool:
    kind = spec.kind
    if kind == "any":
        return True
    if kind == "colour":
        if isinstance(value, str):
            return bool(value) and (not spec.choices or value in spec.choices)
        return (isinstance(value, list | tuple) and len(value) == 3
                and all(_one_ok(v, Spec(int, 0, 255)) for v in value))
    if kind is bool:
        return isinstance(value, bool)
    if kind is str:
        return isinstance(value, str) and (not spec.choices or value in spec.choices)
    if isinstance(value, bool):
        return False
    if kind is int:
        if not isinstance(value, numbers.Integral):
            return False
    elif not isinstance(value, numbers.Real) or not math.isfinite(value):
        return False
    lo, hi = spec.bounds()
    if lo is not None and (value <= lo if spec.lo_open else value < lo):
        return False
    return not (hi is not None and (value >= hi if spec.hi_open else value > hi))


def check_value(value: Any, spec: Spec) -> str | None:
    """What is wrong with ``value`` for ``spec`` (``"expected ..., got ..."``), or None."""
    if spec.size is None:
        ok = _one_ok(value, spec)
    else:
        ok = (isinstance(value, list | tuple)
              and (spec.size == 0 or len(value) == spec.size)
              and all(_one_ok(v, spec) for v in value))
    if ok:
        return None
    shown = repr(value)
    if len(shown) > 60:
        shown = shown[:57] + "..."
    return f"expected {spec.describe()}, got {shown}"


def check_fields(obj: Any, specs: Mapping[str, Spec], where: str) -> None:
    """Check a dataclass's fields against ``specs`` and normalise them in place.

    Lists become tuples (of floats where ``kind`` is float), numbers become
    ``int`` or ``float``. A field whose value is ``None`` is allowed where
    that is its default.

    Parameters
    ----------
    obj : frozen dataclass
        Called from its ``__post_init__``.
    specs : mapping of str to Spec
        Fields to check.
    where : str
        Put before the field's name in the error (``"RenderStyle"``:
        ``RenderStyle.fps``).

    Raises
    ------
    InputError
        The first bad field, named.
    """
    import dataclasses

    defaults = {f.name: f.default for f in dataclasses.fields(obj)}
    for name, spec in specs.items():
        value = getattr(obj, name)
        if value is None and defaults.get(name) is None:
            continue
        if spec.size is not None and not isinstance(value, str | Mapping):
            with contextlib.suppress(TypeError):  # not a sequence: check_value says so
                value = tuple(value)
        problem = check_value(value, spec)
        if problem:
            raise InputError(problem, field=f"{where}.{name}")
        if spec.size is not None:
            value = tuple(float(v) for v in value) if spec.kind is float else tuple(value)
        elif spec.kind is float:
            value = float(value)
        elif spec.kind is int:
            value = int(value)
        elif spec.kind == "colour" and not isinstance(value, str):
            value = tuple(int(v) for v in value)
        object.__setattr__(obj, name, value)


def document_ranges(cls: type, specs: Mapping[str, Spec]) -> None:
    """Append a "Ranges" section, from ``specs``, to ``cls``'s docstring."""
    lines = ["", "    Ranges", "    ------"]
    lines += [f"    {name} : {spec.describe()}" for name, spec in specs.items()]
    cls.__doc__ = (cls.__doc__ or "").rstrip() + "\n" + "\n".join(lines) + "\n"


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


def sub_table(data: Mapping[str, Any], name: str, where: str,
              path: str | os.PathLike | None = None) -> Mapping[str, Any]:
    """``data[name]`` if it is a table (``{}`` when absent).

    Parameters
    ----------
    data : mapping
        The parsed file (or an enclosing table).
    name : str
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
    value = data.get(name, {})
    if not isinstance(value, Mapping):
        raise InputError(f"expected a table, got {type(value).__name__} {value!r}"[:120],
                         path, field=where)
    return value


def check_table(values: Mapping[str, Any], specs: Mapping[str, Spec], where: str,
                path: str | os.PathLike | None = None) -> None:
    """Refuse unknown keys and values of the wrong type or out of range.

    Parameters
    ----------
    values : mapping
        A table read from a file.
    specs : mapping of str to Spec
        Every allowed key's type and range.
    where : str
        The table's name (``"[tracker]"``): the field of a bad value is
        ``"[tracker] key"``.
    path : str or os.PathLike, optional
        The file.

    Raises
    ------
    InputError
        For the first unknown key or bad value, naming the file and field.
    """
    if not isinstance(values, Mapping):
        raise InputError(f"expected a table, got {type(values).__name__}", path, field=where)
    check_keys(values, specs, where, path)
    for key, value in values.items():
        problem = check_value(value, specs[key])
        if problem:
            raise InputError(problem, path, field=f"{where} {key}")


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

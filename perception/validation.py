"""Declared validation for perception's classes: :mod:`minvar.validation`, raising InputError.

The mechanism (pydantic dataclasses, the shared field types, the one-line
messages) is :mod:`minvar.validation`'s; its docstring says why pydantic.
Here :func:`declared` raises :class:`~perception.errors.InputError` (or the
error a class asks for), which the CLI reports as one line and exit 2.
"""

from __future__ import annotations

import functools
from typing import Any

from minvar.validation import Int, Int32, NonNegative, Positive, Share, Tuple
from minvar.validation import declared as _declared
from perception.errors import HammerMVError, InputError

__all__ = ["Int", "Int32", "NonNegative", "Positive", "Share", "Tuple", "declared"]


def declared(cls: type | None = None, /, *, eq: bool = True,
             error: type[HammerMVError] = InputError) -> Any:
    """:func:`minvar.validation.declared`, raising :class:`InputError` (or ``error``).

    Parameters
    ----------
    cls : type
        The class, written as a dataclass would be.
    eq : bool
        Compared field by field (False: by identity).
    error : type
        Raised for a bad value (a scene that cannot be planned for:
        :class:`~perception.errors.PlanningError`).
    """
    if cls is None:
        return functools.partial(declared, eq=eq, error=error)
    return _declared(cls, eq=eq, error=error)

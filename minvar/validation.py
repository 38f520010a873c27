"""One way to check a value: parameter classes declared as pydantic dataclasses.

Every class that holds settings a user chooses (``ReachTask``,
``GraspTask``, ``PointMassPlant`` here; ``TrackerParams``,
``ObserveParams``, ``VerdictRules``, a recipe's scene, a setup file's
tables in :mod:`perception`) is decorated with :func:`declared`. Its fields
carry their type and range in the annotation (``alpha: Annotated[float,
Field(gt=0, le=1)]``), and every construction (in Python, from a TOML
table or from command-line flags) is checked by pydantic against them. A
relation between fields (``lost_ratio <= reacquire_ratio``) stays in
``__post_init__``, which pydantic calls after the fields pass.

Why pydantic v2 rather than attrs with cattrs (which ``movement`` uses):
the classes stay standard-library dataclasses, so ``dataclasses.replace``,
``fields`` and ``asdict`` (used throughout) keep working; the range is part
of the type, visible in the signature; and an error carries its location as
data (``loc``), so a file reader and the CLI rename it to the key or flag
the user wrote through a table, never by reading the message.

The checks are strict: a string is not a number, ``true`` is not an
integer, a float is neither NaN nor infinite. An integer is accepted where
a float is declared, numpy scalars where Python ones are, and a list or
array where a tuple is (TOML has no tuples). A bad value raises a
:class:`ParameterError` (a ``ValueError``) naming ``Owner.field``, in one
line; :mod:`perception`'s classes raise its ``InputError`` instead.
"""

from __future__ import annotations

import functools
import threading
from typing import Annotated, Any

import numpy as np
from pydantic import (
    AfterValidator,
    BeforeValidator,
    ConfigDict,
    Field,
    TypeAdapter,
    ValidationError,
)
from pydantic._internal._mock_val_ser import MockValSer as _MockValSer
from pydantic.dataclasses import dataclass as _pydantic_dataclass
from pydantic.dataclasses import rebuild_dataclass as _rebuild_dataclass

from minvar.errors import LocatedError, ParameterError, suggest
from minvar.limits import MAX_POSITION_M

__all__ = ["INT32_MAX", "Extent", "Int", "Int32", "Length", "NonNegative", "Point", "Positive",
           "Share", "Span", "Tuple", "checked", "declared", "input_error"]


#: Largest integer OpenCV takes (a C ``int``).
INT32_MAX = 2**31 - 1

#: What every declared class shares: unknown fields are errors, values are
#: not coerced from strings or booleans, floats are finite, instances frozen.
#: A class's validator is built when it is first used, not when its module is
#: imported (``defer_build``): a command imports many classes it never makes (the
#: CLI's option tables read only their fields, which are collected at once either
#: way), and building them all cost ~60 ms of every start-up (issue 45).
CONFIG = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False,
                    arbitrary_types_allowed=True, defer_build=True)


def _python_int(value: Any) -> Any:
    # numpy's integers are integers (a count computed with numpy), but a bool is not
    return int(value) if isinstance(value, np.integer) else value


def _as_tuple(value: Any) -> Any:
    return tuple(value.tolist() if isinstance(value, np.ndarray) else value) \
        if isinstance(value, list | np.ndarray) else value


#: An integer (numpy's too).
Int = Annotated[int, BeforeValidator(_python_int)]
#: An integer OpenCV takes.
Int32 = Annotated[Int, Field(ge=-INT32_MAX - 1, le=INT32_MAX)]
#: A finite number > 0.
Positive = Annotated[float, Field(gt=0)]
#: A finite number >= 0.
NonNegative = Annotated[float, Field(ge=0)]
#: A share, 0..1.
Share = Annotated[float, Field(ge=0, le=1)]
#: Put before a tuple type: a list or array is taken as a tuple.
Tuple = BeforeValidator(_as_tuple)


def _on_table(value: float) -> float:
    if abs(value) > MAX_POSITION_M:
        raise ValueError(f"a coordinate or length within +-{MAX_POSITION_M:g} m "
                         "(MAX_POSITION_M: the metres of a table; see docs/model.md, Limits)")
    return value


#: A coordinate or length, m (rad in joint space), within ``MAX_POSITION_M``.
Length = Annotated[float, AfterValidator(_on_table)]
#: A position, (x, y).
Point = Annotated[tuple[Length, Length], Tuple]
#: A length > 0 (>= 0), within ``MAX_POSITION_M``.
Span = Annotated[Length, Field(gt=0)]
Extent = Annotated[Length, Field(ge=0)]


def _shown(value: Any) -> str:
    text = repr(value.tolist() if isinstance(value, np.ndarray) else value)
    return text if len(text) <= 60 else text[:57] + "..."


def _range(info: Any) -> str | None:
    """A numeric field's whole range in words (``"an integer 0..64"``), from its metadata."""
    if info is None or info.annotation not in (int, float):
        return None
    lower = [(m.ge, ">=") if hasattr(m, "ge") else (m.gt, ">") for m in info.metadata
             if hasattr(m, "ge") or hasattr(m, "gt")]
    upper = [(m.le, "<=") if hasattr(m, "le") else (m.lt, "<") for m in info.metadata
             if hasattr(m, "le") or hasattr(m, "lt")]
    lo, hi = max(lower, default=None), min(upper, default=None)
    what = "an integer" if info.annotation is int else "a number"
    if lo and hi and lo[1] == ">=" and hi[1] == "<=":
        return f"{what} {lo[0]:g}..{hi[0]:g}"
    parts = ([f"{lo[1]} {lo[0]:g}"] if lo else []) + ([f"{hi[1]} {hi[0]:g}"] if hi else [])
    return f"{what} {' and '.join(parts)}" if parts else None


def _problem(error: dict[str, Any], valid: list[str], info: Any = None) -> str:
    """One pydantic error in the project's words (``"expected ..., got ..."``)."""
    kind, loc = error["type"], error["loc"]
    if kind == "unexpected_keyword_argument":
        return (f"unknown key {loc[-1]!r}{suggest(str(loc[-1]), valid)}; "
                f"expected one of {', '.join(valid)}")
    ctx = error.get("ctx") or {}
    bound = next(((op, ctx[key]) for key, op in _BOUNDS.items() if key in ctx), None)
    note = getattr(info, "description", None)
    if bound is not None and len(loc) == 1 and _range(info):
        message = _range(info)
    elif bound is not None:
        message = f"a number {bound[0]} {bound[1]:g}"
    elif kind in _WORDS:
        message = _WORDS[kind].format(**ctx)
    else:  # a validator's own words, or pydantic's ("'a' or 'b'")
        message = error["msg"].removeprefix("Value error, ").removeprefix("Input should be ")
    index = "".join(f"[{i}]" for i in loc[1:] if isinstance(i, int))
    if kind == "missing" and not index:
        return "missing (it has no default)"
    note = f" ({note})" if note else ""
    at = f" at {index}" if index else ""
    return f"expected {message}{note}{at}, got {_shown(error['input'])}"


_BOUNDS = {"gt": ">", "ge": ">=", "lt": "<", "le": "<="}
_WORDS = {"int_type": "an integer", "float_type": "a number", "finite_number": "a finite number",
          "bool_type": "true or false", "string_type": "a string", "tuple_type": "a list",
          "too_long": "at most {max_length} values", "missing": "more values",
          "is_instance_of": "{class_}", "dataclass_type": "{class_name}"}


def input_error(exc: ValidationError, owner: type,
                error: type[LocatedError] = ParameterError) -> LocatedError:
    """The one-line error for pydantic's first error in constructing ``owner``.

    Its ``location`` is ``(Owner, attribute)`` (and the key, for a
    mapping's value), and its ``field`` that joined by dots; a field's
    ``description`` (its unit, what it is) is said after the range. An
    error a validator or ``__post_init__`` raised on purpose (a
    :class:`LocatedError`) keeps its words, and is given the location if it
    names none.

    Parameters
    ----------
    exc : pydantic.ValidationError
        What pydantic raised.
    owner : type
        The declared class.
    error : type
        Raised for a bad value (:class:`ParameterError`; perception's
        classes raise its ``InputError``, a scene that cannot be planned for
        its ``PlanningError``).
    """
    name, fields = owner.__name__, owner.__pydantic_fields__
    valid = list(fields)
    first = exc.errors(include_url=False)[0]
    cause = (first.get("ctx") or {}).get("error")
    # a union's member is named in loc ("literal['a','b']"), a mapping's key is not bracketed
    loc = tuple(str(p) for p in first["loc"][1:] if not isinstance(p, int) and "[" not in str(p))
    if first["loc"]:  # the argument: its name, or its place among positional ones
        arg = first["loc"][0]
        loc = (valid[arg] if isinstance(arg, int) and arg < len(valid) else str(arg), *loc)
    if isinstance(cause, LocatedError):  # in its own words
        return cause if cause.location or cause.field else \
            type(cause)(cause.problem, cause.path, location=(name, *loc))
    if cause is not None and not loc:  # __post_init__'s, about the fields together
        return error(str(cause), location=(name,))
    return error(_problem(first, valid, fields.get(loc[0]) if loc else None),
                 location=(name, *loc))


def declared(cls: type | None = None, /, *, eq: bool = True,
             error: type[LocatedError] = ParameterError) -> Any:
    """Make ``cls`` a pydantic dataclass whose bad values raise ``error`` in one line.

    Used as ``@declared`` on a class written as a dataclass would be.

    Parameters
    ----------
    cls : type
        The class.
    eq : bool
        Compared field by field (False: by identity, for classes holding arrays).
    error : type
        Raised for a bad value (see :func:`input_error`).
    """
    if cls is None:
        return functools.partial(declared, eq=eq, error=error)
    # frozen: settings are values
    built = _pydantic_dataclass(cls, frozen=True, eq=eq, config=CONFIG)
    init = built.__init__  # pydantic's: validates with whatever validator the class holds

    @functools.wraps(init)
    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        if not getattr(built, "__pydantic_complete__", True):
            _complete(built, __init__)
        try:
            init(self, *args, **kwargs)
        except ValidationError as exc:
            raise input_error(exc, built, error) from None

    built.__init__ = __init__
    if not getattr(built, "__pydantic_complete__", True):  # deferred: built when first used
        # the signature pydantic gives a built class, read without building it first
        built.__signature__ = _BuiltSignature(built, __init__)
        # pydantic's own stand-in validator rebuilds the class on first use without a
        # lock; this one builds it through _complete (a thread that finds pydantic's
        # __init__ on the class while another builds it waits here, and builds nothing)
        built.__pydantic_validator__ = _MockValSer(
            f"{built.__name__} is not built", code="class-not-fully-defined",
            val_or_ser="validator",
            attempt_rebuild=lambda **_: _complete(built, __init__).__pydantic_validator__)
    return built


class _BuiltSignature:
    """A deferred class's ``__signature__``: pydantic's, read after building the class."""

    def __init__(self, built: type, init: Any):
        self.built, self.init = built, init

    def __get__(self, _instance: Any, _owner: type) -> Any:
        return _complete(self.built, self.init).__signature__


#: Held while a declared class is built: planning threads (and a dask worker's) may make
#: the first instance of a class at once, and pydantic's build changes the class in steps.
_BUILDING = threading.RLock()


def _complete(built: type, init: Any) -> type:
    """Build ``built``'s deferred validator (CONFIG's ``defer_build``) now, once.

    pydantic's build sets the class's ``__init__`` (and its ``__signature__``)
    anew: the one-line-error ``init`` of :func:`declared` is put back.
    """
    with _BUILDING:
        if not built.__pydantic_complete__:
            try:
                _rebuild_dataclass(built, force=True)
            finally:
                built.__init__ = init
    return built


@functools.cache
def _adapter(kind: Any) -> TypeAdapter:
    return TypeAdapter(kind, config=CONFIG)


def checked(value: Any, kind: Any, location: tuple[str, ...],
            error: type[LocatedError] = ParameterError) -> Any:
    """``value`` validated as a declared type (``Point``, ``Positive``) outside a class.

    For a function's argument, as a class's field is checked.

    Parameters
    ----------
    value : object
        What was given.
    kind : type
        A type of this module (or any type pydantic validates).
    location : tuple of str
        ``(function, argument)``, named in the error.
    error : type
        Raised for a bad value.
    """
    try:
        return _adapter(kind).validate_python(value)
    except ValidationError as exc:
        raise error(_problem(exc.errors(include_url=False)[0], []), location=location) from None

"""Flags generated from declared fields, and the one map from a field to the flag that sets it.

A flag that sets a field of a declared settings class
(:func:`perception.validation.declared`) is described once, by a
:class:`Setting`: its flag is ``--`` and the field's name with dashes (unless
the setting says otherwise), its default the class's, its type and choices
the field's annotation, its help the field's ``description`` (or the
setting's own words). :func:`add_settings` adds such flags to a parser and
records each in :data:`FIELD_FLAGS`, which the command line's error printer
(:func:`as_flags`) reads to name the flag the user typed where the library
names the field (``px_per_m`` -> ``--px-per-m``).

Nothing heavy is imported here (``track --help`` stays fast): the classes
come from the caller.
"""

from __future__ import annotations

import argparse
import dataclasses
import re
import types
import typing
from collections.abc import Iterable
from typing import Any

from minvar.errors import LocatedError

__all__ = ["FIELD_FLAGS", "FPS_HELP", "OWNER_FLAGS", "Setting", "add_settings",
           "add_video_options", "as_flags", "field_flag", "flag_text"]

#: Help of ``--fps``; the recognition commands add what it means for pose files.
FPS_HELP = ("true frame rate, frames/s (default: the file's own): for videos whose header is "
            "wrong")

#: The flag of each field a command's flags set, by the field's name (``"px_per_m"``).
#: The tracker's ``rois`` are named by tracking's messages wherever a video is tracked
#: (``recognize``, ``batch``): their flag is ``hammer-mv track``'s.
FIELD_FLAGS: dict[str, str] = {"rois": "--roi"}
#: The same by ``(class name, field)`` (``("ObserveParams", "px_per_m")``): read off a
#: declared class's error, whose ``location`` is that pair.
OWNER_FLAGS: dict[tuple[str, str], str] = {}

#: The default is the class's (a :class:`Setting` may give another: None, "not given").
CLASS_DEFAULT: Any = object()


@dataclasses.dataclass(frozen=True)
class Setting:
    """A flag that sets one field of a declared class.

    Parameters
    ----------
    owner : type
        The declared class.
    field : str
        Its field.
    help : str
        What the flag does, where the field has no ``description``;
        ``{default}`` is the default.
    flag : str, optional
        The flag, where it is not ``--`` and the field's name with dashes.
    default : object
        The flag's default, where it is not the class's (None: "not given",
        so that the class's own applies).
    metavar, type, nargs
        As :meth:`argparse.ArgumentParser.add_argument`'s, where the field's
        annotation does not say (a mapping, a tuple).
    """

    owner: type
    field: str
    help: str = ""
    flag: str | None = None
    default: Any = CLASS_DEFAULT
    metavar: str | None = None
    type: Any = None
    nargs: str | None = None

    @property
    def name(self) -> str:
        """The flag (``--px-per-m``)."""
        return self.flag or "--" + self.field.replace("_", "-")

    def info(self) -> Any:
        """The field's pydantic ``FieldInfo``."""
        return self.owner.__pydantic_fields__[self.field]

    def value(self) -> Any:
        """The flag's default."""
        return self.class_default() if self.default is CLASS_DEFAULT else self.default

    def class_default(self) -> Any:
        """The field's default in the class (what a flag left out, None, means)."""
        info = self.info()
        return info.default_factory() if info.default_factory is not None else info.default


def _plain(annotation: Any) -> Any:
    """The annotation without ``Annotated`` and without ``None`` of an optional field."""
    while typing.get_origin(annotation) is typing.Annotated:
        annotation = typing.get_args(annotation)[0]
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        members = [a for a in typing.get_args(annotation) if a is not type(None)]
        if len(members) == 1:
            return _plain(members[0])
    return annotation


def _arguments(setting: Setting) -> dict[str, Any]:
    """``add_argument``'s keywords for ``setting``, from its field's declaration."""
    info = setting.info()
    kind = _plain(info.annotation)
    text = info.description or setting.help
    shown = setting.class_default()  # said in the help: what applies when not given
    if isinstance(shown, float):
        shown = f"{shown:g}"
    kwargs: dict[str, Any] = {"default": setting.value(),
                              "help": text.replace("{default}", str(shown))}
    if kind is bool:
        return {**kwargs, "action": "store_true"}
    if typing.get_origin(kind) is typing.Literal:
        kwargs["choices"] = typing.get_args(kind)
    elif kind in (int, float) and setting.type is None:
        kwargs["type"] = kind
    for key in ("metavar", "type", "nargs"):
        if getattr(setting, key) is not None:
            kwargs[key] = getattr(setting, key)
    return kwargs


def add_settings(group: Any, settings: Iterable[Setting]) -> None:
    """Add a flag per setting to ``group`` (a parser or argument group), and record each
    in :data:`FIELD_FLAGS` and :data:`OWNER_FLAGS`.

    Parameters
    ----------
    group : argparse.ArgumentParser or argument group
        Where the flags go.
    settings : iterable of Setting
        The flags, in the order ``--help`` lists them.
    """
    for setting in settings:
        group.add_argument(setting.name, **_arguments(setting))
        field_flag(setting.field, setting.name)
        OWNER_FLAGS[(setting.owner.__name__, setting.field)] = setting.name


def field_flag(field: str, flag: str) -> None:
    """Record that ``flag`` sets the field ``field`` (a flag not generated from a class).

    Raises
    ------
    RuntimeError
        The field has another flag already (two flags for one field would make
        an error name either).
    """
    if FIELD_FLAGS.setdefault(field, flag) != flag:
        raise RuntimeError(f"field {field!r} has two flags: {FIELD_FLAGS[field]} and {flag}")


#: A field named in an error's text: its name in backquotes (```rate```).
_NAMED = re.compile(r"`([a-z][a-z0-9_]*)`")
#: The field an error's text begins with (``str(LocatedError)``: ``"field: problem"``).
_LEADING = re.compile(r"([a-z][a-z0-9_]*): ")


def as_flags(exc: BaseException) -> BaseException:
    """``exc`` with the fields it names given as the flags that set them.

    A library error names a field (``field="rate"``, or ```rate``` in its
    text); a declared class's error its ``location`` (``("ObserveParams",
    "px_per_m")``, for a value given on the command line: no file). Each is
    replaced by its flag where the command has one; the rest is kept.

    Parameters
    ----------
    exc : BaseException
        Any error (one that names no field is returned as it is).
    """
    if not isinstance(exc, LocatedError):
        return exc
    flag = FIELD_FLAGS.get(exc.field) if exc.field else None
    if (flag is None and exc.path is None and len(exc.location) >= 2
            and exc.field == ".".join(exc.location)):
        # the class's own flag, else the command's flag of a field of that name (one
        # value set in two classes: --fps sets PoseImport's and RecognitionSettings')
        flag = OWNER_FLAGS.get(tuple(exc.location[-2:]), FIELD_FLAGS.get(exc.location[-1]))
    problem = flag_text(exc.problem)
    if flag is None and problem == exc.problem:
        return exc
    return type(exc)(problem, exc.path, field=flag or exc.field, location=exc.location)


def flag_text(text: str) -> str:
    """``text`` (a reason kept from a library error: a clip's, a trial's) with each field it
    names in backquotes given as its flag, as :func:`as_flags` does for an error, and the
    field an error's text begins with (``"time_column: no column 'globalTime'"``, as a
    batch keeps a clip's error) too."""
    text = _NAMED.sub(lambda m: FIELD_FLAGS.get(m[1], m[0]), text)
    field = _LEADING.match(text)
    if field is not None and field[1] in FIELD_FLAGS:
        text = FIELD_FLAGS[field[1]] + text[field.end(1):]
    return text


def add_video_options(p: argparse.ArgumentParser, *, fps: bool = True) -> None:
    """Add the options that say how to read a damaged or mislabelled video.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    fps : bool
        Add ``--fps`` too (the recognition commands have it among the pose options).
    """
    g = p.add_argument_group("videos")
    g.add_argument("--keep-truncated", action="store_true",
                   help="track the frames a truncated or damaged video decodes instead of "
                        "refusing it")
    field_flag("keep_truncated", "--keep-truncated")
    if fps:
        g.add_argument("--fps", type=float, default=None, metavar="F", help=FPS_HELP)
        field_flag("fps", "--fps")

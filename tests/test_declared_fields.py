"""Every declared settings class refuses every value outside its declared range, in one line.

Generated, not written case by case (issue 46): the classes are found by walking
:mod:`minvar` and :mod:`perception` for :func:`minvar.validation.declared` classes;
each numeric field (optional or not) gets a value just past each declared bound, NaN
and a string; a field of choices a word that is none; a field holding a declared class
a string and a mapping in place of an instance. Each must be refused with a
:class:`~minvar.errors.LocatedError` (a ``ValueError``) that names the class and the
field in one line — never accepted, never an error from deep inside. This replaces the
per-field fault tables (issue 42 item 6): a fault test feeds a value through a file or
a command only where what it checks is more than the field's declaration.
"""

from __future__ import annotations

import importlib
import math
import pkgutil
import typing

import pytest

import minvar
import perception
from hammer_mv.cli.flags import _plain
from minvar.errors import LocatedError
from minvar.validation import CONFIG


def _declared_classes() -> dict[str, type]:
    found = {}
    for pkg in (minvar, perception):
        for info in pkgutil.walk_packages(pkg.__path__, f"{pkg.__name__}."):
            try:
                module = importlib.import_module(info.name)
            except ImportError:  # an optional extra (dask) not installed
                continue
            for obj in vars(module).values():
                if (isinstance(obj, type) and obj.__module__ == info.name
                        and getattr(obj, "__pydantic_config__", None) == CONFIG):
                    found[f"{info.name}.{obj.__qualname__}"] = obj
    return found


CLASSES = _declared_classes()


def _bounds(info) -> list[tuple[str, float]]:
    """A field's bounds, also those inside an optional's ``Annotated`` (``X | None``)."""
    found = [(op, getattr(m, op)) for m in info.metadata for op in ("gt", "ge", "lt", "le")
             if getattr(m, op, None) is not None]

    def walk(kind):
        for arg in typing.get_args(kind):
            for meta in getattr(arg, "__metadata__", ()):
                for m in [meta, *getattr(meta, "metadata", [])]:
                    found.extend((op, getattr(m, op)) for op in ("gt", "ge", "lt", "le")
                                 if getattr(m, op, None) is not None)
            walk(arg)

    walk(info.annotation)
    return sorted(set(found))


def _past(bounds, kind) -> list[object]:
    """Values just past each of ``bounds`` (the bound itself where it is excluded)."""
    values: list[object] = []
    for op, bound in bounds:
        if op in ("gt", "lt"):
            values.append(bound)
        else:
            step = 1 if kind is int else max(abs(bound), 1.0) * 1e-3
            values.append(bound - step if op == "ge" else bound + step)
    return values


def _declared(kind) -> bool:
    return isinstance(kind, type) and getattr(kind, "__pydantic_config__", None) == CONFIG


def _outside(info) -> list[object]:
    """Values the field's declaration refuses: for a number (optional or not) just past each
    bound, NaN, a string; a word that is no choice; for a field holding a declared class, a
    string and a mapping in place of an instance (``MocapImport(markers={...})``)."""
    kind = _plain(info.annotation)
    if kind in (int, float):
        return [*_past(_bounds(info), kind), *([math.nan] if kind is float else []), "x"]
    if typing.get_origin(kind) is typing.Literal:
        return ["no-such-choice"]
    if _declared(kind):
        return ["x", {"x": 1}]
    return []


def _cases():
    for _name, cls in sorted(CLASSES.items()):
        try:
            cls()
        except Exception:  # noqa: BLE001 - a class with required fields: not generated
            continue
        for field, info in cls.__pydantic_fields__.items():
            kind = _plain(info.annotation)
            said = f"{cls.__name__}.{field}" + (
                f": expected an instance of {kind.__name__}" if _declared(kind) else "")
            for value in _outside(info):
                yield pytest.param(cls, field, value, said,
                                   id=f"{cls.__name__}.{field}={value!r}")


CASES = list(_cases())


def test_the_walk_finds_the_settings_classes_users_set():
    names = {cls.__name__ for cls in CLASSES.values()}
    assert {"VerdictRules", "LandmarkParams", "ObserveParams", "TrackerParams", "ReachParams",
            "MocapImport", "CalibrationParams", "ReachTask", "GraspTask"} <= names
    assert len(CASES) > 150  # every bounded numeric field of them, several values each
    generated = {case.id for case in CASES}
    assert {"MocapImport.rate=0", "PoseImport.fps=0", "MocapImport.units='no-such-choice'",
            "MocapImport.markers={'x': 1}", "MocapImport.reaches='x'"} <= generated


@pytest.mark.parametrize(("cls", "field", "value", "said"), CASES)
def test_a_value_outside_a_declared_range_is_refused_naming_the_field(cls, field, value, said):
    with pytest.raises(LocatedError) as caught:
        cls(**{field: value})
    message = str(caught.value)
    assert isinstance(caught.value, ValueError)
    assert "\n" not in message and said in message, message


# -- the same on the command line: every flag that sets a declared field ------------------

#: Values the declarations of fields that are not numbers refuse (an empty name, a
#: mapping that is no ROLE=NAME pair, a name twice, a pattern that does not compile).
NOT_NUMBERS = {"keypoints": ["thumb"], "markers": ["thumb", "thumb=a", "thumb=a finger=a"],
               "columns": [","], "factors": [",", "a,a"], "factors_from_name": ["(", "P1"],
               # a point off the table (MAX_POSITION_M), a coordinate no number
               "start": ["nan 0", "20 0", "x 0"], "goal": ["0 nan", "0 20", "0 x"]}
#: Values a flag gives a meaning of its own (``--cutoff 0``: no low-pass filter).
MEANT = {("--cutoff", "0")}


def _flag_values(setting) -> list[str]:
    """What to type after ``setting``'s flag: just past each declared bound, NaN, a word
    for a number; a word that is no choice; the refused values of :data:`NOT_NUMBERS`."""
    info = setting.info()
    kind = _plain(info.annotation)
    if typing.get_origin(kind) is typing.Literal:
        return ["no-such-choice"]
    if kind not in (int, float):
        return NOT_NUMBERS.get(setting.field, [])
    values = _past(_bounds(info), kind)
    words = [f"{v:g}" if isinstance(v, float) else str(v) for v in values]
    return [w for w in [*words, "nan", "x"] if (setting.name, w) not in MEANT]


def _commands():
    """Each command's words, the arguments it needs besides the flag, its generated flags and
    the function that builds its settings from the parsed arguments."""
    from hammer_mv.cli import grasp, landmarks, options, reach, repertoire

    recognition = (*options.RECOGNITION, *options.POSE, *options.MOCAP, *options.FACTORS)
    yield "recognize", ["x.tracks.h5", "-o", "out"], recognition, options.recognition_settings
    yield "batch", ["clips", "-o", "out"], recognition, options.recognition_settings
    yield ("landmarks", ["x.csv", "-o", "out.csv"],
           (*landmarks.DEFINITIONS, *landmarks.SCALE, *options.POSE, *options.MOCAP,
            *options.FACTORS),
           landmarks.landmark_settings)
    yield "reach", ["-o", "out"], (*reach.TASK, *reach.PLANT), reach.reach_settings
    yield "grasp simulate", ["-o", "out"], grasp.SIMULATE, grasp.grasp_task
    yield "repertoire build", ["-o", "rep.h5"], repertoire.SCENE, repertoire.build_scene


def _flag_cases():
    for command, needed, settings, assemble in _commands():
        for setting in settings:
            for value in _flag_values(setting):
                yield pytest.param(command, [*needed, *setting.name.split(), *value.split()],
                                   setting.name, assemble,
                                   id=f"{command} {setting.name} {value}")


FLAG_CASES = list(_flag_cases())


def test_every_declared_field_a_flag_sets_is_generated():
    flags = {(case.values[0], case.values[2]) for case in FLAG_CASES}
    for command in ("recognize", "batch", "landmarks"):
        named = {flag for c, flag in flags if c == command}
        assert {"--px-per-m", "--object-diameter", "--object-size", "--rate", "--fps",
                "--markers", "--factors-from-name"} <= named, command
    assert {"--w-g", "--filter-gain", "--pcutoff", "--rule", "--units"} <= {
        flag for c, flag in flags if c == "recognize"}
    assert {"--threshold", "--hold", "--cutoff", "--speed"} <= {
        flag for c, flag in flags if c == "landmarks"}
    # the simulation commands (issue 42 item 6): every flag that sets a field
    assert {flag for c, flag in flags if c == "reach"} == {
        "--start", "--goal", "--duration", "--r", "--w-v", "--w-f", "--sigma-u", "--sigma-s"}
    assert {flag for c, flag in flags if c == "grasp simulate"} == {
        "--object-size", "--distance", "--duration", "--viapoint-offset", "--viapoint-height",
        "--viapoint-time", "--tip-start", "--execution-cv", "--dt"}  # (--reach-only: a switch)
    assert {flag for c, flag in flags if c == "repertoire build"} == {
        "--distance", "--object-size"}
    assert len(FLAG_CASES) > 100


@pytest.mark.parametrize(("command", "argv", "flag", "assemble"), FLAG_CASES)
def test_an_invalid_flag_value_is_one_line_naming_the_flag_exit_2(command, argv, flag, assemble,
                                                                   capsys):
    """What ``main`` does with the value, without running the command: the parser, then the
    settings the command builds from the arguments, then the line ``main`` prints."""
    from hammer_mv.cli import build_parser, error_line
    from perception.errors import HammerMVError

    words = command.split()  # main names the command, the parser a subcommand too
    try:
        args = build_parser(words[0]).parse_args([*words, *argv])
    except SystemExit as exc:  # refused by the parser (a word for a number, no choice)
        assert exc.code == 2
        line = capsys.readouterr().err.strip()
    else:
        with pytest.raises(HammerMVError) as caught:  # main's exit 2
            assemble(args)
        line = error_line(words[0], caught.value)
    assert "\n" not in line and flag in line, line
    assert line.startswith((f"hammer-mv {words[0]}: error: {flag}: ",
                            f"hammer-mv {command}: error: argument {flag}: "))

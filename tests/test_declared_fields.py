"""Every declared settings class refuses every value outside its declared range, in one line.

Generated, not written case by case (issue 46): the classes are found by walking
:mod:`minvar` and :mod:`perception` for :func:`minvar.validation.declared` classes;
each numeric field with a declared bound gets a value just past it, NaN and a string,
and each must be refused with a :class:`~minvar.errors.LocatedError` (a ``ValueError``)
that names the class and the field in one line — never accepted, never an error
from deep inside.
"""

from __future__ import annotations

import importlib
import math
import pkgutil

import pytest

import minvar
import perception
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
    return [(op, getattr(m, op)) for m in info.metadata for op in ("gt", "ge", "lt", "le")
            if getattr(m, op, None) is not None]


def _outside(info) -> list[object]:
    """Values the field's declaration refuses: just past each bound, NaN, a string."""
    values: list[object] = []
    for op, bound in _bounds(info):
        if op in ("gt", "lt"):
            values.append(bound)
        else:
            step = 1 if info.annotation is int else max(abs(bound), 1.0) * 1e-3
            values.append(bound - step if op == "ge" else bound + step)
    if info.annotation is float:
        values.append(math.nan)
    return [*values, "x"]


def _cases():
    for _name, cls in sorted(CLASSES.items()):
        try:
            cls()
        except Exception:  # noqa: BLE001 - a class with required fields: not generated
            continue
        for field, info in cls.__pydantic_fields__.items():
            if info.annotation not in (int, float):
                continue
            for value in _outside(info):
                yield pytest.param(cls, field, value, id=f"{cls.__name__}.{field}={value!r}")


CASES = list(_cases())


def test_the_walk_finds_the_settings_classes_users_set():
    names = {cls.__name__ for cls in CLASSES.values()}
    assert {"VerdictRules", "LandmarkParams", "ObserveParams", "TrackerParams", "ReachParams",
            "MocapImport", "CalibrationParams", "ReachTask", "GraspTask"} <= names
    assert len(CASES) > 150  # every bounded numeric field of them, several values each


@pytest.mark.parametrize(("cls", "field", "value"), CASES)
def test_a_value_outside_a_declared_range_is_refused_naming_the_field(cls, field, value):
    with pytest.raises(LocatedError) as caught:
        cls(**{field: value})
    message = str(caught.value)
    assert isinstance(caught.value, ValueError)
    assert "\n" not in message and f"{cls.__name__}.{field}" in message, message

"""Meta-tests: every public function and class documents its parameters."""

import dataclasses
import importlib
import inspect
import pkgutil
import re

import pytest

import minvar
import perception


def _modules():
    for pkg in (minvar, perception):
        yield pkg.__name__
        for info in pkgutil.walk_packages(pkg.__path__, prefix=pkg.__name__ + "."):
            if info.name.rsplit(".", 1)[-1].startswith("_"):
                continue
            yield info.name


def _public(module):
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n in vars(module) if not n.startswith("_")]
    for name in names:
        obj = getattr(module, name)
        if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__ == module.__name__:
            yield name, obj


def _params(obj):
    if inspect.isclass(obj):
        if dataclasses.is_dataclass(obj):
            return [f.name for f in dataclasses.fields(obj) if f.init]
        obj = obj.__init__
        if obj is object.__init__:
            return []
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [
        p.name for p in sig.parameters.values()
        if p.name not in ("self", "cls") and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]


CASES = [
    (mod, name, obj)
    for mod in _modules()
    for name, obj in _public(importlib.import_module(mod))
]


@pytest.mark.parametrize("mod, name, obj", CASES, ids=[f"{m}.{n}" for m, n, _ in CASES])
def test_public_api_is_documented(mod, name, obj):
    doc = inspect.getdoc(obj) or ""
    if inspect.isclass(obj) and not dataclasses.is_dataclass(obj):
        doc += "\n" + (inspect.getdoc(obj.__init__) or "")
    assert doc.strip(), f"{mod}.{name} has no docstring"
    missing = [p for p in _params(obj) if not re.search(rf"\b{re.escape(p)}\b", doc)]
    assert not missing, f"{mod}.{name}: parameters not documented: {missing}"


def test_minvar_never_imports_perception():
    import subprocess
    import sys

    code = (
        "import sys, pkgutil, importlib, minvar\n"
        "for m in pkgutil.walk_packages(minvar.__path__, 'minvar.'):\n"
        "    importlib.import_module(m.name)\n"
        "bad = [m for m in sys.modules if m == 'perception' or m.startswith('perception.')]\n"
        "assert not bad, bad\n"
        "assert 'cv2' not in sys.modules and 'h5py' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)

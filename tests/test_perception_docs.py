"""Every public class and function of the tracking modules documents itself."""

import importlib
import inspect

import pytest

MODULES = [
    "tracking", "tracking.markers", "tracking.params", "tracking.blobs", "tracking.measurement",
    "tracking.reacquisition", "tracking.tracker", "io.video", "io.tracks", "io.repertoire",
    "synthetic.scene", "synthetic.render", "synthetic.demos", "geometry", "observation",
    "pipeline", "recognition.models", "recognition.engine", "recognition.scoring",
    "tracking.candidates", "tracking.hand", "tracking.overlay", "tracking.setup",
    "synthetic.footage", "synthetic.realistic", "report.tracking",
]


def _public(module):
    for name, obj in vars(module).items():
        if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
            continue
        if inspect.isclass(obj) or inspect.isfunction(obj):
            yield name, obj


@pytest.mark.parametrize("name", MODULES)
def test_public_api_is_documented(name):
    module = importlib.import_module(f"perception.{name}")
    assert module.__doc__
    missing = []
    for attr, obj in _public(module):
        if not inspect.getdoc(obj):
            missing.append(attr)
        if inspect.isclass(obj):
            for meth, fn in vars(obj).items():
                if not meth.startswith("_") and inspect.isfunction(fn) and not inspect.getdoc(fn):
                    missing.append(f"{attr}.{meth}")
        elif inspect.isfunction(obj):
            params = [p for p in inspect.signature(obj).parameters if p not in ("self", "cls")]
            doc = inspect.getdoc(obj)
            if len(params) > 2 and "Parameters" not in doc and "As :func:" not in doc:
                missing.append(f"{attr} (parameters)")
    assert not missing, f"perception.{name}: undocumented {missing}"

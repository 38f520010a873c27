"""The packages' public names are plain to see: help(), dir() and the stubs agree.

``minvar``, ``perception`` and ``perception.report`` load their names on
first use (lazy_loader) from the ``__init__.pyi`` stubs that IDEs and type
checkers read: every name listed must resolve, and what help() shows must be
the whole public API.
"""

from __future__ import annotations

import importlib
import pydoc
import subprocess
import sys

import pytest


@pytest.mark.parametrize("package", ["minvar", "perception", "perception.report"])
def test_every_stub_name_resolves_and_help_lists_it(package):
    mod = importlib.import_module(package)
    assert mod.__all__, package
    for name in mod.__all__:
        assert getattr(mod, name) is not None, name
        assert name in dir(mod)
    text = pydoc.render_doc(mod, renderer=pydoc.plaintext)
    for name in [n for n in mod.__all__ if not n.startswith("_")][:40]:
        assert name in text, (package, name)


def test_perception_lists_exactly_the_api_module():
    import perception
    import perception.api

    assert set(perception.__all__) - {"__version__"} == set(perception.api.__all__)


def test_importing_the_facades_loads_nothing_heavy():
    code = ("import sys, minvar, perception, perception.report\n"
            "heavy = [m for m in ('matplotlib', 'statsmodels', 'cv2', 'h5py') "
            "if m in sys.modules]\n"
            "assert not heavy, heavy\n")
    subprocess.run([sys.executable, "-c", code], check=True)

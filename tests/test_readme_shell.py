"""README's shell blocks run as written, in order, in a fresh folder.

Each ```sh block of README.md (but the first: ``make demo`` and ``make
test`` build this very environment) runs under ``bash -e`` with
``hammer-mv`` on PATH, in one scratch folder that holds the shipped
``datasets/`` and ``tests/`` (its real recordings): the pipeline block
renders the clips the later blocks track, export and score, so a renamed
flag or a changed output name fails here.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]


def _blocks() -> list[tuple[int, str]]:
    text = (ROOT / "README.md").read_text()
    found = []
    for m in re.finditer(r"^```(?:sh|bash)\n(.*?)^```", text, flags=re.S | re.M):
        found.append((text[: m.start()].count("\n") + 1, m.group(1)))
    return found


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    d = tmp_path_factory.mktemp("readme")
    (d / "datasets").symlink_to(ROOT / "datasets")
    (d / "tests").symlink_to(ROOT / "tests")  # the trimmed real recordings of tests/data
    bin_dir = d / "bin"
    bin_dir.mkdir()
    shim = bin_dir / "hammer-mv"
    shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m hammer_mv "$@"\n')
    shim.chmod(0o755)
    return d


def test_readme_opens_with_make_demo_and_make_test():
    first = _blocks()[0][1]
    assert first.startswith("make demo") and "\nmake test" in first


BLOCKS = _blocks()[1:]


@pytest.mark.parametrize("line, block", BLOCKS, ids=[f"line{n}" for n, _ in BLOCKS])
def test_readme_shell_block(line, block, workdir):
    env = {**os.environ, "PATH": f"{workdir / 'bin'}{os.pathsep}{os.environ['PATH']}",
           "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    proc = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", block], cwd=workdir, env=env,
                          capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, (f"README line {line}:\n{proc.stdout[-1500:]}\n"
                                  f"{proc.stderr[-3000:]}")

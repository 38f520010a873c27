"""The device kit (tools/device/) carries the versions the project is tested with."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _pins(path: Path) -> dict[str, str]:
    """``name==version`` lines of a requirements file, names normalised (PEP 503)."""
    pins = {}
    for line in path.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if "==" in line:
            name, version = line.split("==", 1)
            pins[re.sub(r"[-_.]+", "-", name).lower()] = version.strip()
    return pins


def test_every_carried_wheel_is_pinned_as_the_lock_pins_it():
    carried = _pins(ROOT / "tools" / "device" / "wheels.txt")
    locked = _pins(ROOT / "requirements-lock.txt")
    assert len(carried) >= 10 and {"pydantic", "pydantic-core", "dask", "distributed"} <= set(
        carried)
    assert {name: v for name, v in carried.items() if locked.get(name) != v} == {}

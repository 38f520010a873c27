"""Every Python name README.md and docs/ give a user exists where they say it is.

A name in backticks that starts with ``perception.``, ``pc.`` (``import
perception as pc``) or ``minvar.`` must import: a module, then its
attributes (a dataclass field, which is no class attribute, counts).
Names move between modules; the pages that point at them must move too.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
NAME = re.compile(r"`((?:pc|perception|minvar)(?:\.[A-Za-z_]\w*)+)")


def _resolves(name: str) -> bool:
    parts = name.split(".")
    parts[0] = "perception" if parts[0] == "pc" else parts[0]
    for i in range(len(parts), 0, -1):  # the longest prefix that is a module
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for part in parts[i:]:
            if part in getattr(obj, "__dataclass_fields__", {}):
                return True
            if not hasattr(obj, part):
                return False
            obj = getattr(obj, part)
        return True
    return False


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_python_name_a_page_gives_exists(page):
    names = sorted(set(NAME.findall(page.read_text())))
    assert [n for n in names if not _resolves(n)] == []


def test_the_late_opening_share_beside_grip_departs_is_the_rules():
    from perception.recognition.rules import VerdictRules

    text = " ".join((ROOT / "docs" / "recognition.md").read_text().split())
    said = re.search(r"grip_departs`\): it starts to open \(10 % of its opening\) after "
                     r"(\d+) % of the movement", text)
    assert said and int(said.group(1)) == round(VerdictRules().late_opening * 100)

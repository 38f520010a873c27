"""tools/reproduce_ch4.py: every chapter-4 figure and the claims table."""

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_reproduce_ch4_writes_figures_and_claims(tmp_path):
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        from reproduce_ch4 import markdown, reproduce
        from reproduce_common import CLAIM_KEYS
    finally:
        sys.path.remove(str(ROOT / "tools"))
    claims = reproduce(tmp_path, trials=20, seed=0)
    for n in (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16):
        assert list(tmp_path.glob(f"fig4_{n}_*.png")), f"Fig. 4.{n} missing"
    assert (tmp_path / "object-size.csv").exists()
    records = claims
    claims = [c for c in records if c.get("kind") != "sensitivity"]
    tables = [c for c in records if c.get("kind") == "sensitivity"]
    assert all(set(c) == set(CLAIM_KEYS) for c in claims)
    assert len(claims) >= 20 and all(c["location"] and c["measure"] for c in claims)
    by = {c["claim"]: c for c in claims}
    slope = next(c for k, c in by.items() if k.startswith("MGA grows linearly"))
    assert slope["verdict"] == "agree" and slope["thesis"].startswith("0.92")
    level = next(c for k, c in by.items() if k.startswith("Digit end-point SD is lowest"))
    assert level["verdict"] == "agree"
    # the thesis contradicting itself is said so, with both places
    wrist = next(c for k, c in by.items() if k.startswith("Wrist SD changes"))
    assert wrist["verdict"] == "thesis inconsistent" and "963" in wrist["location"]
    assert "1207" in wrist["location"]
    # what cannot differ in this model is not counted as agreement
    assert next(c for k, c in by.items() if k.startswith("Wrist peak SD is unaffected")
                )["verdict"] == "by construction"
    # a claim that does not agree says why
    assert all(c["why"] for c in claims if c["verdict"] != "agree")
    assert [t["title"].split(",")[0] for t in tables] == ["tip_start", "transport distance"]
    tip = tables[0]
    assert len(tip["rows"]) == 5 and any("(used)" in r[0] for r in tip["rows"])
    assert markdown(records).count("\n") == len(claims) + 2

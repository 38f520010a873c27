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
    finally:
        sys.path.remove(str(ROOT / "tools"))
    claims = reproduce(tmp_path, trials=20, seed=0)
    for n in (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16):
        assert list(tmp_path.glob(f"fig4_{n}_*.png")), f"Fig. 4.{n} missing"
    assert (tmp_path / "object-size.csv").exists()
    assert all(set(c) == {"section", "claim", "thesis", "ours", "agrees", "note"}
               for c in claims)
    assert len(claims) >= 15
    by = {c["claim"]: c for c in claims}
    slope = next(c for k, c in by.items() if "slope" in k)
    assert slope["agrees"] and slope["thesis"].startswith("0.92")
    level = next(c for k, c in by.items() if k.startswith("Digit end-point SD is lowest"))
    assert level["agrees"]
    # a claim that does not agree says why
    assert all(c["note"] for c in claims if not c["agrees"])
    assert markdown(claims).count("\n") == len(claims) + 2

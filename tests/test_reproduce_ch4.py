"""tools/thesis/ch4.py: every chapter-4 figure and the claims table."""

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tools.thesis.ch4 import reproduce  # noqa: E402
from tools.thesis.ch4_claims import CLAIMS  # noqa: E402
from tools.thesis.records import CLAIM_KEYS  # noqa: E402


@pytest.mark.slow
def test_reproduce_ch4_writes_figures_and_claims(tmp_path):
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
    assert slope["verdict"] == "by construction" and slope["thesis"].startswith("0.92")
    # the thesis contradicting itself is said so, with both places
    wrist = next(c for k, c in by.items() if k.startswith("Wrist SD changes"))
    assert wrist["verdict"] == "thesis inconsistent" and "963" in wrist["location"]
    assert "1207" in wrist["location"]
    # what cannot differ in this model is not counted as agreement
    assert next(c for k, c in by.items() if k.startswith("Wrist peak SD is unaffected")
                )["verdict"] == "by construction"
    # a by-construction row is one at the thesis's settings too
    assert slope["at_thesis"].startswith("r = 0.002, w_v = 0.1: by construction")
    # a claim that does not agree says why
    assert all(c["why"] for c in claims if c["verdict"] != "agree")
    assert [t["title"].split(",")[0] for t in tables] == [
        "tip_start", "tip_start at the thesis's settings (its model and weights)",
        "transport distance"]
    tip = tables[0]
    assert len(tip["rows"]) == 5 and any("(used)" in r[0] for r in tip["rows"])
    assert [c["id"] for c in claims] == [c.id for c in CLAIMS]  # one row per declared claim
    # every verdict pinned: a change that flips one is seen (exact moments, so the
    # reduced repetitions do not move them; the by-construction and own rows included)
    pinned = {
        # holds for tip_start 1-4 cm, fails at 6 cm (the tip_start table)
        "Digit end-point distance from the target": "conditional",
        "Digit end-point SD is lowest": "differs",  # per axis, as Fig. 4.3(c,d) plots
        "End-point SD peaks for a via-point late": "agree",
        "End-point SD is lowest for a via-point near 70 %": "differs",  # falls below 70 %
        "End-point distance hardly changes": "agree",
        "A via-point further from the object gives a larger MGA": "by construction",
        "MGA grows linearly with object size": "by construction",
        "The model's MGA slope is approximately 0.8": "thesis inconsistent",
        "MGA occurs at 60-80 %": "conditional",  # holds at 1-3 cm, fails at 4 and 6 cm
        "MGA occurs later for larger objects": "agree",
        "Wrist peak SD is unaffected by object size": "by construction",
        # line 943 against lines 949 and 1205 (the model's wrist takes no account of size)
        "With no object (size 0)": "thesis inconsistent",
        "Wrist peak SD occurs slightly later": "thesis inconsistent",
        # for each digit, about the wrist (line 790 'in the wrist target frame'): per axis
        # the minima lie off level in this frame too; the SD falls below 70 % here as well
        "Hand frame: digit end-point SD is lowest": "differs",
        "Hand frame: end-point SD is lowest for a via-point near 70 %": "differs",
        "Grip aperture SD is unaffected by transport": "by construction",
        "Wrist SD changes with transport distance": "thesis inconsistent",
        "Object size and the transport component": "thesis inconsistent",
        "The via-point distances of Figs. 4.7-4.8": "thesis inconsistent",
    }
    for prefix, verdict in pinned.items():
        c = next(c for k, c in by.items() if k.startswith(prefix))
        assert c["verdict"] == verdict, (prefix, c["verdict"])
    # at the thesis's weights, and conditional on tip_start where the geometry decides,
    # judged by the tip_start table at the thesis's own settings (not ours)
    assert all(c["at_thesis"] for c in claims)
    mga = next(c for k, c in by.items() if k.startswith("MGA occurs at 60-80 %"))
    assert mga["at_thesis"].startswith("conditional on tip_start")
    assert "fails at 6 cm (the thesis's model and weights)" in mga["at_thesis"]
    assert "fails at 4 cm, 6 cm" in mga["why"]  # ours: at our weights
    # the tip_start table judges line 834 by the row's own rule (a resolvable rise below
    # 70 %), not by an interior minimum, so the row's range agrees with its verdict; a
    # rule that holds at no tip_start is 'differs' in that column, not conditional
    late = next(c for k, c in by.items() if k.startswith("End-point SD is lowest for a"))
    assert "holds at none" in late["at_thesis"]
    assert late["at_thesis"].startswith("r = 0.002, w_v = 0.1: differs")
    assert all("no rise" in r[2] for r in tip["rows"])
    size0 = next(c for k, c in by.items() if k.startswith("With no object"))
    assert "943" in size0["location"] and "1205" in size0["location"]
    assert {c["kind"] for k, c in by.items() if k.startswith("Time of the")} == {"own"}

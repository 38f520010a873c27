"""tools/thesis (``python -m tools.thesis``, tools/reproduce_thesis.py): figures,
numbers.md, the claims as data and the one evaluator."""

import dataclasses
import importlib
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tools.thesis import cli as reproduce_thesis  # noqa: E402
from tools.thesis.claims import Claim, Measured, below, evaluate, holds  # noqa: E402
from tools.thesis.markdown import at_thesis_verdict, numbers_markdown  # noqa: E402
from tools.thesis.records import (  # noqa: E402
    CLAIM_KEYS,
    TABLE_HEADINGS,
    VERDICTS,
    claim,
    sensitivity,
)
from tools.thesis.text import quote_is_on_line, thesis_text  # noqa: E402


def _row(cells) -> str:
    return "| " + " | ".join(cells) + " |"


#: Every chapter's table of claims.
TABLES = ("ch2_claims", "ch3_claims", "appendix_a_claims", "ch4_claims", "ch5_claims")


def _tables():
    return {name: importlib.import_module(f"tools.thesis.{name}").CLAIMS for name in TABLES}


def test_every_cited_line_holds_the_quoted_words():
    # the tools find the thesis text as tools.thesis.text.thesis_text does: users may not
    # have it, so the check is skipped, saying why
    lines = thesis_text()
    if lines is None:
        pytest.skip("thesis text not found ($HAMMER_MV_THESIS or shared/seed/"
                    "minimum-variance-thesis.txt in or beside the checkout)")
    checked = 0
    for name, table in _tables().items():
        for c in table:
            if c.line is None:  # our own check, not a thesis claim
                continue
            assert quote_is_on_line(lines, c.line, c.quote), (name, c.id, c.line, c.quote)
            checked += 1
            if c.against:  # the other place where the thesis says the opposite
                assert quote_is_on_line(lines, *c.against[:2]), (name, c.id, c.against)
    assert checked >= 60
    # and a wrong line is caught: the Fig. 4.8 claims are on 875/877, 880 is blank
    assert not quote_is_on_line(lines, 880, "grip size increases and occurs *earlier*")
    assert quote_is_on_line(lines, 877, "grip size increases and occurs *earlier*")

FIGURES = [
    "fig2_5_minimum_jerk", "fig2_6_derivative_order", "fig2_7_angle_jerk_joints",
    "fig2_8_angle_jerk_hand", "fig3_2_viapoint_timing", "fig3_3_merging",
    "fig3_4_point_to_point", "fig3_5_speed_accuracy", "fig3_6_s_movement",
    "fig3_7_s_speed_accuracy", "fig3_8_letter_a", "fig3_9_letter_a_durations",
    "figA_1_viapoint_criteria", "figA_2_curvature_viapoints", "figA_3_generalisation",
]


@pytest.mark.slow
def test_quick_run_writes_every_figure_and_the_claims_table(tmp_path, capsys):
    status = reproduce_thesis.main(["-o", str(tmp_path), "--quick", "--skip-ch4", "--seed", "1"])
    assert status == 0
    for name in FIGURES:
        png = tmp_path / f"{name}.png"
        assert png.stat().st_size > 10_000, name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if ".part" in p.name]  # no half-written files
    sweep = pd.read_csv(tmp_path / "fig3_5_speed_accuracy.csv")
    assert len(sweep) == 8 and sweep["sd_total"].iloc[0] > sweep["sd_total"].iloc[-1]

    md = (tmp_path / "numbers.md").read_text()
    header = _row(TABLE_HEADINGS)
    body, inside = [], False
    for line in md.splitlines():  # the rows of each chapter's thesis-claims table
        inside = line == header or (inside and line.startswith("|"))
        if inside and line != header and not line.startswith("|---"):
            body.append(line)
    assert len(body) >= 20
    assert all(len(re.split(r"(?<!\\)\|", r)) == 11 for r in body)  # nine cells each
    assert "## Chapter 3" in md and "## Appendix A" in md and "## Settings" in md
    assert "#### Sensitivity: the length unit of eq. A.1" in md
    assert "skipped (--skip-ch4)" in md
    assert "thesis claims, each counted once" in md and "checks of our own" in md
    claims = pd.read_csv(tmp_path / "numbers.csv", keep_default_na=False)
    assert list(claims.columns) == ["chapter", *CLAIM_KEYS]
    thesis = claims[claims["kind"] == "thesis"]
    assert len(thesis) == len(body)
    # every row carries a thesis location and a measure; every thesis claim its line,
    # its words, and its verdict at the thesis's settings
    assert (claims["location"].str.len() > 0).all() and (claims["measure"].str.len() > 0).all()
    assert (thesis["line"].astype(str).str.len() > 0).all()
    assert (thesis["quote"].str.len() > 0).all() and (thesis["at_thesis"].str.len() > 0).all()
    assert set(claims["verdict"]) <= {*VERDICTS, "conditional"}
    # every row names its declared claim, and the rule it was judged by
    assert claims.groupby("chapter")["id"].apply(lambda ids: ids.is_unique).all()
    assert (claims["id"].str.len() > 0).all() and (claims["expected"].str.len() > 0).all()
    human = claims[claims["claim"].str.contains("closest to minimum jerk")].iloc[0]
    assert "15/8" in human["ours"] and human["verdict"] == "by construction"  # closed form
    assert "human" in human["thesis"]  # 1.875 is the thesis's human value
    # the 'a' reverses at 70 % because we put its via-point there
    assert (claims[claims["claim"].str.contains("reversal comes")]["verdict"]
            == "by construction").all()
    for needle in ("Fig. 3.2(b)", "Fig. 3.5", "Fig. 3.7", "Fig. 3.6(a,c)", "Fig. 3.8(b)",
                   "Fig. A.1(b)", "Fig. A.2", "Fig. 3.4(c)", "Fig. 3.4(a)", "line 481"):
        assert claims["location"].str.contains(needle, regex=False).any(), needle
    # line 552's claim is about the thesis's settings, so it is judged at them in both
    # columns: with the printed plant a 500 ms reach ends still moving (9 % of its peak
    # speed), slower ones halt; the thesis gives no time, so the row is conditional on it
    goal = claims[claims["claim"].str.startswith("The cost weights give")].iloc[0]
    assert goal["verdict"] == "conditional" and goal["at_thesis"].startswith("conditional")
    held = goal["ours"].split("holds at ")[1].split(" of ")[0].split(", ")
    assert "500" not in held and "1000" in held, goal["ours"]  # the boundary is sampled
    lines = thesis_text()
    if lines is not None:
        for _, c in thesis.iterrows():
            assert quote_is_on_line(lines, int(c["line"]), c["quote"]), (c["line"], c["quote"])
    assert "15 figures" in capsys.readouterr().out
    # the thin command and the module are the same program
    for cmd in ([sys.executable, "tools/reproduce_thesis.py", "--help"],
                [sys.executable, "-m", "tools.thesis", "--help"]):
        done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
        assert done.returncode == 0 and "--skip-ch4" in done.stdout, cmd


def test_a_failing_chapter_is_reported_and_the_others_go_on(tmp_path, monkeypatch):
    def broken(out, **kw):
        raise RuntimeError("boom")

    monkeypatch.setattr(reproduce_thesis, "load_chapter", lambda module: broken)
    claims, notes, timings, ok = reproduce_thesis.run(
        tmp_path, trials=5, seed=0, quick=True, chapters=[("Chapter 4", "tools.thesis.ch4")])
    assert not ok and claims == [] and "FAILED" in notes[0] and "boom" in notes[0]
    assert timings[0].startswith("Chapter 4: ")


def test_every_chapter_takes_the_same_interface(tmp_path, monkeypatch):
    # one call for every chapter: the trials, seed and smoke flag it was given
    seen = []

    def fake(out, *, trials, seed, quick, progress):
        seen.append((trials, seed, quick))
        return [claim("4.1", "c", "t", f"{trials} {seed}", True)]

    monkeypatch.setattr(reproduce_thesis, "load_chapter", lambda module: fake)
    ch = list(reproduce_thesis.CHAPTERS)
    claims, notes, _, ok = reproduce_thesis.run(tmp_path, trials=None, seed=3, quick=False,
                                                chapters=ch)
    assert ok and not notes and seen == [(None, 3, False)] * len(ch)
    assert [c["chapter"] for c in claims] == [t for t, _ in ch]
    claims, *_ = reproduce_thesis.run(tmp_path, trials=None, seed=3, quick=True, chapters=ch[:1])
    assert claims[0]["ours"] == f"{reproduce_thesis.QUICK_TRIALS} 3"


def test_numbers_markdown_escapes_cells_and_checks_keys():
    # a record of the original six keys still renders, as a row of the new table
    row = dict(section="A.1", claim="a | b", thesis="1", ours="2", agrees=False, note="n")
    md = numbers_markdown([row], ["note line"], ["header"])
    assert "| a \\| b | A.1 |  | not stated | 1 | 2 | **differs** |  | n |" in md
    assert "- note line" in md and "1 claims: 0 agree, 1 differ" in md
    with pytest.raises(ValueError, match="lacks"):
        numbers_markdown([{"section": "x"}], [], [])


def test_claims_and_tables_are_grouped_by_chapter():
    rows = [
        dict(claim("2.2", "c1", "t", "o", True, location="Fig. 2.6(c); line 276",
                   measure="m1"), chapter="Chapter 2"),
        dict(claim("4.2", "c2", "t", "o", verdict="thesis inconsistent", note="both",
                   location="line 903 vs line 971", measure="m2"), chapter="Chapter 4"),
        dict(sensitivity("tip_start", "not given", "we use 2 cm", ["tip_start", "verdict"],
                         [["1 cm", "yes"], ["6 cm", "**no**"]]), chapter="Chapter 4"),
    ]
    md = numbers_markdown(rows, [], ["header"])
    assert md.index("## Chapter 2") < md.index("| c1 |") < md.index("## Chapter 4")
    assert "| c1 | Fig. 2.6(c); line 276 |  | m1 | t | o | agree |  |  |" in md
    assert "| **thesis inconsistent** |  | both |" in md
    assert "#### Sensitivity: tip_start" in md and "| 6 cm | **no** |" in md
    assert ("1 claims: 1 agree, 0 differ, 0 conditional, 0 by construction, 0 thesis "
            "inconsistent") in md
    # our own checks are counted apart from the thesis's claims
    own = dict(claim("5.3", "o1", "—", "o", True, kind="own", measure="m"), chapter="Chapter 4")
    md = numbers_markdown([*rows, own], [], ["header"])
    assert "- 2 thesis claims, each counted once" in md and "- 1 checks of our own" in md
    assert "  - at our settings: 1 agree, 0 differ, 0 conditional, 0 by construction, 1 " \
        "thesis inconsistent;" in md
    assert "### Our own checks (Chapter 4" in md and "| o1 | 5.3 | m | o | agree |  |" in md


def test_claim_record():
    c = claim("3.2.3", "c", "t", "o", False, "why", location="Fig. 3.2(b); line 591",
              measure="m")
    assert c["verdict"] == "differs" and c["agrees"] is False and c["why"] == "why"
    assert claim("3.2", "c", "t", "o", True)["location"] == "3.2"  # defaults to the section
    b = claim("3.3.2", "c", "t", "o", verdict="by construction")
    assert b["verdict"] == "by construction" and not b["agrees"]
    with pytest.raises(ValueError, match="verdict"):
        claim("x", "c", "t", "o", verdict="maybe")
    with pytest.raises(ValueError, match="agrees or verdict"):
        claim("x", "c", "t", "o")
    with pytest.raises(ValueError, match="cells"):
        sensitivity("p", "l", "n", ["a", "b"], [["1"]])
    with pytest.raises(ValueError, match="kind"):
        claim("x", "c", "t", "o", True, kind="mine")
    q = claim("x", "c", "t", "o", True, line=552, quote="r = 0.002", at_thesis="differs: x")
    assert (q["kind"], q["line"], q["quote"], q["at_thesis"]) == ("thesis", 552, "r = 0.002",
                                                                 "differs: x")


def test_chapters_in_two_processes_give_the_same_records(tmp_path):
    ch = [("Chapter 2", "tools.thesis.ch2"), ("Appendix A", "tools.thesis.appendix_a")]
    one, _, _, ok1 = reproduce_thesis.run(tmp_path / "a", trials=3, seed=2, quick=True,
                                          chapters=ch)
    two, _, timings, ok2 = reproduce_thesis.run(tmp_path / "b", trials=3, seed=2, quick=True,
                                                chapters=ch, jobs=2)
    assert ok1 and ok2 and [t.split(":")[0] for t in timings] == ["Chapter 2", "Appendix A"]
    assert one == two  # same order (the thesis's), same numbers


def test_bad_options_exit_2(tmp_path):
    with pytest.raises(SystemExit) as e:
        reproduce_thesis.main(["-o", str(tmp_path), "--trials", "1"])
    assert e.value.code == 2


def test_by_construction_never_enters_an_agree_tally_in_either_column():
    # a row made to hold by how the model or test was built says 'agree' at the thesis's
    # settings when the chapter only dressed its main verdict: it is counted by construction
    rows = [dict(claim("3.3", "built", "t", "o", verdict="by construction",
                       at_thesis="agree: o"), chapter="Chapter 3"),
            dict(claim("5.4", "flips", "t", "o", verdict="differs",
                       at_thesis="conditional (survives text; not printed): o"),
                 chapter="Chapter 5"),
            dict(claim("5.4", "holds", "t", "o", True,
                       at_thesis="agree (survives text, printed, consecutive): o"),
                 chapter="Chapter 5")]
    assert at_thesis_verdict("agree: o", "by construction") == "by construction"
    md = numbers_markdown(rows, [], ["header"])
    assert ("  - at the thesis's settings: 1 agree, 0 differ, 1 conditional, 1 by "
            "construction, 0 thesis inconsistent.") in md
    assert "| Chapter 3 | built |  | by construction | by construction |" in md
    assert "| Chapter 5 | flips |  | differs | conditional |" in md


def test_a_claim_measured_two_ways_is_counted_once():
    # the hand frame beside the world frame is one statement of the thesis: one claim,
    # conditional where the two frames disagree
    rows = [dict(claim("4.2", "Digit SD is lowest at level", "t", "o", False,
                       at_thesis="differs: o"), chapter="Chapter 4"),
            dict(claim("4.2", "Hand frame: digit SD is lowest at level", "t", "o", True,
                       at_thesis="differs: o"), chapter="Chapter 4"),
            dict(claim("4.3", "Another", "t", "o", True, at_thesis="agree: o"),
                 chapter="Chapter 4")]
    md = numbers_markdown(rows, [], ["header"])
    assert "- 2 thesis claims (3 rows: a hand-frame row beside" in md
    assert "  - at our settings: 1 agree, 0 differ, 1 conditional," in md
    assert "  - at the thesis's settings: 1 agree, 1 differ, 0 conditional," in md


def test_claims_are_data_and_one_evaluator_checks_every_one():
    # every chapter's claims are declared in one table: an id, where the thesis says it
    # (a cited line and its words, or our own check), how it is measured and the rule
    for name, table in _tables().items():
        ids = [c.id for c in table]
        assert len(set(ids)) == len(ids) >= 5, name
        for c in table:
            assert isinstance(c, Claim) and c.location and c.measure and c.expected, c.id
            assert (c.line is not None and c.quote) or c.kind == "own", c.id
            assert c.rule or c.verdict in ("by construction", "thesis inconsistent"), c.id
    # the evaluator yields one row per claim, in the table's order, each with the
    # measured value, the rule, the verdict and the note
    table = _tables()["ch2_claims"]
    measured = {c.id: Measured("ours", dict.fromkeys(
        {check.value for check in c.rule}, 0.5)) for c in table}
    rows = evaluate(table, measured)
    assert [r["id"] for r in rows] == [c.id for c in table]
    assert all(set(r) == set(CLAIM_KEYS) for r in rows)
    assert all(r["expected"] == c.expected for r, c in zip(rows, table))
    with pytest.raises(KeyError, match="not measured"):
        evaluate(table, dict(list(measured.items())[1:]))


def test_a_broken_claim_is_reported_as_not_ok():
    straight = Claim("straight", "2.2.2", "Paths are straight", "straight", "line 260",
                     "largest deviation; agree below 1 mm", rule=(below("deviation_m", 1e-3),),
                     line=260, quote="straight")
    ok = evaluate([straight], {"straight": Measured("0.1 mm", {"deviation_m": 1e-4})})[0]
    assert ok["verdict"] == "agree" and ok["agrees"] and ok["expected"] == "deviation_m < 0.001"
    # the same claim with its tolerance broken (a hundred times tighter) fails, and says why
    broken = dataclasses.replace(straight, rule=(below("deviation_m", 1e-5),))
    row = evaluate([broken], {"straight": Measured("0.1 mm", {"deviation_m": 1e-4})},
                   unexplained="the numbers fail the rule")[0]
    assert row["verdict"] == "differs" and not row["agrees"]
    assert row["why"] == "the numbers fail the rule"
    # a rule read against another measured value, and a truth value the chapter computes
    check = below("rise", "se", 2)
    assert check.words() == "rise < 2 × se"
    rise = Claim("rise", "4.2", "Rises", "rises", "line 834", "m", line=834, quote="q",
                 rule=(check, holds("monotone")))
    got = evaluate([rise], {"rise": Measured("o", {"rise": 1.0, "se": 1.0, "monotone": False})})
    assert got[0]["verdict"] == "differs"
    # a fixed verdict is kept whatever the numbers; a chapter's conditional overrides the rule
    built = dataclasses.replace(broken, verdict="by construction")
    assert evaluate([built], {"straight": Measured("o", {"deviation_m": 1.0})})[0][
        "verdict"] == "by construction"
    assert evaluate([broken], {"straight": Measured("o", {"deviation_m": 1.0},
                                                    verdict="conditional")})[0][
        "verdict"] == "conditional"
    # a claim that is not data cannot be declared
    with pytest.raises(ValueError, match="rule or a fixed verdict"):
        Claim("x", "1", "c", "t", "l", "m", line=1, quote="q")
    with pytest.raises(ValueError, match="cites a line"):
        Claim("x", "1", "c", "t", "l", "m", rule=(holds("y"),))


def test_readme_lists_every_option_of_the_reproduction(capsys):
    # --skip-verdict was missing: a quick look at chapters 2-4 still rendered 60 clips
    with pytest.raises(SystemExit):
        reproduce_thesis.main(["--help"])
    usage = capsys.readouterr().out.split("\n\n")[0]
    options = set(re.findall(r"\[(--?[a-z][\w-]*)", usage)) - {"-h"}
    readme = (ROOT / "README.md").read_text()
    synopsis = re.search(r"python -m tools\.thesis (.*?)`\)", readme, flags=re.S).group(1)
    assert len(options) >= 7
    assert options <= set(re.findall(r"\[(--?[a-z][\w-]*)", synopsis))

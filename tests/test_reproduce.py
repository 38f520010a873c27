"""tools/reproduce_thesis.py: figures, numbers.md, and the guarded chapter 4 hook."""

import re
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

TOOLS = Path(__file__).resolve().parents[1] / "tools"
sys.path.insert(0, str(TOOLS))

import reproduce_thesis  # noqa: E402

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
    rows = [line for line in md.splitlines() if line.startswith("| ") and "---" not in line]
    header, body = rows[0], rows[1:]
    assert header == "| section | claim | thesis | ours | agrees | note |"
    assert len(body) >= 20
    assert all(len(re.split(r"(?<!\\)\|", r)) == 8 for r in body)  # six cells each
    assert "skipped (--skip-ch4)" in md
    claims = pd.read_csv(tmp_path / "numbers.csv")
    assert list(claims.columns) == ["section", "claim", "thesis", "ours", "agrees", "note"]
    jerk = claims[claims["claim"].str.contains("minimum jerk \\(n = 3\\)")]
    assert jerk["ours"].iloc[0].startswith("1.8750") and jerk["agrees"].iloc[0]
    for needle in ("Fig. 3.2(b)", "Fig. 3.5", "Fig. 3.7", "Fig. 3.6(c)", "Fig. 3.8(b)",
                   "Fig. A.1(b)", "Fig. 3.4(c)", "Fig. 3.4(a)"):
        assert claims["section"].str.contains(needle, regex=False).any(), needle
    assert "15 figures" in capsys.readouterr().out


def _fake_ch4(folder: Path, body: str) -> None:
    (folder / "reproduce_ch4.py").write_text(textwrap.dedent(body))


def test_chapter4_is_called_with_its_interface(tmp_path, monkeypatch):
    mods = tmp_path / "mods"
    mods.mkdir()
    _fake_ch4(mods, """
        def reproduce(out, *, trials=500, seed=0):
            (out / "fig4_9_fake.png").write_bytes(b"png")
            return [dict(section="4.1", claim="c", thesis="0.92", ours=f"{trials} {seed}",
                         agrees=True, note="")]
    """)
    monkeypatch.syspath_prepend(str(mods))
    monkeypatch.delitem(sys.modules, "reproduce_ch4", raising=False)
    out = tmp_path / "out"
    out.mkdir()
    ch4 = [("Chapter 4", "reproduce_ch4")]
    try:
        claims, notes, _, ok = reproduce_thesis.run(out, trials=None, seed=3, quick=False,
                                                    chapters=ch4)
        assert ok and not notes and claims[0]["ours"] == "500 3"
        claims, *_ = reproduce_thesis.run(out, trials=None, seed=3, quick=True, chapters=ch4)
        assert claims[0]["ours"] == f"{reproduce_thesis.QUICK_TRIALS} 3"
    finally:
        # the fake must not shadow tools/reproduce_ch4.py for later tests in this process
        sys.modules.pop("reproduce_ch4", None)


def test_missing_chapter4_is_noted_and_a_failing_one_reported(tmp_path, monkeypatch):
    monkeypatch.setattr(reproduce_thesis, "load_chapter", lambda module: None)
    ch4 = [("Chapter 4", "reproduce_ch4")]
    claims, notes, _, ok = reproduce_thesis.run(tmp_path, trials=5, seed=0, quick=True,
                                                chapters=ch4)
    assert ok and claims == [] and "missing" in notes[0]

    def broken(out, *, trials, seed):
        raise RuntimeError("boom")

    monkeypatch.setattr(reproduce_thesis, "load_chapter", lambda module: broken)
    claims, notes, _, ok = reproduce_thesis.run(tmp_path, trials=5, seed=0, quick=True,
                                                chapters=ch4)
    assert not ok and "FAILED" in notes[0] and "boom" in notes[0]
    # a chapter of ours that is missing is an error, not a note
    monkeypatch.setattr(reproduce_thesis, "load_chapter", lambda module: None)
    _, notes, _, ok = reproduce_thesis.run(tmp_path, trials=5, seed=0, quick=True,
                                           chapters=[("Chapter 2", "reproduce_ch2")])
    assert not ok and "FAILED" in notes[0]


def test_numbers_markdown_escapes_cells_and_checks_keys():
    row = dict(section="A.1", claim="a | b", thesis="1", ours="2", agrees=False, note="n")
    md = reproduce_thesis.numbers_markdown([row], ["note line"], ["header"])
    assert "| A.1 | a \\| b | 1 | 2 | **no** | n |" in md
    assert "- note line" in md and "0 of 1 claims agree" in md
    with pytest.raises(ValueError, match="lacks"):
        reproduce_thesis.numbers_markdown([{"section": "x"}], [], [])


def test_bad_options_exit_2(tmp_path):
    with pytest.raises(SystemExit) as e:
        reproduce_thesis.main(["-o", str(tmp_path), "--trials", "1"])
    assert e.value.code == 2

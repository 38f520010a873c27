"""numbers.md: the claims of every chapter, their tallies and the sensitivity tables."""

from __future__ import annotations

import pandas as pd

from tools.thesis.common import settings_rows
from tools.thesis.records import (
    OWN_HEADINGS,
    OWN_KEYS,
    TABLE_HEADINGS,
    TABLE_KEYS,
    VERDICTS,
    as_claim,
    is_sensitivity,
)


def _cell(value) -> str:
    return str(value).replace("|", "\\|").replace("\n", " ")


def _row(cells) -> str:
    return "| " + " | ".join(_cell(c) for c in cells) + " |"


#: The verdicts numbers.md tallies, in order: :data:`VERDICTS` with ``conditional``
#: (a verdict that flips with a choice the thesis leaves open) after ``differs``.
TALLIED = (*VERDICTS[:2], "conditional", *VERDICTS[2:])
_WORDS = {"agree": "agree", "differs": "differ", "conditional": "conditional",
          "by construction": "by construction", "thesis inconsistent": "thesis inconsistent"}


def _tally(words: list[str]) -> str:
    """``"37 agree, 5 differ, 0 conditional, ..."``: every tallied verdict, then any other."""
    n = pd.Series(words, dtype=object).value_counts()
    extra = [w for w in n.index if w not in TALLIED]
    return ", ".join([f"{int(n.get(v, 0))} {_WORDS[v]}" for v in TALLIED]
                     + [f"{int(n[w])} {w}" for w in extra])


def verdict_counts(claims: list[dict]) -> str:
    """``"37 agree, 5 differ, ..."`` over the claims, in the order of :data:`TALLIED`.

    Parameters
    ----------
    claims : list of dict
        Claim records (current form).
    """
    return _tally([c["verdict"] for c in claims])


def _sensitivity_md(table: dict) -> list[str]:
    lines = [f"#### Sensitivity: {table['title']}", "",
             f"Thesis: {table['location']}. {table['note']}", ""]
    lines.append(_row(table["columns"]))
    lines.append("|" + "---|" * len(table["columns"]))
    lines += [_row(r) for r in table["rows"]]
    return lines + [""]


def _table(rows: list[dict], keys, headings) -> list[str]:
    lines = [_row(headings), "|" + "---|" * len(headings)]
    for c in rows:
        cells = [c[k] for k in keys]
        cells[keys.index("measure")] = c["measure"] or "not stated"
        if c["verdict"] != "agree":
            cells[keys.index("verdict")] = f"**{c['verdict']}**"
        lines.append(_row(cells))
    return lines + [""]


def at_thesis_verdict(text: str, verdict: str | None = None) -> str:
    """The verdict word of an ``at_thesis`` cell (``conditional`` for tip_start-dependent rows).

    A row that is ``by construction`` at our settings is so at the thesis's too:
    what makes it hold is how the model or the test was built, not the settings,
    so it never enters an agree tally in either column.

    Parameters
    ----------
    text : str
        The cell, e.g. ``"agree (survives text, printed): ..."``, ``"printed: agree: ..."``
        or ``"r = 0.002, w_v = 0.1: differs: ..."``.
    verdict : str, optional
        The row's verdict at our settings.
    """
    if verdict == "by construction":
        return verdict
    text = str(text)
    if text.startswith("conditional"):
        return "conditional"
    for prefix in ("printed: ", "r = 0.002, w_v = 0.1: "):
        text = text[len(prefix):] if text.startswith(prefix) else text
    return text.split(":")[0].split(" (")[0].strip() or "not computed"


#: Prefixes of a row that measures the same statement as another row another way (the
#: hand frame beside the world frame): one claim, counted once.
VARIANT_PREFIXES = ("Hand frame: ",)


def claim_key(c: dict) -> tuple[str, str]:
    """What makes two rows one thesis claim: the chapter and the statement, less any
    :data:`VARIANT_PREFIXES` (case ignored).

    Parameters
    ----------
    c : dict
        A claim record (with ``chapter`` where it has one).
    """
    text = str(c["claim"])
    for prefix in VARIANT_PREFIXES:
        text = text[len(prefix):] if text.startswith(prefix) else text
    return str(c.get("chapter", "")), text.strip().lower()


def unique_verdicts(claims: list[dict], column) -> list[str]:
    """One verdict per thesis claim (:func:`claim_key`): its rows' verdict where they
    agree, ``conditional`` where the variants disagree (the verdict depends on how the
    statement is measured, e.g. the frame).

    Parameters
    ----------
    claims : list of dict
        Claim records.
    column : callable
        A row's verdict in the column tallied (``lambda c: c["verdict"]``).
    """
    groups: dict[tuple, list[str]] = {}
    for c in claims:
        groups.setdefault(claim_key(c), []).append(column(c))
    return [v[0] if len(set(v)) == 1 else "conditional" for v in groups.values()]


def at_thesis_counts(claims: list[dict]) -> str:
    """``"20 agree, 9 differ, ..."``: the verdicts at the thesis's settings (first word).

    Parameters
    ----------
    claims : list of dict
        Thesis claims (current form).
    """
    return _tally(unique_verdicts(
        claims, lambda c: at_thesis_verdict(c.get("at_thesis", ""), c["verdict"])))


def claim_counts(claims: list[dict]) -> str:
    """``"37 agree, 5 differ, ..."`` over the unique thesis claims at our settings.

    Parameters
    ----------
    claims : list of dict
        Thesis claims (current form).
    """
    return _tally(unique_verdicts(claims, lambda c: c["verdict"]))


def n_claims(claims: list[dict]) -> str:
    n, rows = len({claim_key(c) for c in claims}), len(claims)
    return f"{n} claims" + (f" ({rows} rows: a hand-frame row beside its world-frame row is "
                            "one claim)" if rows != n else "")


def numbers_markdown(records: list[dict], notes: list[str], header: list[str]) -> str:
    """numbers.md: a header, the settings, and per chapter its thesis claims, our own
    checks and sensitivity tables, then every verdict at both settings side by side.

    Parameters
    ----------
    records : list of dict
        Claims (:func:`tools.thesis.records.claim`, or the original six-key
        record) and sensitivity tables (:func:`tools.thesis.records.sensitivity`),
        each with a ``chapter`` title (records without one are listed under
        "Claims").
    notes : list of str
        Lines about the run (missing or failed chapters), shown above the tables.
    header : list of str
        Lines describing the run (options, timings).
    """
    claims = [as_claim(r) for r in records if not is_sensitivity(r)]
    thesis = [c for c in claims if c["kind"] == "thesis"]
    own = [c for c in claims if c["kind"] == "own"]
    lines = ["# Thesis claims beside ours", "", *header, ""]
    lines += [f"- {n}" for n in notes]
    lines += [f"- {n_claims(thesis).replace('claims', 'thesis claims', 1)}, each counted "
              "once (chapter 5's on the independent generator's clips; on the model's own "
              "stimuli they are our own checks).",
              f"  - at our settings: {claim_counts(thesis)};",
              f"  - at the thesis's settings: {at_thesis_counts(thesis)}.",
              f"- {len(own)} checks of our own (not thesis claims): {verdict_counts(own)}.",
              ""]
    lines += ["Verdicts: **agree** — ours supports the statement by the measure given; "
              "**differs** — it does not; **by construction** — it holds only because of "
              "how the model or the test was built (in both columns: it never enters an agree "
              "tally); **conditional** — the verdict flips with a choice the thesis leaves "
              "open (geometry it does not give, a reading of eqs. 5.1/5.7 it allows), with "
              "the range where it holds; **thesis inconsistent** — the thesis "
              "says two different things (both places are cited). A thesis claim names the "
              "line of the thesis text it quotes and the words; 'at the thesis's settings' "
              "is the verdict (and our value) with the thesis's model and cost weights "
              "(chapter 5: the repertoire planned with them). Chapter 5's rows are judged "
              "under every reading of eqs. 5.1/5.7 the thesis allows, and say which they "
              "survive.",
              "", "## Settings: the thesis's and ours", ""]
    lines += [_row(("parameter", "thesis", "ours", "effect on the rows")),
              "|---|---|---|---|", *[_row(r) for r in settings_rows()], ""]
    chapters = list(dict.fromkeys(r.get("chapter", "Claims") for r in records))
    for chapter in chapters:
        mine = [r for r in records if r.get("chapter", "Claims") == chapter]
        rows = [as_claim(r) for r in mine if not is_sensitivity(r)]
        lines += [f"## {chapter}", ""]
        mine_thesis = [c for c in rows if c["kind"] == "thesis"]
        mine_own = [c for c in rows if c["kind"] == "own"]
        if mine_thesis:
            lines += [f"### Thesis claims ({chapter})", "",
                      f"{n_claims(mine_thesis)}: {claim_counts(mine_thesis)}; at the "
                      f"thesis's settings: {at_thesis_counts(mine_thesis)}.", ""]
            lines += _table(mine_thesis, TABLE_KEYS, TABLE_HEADINGS)
        if mine_own:
            lines += [f"### Our own checks ({chapter}; not thesis claims)", "",
                      f"{len(mine_own)} checks: {verdict_counts(mine_own)}.", ""]
            lines += _table(mine_own, OWN_KEYS, OWN_HEADINGS)
        for table in (r for r in mine if is_sensitivity(r)):
            lines += _sensitivity_md(table)
    side = [(r.get("chapter", "Claims"), as_claim(r)) for r in records
            if not is_sensitivity(r) and r.get("chapter") in SIDE_BY_SIDE]
    side = [(ch, c) for ch, c in side if c["kind"] == "thesis"]
    if side:
        lines += ["## Verdicts at the thesis's settings and at ours (chapters 3-5)", "",
                  "The thesis's model (printed plant and effort form) and r = 0.002, "
                  "w_v = 0.1, w_f = 0.01 against ours; chapter 5: its repertoire planned "
                  "with them, every row over the readings of eqs. 5.1/5.7 the thesis allows.",
                  "", _row(("chapter", "claim", "line", "ours", "at the thesis's settings")),
                  "|---|---|---|---|---|"]
        lines += [_row((ch, c["claim"], c["line"], c["verdict"],
                        at_thesis_verdict(c["at_thesis"], c["verdict"]))) for ch, c in side]
        lines.append("")
    return "\n".join(lines) + "\n"


#: Chapters whose verdicts the side-by-side table lists.
SIDE_BY_SIDE = ("Chapter 3", "Appendix A", "Chapter 4", "Chapter 5")

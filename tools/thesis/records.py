"""Claim records and sensitivity tables: the rows numbers.md and numbers.csv are made of.

A chapter's evaluation (:func:`tools.thesis.claims.evaluate`) turns each declared
claim and its measurement into one record made by :func:`claim`; a parameter the
thesis leaves open that a verdict depends on gets a table made by
:func:`sensitivity`.

Two kinds of row: ``thesis`` — a statement the thesis makes, with the line of
``minimum-variance-thesis.txt`` it quotes and the quoted words (the tests check
them against the text, :func:`tools.thesis.text.thesis_text`), the verdict at our
settings and ``at_thesis``, the verdict at the thesis's own
(:data:`tools.thesis.common.THESIS_SETTINGS`); ``own`` — a check of the project's
own (the verdict rule, the likelihood rule), counted apart.
"""

from __future__ import annotations

from collections.abc import Sequence

#: Verdicts, in the order numbers.md counts them.
#: ``agree``: ours supports the statement by the stated measure; ``differs``: it
#: does not; ``by construction``: it holds only because of how the model or the
#: test was built, so it says nothing about the model; ``thesis inconsistent``:
#: the thesis says two different things (both locations are cited).
VERDICTS = ("agree", "differs", "by construction", "thesis inconsistent")
#: A verdict that flips with a choice the thesis leaves open (durations, tip_start, ...):
#: the row says over which range it holds. Accepted by :func:`claim`; numbers.md's tallies
#: count it once :data:`VERDICTS` lists it.
CONDITIONAL = "conditional"

#: Kinds of row: a statement of the thesis, or a check of the project's own.
KINDS = ("thesis", "own")
#: Columns of numbers.md's thesis-claim tables, in order (``why`` is a claim's ``note``).
TABLE_KEYS = ("claim", "location", "quote", "measure", "thesis", "ours", "verdict",
              "at_thesis", "why")
#: Their headings in numbers.md.
TABLE_HEADINGS = ("claim", "thesis location (line)", "the thesis's words", "measure",
                  "thesis value", "ours (our settings)", "verdict (our settings)",
                  "at the thesis's settings", "why")
#: Columns and headings of the tables of the project's own checks.
OWN_KEYS = ("claim", "location", "measure", "ours", "verdict", "why")
OWN_HEADINGS = ("check", "basis", "measure", "ours", "verdict", "why")
#: Keys of a claim record (numbers.csv's columns, after ``chapter``): ``id`` names the
#: declared claim (:class:`tools.thesis.claims.Claim`), ``expected`` its rule in words.
CLAIM_KEYS = ("id", "section", "kind", "claim", "line", "quote", "location", "measure",
              "thesis", "ours", "verdict", "at_thesis", "agrees", "expected", "why")


def claim(
    section: str,
    claim: str,
    thesis: str,
    ours: str,
    agrees: bool | None = None,
    note: str = "",
    *,
    location: str | None = None,
    measure: str = "",
    verdict: str | None = None,
    kind: str = "thesis",
    line: int | None = None,
    quote: str = "",
    at_thesis: str = "",
    id: str = "",
    expected: str = "",
) -> dict:
    """One row of numbers.md: a statement of the thesis beside our value.

    The first six parameters are those of the original record, so older
    chapter modules keep working; ``location``, ``measure`` and ``verdict``
    fill the columns added since (numbers.md shows "not stated" for a missing
    measure).

    Parameters
    ----------
    section : str
        The thesis section (e.g. ``"4.2.2.2"``); the location when ``location``
        is not given.
    claim : str
        The statement.
    thesis : str
        The thesis's value or wording.
    ours : str
        Our value, with units (and a confidence interval where it is sampled).
    agrees : bool, optional
        Whether ours supports the statement; used when ``verdict`` is not
        given (True: ``agree``, False: ``differs``).
    note : str
        Why: how the verdict follows from the numbers, where and why ours
        differs, what is by construction (numbers.md's ``why`` column).
    location : str, optional
        Where the thesis says it: section, figure and line of
        ``minimum-variance-thesis.txt`` (e.g. ``"4.2.2.2, Fig. 4.10(b); line 905"``);
        both places where it contradicts itself.
    measure : str
        How the claim is judged: the quantity, its source (exact moments,
        repetitions with a 95 % confidence interval, ...) and the rule.
    verdict : str, optional
        One of :data:`VERDICTS`; overrides ``agrees``.
    kind : str
        ``"thesis"`` (a statement of the thesis) or ``"own"`` (a check of ours).
    line : int, optional
        The line of the thesis text that ``quote`` is on.
    quote : str
        The thesis's words on ``line`` (checked by the tests).
    at_thesis : str
        The verdict, and our value, at the thesis's settings
        (:data:`tools.thesis.common.THESIS_SETTINGS`, or the other reading of eqs.
        5.1/5.7 in chapter 5).
    id : str
        The declared claim's id (:class:`tools.thesis.claims.Claim`).
    expected : str
        Its rule in words (what the measured values must satisfy).

    Returns
    -------
    dict
        Keys :data:`CLAIM_KEYS`; ``agrees`` is True exactly when the verdict is
        ``agree``.

    Raises
    ------
    ValueError
        If the verdict is unknown, or neither ``agrees`` nor ``verdict`` is given.
    """
    if verdict is None:
        if agrees is None:
            raise ValueError(f"claim {claim!r}: give agrees or verdict")
        verdict = "agree" if agrees else "differs"
    if verdict not in (*VERDICTS, CONDITIONAL):
        raise ValueError(f"claim {claim!r}: verdict must be one of {VERDICTS} or "
                         f"{CONDITIONAL!r}, got {verdict!r}")
    if kind not in KINDS:
        raise ValueError(f"claim {claim!r}: kind must be one of {KINDS}, got {kind!r}")
    values = (id, section, kind, claim, "" if line is None else int(line), quote,
              location or section, measure, thesis, ours, verdict, at_thesis,
              verdict == "agree", expected, note)
    return dict(zip(CLAIM_KEYS, values))


def as_claim(record: dict) -> dict:
    """A claim record in the current form, from the current or the original one.

    The original record had keys section, claim, thesis, ours, agrees, note.

    Parameters
    ----------
    record : dict
        From :func:`claim` (any version), or built by hand with those keys.

    Raises
    ------
    ValueError
        If a required key is missing.
    """
    if "verdict" in record:
        defaults = {"id": "", "kind": "thesis", "line": "", "quote": "", "at_thesis": "",
                    "expected": ""}
        missing = [k for k in CLAIM_KEYS if k not in record and k not in defaults]
        if missing:
            raise ValueError(f"claim {record!r} lacks {missing}")
        return {**defaults, **record}
    missing = [k for k in ("section", "claim", "thesis", "ours", "agrees") if k not in record]
    if missing:
        raise ValueError(f"claim {record!r} lacks {missing}")
    return claim(record["section"], record["claim"], record["thesis"], record["ours"],
                 bool(record["agrees"]), record.get("note", ""))


def sensitivity(
    title: str,
    location: str,
    note: str,
    columns: Sequence[str],
    rows: Sequence[Sequence],
) -> dict:
    """A table for numbers.md: how verdicts change across a parameter's plausible range.

    Parameters
    ----------
    title : str
        The parameter and what it is (e.g. ``"tip_start: where the closed digit
        tips start"``).
    location : str
        What in the thesis bounds its range (line or figure).
    note : str
        The value used and why; what the table shows.
    columns : sequence of str
        Column headings: the parameter first, then one per verdict or measure.
    rows : sequence of sequences
        One row per value, cells in the order of ``columns`` (converted to str).

    Returns
    -------
    dict
        ``kind="sensitivity"`` and the arguments.
    """
    rows = [[str(c) for c in r] for r in rows]
    if any(len(r) != len(columns) for r in rows):
        raise ValueError(f"sensitivity {title!r}: every row needs {len(columns)} cells")
    return dict(kind="sensitivity", title=title, location=location, note=note,
                columns=[str(c) for c in columns], rows=rows)


def is_sensitivity(record: dict) -> bool:
    """Whether a record from a chapter's ``reproduce`` is a sensitivity table.

    Parameters
    ----------
    record : dict
        A claim or a table.
    """
    return record.get("kind") == "sensitivity"

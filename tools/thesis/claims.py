"""Claims as data, and the one evaluator that checks every claim the same way.

Each chapter declares its claims in one table (a tuple of :class:`Claim`): the
claim's id, the statement, the thesis's words and value and where it says them
(section, figure, line), how the claim is measured, and the rule the measurement
must satisfy (:class:`Check`: a tolerance or an expected direction). The chapter's
measurement code returns one :class:`Measured` per id: our value in words, the named
numbers the rule reads, and a note. :func:`evaluate` checks each claim's rule on its
numbers and returns one record per claim (:func:`tools.thesis.records.claim`:
measured, expected, verdict, note), in the table's order.

A claim's texts may name measured values in braces (``"{scatter_mm:.1f} mm"``):
they are filled from the measurement's values and the chapter's context (e.g. the
generator of chapter 5's clips).
"""

from __future__ import annotations

import dataclasses
import operator
from collections.abc import Mapping, Sequence
from typing import Any

from tools.thesis.records import CONDITIONAL, KINDS, VERDICTS, claim

#: The comparisons a :class:`Check` may make, and how :attr:`Check.words` writes them.
OPS = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
       "==": operator.eq, "is": operator.is_}


@dataclasses.dataclass(frozen=True)
class Check:
    """One comparison of a measured value: ``value op limit``.

    Parameters
    ----------
    value : str
        Name of the measured value (a key of :attr:`Measured.values`).
    op : str
        One of :data:`OPS`. ``"is"`` compares a truth value: the measured value is a
        rule the chapter computes from many numbers (e.g. "lowest at level and
        monotone on both sides"), whose name says it.
    limit : float, str or bool
        A number, the name of another measured value, or for ``"is"`` True or False.
    times : float
        Factor on a named limit (``rise > 2 × se``).
    """

    value: str
    op: str
    limit: float | str | bool = True
    times: float = 1.0

    def __post_init__(self):
        if self.op not in OPS:
            raise ValueError(f"check {self.value!r}: op must be one of {tuple(OPS)}")

    def holds(self, values: Mapping[str, Any]) -> bool:
        """Whether the measured ``values`` satisfy the check.

        Parameters
        ----------
        values : mapping
            Measured values by name.
        """
        got = values[self.value]
        if self.op == "is":
            return bool(got) is bool(self.limit)
        limit = (self.times * values[self.limit] if isinstance(self.limit, str)
                 else self.limit)
        return bool(OPS[self.op](got, limit))

    def words(self) -> str:
        """The check as text, e.g. ``"max_deviation_m < 1e-09"`` or ``"rise > 2 × se"``."""
        if self.op == "is":
            return self.value if self.limit else f"not {self.value}"
        limit = (f"{self.times:g} × {self.limit}" if isinstance(self.limit, str)
                 and self.times != 1 else f"{self.limit:g}" if not isinstance(
                     self.limit, str) else self.limit)
        return f"{self.value} {self.op} {limit}"


def below(value: str, limit: float | str, times: float = 1.0) -> Check:
    """``value < limit`` (see :class:`Check`)."""
    return Check(value, "<", limit, times)


def above(value: str, limit: float | str, times: float = 1.0) -> Check:
    """``value > limit`` (see :class:`Check`)."""
    return Check(value, ">", limit, times)


def at_most(value: str, limit: float | str, times: float = 1.0) -> Check:
    """``value <= limit`` (see :class:`Check`)."""
    return Check(value, "<=", limit, times)


def at_least(value: str, limit: float | str, times: float = 1.0) -> Check:
    """``value >= limit`` (see :class:`Check`)."""
    return Check(value, ">=", limit, times)


def equals(value: str, limit: float) -> Check:
    """``value == limit`` (see :class:`Check`)."""
    return Check(value, "==", limit)


def holds(value: str) -> Check:
    """The measured truth value ``value`` is True (see :class:`Check`)."""
    return Check(value, "is", True)


def fails(value: str) -> Check:
    """The measured truth value ``value`` is False (see :class:`Check`)."""
    return Check(value, "is", False)


@dataclasses.dataclass(frozen=True)
class Claim:
    """One quantitative statement of the thesis (or a check of our own), as data.

    Parameters
    ----------
    id : str
        Unique within the chapter's table; the measurement returns its value under it.
    section : str
        The thesis section.
    claim : str
        The statement.
    thesis : str
        The thesis's value or words.
    location : str
        Where the thesis says it: section, figure, line(s).
    measure : str
        How it is judged: the quantity, its source and the rule in words.
    rule : tuple of Check
        What the measured values must satisfy (every check): the claim agrees when
        they do. Empty only where :attr:`verdict` fixes the verdict.
    line : int, optional
        The line of the thesis text that :attr:`quote` is on (a thesis claim).
    quote : str
        The thesis's words on :attr:`line` (checked against the text by the tests).
    kind : str
        ``"thesis"`` or ``"own"`` (a check of ours; no line).
    verdict : str, optional
        A verdict the numbers cannot change: ``by construction`` (it holds because
        of how the model or test was built) or ``thesis inconsistent``.
    why : str
        Appended to the measurement's note (e.g. why the verdict is fixed).
    against : tuple, optional
        ``(line, words, why)`` of the other place where the thesis says the
        opposite: the chapter reports the row ``thesis inconsistent`` with both
        lines cited, after judging it (chapter 5 judges it under every reading of
        its rule first); the tests check these words too.
    ours : str
        Our value where none is measured (a reading of the thesis's text).
    at_thesis : str
        The verdict at the thesis's settings where no model enters.
    """

    id: str
    section: str
    claim: str
    thesis: str
    location: str
    measure: str
    rule: tuple[Check, ...] = ()
    line: int | None = None
    quote: str = ""
    kind: str = "thesis"
    verdict: str | None = None
    why: str = ""
    against: tuple = ()
    ours: str = ""
    at_thesis: str = ""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"claim {self.id}: kind must be one of {KINDS}")
        if self.verdict is not None and self.verdict not in (*VERDICTS, CONDITIONAL):
            raise ValueError(f"claim {self.id}: unknown verdict {self.verdict!r}")
        if not self.rule and self.verdict is None:
            raise ValueError(f"claim {self.id}: give a rule or a fixed verdict")
        if (self.line is None) != (self.kind == "own"):
            raise ValueError(f"claim {self.id}: a thesis claim cites a line, our own none")

    @property
    def expected(self) -> str:
        """The rule in words (``"fixed: <verdict>"`` where none is given)."""
        return " and ".join(c.words() for c in self.rule) or f"fixed: {self.verdict}"


@dataclasses.dataclass
class Measured:
    """What a chapter measured for one claim.

    Parameters
    ----------
    ours : str
        Our value in words, with units and intervals.
    values : dict
        The numbers the claim's rule and texts read, by name.
    note : str
        Why: how the verdict follows, what ours depends on.
    verdict : str, optional
        ``conditional`` where the verdict flips with a choice the thesis leaves
        open (the note says over which range it holds); overrides the rule.
    """

    ours: str
    values: dict = dataclasses.field(default_factory=dict)
    note: str = ""
    verdict: str | None = None


def _fill(text: str, values: Mapping) -> str:
    return text.format_map(values) if "{" in text else text


def evaluate(
    table: Sequence[Claim], measured: Mapping[str, Measured], *, context: Mapping | None = None,
    unexplained: str = "", strict: bool = True,
) -> list[dict]:
    """Check every claim of ``table`` on its measurement: one record per claim.

    The verdict is the claim's fixed one if it has one, else the measurement's
    (conditional), else ``agree`` when every check of the rule holds and
    ``differs`` when one does not.

    Parameters
    ----------
    table : sequence of Claim
        A chapter's claims (ids unique).
    measured : mapping
        Claim id -> :class:`Measured`.
    context : mapping, optional
        Values every claim's texts may name (besides its own measured values).
    unexplained : str
        Note for a claim that fails its rule with no note (``{why}`` in the text
        is left as it is); empty: none.
    strict : bool
        Every claim must be measured and every measurement claimed (False: the
        claims measured are evaluated, in the table's order).

    Returns
    -------
    list of dict
        :func:`tools.thesis.records.claim` records with ``id`` and ``expected``.

    Raises
    ------
    KeyError
        If ``strict`` and a claim has no measurement or a measurement no claim.
    """
    ids = [c.id for c in table]
    if len(set(ids)) != len(ids):
        raise ValueError(f"claim ids repeat: {sorted(i for i in ids if ids.count(i) > 1)}")
    fixed = {c.id: Measured(c.ours) for c in table if c.ours}
    measured = {**fixed, **measured}
    if strict and set(ids) ^ set(measured):
        raise KeyError(f"claims not measured: {sorted(set(ids) - set(measured))}; "
                       f"measured, not claimed: {sorted(set(measured) - set(ids))}")
    rows = []
    for c in table:
        if c.id not in measured:
            continue
        m = measured[c.id]
        values = {**(context or {}), **m.values}
        ok = all(check.holds(values) for check in c.rule)
        verdict = m.verdict or ("agree" if ok else "differs")
        note = m.note
        if unexplained and verdict == "differs" and not note:
            note = unexplained
        if c.why:
            note = (note + " " + c.why).strip()
        rows.append(claim(
            c.section, _fill(c.claim, values), _fill(c.thesis, values), m.ours,
            note=note, location=_fill(c.location, values), measure=_fill(c.measure, values),
            verdict=c.verdict or verdict, kind=c.kind, line=c.line, quote=c.quote,
            at_thesis=c.at_thesis, id=c.id, expected=c.expected))
    return rows


def at_settings(ours: list[dict], theirs: list[dict], what: str = "") -> list[dict]:
    """Fill each of ``ours``' ``at_thesis`` with the same claim's verdict and value in
    ``theirs`` (matched by id, else by the statement).

    Parameters
    ----------
    ours : list of dict
        Claims at our settings (changed in place and returned).
    theirs : list of dict
        The same claims computed at the thesis's settings.
    what : str
        Prefix naming the settings (e.g. ``"r = 0.002, w_v = 0.1: "``).
    """
    by = {(c.get("id") or c["claim"]): c for c in theirs if c.get("kind") != "sensitivity"}
    for c in ours:
        if c.get("kind") == "sensitivity" or c.get("at_thesis"):
            continue
        other = by.get(c.get("id") or c["claim"])
        if other is not None:
            c["at_thesis"] = f"{what}{other['verdict']}: {other['ours']}"
    return ours

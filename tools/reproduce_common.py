"""What the thesis reproduction modules share: claims, sensitivity tables, seeds, outputs.

Each chapter module (``reproduce_ch2.py``, ``reproduce_ch3.py``,
``reproduce_appendix_a.py``, ``reproduce_ch4.py``, ...) exposes
``reproduce(out, *, trials, seed) -> list[dict]``: it writes its figures (PNG)
and tables (CSV) into ``out`` and returns one record per quantitative
statement of the thesis, made by :func:`claim`, and, for a parameter the
thesis leaves open that a verdict depends on, a table made by
:func:`sensitivity`.

A claim is judged by the measure the thesis itself uses where it states one
(or the one its figure shows), and the record says which: numbers.md prints
the measure beside the verdict.

Two kinds of row: ``thesis`` — a statement the thesis makes, with the line of
``minimum-variance-thesis.txt`` it quotes and the quoted words (the tests check
them against the text, found by :func:`thesis_text`), the verdict at our
settings and ``at_thesis``, the verdict at the thesis's own (:data:`THESIS_SETTINGS`);
``own`` — a check of the project's own (the verdict rule, the likelihood rule),
counted apart.
"""

from __future__ import annotations

import os
import re
import zlib
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from perception.io.atomic import save_figure, write_csv

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
#: Keys of a claim record (numbers.csv's columns, after ``chapter``).
CLAIM_KEYS = ("section", "kind", "claim", "line", "quote", "location", "measure", "thesis",
              "ours", "verdict", "at_thesis", "agrees", "why")

#: The thesis's model and cost weights: its printed plant and effort form
#: (``form="thesis"``: exponential muscle filter, u into f~ at unit gain, lines 520-524;
#: R = r/T, lines 382, 558), r (line 552), w_v and w_f (line 537). Ours are the
#: defaults of :class:`minvar.task.ReachTask` and :class:`minvar.grasp.GraspTask`.
THESIS_SETTINGS = {"r": 0.002, "w_v": 0.1, "w_f": 0.01, "form": "thesis"}
#: Where the thesis text is looked for, after ``$HAMMER_MV_THESIS``: a ``shared/seed``
#: folder inside the checkout, then beside it.
_ROOT = Path(__file__).resolve().parents[1]
THESIS_CANDIDATES = tuple(base / "shared" / "seed" / "minimum-variance-thesis.txt"
                          for base in (_ROOT, _ROOT.parent))

Progress = Callable[[str], None]


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
        The verdict, and our value, at the thesis's settings (:data:`THESIS_SETTINGS`,
        or the other reading of eqs. 5.1/5.7 in chapter 5).

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
    values = (section, kind, claim, "" if line is None else int(line), quote,
              location or section, measure, thesis, ours, verdict, at_thesis,
              verdict == "agree", note)
    return dict(zip(CLAIM_KEYS, values))


def cite(claims: list[dict], table: Mapping[str, tuple]) -> list[dict]:
    """Give each claim its thesis line and words from ``table``, by the claim's start.

    Parameters
    ----------
    claims : list of dict
        Claim records (changed in place and returned).
    table : mapping
        Claim text prefix -> ``(line, quote)`` or ``(line, quote, changes)``,
        ``changes`` a dict of other keys to set (``verdict``, ``kind``, ``why``
        appended with a leading ``+``). ``line`` None makes the row ``own``.

    Returns
    -------
    list of dict
    """
    for c in claims:
        for prefix, entry in table.items():
            if not c["claim"].startswith(prefix):
                continue
            line, quote, changes = (*entry, {})[:3]
            c["line"], c["quote"] = ("", "") if line is None else (int(line), quote)
            if line is None:
                c["kind"] = "own"
            elif f"line {line}" not in c["location"] and f"{line}" not in c["location"]:
                c["location"] = f"{c['location']}; line {line}"
            for key, value in changes.items():
                if key == "why" and value.startswith("+"):
                    c["why"] = (c["why"] + " " + value[1:]).strip()
                else:
                    c[key] = value
            c["agrees"] = c["verdict"] == "agree"
            break
    return claims


def at_settings(ours: list[dict], theirs: list[dict], what: str = "") -> list[dict]:
    """Fill each of ``ours``' ``at_thesis`` with the same claim's verdict and value in ``theirs``.

    Parameters
    ----------
    ours : list of dict
        Claims at our settings (changed in place and returned).
    theirs : list of dict
        The same claims computed at the thesis's settings (matched by ``claim``).
    what : str
        Prefix naming the settings (e.g. ``"r = 0.002, w_v = 0.1: "``).
    """
    by = {c["claim"]: c for c in theirs if not is_sensitivity(c)}
    for c in ours:
        if is_sensitivity(c) or c.get("at_thesis"):
            continue
        other = by.get(c["claim"])
        if other is not None:
            c["at_thesis"] = f"{what}{other['verdict']}: {other['ours']}"
    return ours


def thesis_text() -> list[str] | None:
    """The thesis's lines (index 0 is line 1), or None where the text is not at hand.

    Looked for at ``$HAMMER_MV_THESIS``, then :data:`THESIS_CANDIDATES`.
    """
    env = os.environ.get("HAMMER_MV_THESIS")
    for path in ([Path(env)] if env else []) + list(THESIS_CANDIDATES):
        if path.is_file():
            return path.read_text(encoding="utf-8").splitlines()
    return None


def _plain(text: str) -> str:
    return re.sub(r"\s+", " ", re.sub(r"[*_$]", "", text)).strip().lower()


def quote_is_on_line(lines: list[str], line: int, quote: str) -> bool:
    """Whether ``quote`` is on ``line`` (1-based) of the thesis ``lines``.

    Case, runs of white space and markdown emphasis (``*``, ``_``, ``$``) are ignored.

    Parameters
    ----------
    lines : list of str
        From :func:`thesis_text`.
    line : int
        Line number, from 1.
    quote : str
        The words.
    """
    return 1 <= line <= len(lines) and bool(quote) and _plain(quote) in _plain(lines[line - 1])


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
        defaults = {"kind": "thesis", "line": "", "quote": "", "at_thesis": ""}
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


def ci95(samples: np.ndarray) -> tuple[float, float]:
    """The central 95 % interval of bootstrap (or other) samples.

    Parameters
    ----------
    samples : array_like
        Draws of a statistic.
    """
    lo, hi = np.percentile(np.asarray(samples, dtype=float), [2.5, 97.5])
    return float(lo), float(hi)


def borderline(value: float, limit: float) -> str:
    """A note when ``value`` lies within 10 % of the ``limit`` it was judged against.

    Parameters
    ----------
    value : float
        Our number.
    limit : float
        The threshold of the agreement test.
    """
    if limit and abs(value / limit - 1) < 0.1:
        return f" Borderline: {value:.3g} against a limit of {limit:.3g}."
    return ""


def rng_for(seed: int, name: str) -> np.random.Generator:
    """A generator for one figure: its own stream of ``seed``, keyed by ``name``.

    Adding or dropping a figure never changes another figure's numbers.

    Parameters
    ----------
    seed : int
        The run's seed.
    name : str
        The figure's name.
    """
    key = zlib.crc32(name.encode())
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(key,)))


def save(out: Path | None, name: str, fig=None, table=None) -> None:
    """Write ``name``.png and/or ``name``.csv into ``out`` atomically.

    Parameters
    ----------
    out : Path or None
        Output folder; None writes nothing (a run at other settings).
    name : str
        File stem, named after the thesis figure (``fig3_5_speed_accuracy``).
    fig : matplotlib.figure.Figure, optional
        Saved as PNG.
    table : pandas.DataFrame, optional
        Saved as CSV.
    """
    if out is None:
        return
    if fig is not None:
        save_figure(out / f"{name}.png", fig)
    if table is not None:
        write_csv(out / f"{name}.csv", table)


def no_progress(_: str) -> None:
    """Progress callback that ignores the step name ``_``."""


def settings_rows() -> list[list[str]]:
    """numbers.md's settings table: each parameter, the thesis's value and line, ours.

    Returns
    -------
    list of [parameter, thesis, ours, effect] rows (str).
    """
    from minvar.grasp import GraspTask
    from minvar.task import ReachTask

    reach, grasp = ReachTask((0.2, 0.2), (0.4, 0.5), 0.5), GraspTask()

    def same(name):
        return "same" if getattr(reach, name) == THESIS_SETTINGS[name] else "**differs**"

    return [
        ["model form", "exponential muscle filter, u entering f~ at unit gain (lines "
         "520-524); R = r/T, T the number of steps (lines 382, 558)", "Euler filter; "
         "R = r dt/T (Todorov's code; **differs**)", "the thesis's settings column uses the "
         "thesis's form in every chapter (chapter 5: its repertoire re-planned with it; "
         "docs/thesis.md)"],
        ["r (effort weight)", "0.002 ('provided a good tradeoff between error and effort', "
         "line 552)", f"{reach.r:g} ({same('r')})",
         "every chapter computed at both (chapter 5: its repertoire planned at each)"],
        ["w_v (final velocity weight)", "0.1 (line 537)", f"{reach.w_v:g} ({same('w_v')})",
         "as r"],
        ["w_f (final force weight)", "0.01 (line 537)", f"{reach.w_f:g} ({same('w_f')})",
         "as r"],
        ["tip_start (closed digit tips ahead of the wrist)", "not given: 0 to 6 cm ('with "
         "the digits touching', line 730; the targets 6 cm above the wrist target, line 724)",
         f"{100 * grasp.tip_start:g} cm (chosen after the verdicts: not a thesis value)",
         "rows that depend on it are reported as conditional, with the range over which "
         "they hold (tip_start tables, one per column's settings)"],
        ["wrist travel", "20 cm ('the distance to be moved', line 953)",
         f"{100 * grasp.transport_distance:g} cm (same)", "transport distance table"],
        ["w_r / w_g (thesis rule weights)", "1/2 (line 1125)", "1/2 (same)",
         "the ratio that gives equal transport and grip shares (0.72-0.76, per generator "
         "and setting: chapter 5's line-1125 rows) is reported beside it; no verdict is "
         "taken from it"],
        ["sign of eqs. 5.1/5.7/5.8", "text: +1 if the changes agree, -1 if not (line 1070); "
         "as printed: sgn(observed) x (predicted change); the predicted change taken "
         "between consecutive predictions; to the letter, sgn(r_n - r_n-1) x |predicted "
         "change| (contradicts line 1070)", "text (`--thesis-sign text`; `printed` "
         "selectable)", "chapter 5 rows are scored under all four and say which they "
         "survive; only the three the thesis allows decide a verdict"],
        ["unstated geometry (Fig. 3.2 reach, the 'a' via-points and times, appendix A "
         "trajectory)", "not given", "ours, stated in each row", "rows say so"],
    ]

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
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from perception.io.atomic import save_figure, write_csv

#: Verdicts, in the order numbers.md counts them.
#: ``agree``: ours supports the statement by the stated measure; ``differs``: it
#: does not; ``by construction``: it holds only because of how the model or the
#: test was built, so it says nothing about the model; ``thesis inconsistent``:
#: the thesis says two different things (both locations are cited).
VERDICTS = ("agree", "differs", "by construction", "thesis inconsistent")

#: Columns of numbers.md, in order (``why`` is a claim's ``note``).
TABLE_KEYS = ("claim", "location", "measure", "thesis", "ours", "verdict", "why")
#: Their headings in numbers.md.
TABLE_HEADINGS = ("claim", "thesis location", "measure", "thesis value", "ours", "verdict",
                  "why")
#: Keys of a claim record (numbers.csv's columns, after ``chapter``).
CLAIM_KEYS = ("section", "claim", "location", "measure", "thesis", "ours", "verdict",
              "agrees", "why")

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
    if verdict not in VERDICTS:
        raise ValueError(f"claim {claim!r}: verdict must be one of {VERDICTS}, got {verdict!r}")
    values = (section, claim, location or section, measure, thesis, ours, verdict,
              verdict == "agree", note)
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
        missing = [k for k in CLAIM_KEYS if k not in record]
        if missing:
            raise ValueError(f"claim {record!r} lacks {missing}")
        return record
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


def save(out: Path, name: str, fig=None, table=None) -> None:
    """Write ``name``.png and/or ``name``.csv into ``out`` atomically.

    Parameters
    ----------
    out : Path
        Output folder.
    name : str
        File stem, named after the thesis figure (``fig3_5_speed_accuracy``).
    fig : matplotlib.figure.Figure, optional
        Saved as PNG.
    table : pandas.DataFrame, optional
        Saved as CSV.
    """
    if fig is not None:
        save_figure(out / f"{name}.png", fig)
    if table is not None:
        write_csv(out / f"{name}.csv", table)


def no_progress(_: str) -> None:
    """Progress callback that ignores the step name ``_``."""

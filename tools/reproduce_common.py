"""What the thesis reproduction modules share: claims, seeds, outputs.

Each chapter module (``reproduce_ch2.py``, ``reproduce_ch3.py``,
``reproduce_appendix_a.py``, and ``reproduce_ch4.py`` from the grasp work)
exposes ``reproduce(out, *, trials, seed) -> list[dict]``: it writes its
figures (PNG) and tables (CSV) into ``out`` and returns one claim per
quantitative statement of the thesis, made by :func:`claim`.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from pathlib import Path

import numpy as np

from perception.io.atomic import save_figure, write_csv

#: Keys of a claim, in the column order of numbers.md.
CLAIM_KEYS = ("section", "claim", "thesis", "ours", "agrees", "note")

Progress = Callable[[str], None]


def claim(section: str, claim: str, thesis: str, ours: str, agrees: bool, note: str = "") -> dict:
    """One row of numbers.md: a statement of the thesis beside our value.

    Parameters
    ----------
    section : str
        Where the thesis says it (section, figure).
    claim : str
        The statement.
    thesis : str
        The thesis's value or wording.
    ours : str
        Our value, with units.
    agrees : bool
        Whether ours supports the statement (by the test given in ``note``).
    note : str
        How agreement was judged, and where and why ours differs.
    """
    return dict(zip(CLAIM_KEYS, (section, claim, thesis, ours, bool(agrees), note)))


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

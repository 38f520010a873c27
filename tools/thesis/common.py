"""What the chapters share besides their claims: the thesis's settings, seeds, outputs."""

from __future__ import annotations

import zlib
from collections.abc import Callable
from pathlib import Path

import numpy as np

from perception.io.atomic import save_figure, write_csv

#: The thesis's model and cost weights: its printed plant and effort form
#: (``form="thesis"``: exponential muscle filter, u into f~ at unit gain, lines 520-524;
#: R = r/T, lines 382, 558), r (line 552), w_v and w_f (line 537). Ours are the
#: defaults of :class:`minvar.task.ReachTask` and :class:`minvar.grasp.GraspTask`.
THESIS_SETTINGS = {"r": 0.002, "w_v": 0.1, "w_f": 0.01, "form": "thesis"}

#: Called with the name of each step (figure) as it starts.
Progress = Callable[[str], None]


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

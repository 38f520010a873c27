"""Thesis chapter 3: the minimum variance model's trajectories, Figs. 3.2-3.9.

``reproduce(out, *, trials, seed)`` writes the figures and returns the claims of
:data:`tools.thesis.ch3_claims.CLAIMS`, evaluated at our cost weights and, in each
row's ``at_thesis``, at the thesis's. Default repetitions follow the thesis: 50
drawn (Figs. 3.4, 3.6), 200 per movement time (Figs. 3.5, 3.7); the mean-path
claims use 200.
"""

from __future__ import annotations

from pathlib import Path

from tools.thesis import ch3_iteration, ch3_letters, ch3_reach
from tools.thesis.ch3_claims import CLAIMS
from tools.thesis.claims import Measured, at_settings, evaluate
from tools.thesis.common import THESIS_SETTINGS, Progress, no_progress


def measure(out: Path | None, n: int, seed: int, w: dict,
            progress: Progress = no_progress) -> dict[str, Measured]:
    """Every chapter 3 measurement at cost weights and model form ``w``, by claim id.

    Parameters
    ----------
    out : Path or None
        Folder for the figures and tables (None: none written).
    n : int
        Repetitions of every Monte Carlo movement.
    seed : int
        Base seed; each figure draws from its own stream.
    w : dict
        Task settings (``{}``: ours; :data:`tools.thesis.common.THESIS_SETTINGS`).
    progress : callable
        Called with the name of each figure as it starts.
    """
    got: dict[str, Measured] = {}
    progress("convergence")
    ch3_iteration.convergence(got, seed, w)
    ch3_iteration.exponential(got, w)
    ch3_iteration.noise(got, n, seed, w)
    progress("fig3_2")
    ch3_reach.fig3_2(out, got, seed, w)
    progress("fig3_3")
    ch3_reach.fig3_3(out, got, n, seed, w)
    progress("fig3_4-3_5")
    ch3_reach.fig3_4_3_5(out, got, n, seed, w)
    progress("fig3_6-3_7")
    ch3_letters.fig3_6_3_7(out, got, n, seed, w)
    progress("fig3_8-3_9")
    ch3_letters.fig3_8_3_9(out, got, n, seed, w)
    return got


def reproduce(
    out: Path, *, trials: int | None = None, seed: int = 0, quick: bool = False,
    progress: Progress = no_progress,
) -> list[dict]:
    """Figs. 3.2-3.9 into ``out``; the chapter's claims, at our cost weights and the thesis's.

    Parameters
    ----------
    out : Path
        Output folder.
    trials : int, optional
        Repetitions of every Monte Carlo movement (default: 200, as the
        thesis's speed-accuracy figures).
    seed : int
        Base seed; each figure draws from its own stream.
    quick : bool
        Unused (``trials`` sets a smoke run's size).
    progress : callable
        Called with the name of each figure as it starts.
    """
    n = 200 if trials is None else int(trials)
    ours = evaluate(CLAIMS, measure(Path(out), n, seed, {}, progress))
    theirs = evaluate(CLAIMS, measure(None, n, seed, THESIS_SETTINGS, progress))
    at_settings(ours, theirs, "")
    _judged_at_thesis(ours, theirs, "goal")
    return ours


def _judged_at_thesis(ours: list[dict], theirs: list[dict], id: str) -> None:
    """A claim about the thesis's own settings (line 552: r = 0.002 is a good tradeoff)
    takes its verdict from them in both columns; our settings' number stays as an aside."""
    mine = next(c for c in ours if c["id"] == id)
    other = next(c for c in theirs if c["id"] == id)
    aside = f" At our settings (r = 2e-4, w_v = 0.2, the project's form): {mine['ours']}."
    mine.update(ours=other["ours"], verdict=other["verdict"], agrees=other["agrees"],
                at_thesis=f"{other['verdict']}: {other['ours']}",
                measure=other["measure"] + " (at the thesis's settings: the claim is about "
                "them)", why=other["why"] + "." + aside)

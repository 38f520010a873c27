"""Thesis chapter 4 (grasping): every figure, table and quantitative claim.

``reproduce(out, trials=500, seed=0)`` runs the seven experiments of
:mod:`minvar.grasp_experiments` (each from its own child of ``seed``), saves their
figures (PNG, named after the thesis's, e.g. ``fig4_10_object_size_mga.png``) and
tables (CSV) into ``out``, and returns the claims of
:data:`tools.thesis.ch4_claims.CLAIMS`, evaluated at our settings and, in each
row's ``at_thesis``, at the thesis's, then three sensitivity tables
(:mod:`tools.thesis.ch4_sensitivity`): the verdicts that depend on where the
closed digits start (``tip_start``, at both settings) and on how far the wrist
travels, across their plausible ranges.

Measures: trends in standard deviations and distances are judged on exact
(first-order) moments (``*_exact``), so no verdict hinges on sampling error;
what 500 repetitions per setting could resolve is given as 95 % intervals
(bootstrap for peak SDs, normal for means). The geometry follows the text and
its figures (docs/model.md); nothing was tuned to these numbers.
"""

from __future__ import annotations

import logging
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from hammer_mv.cli.grasp import write_experiment
from minvar.grasp import GraspTask, plan_grasp, simulate_grasp
from minvar.grasp_experiments import EXPERIMENTS
from minvar.plotting.grasp import grasp_figure, setup_figure
from perception.io.atomic import save_figure
from tools.thesis import ch4_grasping, ch4_variability, ch4_viapoints
from tools.thesis.ch4_claims import CLAIMS, TIP_DEPENDENT
from tools.thesis.ch4_sensitivity import mark_conditional, tip_start_table, travel_table
from tools.thesis.claims import Measured, at_settings, evaluate
from tools.thesis.common import THESIS_SETTINGS, Progress, no_progress

log = logging.getLogger("tools.thesis.ch4")

#: Each experiment's measurements (claim id -> :class:`Measured` pairs).
MEASURES = {
    "viapoint-height": ch4_viapoints.viapoint_height,
    "viapoint-time": ch4_viapoints.viapoint_time,
    "viapoint-distance": ch4_grasping.viapoint_distance,
    "object-size": ch4_grasping.object_size,
    "movement-time": ch4_variability.movement_time,
    "variability-size": ch4_variability.variability_size,
    "variability-distance": ch4_variability.variability_distance,
}
#: Repetitions per setting where none are given (the thesis's).
TRIALS = 500


def _measure(base: GraspTask, trials: int, seed: int, out: Path | None):
    """Every experiment run on ``base`` and measured (figures and tables into ``out``
    unless None): the measurements by claim id, the experiments, their seeds."""
    children = np.random.SeedSequence(seed).spawn(len(EXPERIMENTS) + 1)
    got: dict[str, Measured] = {}
    done = {}
    for (name, run), child in zip(EXPERIMENTS.items(), children):
        t0 = time.perf_counter()
        done[name] = exp = run(trials=trials, seed=child, base=base)
        if out is not None:
            write_experiment(exp, out)
        got.update(MEASURES[name](exp))
        log.info("%s: %.1f s", name, time.perf_counter() - t0)
    got.update([ch4_variability.slope_change(
        [done[k] for k in ("movement-time", "variability-size", "variability-distance")])])
    return got, done, children


def _evaluate(got: dict[str, Measured], trials: int) -> list[dict]:
    # a verdict that fails its rule says so, even where no cause is known
    return evaluate(CLAIMS, got, unexplained=f"the numbers fail the rule in the measure "
                    f"column ({trials} repetitions per setting)")


def reproduce(out: Path, *, trials: int | None = None, seed: int = 0, quick: bool = False,
              progress: Progress = no_progress) -> list[dict]:
    """Run every chapter-4 experiment, save figures and tables, return the claims.

    Every claim is also computed at the thesis's cost weights
    (:data:`tools.thesis.common.THESIS_SETTINGS`; its ``at_thesis``), and those
    that depend on ``tip_start`` say over which of its values they hold.

    Parameters
    ----------
    out : pathlib.Path
        Folder for the PNG figures (``fig4_*.png``) and CSV tables (created).
    trials : int, optional
        Repetitions per setting (default :data:`TRIALS`, the thesis's 500).
    seed : int
        Root seed; each experiment uses its own child.
    quick : bool
        Unused (``trials`` sets a smoke run's size).
    progress : callable
        Called with the name of each step as it starts.

    Returns
    -------
    list of dict
        One claim per quantitative statement (:func:`tools.thesis.records.claim`),
        then the sensitivity tables (:func:`tools.thesis.records.sensitivity`).
    """
    trials = TRIALS if trials is None else int(trials)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    base = GraspTask()
    plan = plan_grasp(base)
    save_figure(out / "fig4_1_setup.png", setup_figure(plan=plan))
    progress("ch4: experiments")
    got, done, children = _measure(base, trials, seed, out)
    typical = simulate_grasp(base, trials, seed=children[-1], plan=plan)
    save_figure(out / "fig4_6_typical_grasp.png", grasp_figure(typical))
    progress("ch4: the thesis's settings")
    got_t, done_t, _ = _measure(replace(base, **THESIS_SETTINGS), trials, seed, None)
    claims = at_settings(_evaluate(got, trials), _evaluate(got_t, trials),
                         "r = 0.002, w_v = 0.1: ")
    progress("ch4: sensitivity")
    t0 = time.perf_counter()
    tip, used = tip_start_table(base, done)
    tip_t, _ = tip_start_table(replace(base, **THESIS_SETTINGS), done_t,
                               " at the thesis's settings (its model and weights)")
    tables = [tip, tip_t, travel_table(base, used)]
    log.info("sensitivity: %.1f s", time.perf_counter() - t0)
    mark_conditional(claims, TIP_DEPENDENT, tip, tip_t)
    return claims + tables

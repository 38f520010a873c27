"""The experiments of thesis chapter 4: one grasp parameter swept at a time.

Each experiment repeats a grasp ``trials`` times (thesis: 500) for every value
of one :class:`~minvar.grasp.GraspTask` parameter, all else at the thesis's
values (4 cm disk 20 cm away, 1000 ms, via-point 1 cm outside the object,
level with the targets, at 70 %). Every setting draws from its own child of
``seed`` (``numpy.random.SeedSequence(seed).spawn``), so adding a setting
leaves the others unchanged.

The result holds three tidy tables — ``summary`` (one row per setting),
``trials`` (one row per repetition) and ``curves`` (one row per setting and
time step: mean paths, speeds, aperture and SDs) — and the experiment's
statistics. Its figures, named after the thesis's, are drawn from these on
request: :meth:`GraspExperiment.plot` (or
:func:`minvar.plotting.experiment_figures`).

Variability (4.2.3) is reported as effect sizes with confidence intervals,
not p-values: the peak SD over time and its timing, exactly
(:func:`minvar.grasp_stats.grasp_moments`) and from the repetitions with a
95 % bootstrap interval (:func:`minvar.grasp_stats.bootstrap_peak`), and
their change across settings with its interval. (The thesis compared settings
by one-way ANOVA; over 500 repetitions per setting, or exact moments, any
nonzero effect is "significant", so the size of the effect is what tells.)
The transport-distance sweep is expressed as the thesis does, as the distance
the wrist moves (line 953); the object centre is ``wrist_offset`` further.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pandas as pd

from . import limits
from .grasp import GraspTask, plan_grasp, simulate_grasp
from .grasp_stats import (
    GraspMoments,
    bootstrap_peak,
    grasp_moments,
    max_grip_aperture,
    path_sd,
    peak_deviation,
    summarize_grasp,
)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

# scipy.stats is imported where the statistics are computed, not here: it
# takes about a second to import, and the command line reads EXPERIMENTS
# when it builds its parser, before any experiment runs.

log = logging.getLogger(__name__)

__all__ = [
    "GraspExperiment",
    "SweepTables",
    "EXPERIMENTS",
    "THESIS_TRIALS",
    "check_trials",
    "run_experiment",
    "run_sweep",
    "Sweep",
    "SWEEPS",
    "viapoint_height_experiment",
    "viapoint_time_experiment",
    "viapoint_distance_experiment",
    "object_size_experiment",
    "movement_time_experiment",
    "variability_size_experiment",
    "variability_distance_experiment",
]

#: Repetitions per setting in the thesis.
THESIS_TRIALS = 500
#: Bootstrap resamples behind the variability experiments' confidence intervals.
BOOTSTRAP_DRAWS = 400

#: Settings of the thesis's sweeps (SI units; via-point time as a fraction).
VIAPOINT_HEIGHTS = tuple(np.round(np.arange(-0.02, 0.0201, 0.005), 4))
VIAPOINT_TIMES = tuple(np.round(np.arange(0.5, 0.951, 0.025), 3))
VIAPOINT_DISTANCES = tuple(np.round(np.arange(10) * 0.0025, 4))
OBJECT_SIZES = tuple(np.round(np.arange(9) * 0.01, 3))
MOVEMENT_TIMES = (0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2)
VARIABILITY_SIZES = (0.0, 0.02, 0.04, 0.06, 0.08)
#: How far the wrist travels in the distance sweep, m (thesis line 953).
TRANSPORT_DISTANCES = (0.08, 0.12, 0.16, 0.20, 0.24)
#: The peak-SD quantities bootstrapped per setting (columns of ``bootstrap``).
PEAK_COLUMNS = ("wrist_sd_peak", "wrist_sd_peak_time", "aperture_sd_peak",
                "aperture_sd_peak_time")


@dataclass(frozen=True, eq=False)
class GraspExperiment:
    """One chapter-4 sweep: tables and statistics; figures on request (:meth:`plot`).

    Attributes
    ----------
    name : str
        Experiment name, e.g. ``"object-size"``.
    parameter : str
        The :class:`~minvar.grasp.GraspTask` field varied.
    base : GraspTask
        The task every setting starts from.
    summary : pandas.DataFrame
        One row per setting: ``setting``, the parameter's value, the
        :class:`~minvar.grasp_stats.GraspSummary` fields (m; times as
        fractions of the movement) and ``finger_sd``, ``thumb_sd`` (total).
    trials : pandas.DataFrame
        One row per setting and repetition: ``mga``, ``mga_time``, digit
        end-points ``finger_end_x`` ... and distances from target,
        ``wrist_peak_dev``, ``aperture_peak_dev`` (m) and their times.
    curves : pandas.DataFrame
        One row per setting and step: ``time`` (s), ``relative_time``, mean
        ``wrist_x`` ... ``thumb_y`` (m), mean speeds (m/s), mean ``aperture``,
        ``wrist_sd``, ``aperture_sd`` and their ``*_exact`` values (m).
    stats : dict
        Experiment-level numbers: effect sizes with their 95 % intervals
        (``*_ci`` pairs), regression slopes, ...
    bootstrap : pandas.DataFrame
        One row per setting and bootstrap resample of its repetitions
        (``setting``, ``draw`` and :data:`PEAK_COLUMNS`); empty for the
        experiments that do not need it.
    moments : tuple of GraspMoments
        The exact moments of each setting's plan, in setting order.
    axis : str, optional
        The column shown on the figures' x axes when it is not ``parameter``
        (``transport_distance`` for the distance sweep).
    """

    name: str
    parameter: str
    base: GraspTask
    summary: pd.DataFrame = field(repr=False)
    trials: pd.DataFrame = field(repr=False)
    curves: pd.DataFrame = field(repr=False)
    stats: dict = field(default_factory=dict)
    bootstrap: pd.DataFrame = field(default_factory=pd.DataFrame, repr=False)
    moments: tuple[GraspMoments, ...] = field(default=(), repr=False)
    axis: str | None = None

    @property
    def values(self) -> np.ndarray:
        """(settings,) values of the varied parameter."""
        return self.summary[self.parameter].to_numpy()

    @property
    def shown(self) -> str:
        """The column the figures plot against: ``axis``, else ``parameter``."""
        return self.axis or self.parameter

    def to_pandas(self) -> pd.DataFrame:
        """The per-setting summary table."""
        return self.summary

    def plot(self) -> dict[str, Figure]:
        """Draw this experiment's figures (matplotlib is imported here, not before).

        Returns
        -------
        dict of str to matplotlib.figure.Figure
            Keyed by file stem named after the thesis figure, e.g.
            ``"fig4_10_object_size_mga"``; see
            :func:`minvar.plotting.experiment_figures`.
        """
        from .plotting.grasp_experiments import experiment_figures

        return experiment_figures(self)


def check_trials(trials, *, name: str = "trials") -> int:
    """Check a number of repetitions per setting: an integer from 2 to ``MAX_TRIALS``.

    Two is the fewest from which a standard deviation can be computed;
    :data:`minvar.limits.MAX_TRIALS` (10 000) the most one setting may run.

    Parameters
    ----------
    trials : int
        The number to check.
    name : str
        What to call it in the error message (e.g. ``"--trials"`` on the
        command line).

    Returns
    -------
    int
        ``trials`` as a Python int.

    Raises
    ------
    ValueError
        If ``trials`` is not an integer >= 2 (a bool is not an integer here),
        or is more than :data:`minvar.limits.MAX_TRIALS`.
    """
    if isinstance(trials, bool) or not isinstance(trials, int | np.integer) or trials < 2:
        raise ValueError(
            f"{name}: expected an integer number of repetitions >= 2, got {trials!r}"
        )
    return limits.check_trials(int(trials), name)


class SweepTables(NamedTuple):
    """What :func:`run_sweep` returns (the attributes of :class:`GraspExperiment`).

    Attributes
    ----------
    summary, trials, curves, bootstrap : pandas.DataFrame
        As in :class:`GraspExperiment`.
    moments : tuple of GraspMoments
        Exact moments per setting.
    """

    summary: pd.DataFrame
    trials: pd.DataFrame
    curves: pd.DataFrame
    bootstrap: pd.DataFrame
    moments: tuple[GraspMoments, ...]


def run_sweep(
    parameter: str,
    values: Sequence[float],
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
    bootstrap: int = 0,
) -> SweepTables:
    """Simulate a grasp for each value of one task parameter and tabulate it.

    Parameters
    ----------
    parameter : str
        A numeric :class:`~minvar.grasp.GraspTask` field, e.g. ``"object_size"``.
    values : sequence of float
        Its settings (SI units).
    trials : int
        Repetitions per setting (>= 2).
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses child ``i`` of ``SeedSequence(seed)``.
    base : GraspTask, optional
        The task the settings modify (default: the thesis's).
    bootstrap : int
        Bootstrap resamples of each setting's peak SDs (0: none).

    Returns
    -------
    SweepTables
        ``(summary, trials, curves, bootstrap, moments)``, described in
        :class:`GraspExperiment`.

    Raises
    ------
    ValueError
        If a setting is not a valid task (the message names the field).
    """
    trials = check_trials(trials)
    base = GraspTask() if base is None else base
    values = [float(v) for v in values]
    if not values:
        raise ValueError(f"{parameter}: expected at least one setting")
    if parameter not in GraspTask.__dataclass_fields__:
        raise ValueError(f"parameter: {parameter!r} is not a GraspTask field")
    tasks = [replace(base, **{parameter: v}) for v in values]  # validate all before working
    if isinstance(seed, np.random.SeedSequence):
        # a fresh copy: spawning from the caller's object would depend on its history
        root = np.random.SeedSequence(seed.entropy, spawn_key=seed.spawn_key)
    else:
        root = np.random.SeedSequence(seed)
    children = root.spawn(len(values))
    tables = [_setting(i, parameter, task, child, trials, int(bootstrap))
              for i, (task, child) in enumerate(zip(tasks, children))]
    summary, trial_rows, curve_rows, boot_rows, moments = zip(*tables)
    return SweepTables(
        pd.DataFrame(list(summary)),
        pd.concat(trial_rows, ignore_index=True),
        pd.concat(curve_rows, ignore_index=True),
        pd.concat(boot_rows, ignore_index=True),
        tuple(moments),
    )


def _setting(i: int, parameter: str, task: GraspTask, child, trials: int, draws: int):
    """Setting ``i``'s rows of the four tables, and its moments: plan, simulate, measure."""
    value = getattr(task, parameter)
    log.debug("%s = %g: %d repetitions", parameter, value, trials)
    plan = plan_grasp(task)
    res = simulate_grasp(task, trials, seed=child, plan=plan)
    mom = grasp_moments(plan)
    s = summarize_grasp(res, mom)
    summary = {"setting": i, parameter: value, **s.as_dict(),
               "finger_sd": s.finger_sd, "thumb_sd": s.thumb_sd}
    rt = res.relative_time
    mga, mga_t = max_grip_aperture(res.aperture, rt)
    w_dev, w_t = peak_deviation(res.wrist, rt)
    a_dev, a_t = peak_deviation(res.aperture, rt)
    fe, te = res.finger_end, res.thumb_end
    per_trial = pd.DataFrame({
        "setting": i, parameter: value, "trial": np.arange(trials),
        "mga": mga, "mga_time": mga_t,
        "finger_end_x": fe[:, 0], "finger_end_y": fe[:, 1],
        "finger_distance": np.linalg.norm(fe - task.finger_target, axis=1),
        "thumb_end_x": te[:, 0], "thumb_end_y": te[:, 1],
        "thumb_distance": np.linalg.norm(te - task.thumb_target, axis=1),
        "wrist_peak_dev": w_dev, "wrist_peak_dev_time": w_t,
        "aperture_peak_dev": a_dev, "aperture_peak_dev_time": a_t,
    })
    mean = {k: getattr(res, k).mean(axis=0) for k in ("wrist", "finger", "thumb")}
    curves = pd.DataFrame({
        "setting": i, parameter: value, "step": np.arange(len(rt)),
        "time": res.time, "relative_time": rt,
        "wrist_x": mean["wrist"][:, 0], "wrist_y": mean["wrist"][:, 1],
        "finger_x": mean["finger"][:, 0], "finger_y": mean["finger"][:, 1],
        "thumb_x": mean["thumb"][:, 0], "thumb_y": mean["thumb"][:, 1],
        "wrist_speed": res.wrist_speed.mean(axis=0),
        "finger_speed": res.finger_speed.mean(axis=0),
        "thumb_speed": res.thumb_speed.mean(axis=0),
        "aperture": res.aperture.mean(axis=0),
        "wrist_sd": path_sd(res.wrist), "aperture_sd": path_sd(res.aperture),
        "wrist_sd_exact": mom.wrist_sd, "aperture_sd_exact": mom.aperture_sd,
    })
    boot = pd.DataFrame(columns=["setting", "draw", *PEAK_COLUMNS])
    if draws:
        # its own stream, apart from the simulation's children of ``child``
        rng = np.random.default_rng(
            np.random.SeedSequence(child.entropy, spawn_key=(*child.spawn_key, 2**31)))
        w, a = bootstrap_peak(res.wrist, rt, draws, rng), bootstrap_peak(res.aperture, rt,
                                                                          draws, rng)
        boot = pd.DataFrame({"setting": i, "draw": np.arange(draws),
                             "wrist_sd_peak": w[:, 0], "wrist_sd_peak_time": w[:, 1],
                             "aperture_sd_peak": a[:, 0], "aperture_sd_peak_time": a[:, 1]})
    return summary, per_trial, curves, boot, mom


def _percentiles(draws: np.ndarray) -> list[float]:
    """The central 95 % interval of ``draws``, as a JSON-ready pair."""
    return [float(x) for x in np.percentile(draws, [2.5, 97.5])]


def _peak_effects(summary: pd.DataFrame, boot: pd.DataFrame) -> dict:
    """How the peak SDs and their times change across settings, with 95 % intervals.

    For each of :data:`PEAK_COLUMNS`: ``*_change`` (last setting minus first)
    and ``*_max_diff`` (largest minus smallest setting, signed by their order),
    exact, each with a ``*_ci`` interval from the bootstrap draws: what 500
    repetitions per setting can resolve. Also ``*_exact_range``: the exact
    spread relative to the mean, 0 when the parameter cannot act on the
    component (e.g. the arm's plan does not depend on object size).
    """
    out = {}
    for col in PEAK_COLUMNS:
        exact = summary[f"{col}_exact"].to_numpy()
        d = boot.pivot(index="draw", columns="setting", values=col).to_numpy()
        hi, lo = int(np.argmax(exact)), int(np.argmin(exact))
        first, last = (min(lo, hi), max(lo, hi)) if hi != lo else (0, len(exact) - 1)
        out[f"{col}_change"] = float(exact[-1] - exact[0])
        out[f"{col}_change_ci"] = _percentiles(d[:, -1] - d[:, 0])
        out[f"{col}_max_diff"] = float(exact[last] - exact[first])
        out[f"{col}_max_diff_ci"] = _percentiles(d[:, last] - d[:, first])
        out[f"{col}_exact_range"] = float(np.ptp(exact) / np.mean(exact))
    return out


def _with_intervals(summary: pd.DataFrame, boot: pd.DataFrame) -> pd.DataFrame:
    """``summary`` with 95 % intervals: MGA and its time (normal, from the repetitions'
    SD) and, where bootstrapped, the peak SDs and their times."""
    se = 1.959964 / np.sqrt(summary["trials"])
    out = summary.assign(
        mga_ci_low=summary.mga_mean - se * summary.mga_sd,
        mga_ci_high=summary.mga_mean + se * summary.mga_sd,
        mga_time_ci_low=summary.mga_time_mean - se * summary.mga_time_sd,
        mga_time_ci_high=summary.mga_time_mean + se * summary.mga_time_sd,
    )
    if len(boot):
        q = boot.groupby("setting")[list(PEAK_COLUMNS)].quantile([0.025, 0.975]).unstack()
        for col in PEAK_COLUMNS:
            out[f"{col}_ci_low"] = q[(col, 0.025)].to_numpy()
            out[f"{col}_ci_high"] = q[(col, 0.975)].to_numpy()
    return out


def _mga_stats(parameter):
    def stats(summary, trials):
        from scipy import stats as sps

        x = summary[parameter].to_numpy()
        fit = sps.linregress(x, summary["mga_mean"].to_numpy())
        tfit = sps.linregress(x, summary["mga_time_mean"].to_numpy())
        # the slope's uncertainty from the repetitions themselves (same slope as
        # the means' regression: every setting has the same number of them)
        each = sps.linregress(trials[parameter].to_numpy(), trials["mga"].to_numpy())
        half = 1.959964 * float(each.stderr)
        return {
            "mga_slope": float(fit.slope), "mga_intercept": float(fit.intercept),
            "mga_r": float(fit.rvalue),
            "mga_slope_ci": [float(fit.slope) - half, float(fit.slope) + half],
            "mga_time_slope": float(tfit.slope),
            "mga_time_min": float(summary["mga_time_mean"].min()),
            "mga_time_max": float(summary["mga_time_mean"].max()),
        }
    return stats


class Sweep(NamedTuple):
    """One chapter-4 experiment: the parameter it sweeps and how it is reported.

    Attributes
    ----------
    parameter : str
        The :class:`~minvar.grasp.GraspTask` field swept.
    values : tuple of float
        The thesis's settings (SI units).
    title : str
        What it measures, with the thesis's section and figures.
    values_doc : str
        What the values are (the experiment function's first parameter).
    stats : callable, optional
        ``(summary, trials) -> dict`` of extra statistics (the MGA regressions).
    draws : int
        Bootstrap resamples of the peak SDs (0: none).
    moved : bool
        The values are how far the wrist travels (line 953): each setting's
        ``distance`` is the value plus ``base.wrist_offset``, and the tables gain
        a ``transport_distance`` column, which the figures show.
    """

    parameter: str
    values: tuple[float, ...]
    title: str
    values_doc: str
    stats: Callable | None = None
    draws: int = 0
    moved: bool = False


#: The seven experiments, in thesis order: what each sweeps and reports.
SWEEPS: dict[str, Sweep] = {
    "viapoint-height": Sweep(
        "viapoint_height", VIAPOINT_HEIGHTS,
        "Via-point vertical position vs digit end-point accuracy (thesis 4.2.1.1, "
        "Figs. 4.2-4.3).", "Via-point heights relative to the target line, m (default -2 "
        "to +2 cm)."),
    "viapoint-time": Sweep(
        "viapoint_time", VIAPOINT_TIMES,
        "Via-point timing vs digit end-point accuracy (thesis 4.2.1.2, Figs. 4.4-4.5).",
        "Via-point times, fractions of the movement (default 50 % to 95 %)."),
    "viapoint-distance": Sweep(
        "viapoint_offset", VIAPOINT_DISTANCES,
        "Via-point distance from the object vs MGA and its timing (thesis 4.2.2.1, "
        "Figs. 4.7-4.8).", "Via-point distances outside the object surface, m (default 0 "
        "to 2.25 cm).", _mga_stats("viapoint_offset")),
    "object-size": Sweep(
        "object_size", OBJECT_SIZES,
        "Object size vs MGA (regression slope) and its timing (thesis 4.2.2.2, "
        "Figs. 4.9-4.10).", "Object diameters, m (default 0 to 8 cm in 1 cm steps).",
        _mga_stats("object_size")),
    "movement-time": Sweep(
        "duration", MOVEMENT_TIMES,
        "Wrist and aperture variability vs movement time (thesis 4.2.3.1, Figs. "
        "4.11-4.12).", "Movement times, s (default 0.6 to 1.2 s).", draws=BOOTSTRAP_DRAWS),
    "variability-size": Sweep(
        "object_size", VARIABILITY_SIZES,
        "Wrist and aperture variability vs object size (thesis 4.2.3.2, Figs. "
        "4.13-4.14).", "Object diameters, m (default 0 to 8 cm in 2 cm steps).",
        draws=BOOTSTRAP_DRAWS),
    "variability-distance": Sweep(
        "distance", TRANSPORT_DISTANCES,
        "Wrist and aperture variability vs transport distance (thesis 4.2.3.3, Figs. "
        "4.15-4.16).", "How far the wrist travels, m (default 8-24 cm; the object "
        "centre is ``base.wrist_offset`` further: the thesis's 'distance to be moved', "
        "line 953).", draws=BOOTSTRAP_DRAWS, moved=True),
}


def run_experiment(
    name: str,
    values: Sequence[float] | None = None,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Run one chapter-4 experiment by name (:data:`SWEEPS`), over the thesis's settings
    or ``values``.

    Parameters
    ----------
    name : str
        One of :data:`SWEEPS` (the keys of :data:`EXPERIMENTS`).
    values : sequence of float, optional
        The settings (default: the thesis's, ``SWEEPS[name].values``).
    trials : int
        Repetitions per setting (thesis: :data:`THESIS_TRIALS`, 500).
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.

    Raises
    ------
    ValueError
        An unknown ``name``, ``trials`` out of range, a setting that is not a
        valid task (naming the field), or fewer than 2 different ``values``
        for an experiment that fits the MGA's regression (viapoint-distance,
        object-size), refused before anything is simulated.
    """
    if name not in SWEEPS:
        raise ValueError(f"experiment: unknown name {name!r}; expected one of "
                         f"{', '.join(SWEEPS)}")
    trials = check_trials(trials)
    spec = SWEEPS[name]
    base = GraspTask() if base is None else base
    given = [float(v) for v in (spec.values if values is None else values)]
    if spec.stats is not None and len(set(given)) < 2:  # before minutes of simulation
        raise ValueError(f"values: the MGA regression of the {name} experiment needs at least "
                         f"2 different settings, got {given}")
    swept = [v + base.wrist_offset for v in given] if spec.moved else given
    sweep = run_sweep(spec.parameter, swept, trials=trials, seed=seed, base=base,
                      bootstrap=spec.draws)
    summary = _with_intervals(sweep.summary, sweep.bootstrap)
    stats = spec.stats(summary, sweep.trials) if spec.stats else {}
    if spec.draws:
        stats.update(_peak_effects(summary, sweep.bootstrap))
    exp = GraspExperiment(
        name=name, parameter=spec.parameter, base=base, summary=summary,
        trials=sweep.trials, curves=sweep.curves, stats=stats, bootstrap=sweep.bootstrap,
        moments=sweep.moments, axis="transport_distance" if spec.moved else None,
    )
    if spec.moved:
        by_setting = dict(enumerate(given))
        for table in (exp.summary, exp.trials, exp.curves):
            table.insert(2, "transport_distance", table["setting"].map(by_setting))
    return exp


_DOC = """{title}

    Parameters
    ----------
    values : sequence of float
        {values_doc}
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """


def _experiment_function(name: str) -> Callable[..., GraspExperiment]:
    """The public function of one experiment: :func:`run_experiment` with its name."""
    spec = SWEEPS[name]

    def experiment(values: Sequence[float] = spec.values, *, trials: int = THESIS_TRIALS,
                   seed: int | np.random.SeedSequence = 0,
                   base: GraspTask | None = None) -> GraspExperiment:
        return run_experiment(name, values, trials=trials, seed=seed, base=base)

    experiment.__name__ = experiment.__qualname__ = f"{name.replace('-', '_')}_experiment"
    experiment.__doc__ = _DOC.format(title=spec.title, values_doc=spec.values_doc)
    return experiment


viapoint_height_experiment = _experiment_function("viapoint-height")
viapoint_time_experiment = _experiment_function("viapoint-time")
viapoint_distance_experiment = _experiment_function("viapoint-distance")
object_size_experiment = _experiment_function("object-size")
movement_time_experiment = _experiment_function("movement-time")
variability_size_experiment = _experiment_function("variability-size")
variability_distance_experiment = _experiment_function("variability-distance")

#: Experiment functions by CLI name, in thesis order.
EXPERIMENTS: dict[str, Callable[..., GraspExperiment]] = {
    "viapoint-height": viapoint_height_experiment,
    "viapoint-time": viapoint_time_experiment,
    "viapoint-distance": viapoint_distance_experiment,
    "object-size": object_size_experiment,
    "movement-time": movement_time_experiment,
    "variability-size": variability_size_experiment,
    "variability-distance": variability_distance_experiment,
}

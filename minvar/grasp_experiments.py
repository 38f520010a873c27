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

Variability (4.2.3) is compared across settings by one-way ANOVA
(:func:`scipy.stats.f_oneway`) on each repetition's peak deviation from its
setting's mean path (:func:`minvar.grasp_stats.peak_deviation`): the SD over
time is the root mean square of these deviations, so a parameter that changes
the variability changes their mean. The SDs themselves are reported both from
the repetitions and exactly (:func:`minvar.grasp_stats.grasp_moments`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from .grasp import GraspTask, plan_grasp, simulate_grasp
from .grasp_stats import (
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
    "EXPERIMENTS",
    "THESIS_TRIALS",
    "check_trials",
    "run_experiment",
    "run_sweep",
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

#: Settings of the thesis's sweeps (SI units; via-point time as a fraction).
VIAPOINT_HEIGHTS = tuple(np.round(np.arange(-0.02, 0.0201, 0.005), 4))
VIAPOINT_TIMES = tuple(np.round(np.arange(0.5, 0.951, 0.025), 3))
VIAPOINT_DISTANCES = tuple(np.round(np.arange(10) * 0.0025, 4))
OBJECT_SIZES = tuple(np.round(np.arange(9) * 0.01, 3))
MOVEMENT_TIMES = (0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2)
VARIABILITY_SIZES = (0.0, 0.02, 0.04, 0.06, 0.08)
TRANSPORT_DISTANCES = (0.08, 0.12, 0.16, 0.20, 0.24)


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
        Experiment-level numbers (regression slope, ANOVA F and p, ...).
    """

    name: str
    parameter: str
    base: GraspTask
    summary: pd.DataFrame = field(repr=False)
    trials: pd.DataFrame = field(repr=False)
    curves: pd.DataFrame = field(repr=False)
    stats: dict = field(default_factory=dict)

    @property
    def values(self) -> np.ndarray:
        """(settings,) values of the varied parameter."""
        return self.summary[self.parameter].to_numpy()

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
    """Check a number of repetitions per setting: an integer of at least 2.

    Two is the fewest from which a standard deviation can be computed.

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
        If ``trials`` is not an integer >= 2 (a bool is not an integer here).
    """
    if isinstance(trials, bool) or not isinstance(trials, int | np.integer) or trials < 2:
        raise ValueError(
            f"{name}: expected an integer number of repetitions >= 2, got {trials!r}"
        )
    return int(trials)


def run_sweep(
    parameter: str,
    values: Sequence[float],
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
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

    Returns
    -------
    summary, trials, curves : pandas.DataFrame
        The tables described in :class:`GraspExperiment`.

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
    summaries, trial_rows, curve_rows = [], [], []
    for i, (value, task, child) in enumerate(zip(values, tasks, children)):
        log.debug("%s = %g: %d repetitions", parameter, value, trials)
        plan = plan_grasp(task)
        res = simulate_grasp(task, trials, seed=child, plan=plan)
        mom = grasp_moments(plan)
        s = summarize_grasp(res, mom)
        summaries.append(
            {"setting": i, parameter: value, **s.as_dict(),
             "finger_sd": s.finger_sd, "thumb_sd": s.thumb_sd}
        )
        rt = res.relative_time
        mga, mga_t = max_grip_aperture(res.aperture, rt)
        w_dev, w_t = peak_deviation(res.wrist, rt)
        a_dev, a_t = peak_deviation(res.aperture, rt)
        fe, te = res.finger_end, res.thumb_end
        trial_rows.append(pd.DataFrame({
            "setting": i, parameter: value, "trial": np.arange(trials),
            "mga": mga, "mga_time": mga_t,
            "finger_end_x": fe[:, 0], "finger_end_y": fe[:, 1],
            "finger_distance": np.linalg.norm(fe - task.finger_target, axis=1),
            "thumb_end_x": te[:, 0], "thumb_end_y": te[:, 1],
            "thumb_distance": np.linalg.norm(te - task.thumb_target, axis=1),
            "wrist_peak_dev": w_dev, "wrist_peak_dev_time": w_t,
            "aperture_peak_dev": a_dev, "aperture_peak_dev_time": a_t,
        }))
        mean = {k: getattr(res, k).mean(axis=0) for k in ("wrist", "finger", "thumb")}
        curve_rows.append(pd.DataFrame({
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
        }))
    return (
        pd.DataFrame(summaries),
        pd.concat(trial_rows, ignore_index=True),
        pd.concat(curve_rows, ignore_index=True),
    )


def _anova(trials: pd.DataFrame, column: str, keep=None) -> tuple[float, float]:
    """One-way ANOVA of ``column`` across settings: (F, p)."""
    from scipy import stats as sps

    groups = [g[column].to_numpy() for _, g in trials.groupby("setting", sort=True)]
    if keep is not None:
        groups = [g for g, k in zip(groups, keep) if k]
    if len(groups) < 2:
        return float("nan"), float("nan")
    res = sps.f_oneway(*groups)
    return float(res.statistic), float(res.pvalue)


def _variability_stats(summary: pd.DataFrame, trials: pd.DataFrame, parameter: str) -> dict:
    from scipy import stats as sps

    out = {"anova_measure": "per-repetition peak deviation from the setting's mean path"}
    for comp in ("wrist", "aperture"):
        f, p = _anova(trials, f"{comp}_peak_dev")
        out[f"{comp}_anova_F"], out[f"{comp}_anova_p"] = f, p
        f, p = _anova(trials, f"{comp}_peak_dev_time")
        out[f"{comp}_time_anova_F"], out[f"{comp}_time_anova_p"] = f, p
        peaks = summary[f"{comp}_sd_peak_exact"].to_numpy()
        # relative spread of the exact peaks: 0 when the parameter cannot act
        # on this component (e.g. the arm plan does not depend on object size)
        out[f"{comp}_sd_peak_exact_range"] = float(np.ptp(peaks) / np.mean(peaks))
        constant = np.ptp(peaks) <= 1e-9 * np.mean(peaks)
        out[f"{comp}_sd_peak_spearman"] = (
            0.0 if constant else float(sps.spearmanr(summary[parameter], peaks).statistic))
    return out


def _experiment(name, parameter, values, trials, seed, base, extra=None) -> GraspExperiment:
    summary, tr, curves = run_sweep(parameter, values, trials=trials, seed=seed, base=base)
    stats = extra(summary, tr) if extra else {}
    return GraspExperiment(
        name=name, parameter=parameter, base=GraspTask() if base is None else base,
        summary=summary, trials=tr, curves=curves, stats=stats,
    )


def viapoint_height_experiment(
    heights: Sequence[float] = VIAPOINT_HEIGHTS,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Via-point vertical position vs digit end-point accuracy (thesis 4.2.1.1, Figs. 4.2-4.3).

    Parameters
    ----------
    heights : sequence of float
        Via-point heights relative to the target line, m (default -2 to +2 cm).
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    return _experiment("viapoint-height", "viapoint_height", heights, trials, seed, base)


def viapoint_time_experiment(
    fractions: Sequence[float] = VIAPOINT_TIMES,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Via-point timing vs digit end-point accuracy (thesis 4.2.1.2, Figs. 4.4-4.5).

    Parameters
    ----------
    fractions : sequence of float
        Via-point times, fractions of the movement (default 50 % to 95 %).
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    return _experiment("viapoint-time", "viapoint_time", fractions, trials, seed, base)


def _mga_stats(parameter):
    def stats(summary, trials):
        from scipy import stats as sps

        x = summary[parameter].to_numpy()
        fit = sps.linregress(x, summary["mga_mean"].to_numpy())
        tfit = sps.linregress(x, summary["mga_time_mean"].to_numpy())
        return {
            "mga_slope": float(fit.slope), "mga_intercept": float(fit.intercept),
            "mga_r": float(fit.rvalue),
            "mga_time_slope": float(tfit.slope),
            "mga_time_min": float(summary["mga_time_mean"].min()),
            "mga_time_max": float(summary["mga_time_mean"].max()),
        }
    return stats


def viapoint_distance_experiment(
    offsets: Sequence[float] = VIAPOINT_DISTANCES,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Via-point distance from the object vs MGA and its timing (thesis 4.2.2.1, Figs. 4.7-4.8).

    Parameters
    ----------
    offsets : sequence of float
        Via-point distances outside the object surface, m (default 0 to 2.25 cm).
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    return _experiment(
        "viapoint-distance", "viapoint_offset", offsets, trials, seed, base,
        _mga_stats("viapoint_offset"),
    )


def object_size_experiment(
    sizes: Sequence[float] = OBJECT_SIZES,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Object size vs MGA (regression slope) and its timing (thesis 4.2.2.2, Figs. 4.9-4.10).

    Parameters
    ----------
    sizes : sequence of float
        Object diameters, m (default 0 to 8 cm in 1 cm steps).
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    return _experiment(
        "object-size", "object_size", sizes, trials, seed, base,
        _mga_stats("object_size"),
    )


def _variability(name, parameter, values, trials, seed, base):
    def extra(summary, tr):
        out = _variability_stats(summary, tr, parameter)
        if parameter == "object_size":  # the thesis's exception: no object at all
            keep = summary[parameter].to_numpy() > 0
            out["wrist_anova_F_nonzero"], out["wrist_anova_p_nonzero"] = _anova(
                tr, "wrist_peak_dev", keep)
        return out

    return _experiment(name, parameter, values, trials, seed, base, extra)


def movement_time_experiment(
    durations: Sequence[float] = MOVEMENT_TIMES,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Wrist and aperture variability vs movement time (thesis 4.2.3.1, Figs. 4.11-4.12).

    Parameters
    ----------
    durations : sequence of float
        Movement times, s (default 0.6 to 1.2 s).
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    return _variability("movement-time", "duration", durations, trials, seed, base)


def variability_size_experiment(
    sizes: Sequence[float] = VARIABILITY_SIZES,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Wrist and aperture variability vs object size (thesis 4.2.3.2, Figs. 4.13-4.14).

    Parameters
    ----------
    sizes : sequence of float
        Object diameters, m (default 0 to 8 cm in 2 cm steps).
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    return _variability("variability-size", "object_size", sizes, trials, seed, base)


def variability_distance_experiment(
    distances: Sequence[float] = TRANSPORT_DISTANCES,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Wrist and aperture variability vs transport distance (thesis 4.2.3.3, Figs. 4.15-4.16).

    Parameters
    ----------
    distances : sequence of float
        Distances from the wrist's start to the object centre, m (default 8-24 cm).
    trials : int
        Repetitions per setting.
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    return _variability("variability-distance", "distance", distances, trials, seed, base)


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


def run_experiment(
    name: str,
    *,
    trials: int = THESIS_TRIALS,
    seed: int | np.random.SeedSequence = 0,
    base: GraspTask | None = None,
) -> GraspExperiment:
    """Run one chapter-4 experiment by name with the thesis's settings.

    Parameters
    ----------
    name : str
        One of :data:`EXPERIMENTS`.
    trials : int
        Repetitions per setting (thesis: :data:`THESIS_TRIALS`, 500).
    seed : int or numpy.random.SeedSequence
        Root seed; setting ``i`` uses its child ``i``.
    base : GraspTask, optional
        Task the settings modify.
    """
    if name not in EXPERIMENTS:
        raise ValueError(f"experiment: unknown name {name!r}; expected one of "
                         f"{', '.join(EXPERIMENTS)}")
    return EXPERIMENTS[name](trials=check_trials(trials), seed=seed, base=base)

"""``hammer-mv reach``: simulate reaching movements (thesis chapter 3)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from hammer_mv.cli.checks import check_seed, options, output_folder
from hammer_mv.cli.flags import Setting, add_settings
from minvar.analysis import (
    THESIS_DURATIONS,
    closest_approach,
    count_speed_peaks,
    endpoint_stats,
    path_deviation,
    peak_to_mean_speed,
    speed_accuracy,
)
from minvar.limits import (
    MAX_TRIALS,
    check_memory,
    check_simulation,
    check_steps,
    simulation_bytes,
)
from minvar.plant import PointMassPlant
from minvar.reach import simulate_reach
from minvar.task import ReachTask, ViaPoint
from perception.errors import InputError
from perception.io.atomic import save_figure, write_csv, write_json

#: Columns of trajectories.csv (:meth:`minvar.reach.ReachResult.to_pandas`).
TABLE_COLUMNS = 10


#: The flags that set the reach's task (ReachTask): where, how long (first in ``--help``),
#: and the cost's weights (after ``--durations``).
TASK = (
    Setting(ReachTask, "start", "start position, m (default: 0.2 0.2, thesis Fig. 3.4)",
            default=(0.2, 0.2), type=float, nargs=2, metavar=("X", "Y")),
    Setting(ReachTask, "goal", "goal position, m (default: 0.4 0.5)", default=(0.4, 0.5),
            type=float, nargs=2, metavar=("X", "Y")),
    Setting(ReachTask, "duration", "movement time, s (default: 0.5)", default=0.5,
            metavar="S"),
    Setting(ReachTask, "r", "effort weight r (default: {default})"),
    Setting(ReachTask, "w_v", "final velocity weight (default: {default})"),
    Setting(ReachTask, "w_f", "final force weight (default: {default})"),
)
#: The flags that set the plant's noise (PointMassPlant).
PLANT = (
    Setting(PointMassPlant, "sigma_u", "control-dependent noise scale (default: {default})"),
    Setting(PointMassPlant, "sigma_s", "sensory noise scale (default: {default})"),
)


def register(sub) -> None:
    """Add the ``reach`` subcommand to ``sub`` (an argparse subparsers action)."""
    p = sub.add_parser(
        "reach",
        help="simulate noisy repetitions of a reach (figures + CSV)",
        description="Plan a reach with the minimum variance model, execute noisy repetitions "
        "and write figures (PNG) and trajectories (CSV). With --sweep, the speed-accuracy "
        "trade-off over several movement times (thesis Figs. 3.5, 3.7).",
    )
    add_settings(p, TASK[:3])
    p.add_argument("--via", nargs=3, type=float, action="append", default=[],
                   metavar=("X", "Y", "FRACTION"),
                   help="via-point at (X, Y) m, at FRACTION (0-1) of the movement; repeatable")
    p.add_argument("--trials", type=int, default=None, metavar="N",
                   help="repetitions (default: 100; 200 per duration with --sweep)")
    p.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default: 0)")
    p.add_argument("--sweep", action="store_true",
                   help="speed-accuracy sweep over --durations instead of one movement")
    p.add_argument("--durations", nargs="+", type=float, default=list(THESIS_DURATIONS),
                   metavar="S", help=f"movement times for --sweep, s (default: "
                                     f"{THESIS_DURATIONS[0]:g} ... {THESIS_DURATIONS[-1]:g})")
    add_settings(p, TASK[3:])
    add_settings(p, PLANT)
    p.add_argument("-o", "--output", required=True, type=Path, metavar="DIR",
                   help="folder for the figures and tables")
    p.set_defaults(func=run)


def _flags(settings) -> dict[str, str]:
    """Field -> flag of ``settings``, for :func:`~hammer_mv.cli.checks.options`."""
    return {s.field: s.name for s in settings}


def reach_settings(args: argparse.Namespace) -> tuple[PointMassPlant, ReachTask]:
    """The plant and the task that parsed ``args`` say, each value checked and a bad one
    named by its flag (the via-points' times and the movement's steps too).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of ``hammer-mv reach``.
    """
    with options(_flags(PLANT)):
        plant = PointMassPlant(sigma_u=args.sigma_u, sigma_s=args.sigma_s)
    with options("--via"):
        vias = tuple(ViaPoint((x, y), fraction=f) for x, y, f in args.via)
    with options(_flags(TASK)):
        task = ReachTask(tuple(args.start), tuple(args.goal), args.duration, vias,
                         r=args.r, w_v=args.w_v, w_f=args.w_f)
        task.steps(plant.dt)
    with options("--via"):
        for v in vias:
            v.step(task.duration, plant.dt)  # reject bad via-point times before any work
    return plant, task


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv reach`` with parsed ``args``; return the exit status."""
    from minvar.plotting import reach_figure, speed_accuracy_figure

    check_seed(args.seed)
    plant, task = reach_settings(args)
    vias = task.via_points
    n_states = plant.n_states(len(task.targets))
    out: Path = output_folder(args.output)
    if args.sweep:
        trials = 200 if args.trials is None else args.trials
        if trials < 2:
            raise InputError(f"need at least 2 repetitions for a sweep, got {trials}",
                             field="--trials")
        for d in args.durations:
            with options("--durations"):
                check_steps(d, plant.dt, "--durations")
                steps = ReachTask(task.start, task.goal, d, vias).steps(plant.dt)
                for v in vias:
                    v.step(d, plant.dt)
            with options("--trials"):
                check_simulation(trials, steps, n_states, "--trials", max_trials=MAX_TRIALS)
        sweep = speed_accuracy(task, args.durations, trials, seed=args.seed, plant=plant)
        write_csv(out / "speed_accuracy.csv", sweep.summary)
        write_csv(out / "speed_accuracy_trials.csv", sweep.trials)
        save_figure(out / "speed_accuracy.png", speed_accuracy_figure(sweep))
        if not args.quiet:
            print(f"wrote {out / 'speed_accuracy.png'} and speed_accuracy.csv "
                  f"({len(args.durations)} durations x {trials} repetitions)")
        return 0

    trials = 100 if args.trials is None else args.trials
    if trials < 2:
        raise InputError(f"need at least 2 repetitions, got {trials}", field="--trials")
    steps = task.steps(plant.dt)
    with options("--trials"):
        check_simulation(trials, steps, n_states, "--trials", max_trials=MAX_TRIALS)
        # ... and the table of trajectories.csv: TABLE_COLUMNS floats per repetition and step
        check_memory(simulation_bytes(trials, steps, n_states)
                     + 8 * TABLE_COLUMNS * trials * (steps + 1),
                     "--trials", f"{trials} repetitions x {steps + 1} time points and their "
                     "table")
    result = simulate_reach(task, trials, seed=args.seed, plant=plant)
    stats = endpoint_stats(result.endpoint, task.goal)
    summary = {
        "start": task.start,
        "goal": task.goal,
        "duration_s": task.duration,
        "via_points": [{"position": v.position, "fraction": v.fraction} for v in vias],
        "trials": trials,
        "seed": args.seed,
        "solver": {"iterations": result.solution.iterations,
                   "converged": result.solution.converged,
                   "expected_cost": result.solution.cost},
        "endpoint_mean_m": stats.mean,
        "endpoint_sd_m": stats.sd,
        "endpoint_distance_mean_m": stats.distance_mean,
        "peak_to_mean_speed": peak_to_mean_speed(result.mean_speed, result.time),
        "speed_peaks": count_speed_peaks(result.mean_speed),
        "max_deviation_of_mean_path_m": float(np.max(np.abs(
            path_deviation(result.mean_position, task.start, task.goal)))),
        "via_point_closest_approach_m": [closest_approach(result.mean_position, v.position)
                                         for v in vias],
    }
    write_csv(out / "trajectories.csv", result.to_pandas())
    write_json(out / "summary.json", summary)
    save_figure(out / "reach.png", reach_figure(result))
    if not args.quiet:
        print(f"wrote {out / 'reach.png'}, trajectories.csv and summary.json "
              f"({trials} repetitions; end-point SD {stats.sd_total * 1000:.2f} mm)")
    return 0


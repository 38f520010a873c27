"""``hammer-mv grasp``: simulate reach-to-grasp movements (thesis chapter 4).

``grasp simulate`` runs one grasp setting (figures + tidy CSV + summary);
``grasp experiment NAME`` runs one of the chapter's sweeps (or ``all``) and
writes its tables (CSV), statistics (JSON) and figures (PNG, named after the
thesis's figures).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from hammer_mv.cli.checks import check_seed, options, output_folder
from hammer_mv.cli.flags import Setting, add_settings
from minvar.grasp import GraspTask, check_grasp_simulation
from minvar.grasp_experiments import EXPERIMENTS, THESIS_TRIALS, check_trials
from minvar.limits import MAX_TRIALS
from minvar.plant import PointMassPlant
from perception.io.atomic import save_figure, write_csv, write_json

#: Columns of trajectories.csv (:meth:`minvar.grasp.GraspResult.to_pandas`).
TABLE_COLUMNS = 17
#: The task's defaults, which the help says in its own words.
_D = GraspTask()
#: The flags of ``grasp simulate`` that set the task (GraspTask) and its plant's time step
#: (PointMassPlant), in ``--help``'s order; the help says the defaults as it always has.
SIMULATE = (
    Setting(GraspTask, "object_size", f"object diameter, m (default {_D.object_size})",
            metavar="M"),
    Setting(GraspTask, "distance", f"wrist start to object centre, m (default {_D.distance}: "
            f"the wrist travels {_D.transport_distance:g}, stopping {_D.wrist_offset:g} short "
            "of the centre)", metavar="M"),
    Setting(GraspTask, "duration", f"movement time, s (default {_D.duration})", metavar="S"),
    Setting(GraspTask, "viapoint_offset", "digit via-point distance outside the object, m "
            f"(default {_D.viapoint_offset})", metavar="M"),
    Setting(GraspTask, "viapoint_height", "digit via-point height above the target line, m "
            f"(default {_D.viapoint_height:g})", metavar="M"),
    Setting(GraspTask, "viapoint_time", "digit via-point time, fraction of the movement "
            f"(default {_D.viapoint_time})", metavar="F"),
    Setting(GraspTask, "tip_start", "how far ahead of the wrist the closed digit tips start, m "
            f"(default {_D.tip_start}: below the target line, {_D.wrist_offset:g} ahead of the "
            "wrist at the goal)", metavar="M"),
    Setting(GraspTask, "reach_only", "transport only: the digits stay closed"),
    Setting(GraspTask, "execution_cv", "coefficient of variation of the execution noise "
            f"(default {_D.execution_cv})", metavar="CV"),
    Setting(PointMassPlant, "dt", f"time step, s (default {_D.plant.dt})", metavar="S"),
)


def register(sub) -> None:
    """Add the ``grasp`` subcommand to ``sub`` (an argparse subparsers action)."""
    p = sub.add_parser(
        "grasp",
        help="simulate reach-to-grasp movements and the thesis's chapter 4 experiments",
        description="Reach-to-grasp with the minimum variance model: an arm and a two-digit "
        "gripper, transport and grip planned separately and executed together "
        "(thesis chapter 4). World frame: origin at the object centre, +y toward the object, m.",
    )
    p.set_defaults(func=lambda args: _usage(p))
    gsub = p.add_subparsers(dest="grasp_command", metavar="{simulate,experiment}")
    _add_simulate(gsub)
    _add_experiment(gsub)


def _add_simulate(gsub) -> None:
    s = gsub.add_parser(
        "simulate",
        help="noisy repetitions of one grasp (figures + CSV)",
        description="Plan one grasp, execute noisy repetitions and write trajectories.csv "
        "(one row per repetition and step), summary.json (MGA, variability, end-points), "
        "grasp.png and setup.png.",
    )
    add_settings(s, SIMULATE)
    s.add_argument("--trials", type=int, default=THESIS_TRIALS, metavar="N",
                   help=f"repetitions (default {THESIS_TRIALS})")
    s.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default 0)")
    s.add_argument("-o", "--output", required=True, type=Path, metavar="DIR",
                   help="folder for the figures and tables")
    s.set_defaults(func=run_simulate)


def _add_experiment(gsub) -> None:
    e = gsub.add_parser(
        "experiment",
        help="one of the thesis's chapter 4 experiments, or all",
        description=f"Run a chapter 4 sweep ({THESIS_TRIALS} repetitions per setting by "
        "default) and write "
        "NAME.csv (one row per setting), NAME_trials.csv, NAME_curves.csv, NAME_stats.json "
        "(effect sizes with 95 % confidence intervals), NAME_bootstrap.csv for the "
        "variability sweeps, and the figures as PNG, named after the thesis's (e.g. "
        "fig4_10_object_size_mga.png).",
    )
    e.add_argument("name", choices=(*EXPERIMENTS, "all"), metavar="NAME",
                   help=f"one of {', '.join(EXPERIMENTS)}, all")
    e.add_argument("--trials", type=int, default=THESIS_TRIALS, metavar="N",
                   help=f"repetitions per setting (default {THESIS_TRIALS}, as in the thesis)")
    e.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default 0)")
    e.add_argument("-o", "--output", required=True, type=Path, metavar="DIR",
                   help="folder for the tables and figures")
    e.set_defaults(func=run_experiment)


def _usage(parser: argparse.ArgumentParser) -> int:
    parser.print_help()
    return 2


#: GraspTask fields -> the ``grasp simulate`` options that set them (the plant's too).
TASK_FIELDS = {setting.field: setting.name for setting in SIMULATE}


def grasp_task(args: argparse.Namespace) -> GraspTask:
    """The task that parsed ``args`` say, each value checked and a bad one named by its flag.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of ``hammer-mv grasp simulate``.
    """
    # every size, length and the movement's steps are the task's fields, named by their flags
    with options(TASK_FIELDS):
        plant = PointMassPlant(dt=args.dt)
        return GraspTask(
            object_size=args.object_size, distance=args.distance, duration=args.duration,
            viapoint_offset=args.viapoint_offset, viapoint_height=args.viapoint_height,
            viapoint_time=args.viapoint_time, tip_start=args.tip_start,
            reach_only=args.reach_only, execution_cv=args.execution_cv, plant=plant,
        )


def run_simulate(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv grasp simulate`` with parsed ``args``; return the exit status."""
    from minvar.grasp import plan_grasp, simulate_grasp
    from minvar.grasp_stats import grasp_moments, summarize_grasp
    from minvar.plotting import grasp_figure, setup_figure

    with options("--trials"):
        check_trials(args.trials, name="--trials")
    check_seed(args.seed)
    task = grasp_task(args)
    out = output_folder(args.output)
    # the simulation, and the table of trajectories.csv in the same budget
    with options("--trials"):
        check_grasp_simulation(task, args.trials, "--trials", extra_floats=TABLE_COLUMNS,
                               max_trials=MAX_TRIALS)
    plan = plan_grasp(task)
    result = simulate_grasp(task, args.trials, seed=args.seed, plan=plan)
    summary = summarize_grasp(result, grasp_moments(plan))
    info = {
        "task": {k: getattr(task, k) for k in (
            "object_size", "distance", "transport_distance", "duration", "viapoint_offset",
            "viapoint_height", "viapoint_time", "reach_only", "execution_cv", "execution_sigma_s",
            "wrist_offset", "tip_start", "shoulder_offset", "arm_links", "digit_links")},
        "dt_s": task.plant.dt,
        "trials": args.trials,
        "seed": args.seed,
        "units": "m; times as fractions of the movement",
        "wrist_target": task.wrist_target,
        "finger_target": task.finger_target,
        "thumb_target": task.thumb_target,
        "solver": {name: {"iterations": cp.solution.iterations,
                          "converged": cp.solution.converged,
                          "expected_cost": cp.solution.cost}
                   for name, cp in plan.chains.items()},
        "summary": summary.as_dict(),
    }
    write_csv(out / "trajectories.csv", result.to_pandas())
    write_json(out / "summary.json", info)
    save_figure(out / "grasp.png", grasp_figure(result))
    save_figure(out / "setup.png", setup_figure(plan=plan))
    if not args.quiet:
        print(f"wrote {out / 'grasp.png'}, setup.png, trajectories.csv and summary.json "
              f"({args.trials} repetitions; MGA {summary.mga_mean * 100:.2f} cm at "
              f"{summary.mga_time_mean * 100:.0f} % of the movement)")
    return 0


def run_experiment(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv grasp experiment`` with parsed ``args``; return the exit status."""
    with options("--trials"):
        check_trials(args.trials, name="--trials")
    check_seed(args.seed)
    out = output_folder(args.output)
    names = list(EXPERIMENTS) if args.name == "all" else [args.name]
    for name in names:
        t0 = time.perf_counter()
        exp = EXPERIMENTS[name](trials=args.trials, seed=args.seed)
        written = write_experiment(exp, out)
        if not args.quiet:
            print(f"{name}: {len(exp.summary)} settings x {args.trials} repetitions in "
                  f"{time.perf_counter() - t0:.1f} s -> {out / (name + '.csv')}, "
                  + ", ".join(p.name for p in written if p.suffix == ".png"))
    return 0


def write_experiment(exp, out: Path) -> list[Path]:
    """Write an experiment's tables, statistics and figures into ``out``.

    The figures are drawn here (:meth:`~minvar.grasp_experiments.GraspExperiment.plot`)
    and written as ``<stem>.png``, one at a time.

    Parameters
    ----------
    exp : minvar.grasp_experiments.GraspExperiment
        The experiment.
    out : pathlib.Path
        Output folder (created if missing).

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    written = [
        write_csv(out / f"{exp.name}.csv", exp.summary),
        write_csv(out / f"{exp.name}_trials.csv", exp.trials),
        write_csv(out / f"{exp.name}_curves.csv", exp.curves),
        write_json(out / f"{exp.name}_stats.json", exp.stats),
    ]
    if len(exp.bootstrap):
        written.append(write_csv(out / f"{exp.name}_bootstrap.csv", exp.bootstrap))
    written += [save_figure(out / f"{stem}.png", fig) for stem, fig in exp.plot().items()]
    return written

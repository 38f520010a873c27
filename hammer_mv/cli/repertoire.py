"""``hammer-mv repertoire``: build and inspect HAMMER-MV model repertoires."""

from __future__ import annotations

import argparse
from pathlib import Path

from hammer_mv.cli.checks import options
from hammer_mv.cli.flags import Setting, add_settings
from minvar.limits import check_position, check_steps
from perception.errors import InputError, PlanningError
from perception.limits import MAX_FPS
from perception.recognition.models import SceneSpec, model_substeps
from perception.recognition.planning import DEFAULT_DURATIONS, default_specs
from perception.recognition.repertoire import Repertoire

#: The flags that set the scene of a repertoire built without CONFIG (SceneSpec).
SCENE = (
    Setting(SceneSpec, "distance", "wrist start to object centre, m (without CONFIG)"),
    Setting(SceneSpec, "object_size", "object diameter, m (without CONFIG)"),
)


def register(sub) -> None:
    """Add the ``repertoire`` subcommand to ``sub`` (an argparse subparsers action)."""
    p = sub.add_parser("repertoire", help="build or inspect a model repertoire",
                       description="Inverse/forward model pairs planned with the minimum "
                       "variance grasp model, stored in HDF5 so they are built once.")
    verbs = p.add_subparsers(dest="verb", metavar="VERB", required=True)
    b = verbs.add_parser("build", help="plan the models and save them",
                         description="Without CONFIG: grasp and reach-only models at each "
                         "of --durations. CONFIG is TOML with a [scene] table (distance, "
                         "object_size, frame_period) and [[model]] entries (name, kind, "
                         "and GraspTask fields such as duration or grip_via).")
    b.add_argument("config", nargs="?", type=Path, help="TOML configuration")
    b.add_argument("-o", "--output", type=Path, required=True, metavar="REP.h5",
                   help="repertoire file to write (HDF5)")
    b.add_argument("--durations", nargs="+", type=float, default=list(DEFAULT_DURATIONS),
                   metavar="S", help="movement times without CONFIG (default: 0.8 ... 1.2)")
    add_settings(b, SCENE)
    b.add_argument("--fps", type=float, default=30.0, help="video frame rate (without CONFIG)")
    b.set_defaults(func=run_build)
    i = verbs.add_parser("info", help="list the models of a repertoire file")
    i.add_argument("file", type=Path, metavar="REP.h5", help="repertoire file")
    i.set_defaults(func=run_info)


#: The GraspTask fields a planning problem can be about, by the flag that sets them.
_SCENE_FLAGS = {**{s.field: s.name for s in SCENE}, "duration": "--durations"}


def build_scene(args: argparse.Namespace) -> SceneSpec:
    """The scene that parsed ``args`` say (no CONFIG), each value checked and a bad one
    named by its flag.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of ``hammer-mv repertoire build``.
    """
    if not 0 < args.fps <= MAX_FPS:  # a rate: SceneSpec declares the period's range only
        raise InputError(f"expected a frame rate in (0, {MAX_FPS:g}] frames/s, "
                         f"got {args.fps}", field="--fps")
    with options(_SCENE_FLAGS):  # SceneSpec declares what a distance and a size may be
        scene = SceneSpec(distance=args.distance, object_size=args.object_size,
                          frame_period=1.0 / args.fps)
    for flag, value in (("--distance", args.distance), ("--object-size", args.object_size)):
        with options(flag):  # and the table's metres, which no field declares
            check_position(value, flag)
    return scene


def run_build(args: argparse.Namespace) -> int:
    """Execute ``repertoire build`` with parsed ``args``; return the exit status."""
    from perception.io.atomic import check_output

    check_output(args.output, [args.config] if args.config is not None else [])
    if args.config is not None:
        rep = Repertoire.from_config(args.config)
    else:
        scene = build_scene(args)
        dt = scene.frame_period / model_substeps(scene.frame_period)
        for duration in args.durations:  # named by the flag, before any planning
            with options("--durations"):
                check_steps(duration, dt, "--durations")
        # a scene the arm cannot reach is a PlanningError, named by its option here
        with options(_SCENE_FLAGS):  # a duration shorter than two model steps
            specs = default_specs(args.durations)
        try:
            rep = Repertoire.build(specs, scene)
        except PlanningError as exc:
            flag = _SCENE_FLAGS.get(exc.location[-1]) if exc.location else None
            raise PlanningError(exc.problem, field=exc.field or flag) from None
    rep.save(args.output)
    if not args.quiet:
        print(f"wrote {args.output}: {len(rep)} models ({', '.join(rep.names)})")
    return 0


def run_info(args: argparse.Namespace) -> int:
    """Execute ``repertoire info`` with parsed ``args``; return the exit status."""
    rep = Repertoire.load(args.file)
    print(f"{args.file}: {len(rep)} models")
    for m in rep:
        s = m.scene
        print(f"  {m.name:<14} {m.kind:<6} {m.duration:.2f} s  dt {m.dt * 1000:.2f} ms "
              f"({m.substeps}/frame)  distance {s.distance:.3f} m  object {s.object_size:.3f} m")
    return 0

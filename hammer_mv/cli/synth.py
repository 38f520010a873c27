"""``hammer-mv synth``: render a set of synthetic grasp clips from a recipe."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hammer_mv.cli.checks import cap_jobs, check_seed, output_folder
from hammer_mv.cli.flags import field_flag


def register(sub) -> None:
    """Add the ``synth`` subcommand to ``sub`` (an argparse subparsers action)."""
    p = sub.add_parser("synth", help="render synthetic grasp clips from a recipe",
                       description="Render the clips of RECIPE (TOML, see datasets/README.md): "
                       "normal, delayed-opening and open-close-open grasps from the minimum "
                       "variance model, each with ground truth (<clip>.truth.h5), plus "
                       "DIR/manifest.csv.")
    p.add_argument("recipe", type=Path, metavar="RECIPE",
                   help="recipe file (TOML; docs/recipes.md), e.g. datasets/smoke.toml")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                   help="folder for the clips, their ground truth and manifest.csv")
    p.add_argument("--seed", type=int, default=0, metavar="N", help="master seed (default: 0)")
    p.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="processes rendering clips (default: 1); the clips do not depend on it")
    field_flag("jobs", "--jobs")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute ``hammer-mv synth`` with parsed ``args``; return the exit status."""
    from perception.synthetic.recipes import load_recipe, synthesize

    jobs = cap_jobs(args.jobs, "synth", quiet=args.quiet)
    check_seed(args.seed)
    output_folder(args.output)
    recipe = load_recipe(args.recipe)
    manifest = synthesize(recipe, args.output, seed=args.seed, jobs=jobs,
                          progress=not args.quiet and sys.stderr.isatty())
    if not args.quiet:
        counts = manifest["condition"].value_counts().to_dict()
        print(f"wrote {len(manifest)} clips to {args.output} "
              f"({', '.join(f'{k}: {v}' for k, v in counts.items())}); "
              f"manifest {args.output / 'manifest.csv'}")
    return 0

"""Options shared by the recognition commands (``recognize``, ``batch``).

Defaults are read from the parameter dataclasses, so the help text and the
library agree by construction.
"""

from __future__ import annotations

import argparse
import hashlib
import json
from pathlib import Path

from perception.observation import ObserveParams
from perception.pipeline import RecognitionSettings
from perception.recognition.engine import RULES, HammerParams
from perception.recognition.repertoire import Repertoire

_OBSERVE = ObserveParams()
_HAMMER = HammerParams()


def add_recognition_options(p: argparse.ArgumentParser) -> None:
    """Add repertoire, scale and rule options to parser ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    g = p.add_argument_group("recognition")
    g.add_argument("--repertoire", type=Path, metavar="REP.h5",
                   help="models to score against (default: build the default repertoire)")
    g.add_argument("--rule", choices=RULES, default=_HAMMER.rule,
                   help=f"rule that picks the winner (default: {_HAMMER.rule}); the thesis "
                        "rule's confidence is reported either way")
    g.add_argument("--w-r", type=float, default=_HAMMER.w_r,
                   help=f"transport weight of the thesis rule (default: {_HAMMER.w_r:g})")
    g.add_argument("--w-g", type=float, default=_HAMMER.w_g,
                   help=f"grip weight of the thesis rule (default: {_HAMMER.w_g:g})")
    g.add_argument("--filter-gain", type=float, default=_HAMMER.filter_gain, metavar="G",
                   help="how strongly observed positions correct each model's estimate of "
                        "velocity and force (0: the plan alone; 1: the plan's Kalman gains; "
                        f"default {_HAMMER.filter_gain:g})")
    g.add_argument("--object-diameter", type=float, default=_OBSERVE.object_diameter,
                   metavar="M", help="real diameter of the object, m (default: "
                   f"{_OBSERVE.object_diameter:g}, the thesis's ball)")
    g.add_argument("--px-per-m", type=float, default=None, metavar="X",
                   help="image scale (default: from the object's apparent size)")
    g.add_argument("--mirror", action="store_true",
                   help="mirror the image so the finger lies on the model's +x side")
    g.add_argument("--setup", type=Path, metavar="SETUP.toml",
                   help="colour models and marker sizes for tracking videos "
                        "(hammer-mv calibrate)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")


def recognition_settings(args: argparse.Namespace) -> RecognitionSettings:
    """:class:`~perception.pipeline.RecognitionSettings` from parsed ``args``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_recognition_options`.
    """
    observe = ObserveParams(object_diameter=args.object_diameter, px_per_m=args.px_per_m,
                            mirror=args.mirror)
    hammer = HammerParams(rule=args.rule, w_r=args.w_r, w_g=args.w_g,
                          filter_gain=args.filter_gain)
    tracking = None
    if getattr(args, "setup", None) is not None:
        from perception.tracking.setup import load_setup

        tracking = load_setup(args.setup)
    return RecognitionSettings(observe=observe, hammer=hammer, tracking=tracking)


def load_repertoire(args: argparse.Namespace) -> tuple[Repertoire, str]:
    """The repertoire named by ``args`` (or the default one) and an identity string.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments with ``repertoire``.
    """
    if args.repertoire is None:
        rep = Repertoire.default()  # planned for the clip's scene when first needed
        config = json.dumps(rep.config, sort_keys=True).encode()
        return rep, f"default:{hashlib.sha256(config).hexdigest()[:16]}"
    rep = Repertoire.load(args.repertoire)
    digest = hashlib.sha256(Path(args.repertoire).read_bytes()).hexdigest()[:16]
    return rep, f"{Path(args.repertoire).name}:{digest}"

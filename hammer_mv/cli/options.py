"""Options shared by the recognition commands (``recognize``, ``batch``).

Defaults are read from the parameter dataclasses, so the help text and the
library agree by construction.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
from pathlib import Path

from hammer_mv.cli.checks import options
from hammer_mv.cli.flags import FPS_HELP, add_video_options
from perception.errors import InputError
from perception.factors import DEFAULT_FACTORS
from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.io.config import check_keys, read_toml, sub_table
from perception.landmarks import LandmarkParams
from perception.observation import ObserveParams
from perception.pipeline import RecognitionSettings
from perception.recognition.engine import RULES, HammerParams
from perception.recognition.repertoire import Repertoire
from perception.recognition.rules import VerdictRules
from perception.recognition.scoring import THESIS_SIGNS

_OBSERVE = ObserveParams()
_HAMMER = HammerParams()
#: The pose options, by the PoseImport fields they set.
POSE_FIELDS = {"keypoints": "--keypoints", "pcutoff": "--pcutoff", "fps": "--fps",
               "object_diameter_px": "--object-diameter-px", "individual": "--individual"}
#: The motion-capture options, by the MocapImport fields they set.
MOCAP_FIELDS = {"rate": "--rate", "units": "--units", "trial_column": "--trial-column",
                "time_column": "--time-column", "columns": "--columns", "markers": "--markers",
                "object_size": "--object-size", "factors": "--factors",
                "factors_from_name": "--factors-from-name"}
#: The flags that ask for motion-capture settings (none: the defaults).
MOCAP_FLAGS = ("markers", "rate", "units", "trial_column", "time_column", "columns",
               "object_size", "factors", "factors_from_name")


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
    g.add_argument("--thesis-sign", choices=THESIS_SIGNS, default=_HAMMER.thesis_sign,
                   help="reading of the sign in the thesis rule, eqs. 5.1/5.7/5.8 (default: "
                        f"{_HAMMER.thesis_sign}: +1 when observed and predicted changes agree; "
                        "printed: the equations as printed, the observed change's sign "
                        "alone); see docs/recognition.md")
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
    g.add_argument("--verdict-rules", type=Path, metavar="RULES.toml",
                   help="the verdict's thresholds: a TOML file with a [verdict] table of "
                        "VerdictRules fields (and [verdict.landmarks]); the report's "
                        "verdict_rules lists them all (docs/recognition.md)")
    add_pose_options(p)
    add_mocap_options(p)
    add_video_options(p, fps=False)
    g.add_argument("--setup", type=Path, metavar="SETUP.toml",
                   help="colour models and marker sizes for tracking videos "
                        "(hammer-mv calibrate)")


def add_pose_options(p: argparse.ArgumentParser) -> None:
    """Add the options that turn pose files (DeepLabCut, SLEAP, ...) into tracks.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    g = p.add_argument_group("pose files (DeepLabCut, SLEAP, Lightning Pose, NWB, movement; "
                             "docs/pose-files.md)")
    g.add_argument("--keypoints", nargs="+", metavar="MARKER=NAME", default=None,
                   help="which keypoint is which marker: thumb=NAME finger=NAME wrist=NAME "
                        "object=NAME (markers left out take the keypoint of their own name)")
    g.add_argument("--pose-config", type=Path, metavar="FILE",
                   help="TOML with a [keypoints] table and any of pcutoff, fps, "
                        "object_diameter_px, individual (for a batch)")
    g.add_argument("--pcutoff", type=float, default=None, metavar="P",
                   help="points below this likelihood count as lost (default: 0.6, "
                        "DeepLabCut's)")
    g.add_argument("--individual", metavar="NAME",
                   help="the individual to score in a multi-individual file")
    g.add_argument("--fps", type=float, default=None, metavar="F",
                   help=FPS_HELP + "; a pose file that carries none (DeepLabCut, SLEAP "
                        "analysis, Lightning Pose) takes the rate of the video of its name "
                        "beside it, else needs this")
    g.add_argument("--object-diameter-px", type=float, default=None, metavar="D",
                   help="the object's apparent diameter in pixels: sets the metric scale of "
                        "a pose file (or give --px-per-m)")


def add_mocap_options(p: argparse.ArgumentParser) -> None:
    """Add the options that turn motion-capture files (C3D, Qualisys TSV, tables) into reaches.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    g = p.add_argument_group("motion capture (C3D, Qualisys TSV, X/Y/Z tables; docs/mocap.md)")
    g.add_argument("--markers", nargs="+", metavar="ROLE=NAME", default=None,
                   help="which markers are which: thumb=NAME finger=NAME, and optionally "
                        "wrist=NAME[+NAME...] object=NAME[+NAME...] (default: guessed from "
                        "the names: thumb*, index*, hand*/wrist*, object/pillow/target*)")
    g.add_argument("--rate", type=float, default=None, metavar="HZ",
                   help="samples per second of a table without a time column (or with "
                        "--time-column none)")
    g.add_argument("--columns", type=_names, default=None, metavar="NAME,NAME,...",
                   help="the markers' names in column order, for a table without a header "
                        "(X, Y and Z of each, as RTMocap writes them): e.g. "
                        "object,thumb,index,hand,wrist1,wrist2")
    g.add_argument("--time-column", metavar="NAME|none", default=None,
                   help="the column that holds the time, in s or ms (default: time, t, "
                        "Time (s), ...); none: ignore any time column and take the clock "
                        "from --rate")
    g.add_argument("--units", choices=("mm", "cm", "m"), default=None,
                   help="the file's length unit, if it does not say (default: inferred)")
    g.add_argument("--trial-column", metavar="NAME", default=None,
                   help="the column that numbers a long table's trials (default: trial, "
                        "trialN, ...)")
    g.add_argument("--object-size", type=float, default=None, metavar="M",
                   help="the object's size across the grip, m (default: the grip's opening "
                        "at the reach's end)")
    f = p.add_argument_group("factors (the design's participant, condition, ...; "
                             "docs/mocap.md)")
    f.add_argument("--factors", type=_names, default=None, metavar="COL[,COL...]",
                   help="columns of a long table that are the design's factors, text or "
                        "numbers, one value per trial, carried into every output row "
                        f"(default: any column called {', '.join(DEFAULT_FACTORS)}, any case, "
                        "that holds one value per trial)")
    f.add_argument("--factors-from-name", metavar="REGEX", default=None,
                   help="a regular expression whose named groups, searched in each input's "
                        "file name, are factors of its every row: e.g. "
                        "'(?P<participant>P\\d+)_(?P<condition>[a-z]+)'")


def mocap_import(args: argparse.Namespace):
    """The :class:`~perception.recordings.MocapImport` the motion-capture options ask for.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_mocap_options`.
    """
    from perception.reaches import MarkerMap, ReachParams
    from perception.recordings import MocapImport

    markers = None
    if getattr(args, "markers", None):
        roles = {}
        for pair in args.markers:
            role, sep, name = pair.partition("=")
            if not sep or role not in ("thumb", "finger", "wrist", "object") or not name:
                raise InputError(f"{pair}: expected ROLE=NAME with ROLE thumb, finger, wrist "
                                 "or object", field="--markers")
            roles[role] = name
        if "thumb" not in roles or "finger" not in roles:
            raise InputError("give both thumb=NAME and finger=NAME", field="--markers")
        markers = MarkerMap(roles["thumb"], roles["finger"],
                            tuple(roles.get("wrist", "").split("+")) if "wrist" in roles else (),
                            tuple(roles.get("object", "").split("+")) if "object" in roles
                            else ())
    size = getattr(args, "object_size", None)  # ReachParams declares its range
    with options(MOCAP_FIELDS):
        return MocapImport(markers=markers, rate=getattr(args, "rate", None),
                           units=getattr(args, "units", None),
                           trial_column=getattr(args, "trial_column", None),
                           time_column=getattr(args, "time_column", None),
                           columns=getattr(args, "columns", None),
                           reaches=ReachParams(object_size=size),
                           factors=getattr(args, "factors", None),
                           factors_from_name=getattr(args, "factors_from_name", None))


def _names(text: str) -> tuple[str, ...]:
    """``--columns``' comma-separated names (each checked by MocapImport)."""
    return tuple(name.strip() for name in text.split(","))


def _mapping(pairs: list[str]) -> dict[str, str]:
    out = {}
    for pair in pairs:
        marker, sep, name = pair.partition("=")
        if not sep or not marker or not name:
            raise InputError(f"{pair}: expected MARKER=NAME, e.g. thumb=Thumb_tip",
                             field="--keypoints")
        out[marker] = name
    return out


def pose_import(args: argparse.Namespace):
    """The :class:`~perception.io.pose.PoseImport` the pose options ask for, or None if none.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_pose_options`.
    """
    given = {k: getattr(args, k, None) for k in ("pcutoff", "individual", "fps",
                                                 "object_diameter_px")}
    given = {k: v for k, v in given.items() if v is not None}
    if getattr(args, "keypoints", None):
        given["keypoints"] = _mapping(args.keypoints)
    # the cleaning's distances are metres: it reads pixels at the scale the user gave
    scale = {"px_per_m": getattr(args, "px_per_m", None),
             "object_diameter": getattr(args, "object_diameter", None)}
    # (the default object, the cleaning's own default: no settings to record)
    scale = {k: v for k, v in scale.items()
             if v is not None and not (k == "object_diameter" and v == DEFAULT_OBJECT_DIAMETER)}
    config = getattr(args, "pose_config", None)
    if config is None and not given and not scale:
        return None
    from perception.io.pose import PoseImport, load_pose_config

    base = load_pose_config(config) if config is not None else PoseImport()
    if "keypoints" in given:
        given["keypoints"] = {**base.keypoints, **given["keypoints"]}
    with options({**POSE_FIELDS, "px_per_m": "--px-per-m",
                  "object_diameter": "--object-diameter"}):
        if scale and base.cleaning is not None:
            given["cleaning"] = dataclasses.replace(base.cleaning, **scale)
        return dataclasses.replace(base, **given)


def recognition_settings(args: argparse.Namespace) -> RecognitionSettings:
    """:class:`~perception.pipeline.RecognitionSettings` from parsed ``args``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_recognition_options`.
    """
    with options({"object_diameter": "--object-diameter", "px_per_m": "--px-per-m"}):
        observe = ObserveParams(object_diameter=args.object_diameter, px_per_m=args.px_per_m,
                                mirror=args.mirror)
    with options({"rule": "--rule", "filter_gain": "--filter-gain", "w_r": "--w-r",
                  "w_g": "--w-g"}):
        hammer = HammerParams(rule=args.rule, w_r=args.w_r, w_g=args.w_g,
                              filter_gain=args.filter_gain, thesis_sign=args.thesis_sign)
    tracking = None
    if getattr(args, "setup", None) is not None:
        from perception.tracking.setup import load_setup

        tracking = load_setup(args.setup)
    mocap = None
    if any(getattr(args, k, None) is not None for k in MOCAP_FLAGS):
        mocap = mocap_import(args)
    rules = VerdictRules()
    if getattr(args, "verdict_rules", None) is not None:
        data = read_toml(args.verdict_rules, "verdict rules")
        check_keys(data, ["verdict"], "the top level", args.verdict_rules)
        rules = VerdictRules.from_dict(sub_table(data, "verdict", "[verdict]", args.verdict_rules),
                                       args.verdict_rules)
    if rules.landmarks != LandmarkParams():  # the user's definitions bound reaches too
        mocap = (mocap or mocap_import(args)).with_landmarks(rules.landmarks)
    return RecognitionSettings(observe=observe, hammer=hammer, rules=rules, tracking=tracking,
                               pose=pose_import(args), keep_truncated=args.keep_truncated,
                               fps=args.fps, mocap=mocap)


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

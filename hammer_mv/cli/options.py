"""Options shared by the recognition commands (``recognize``, ``batch``, ``watch``,
``landmarks``), generated from the declared fields they set.

Each flag that sets a field is a :class:`~hammer_mv.cli.flags.Setting` of the
tables below (:data:`RECOGNITION`, :data:`POSE`, :data:`MOCAP`,
:data:`FACTORS`): its name, type, choices and default come from the field, so
the help text and the library agree by construction, and an error about the
field names the flag (:func:`hammer_mv.cli.flags.as_flags`).
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
from pathlib import Path

from hammer_mv.cli.flags import FPS_HELP, Setting, add_settings, add_video_options
from perception.errors import InputError
from perception.factors import DEFAULT_FACTORS
from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.io.config import check_keys, read_toml, sub_table
from perception.io.pose import PoseImport
from perception.landmarks import LandmarkParams
from perception.observation import ObserveParams
from perception.pipeline import RecognitionSettings
from perception.reach_data import MarkerMap, ReachParams
from perception.recognition.engine import HammerParams
from perception.recognition.repertoire import Repertoire
from perception.recognition.rules import VerdictRules
from perception.recordings import MocapImport

#: The recognition flags of recognize, batch and watch, each a declared field.
RECOGNITION = (
    Setting(HammerParams, "rule", "rule that picks the winner (default: {default}); the "
            "thesis rule's confidence is reported either way"),
    Setting(HammerParams, "w_r", "transport weight of the thesis rule (default: {default})"),
    Setting(HammerParams, "w_g", "grip weight of the thesis rule (default: {default})"),
    Setting(HammerParams, "thesis_sign", "reading of the sign in the thesis rule, eqs. "
            "5.1/5.7/5.8 (default: {default}: +1 when observed and predicted changes agree; "
            "printed: the equations as printed, the observed change's sign alone); see "
            "docs/recognition.md"),
    Setting(HammerParams, "filter_gain", "how strongly observed positions correct each "
            "model's estimate of velocity and force (0: the plan alone; 1: the plan's Kalman "
            "gains; default {default})", metavar="G"),
    Setting(ObserveParams, "object_diameter", "real diameter of the object, m (default: "
            "{default}, the thesis's ball)", metavar="M"),
    Setting(ObserveParams, "px_per_m", "image scale (default: from the object's apparent "
            "size)", metavar="X"),
    Setting(ObserveParams, "mirror", "mirror the image so the finger lies on the model's +x "
            "side"),
)


#: The pose options; ``--pose-config`` (a file, no field) goes between the first two.
#: ``--keypoints`` and ``--pcutoff`` default to None, "not given", so that a
#: ``--pose-config``'s value applies.
POSE = (
    Setting(PoseImport, "keypoints", "which keypoint is which marker: thumb=NAME finger=NAME "
            "wrist=NAME object=NAME (markers left out take the keypoint of their own name)",
            default=None, nargs="+", metavar="MARKER=NAME"),
    Setting(PoseImport, "pcutoff", "points below this likelihood count as lost (default: "
            "{default}, DeepLabCut's)", default=None, metavar="P"),
    Setting(PoseImport, "individual", "the individual to score in a multi-individual file",
            metavar="NAME"),
    Setting(PoseImport, "fps", FPS_HELP + "; a pose file that carries none (DeepLabCut, SLEAP "
            "analysis, Lightning Pose) takes the rate of the video of its name beside it, else "
            "needs this", metavar="F"),
    Setting(PoseImport, "object_diameter_px", "the object's apparent diameter in pixels: sets "
            "the metric scale of a pose file (or give --px-per-m)", metavar="D"),
)


def _names(text: str) -> tuple[str, ...]:
    """``--columns``' comma-separated names (each checked by MocapImport)."""
    return tuple(name.strip() for name in text.split(","))


#: The motion-capture options, each a field of MocapImport (or of its ReachParams).
MOCAP = (
    Setting(MocapImport, "markers", "which markers are which: thumb=NAME finger=NAME, and "
            "optionally wrist=NAME[+NAME...] object=NAME[+NAME...] (default: guessed from the "
            "names: thumb*, index*, hand*/wrist*, object/pillow/target*)", nargs="+",
            metavar="ROLE=NAME"),
    Setting(MocapImport, "rate", "samples per second of a table without a time column (or "
            "with --time-column none)", metavar="HZ"),
    Setting(MocapImport, "columns", "the markers' names in column order, for a table without "
            "a header (X, Y and Z of each, as RTMocap writes them): e.g. "
            "object,thumb,index,hand,wrist1,wrist2", type=_names, metavar="NAME,NAME,..."),
    Setting(MocapImport, "time_column", "the column that holds the time, in s or ms "
            "(default: time, t, Time (s), ...); none: ignore any time column and take the "
            "clock from --rate", metavar="NAME|none"),
    Setting(MocapImport, "units", "the file's length unit, if it does not say (default: "
            "inferred)"),
    Setting(MocapImport, "trial_column", "the column that numbers a long table's trials "
            "(default: trial, trialN, ...)", metavar="NAME"),
    Setting(ReachParams, "object_size", "the object's size across the grip, m (default: the "
            "grip's opening at the reach's end)", metavar="M"),
)
#: The design's factors, fields of MocapImport.
FACTORS = (
    Setting(MocapImport, "factors", "columns of a long table that are the design's factors, "
            "text or numbers, one value per trial, carried into every output row (default: "
            f"any column called {', '.join(DEFAULT_FACTORS)}, any case, that holds one value "
            "per trial)", type=_names, metavar="COL[,COL...]"),
    Setting(MocapImport, "factors_from_name", "a regular expression whose named groups, "
            "searched in each input's file name, are factors of its every row: e.g. "
            "'(?P<participant>P\\d+)_(?P<condition>[a-z]+)'", metavar="REGEX"),
)


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
    add_settings(g, RECOGNITION)
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
    add_settings(g, POSE[:1])
    g.add_argument("--pose-config", type=Path, metavar="FILE",
                   help="TOML with a [keypoints] table and any of pcutoff, fps, "
                        "object_diameter_px, individual (for a batch)")
    add_settings(g, POSE[1:])


def add_mocap_options(p: argparse.ArgumentParser) -> None:
    """Add the options that turn motion-capture files (C3D, Qualisys TSV, tables) into reaches.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    add_settings(p.add_argument_group("motion capture (C3D, OpenSim TRC, Qualisys TSV, X/Y/Z "
                                      "tables; docs/mocap.md)"), MOCAP)
    add_settings(p.add_argument_group("factors (the design's participant, condition, ...; "
                                      "docs/mocap.md)"), FACTORS)


#: The flags that only one kind of input reads, by kind (:func:`flags_not_read`).
_ONLY = {"mocap": ("a motion-capture recording", (*MOCAP, *FACTORS)),
         "pose": ("a pose file", tuple(s for s in POSE if s.field in ("keypoints", "pcutoff",
                                                                       "individual")))}


def flags_not_read(args: argparse.Namespace, kind: str) -> str | None:
    """A warning naming the flags given that an input of ``kind`` does not read (another
    kind's: ``--rate`` for a video), or None.

    Parameters
    ----------
    args : argparse.Namespace
        The command's.
    kind : str
        The input's kind (:func:`perception.pipeline.clip_name`'s: ``video``,
        ``tracks``, ``pose``, ``mocap``).
    """
    from perception.sources import KINDS

    said = []
    for owner, (what, settings) in _ONLY.items():
        if owner == kind:
            continue
        given = [s.name for s in settings if getattr(args, s.field, s.value()) != s.value()]
        if given:
            said.append(f"{', '.join(given)} (options of {what})")
    names = {k.name: k.what for k in KINDS}
    return (f"{'; '.join(said)} not read: the input is {names.get(kind, kind)}" if said
            else None)


def mocap_import(args: argparse.Namespace) -> MocapImport:
    """The :class:`~perception.recordings.MocapImport` the motion-capture options ask for.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_mocap_options`.

    Raises
    ------
    InputError
        A bad value, naming its field (the command line names its flag).
    """
    markers = None
    if getattr(args, "markers", None):
        roles = {}
        for pair in args.markers:
            role, sep, name = pair.partition("=")
            if not sep or role not in ("thumb", "finger", "wrist", "object") or not name:
                raise InputError(f"{pair}: expected ROLE=NAME with ROLE thumb, finger, wrist "
                                 "or object", field="markers")
            roles[role] = name
        if "thumb" not in roles or "finger" not in roles:
            raise InputError("give both thumb=NAME and finger=NAME", field="markers")
        try:
            markers = MarkerMap(roles["thumb"], roles["finger"],
                                tuple(roles["wrist"].split("+")) if "wrist" in roles else (),
                                tuple(roles["object"].split("+")) if "object" in roles else ())
        except InputError as exc:  # the role it is about, after the flag that gave it
            raise InputError(f"{exc.field}: {exc.problem}" if exc.field else exc.problem,
                             field="markers") from None
    given = {s.field: getattr(args, s.field, None) for s in (*MOCAP, *FACTORS)
             if s.owner is MocapImport and s.field != "markers"}
    return MocapImport(markers=markers, reaches=ReachParams(
        object_size=getattr(args, "object_size", None)), **given)


def mocap_asked(args: argparse.Namespace) -> bool:
    """Whether any motion-capture flag was given (none: the defaults, no settings recorded)."""
    return any(getattr(args, s.field, None) is not None for s in (*MOCAP, *FACTORS))


def _mapping(pairs: list[str]) -> dict[str, str]:
    out = {}
    for pair in pairs:
        marker, sep, name = pair.partition("=")
        if not sep or not marker or not name:
            raise InputError(f"{pair}: expected MARKER=NAME, e.g. thumb=Thumb_tip",
                             field="keypoints")
        out[marker] = name
    return out


def pose_import(args: argparse.Namespace) -> PoseImport | None:
    """The :class:`~perception.io.pose.PoseImport` the pose options ask for, or None if none.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_pose_options`.
    """
    given = {s.field: getattr(args, s.field, None) for s in POSE if s.field != "keypoints"}
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
    from perception.io.pose import load_pose_config

    base = load_pose_config(config) if config is not None else PoseImport()
    if "keypoints" in given:
        given["keypoints"] = {**base.keypoints, **given["keypoints"]}
    if scale and base.cleaning is not None:
        given["cleaning"] = dataclasses.replace(base.cleaning, **scale)
    return dataclasses.replace(base, **given)


def recognition_settings(args: argparse.Namespace) -> RecognitionSettings:
    """:class:`~perception.pipeline.RecognitionSettings` from parsed ``args``.

    A bad value raises its class's error, which names the field
    (``ObserveParams.px_per_m``); the command line names its flag.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_recognition_options`.
    """
    observe = ObserveParams(object_diameter=args.object_diameter, px_per_m=args.px_per_m,
                            mirror=args.mirror)
    hammer = HammerParams(rule=args.rule, w_r=args.w_r, w_g=args.w_g,
                          filter_gain=args.filter_gain, thesis_sign=args.thesis_sign)
    tracking = None
    if getattr(args, "setup", None) is not None:
        from perception.tracking.setup import load_setup

        tracking = load_setup(args.setup)
    mocap = mocap_import(args) if mocap_asked(args) else None
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

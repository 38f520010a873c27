"""The kinds of input, in one place: how each is recognised, what configures it, who takes it.

Every command and the Python API ask :func:`input_kind` what an input is,
and :func:`check_command` refuses, in one line and before anything is read,
a kind the command cannot take ("0: a camera: recognize takes a video, a
tracks file, a pose file or a motion-capture recording; watch it with
hammer-mv watch"). A new format belongs here: its test, its clip name, the
settings that configure it (a :class:`~perception.pipeline.RecognitionSettings`
field) and the commands that take it.

The order of :data:`KINDS` is the order of the tests: a live source by its
name alone, then a tracks file (``.tracks.h5``, before the pose files'
``.h5``), a video by its ending, a motion-capture recording (a ``.c3d`` or
an OpenSim ``.trc`` by its ending, a table by its first lines: a ``.csv``
may be either; :data:`perception.io.mocap.MOCAP_SUFFIXES`), then a pose file.

Each kind also registers its loader (:attr:`Kind.load`), which brings a file to one
:class:`~perception.movement_record.MovementRecord` per movement in metres, as
recognition observes it (:func:`load_movements`).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

from perception.errors import InputError
from perception.io.names import POSE_SUFFIXES, TRACKS_SUFFIX, VIDEO_SUFFIXES, live_kind

__all__ = ["KINDS", "POSE_SUFFIXES", "TRACKS_SUFFIX", "VIDEO_SUFFIXES", "Kind", "Movements",
           "check_command", "clip_name", "input_kind", "load_movements"]



@dataclass(frozen=True)
class Kind:
    """One kind of input.

    Attributes
    ----------
    name : str
        ``camera``, ``stream``, ``tracks``, ``video``, ``mocap`` or ``pose``.
    what : str
        The kind in words, with its article ("a pose file").
    options : str or None
        The :class:`~perception.pipeline.RecognitionSettings` field that says
        how it is read (``tracking``, ``pose``, ``mocap``; None: nothing to set).
    commands : frozenset of str
        The commands that take it.
    recognises : callable
        Whether an input (as the user wrote it) is of this kind.
    load : callable or None
        ``load(source, settings, tracks_out)``: its movements in metres, a
        :class:`Movements` (None: a live source, read while it is filmed).
    """

    name: str
    what: str
    options: str | None
    commands: frozenset[str]
    recognises: Callable[[str], bool]
    load: Callable[..., Movements] | None = None

    def takes(self, command: str) -> bool:
        """Whether ``command`` takes this kind of input."""
        return command in self.commands


def _suffix(spec: str) -> str:
    return Path(spec).suffix.lower()


def _is_mocap(spec: str) -> bool:
    # every layout perception.io.mocap reads (C3D, TRC, the vendors' and labs' tables);
    # a table's first lines only are read
    from perception.io.mocap import is_mocap_file

    return Path(spec).is_file() and is_mocap_file(spec)


class Movements(NamedTuple):
    """What :func:`load_movements` read: the movements, and what gave none, and why.

    Attributes
    ----------
    records : list of MovementRecord
        One per clip, or per reach of a motion-capture recording.
    not_read : list of (str, str)
        ``(name, why)`` of each trial or movement of a recording that gives no
        reach (:attr:`perception.recordings.Recording.unscored`).
    """

    records: list
    not_read: list


def _record(tracks, observe, clip: str, **also):
    """The record recognition observes: from the first rows at rest, as it settles them."""
    from perception.movement_record import movement_record
    from perception.settling import settle_start

    tracks, settled = settle_start(tracks, observe, clip=clip)
    rec = movement_record(tracks, observe, clip=clip)
    notes = (*also.pop("notes", ()), *rec.notes, *((settled,) if settled else ()))
    return dataclasses.replace(rec, notes=notes, **also)


def _load_clip(source, settings, tracks_out) -> Movements:
    """A video (tracked, or its current tracks read), a tracks file or a pose file."""
    from perception.pipeline import load_clip

    tracks = load_clip(source, tracks_out=tracks_out, setup=settings.tracking,
                       pose=settings.pose, **settings.video_options())
    return Movements([_record(tracks, settings.observe, clip_name(source)[0])], [])


def _load_recording(source, settings, tracks_out) -> Movements:
    """A motion-capture recording: each reach in its plane, and the trials that give none."""
    from perception.recordings import MocapImport, prepare_reach, read_recording

    options = settings.mocap or MocapImport()
    recording = read_recording(source, options)
    wrist = (f"wrist: the models' own, {options.reaches.wrist_behind * 100:g} cm behind the "
             "grip (no marker's)")
    records = []
    for reach in recording.reaches:
        p = prepare_reach(reach, settings, options)
        records.append(_record(p.tracks, p.settings.observe, reach.name, source=reach.source,
                               clock_offset=p.paths.clock_offset,
                               notes=(*p.info["notes"], wrist)))
    return Movements(records, [(u.name, u.reason) for u in recording.unscored])


#: The commands that take a file of a kind (batch: in the folder or manifest it reads).
_FILES = frozenset({"recognize", "landmarks", "watch", "batch"})
#: Every kind, in the order they are tested (the module docstring).
KINDS: tuple[Kind, ...] = (
    Kind("camera", "a camera", None, frozenset({"watch"}), lambda s: live_kind(s) == "camera"),
    Kind("stream", "a stream URL", None, frozenset({"watch"}), lambda s: live_kind(s) == "stream"),
    Kind("tracks", "a tracks file", None, frozenset({"recognize", "landmarks", "batch"}),
         lambda s: s.endswith(TRACKS_SUFFIX), _load_clip),
    Kind("video", "a video", "tracking", _FILES, lambda s: _suffix(s) in VIDEO_SUFFIXES,
         _load_clip),
    Kind("mocap", "a motion-capture recording", "mocap", _FILES, _is_mocap, _load_recording),
    Kind("pose", "a pose file", "pose", _FILES, lambda s: _suffix(s) in POSE_SUFFIXES,
         _load_clip),
)


def input_kind(spec: str | os.PathLike) -> Kind | None:
    """The kind of an input (a file, a camera index, a URL); None for none of them.

    Parameters
    ----------
    spec : str or os.PathLike
        The input as the user gave it.
    """
    spec = os.fspath(spec)
    return next((k for k in KINDS if k.recognises(spec)), None)


def clip_name(path: str | os.PathLike) -> tuple[str, str]:
    """Clip name and input kind (``video``, ``tracks``, ``pose``, ``mocap``, ``camera``,
    ``stream`` or ``unknown``) of an input (a DeepLabCut or SLEAP output is named after
    its video: ``trial01DLC_….h5``, ``trial01``).

    Parameters
    ----------
    path : str or os.PathLike
        The input.
    """
    from perception.io.pose import pose_output

    kind = input_kind(path)
    name = Path(path).name
    if kind is None:
        return Path(path).stem, "unknown"
    if kind.name == "tracks":
        return name[: -len(TRACKS_SUFFIX)], "tracks"
    if kind.name == "pose":
        output = pose_output(name)  # DeepLabCut's and SLEAP's: the clip is their video's
        return (output[0] if output else Path(path).stem), "pose"
    if kind.name in ("camera", "stream"):
        return {"camera": f"camera{path}", "stream": "stream"}[kind.name], kind.name
    return Path(path).stem, kind.name


#: What a command takes, where it is not its files' kinds: batch reads a folder of them.
_TAKES = {"batch": "a folder of clips or a manifest.csv"}
#: What to do instead, by the kind a command refused.
_INSTEAD = {"camera": "watch it with hammer-mv watch",
            "stream": "watch it with hammer-mv watch",
            "tracks": "recognize it with hammer-mv recognize"}


def check_command(spec: str | os.PathLike, command: str) -> Kind | None:
    """The kind of ``spec``, refused in one line if ``command`` does not take it.

    An input of no kind is left to the command (a folder, a manifest, a file
    not found: each command says what it is).

    Parameters
    ----------
    spec : str or os.PathLike
        The input as the user gave it.
    command : str
        ``recognize``, ``landmarks``, ``batch`` or ``watch``.

    Raises
    ------
    InputError
        ``spec``'s kind is not one ``command`` takes, naming what it takes.
    """
    kind = input_kind(spec)
    if kind is None or kind.takes(command):
        return kind
    takes = [k.what for k in KINDS if k.takes(command)]
    listed = _TAKES.get(command) or (", ".join(takes[:-1]) + f" or {takes[-1]}")
    instead = _INSTEAD.get(kind.name)
    raise InputError(f"{kind.what}: {command} takes {listed}"
                     + (f"; {instead}" if instead else ""), os.fspath(spec))


def load_movements(source: str | os.PathLike, settings=None, *,
                   tracks_out: str | os.PathLike | None = None) -> Movements:
    """The movements of an input in metres (:class:`~perception.movement_record.
    MovementRecord`), as recognition sees them.

    A video is tracked (its tracks file written as ``recognize`` writes it, or a current
    one read), a tracks or pose file read, a motion-capture recording's reaches found and
    each brought into its movement's plane; a start that is not yet at rest is left out
    as recognition leaves it out (:func:`~perception.settling.settle_start`, its note among
    the record's).

    Parameters
    ----------
    source : str or os.PathLike
        A video, tracks file, pose file or motion-capture recording.
    settings : RecognitionSettings, optional
        How each kind is read (``tracking``, ``pose``, ``mocap``) and the scale and rest
        rules (``observe``).
    tracks_out : str or os.PathLike, optional
        Where a video's tracks are written (default: beside the video).

    Raises
    ------
    InputError
        An input of no kind, a camera or a stream (``hammer-mv watch`` reads those), or
        one that cannot be read, naming the file and the field.
    """
    from perception.pipeline import RecognitionSettings

    settings = RecognitionSettings() if settings is None else settings
    kind = input_kind(source)
    if kind is None or kind.load is None:
        what = "not a video, tracks, pose or motion-capture file" if kind is None else (
            f"{kind.what}: a live source gives its movement while it is filmed (hammer-mv watch)")
        raise InputError(what, os.fspath(source))
    return kind.load(source, settings, tracks_out)

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

Each file kind's loader to the movement in metres that recognition observes is
:data:`perception.loading.LOADERS`' (above the pipeline it calls).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from perception.errors import InputError
from perception.io.names import POSE_SUFFIXES, TRACKS_SUFFIX, VIDEO_SUFFIXES, live_kind

__all__ = ["KINDS", "POSE_SUFFIXES", "TRACKS_SUFFIX", "VIDEO_SUFFIXES", "Kind", "check_command",
           "clip_name", "files_taken", "input_kind"]



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
    """

    name: str
    what: str
    options: str | None
    commands: frozenset[str]
    recognises: Callable[[str], bool]

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


#: The commands that take a file of a kind (batch: in the folder or manifest it reads).
_FILES = frozenset({"recognize", "landmarks", "watch", "batch"})
#: Every kind, in the order they are tested (the module docstring).
KINDS: tuple[Kind, ...] = (
    Kind("camera", "a camera", None, frozenset({"watch"}), lambda s: live_kind(s) == "camera"),
    Kind("stream", "a stream URL", None, frozenset({"watch"}), lambda s: live_kind(s) == "stream"),
    Kind("tracks", "a tracks file", None, frozenset({"recognize", "landmarks", "batch"}),
         lambda s: s.endswith(TRACKS_SUFFIX)),
    Kind("video", "a video", "tracking", _FILES, lambda s: _suffix(s) in VIDEO_SUFFIXES),
    Kind("mocap", "a motion-capture recording", "mocap", _FILES, _is_mocap),
    Kind("pose", "a pose file", "pose", _FILES, lambda s: _suffix(s) in POSE_SUFFIXES),
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


#: The file kinds in the order their names are said (:func:`files_taken`).
_SAID = ("video", "tracks", "pose", "mocap")


def files_taken(command: str) -> str:
    """The kinds of file ``command`` reads, in words: ``"video, tracks file, pose file or
    motion-capture recording"`` (what its refusal of a file of no kind says).

    Parameters
    ----------
    command : str
        ``recognize``, ``landmarks``, ``batch`` or ``watch``.
    """
    kinds = {k.name: k for k in KINDS}
    # without the article: "video, tracks file, ..." reads as one list after "a"
    takes = [kinds[n].what.split(" ", 1)[1] for n in _SAID if kinds[n].takes(command)]
    return ", ".join(takes[:-1]) + f" or {takes[-1]}" if len(takes) > 1 else takes[0]


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


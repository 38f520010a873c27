"""Any input file to the movements recognition observes, in metres (the Python API's
:func:`load_movements`).

Each file kind of the registry (:mod:`perception.sources`) has its loader here
(:data:`LOADERS`): a video, tracks file or pose file gives one
:class:`~perception.records.MovementRecord`, a motion-capture recording one
per reach, with the trials that give none and why. The module sits above the
pipeline whose readers it calls, so the registry below it stays free of them.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from typing import NamedTuple

from perception.errors import InputError
from perception.sources import clip_name, input_kind

__all__ = ["LOADERS", "Movements", "load_movements"]


class Movements(NamedTuple):
    """What :func:`load_movements` read: the movements, and what gave none, and why.

    Attributes
    ----------
    records : list of MovementRecord
        One per clip, or per reach of a motion-capture recording.
    no_reach : list of (str, str)
        ``(name, why)`` of each trial or movement of a recording that gives no
        reach (:attr:`perception.recordings.Recording.unscored`), or whose reach
        could not be observed.
    """

    records: list
    no_reach: list


def _record(tracks, observe, clip: str, source: str, **also):
    """The record recognition observes: from the first rows at rest, as it settles them;
    a refusal names ``source``, the file the user gave, as ``recognize``'s does."""
    from perception.observation import movement_record
    from perception.settling import settle_start

    try:
        tracks, settled = settle_start(tracks, observe, clip=clip)
        rec = movement_record(tracks, observe, clip=clip)
    except InputError as exc:
        raise exc.at(source) from None
    notes = (*also.pop("notes", ()), *rec.notes, *((settled,) if settled else ()))
    return dataclasses.replace(rec, source=source, notes=notes, **also)


def _load_clip(source, settings, tracks_out) -> Movements:
    """A video (tracked, or its current tracks read), a tracks file or a pose file."""
    from perception.pipeline import load_clip

    tracks = load_clip(source, tracks_out=tracks_out, setup=settings.tracking,
                       pose=settings.pose, **settings.video_options())
    return Movements([_record(tracks, settings.observe, clip_name(source)[0],
                              os.fspath(source))], [])


def _load_recording(source, settings, tracks_out) -> Movements:
    """A motion-capture recording: each reach in its plane, and the trials that give none."""
    from perception.recordings import MocapImport, prepare_reach, read_recording

    options = settings.mocap or MocapImport()
    recording = read_recording(source, options)
    wrist = (f"wrist: the models' own, {options.reaches.wrist_behind * 100:g} cm behind the "
             "grip (no marker's)")
    records, none = [], [(u.name, u.reason) for u in recording.unscored]
    for reach in recording.reaches:
        try:  # one reach that cannot be observed costs that reach, not the recording
            p = prepare_reach(reach, settings, options)
            records.append(_record(p.tracks, p.settings.observe, reach.name, reach.source,
                                   clock_offset=p.paths.clock_offset,
                                   notes=(*p.info["notes"], wrist)))
        except InputError as exc:
            none.append((reach.name, exc.problem))
    return Movements(records, none)


#: Each file kind's loader: ``load(source, settings, tracks_out) -> Movements`` (a live
#: source, a camera or a stream, has none: ``hammer-mv watch`` reads it as it is filmed).
LOADERS: dict[str, Callable[..., Movements]] = {
    "tracks": _load_clip, "video": _load_clip, "pose": _load_clip, "mocap": _load_recording}


def load_movements(source: str | os.PathLike, settings=None, *,
                   tracks_out: str | os.PathLike | None = None) -> Movements:
    """The movements of an input in metres (:class:`~perception.records.
    MovementRecord`), as recognition sees them.

    A video is tracked (its tracks file written as ``recognize`` writes it, or a current
    one read), a tracks or pose file read, a motion-capture recording's reaches found and
    each brought into its movement's plane. A start that is not yet at rest is settled as
    recognition settles it (:func:`~perception.settling.settle_start`): its first frames
    left out, or, where the hand moves from the first frame, that frame held still before
    it; its note is among the record's.

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
    from perception.boundary import expect
    from perception.pipeline import RecognitionSettings

    expect(settings, RecognitionSettings, "load_movements(settings=)", optional=True)
    settings = RecognitionSettings() if settings is None else settings
    kind = input_kind(source)
    load = LOADERS.get(kind.name) if kind is not None else None
    if load is None:
        what = "not a video, tracks, pose or motion-capture file" if kind is None else (
            f"{kind.what}: a live source gives its movement while it is filmed (hammer-mv watch)")
        raise InputError(what, os.fspath(source))
    return load(source, settings, tracks_out)

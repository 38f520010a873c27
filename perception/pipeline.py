"""The recognition pipeline of one clip: video -> tracks -> observation -> models -> recognition.

:func:`recognize_clip` is the one place the chain is assembled; the
``recognize`` and ``batch`` commands and :func:`perception.batch.run_batch`
all go through it:

1. **tracks** — a video is tracked (:func:`perception.tracking.track_video`)
   into a tracks file; a tracks file is loaded; a :class:`Tracks` object is
   used as it is;
2. **observation** — :func:`perception.observation.observe` maps the tracks to
   the model frame and finds the movement;
3. **planning** — the repertoire's models are taken, or re-planned, for the
   scene of the clip's first frames (:meth:`Repertoire.for_scene`);
4. **recognition** — :func:`perception.recognition.engine.recognize` scores
   every model's one-step predictions.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from perception import __version__
from perception.errors import InputError
from perception.io.tracks import Tracks, tracks_path_for
from perception.observation import ObserveParams, observe
from perception.recognition.engine import HammerParams, recognize
from perception.recognition.models import SceneSpec
from perception.recognition.repertoire import Repertoire
from perception.recognition.result import Recognition

if TYPE_CHECKING:  # the tracker (OpenCV) is imported only when there is video
    from perception.tracking.setup import TrackingSetup

__all__ = [
    "RecognitionSettings",
    "TRACKS_SUFFIX",
    "VIDEO_SUFFIXES",
    "clip_fingerprint",
    "clip_name",
    "load_clip",
    "recognize_clip",
]

#: Video file extensions the pipeline accepts (case-insensitive).
VIDEO_SUFFIXES = (".mp4", ".avi", ".mkv", ".mov", ".m4v")
#: Name ending of a tracks file.
TRACKS_SUFFIX = ".tracks.h5"


@dataclass(frozen=True)
class RecognitionSettings:
    """Everything that decides a clip's recognition besides its input and the repertoire.

    Parameters
    ----------
    observe : ObserveParams
        Tracks -> observation settings.
    hammer : HammerParams
        Rule and weights of the engine.
    tracking : TrackingSetup, optional
        Colour models and marker sizes for tracking videos (``--setup``).
    """

    observe: ObserveParams = field(default_factory=ObserveParams)
    hammer: HammerParams = field(default_factory=HammerParams)
    tracking: TrackingSetup | None = None

    def fingerprint(self) -> dict:
        """JSON-able settings that change results."""
        out = {"observe": dataclasses.asdict(self.observe),
               "hammer": dataclasses.asdict(self.hammer)}
        if self.tracking is not None:
            out["tracking"] = self.tracking.to_dict()
        return out


def clip_name(path: str | os.PathLike) -> tuple[str, str]:
    """Clip name and input kind (``video``, ``tracks`` or ``unknown``) of a file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    """
    path = Path(path)
    name = path.name
    if name.endswith(TRACKS_SUFFIX):
        return name[: -len(TRACKS_SUFFIX)], "tracks"
    if path.suffix.lower() in VIDEO_SUFFIXES:
        return path.stem, "video"
    return path.stem, "unknown"


def clip_fingerprint(path: str | os.PathLike, settings: RecognitionSettings,
                     repertoire_id: str) -> str:
    """A short hash of what decides a clip's recognition report.

    The input file (path, size, modification time), the settings, the
    repertoire's identity and the software version: a report carrying the
    same fingerprint is current and need not be made again.

    Parameters
    ----------
    path : str or os.PathLike
        The clip's input file.
    settings : RecognitionSettings
        Observation and engine settings.
    repertoire_id : str
        Identity of the repertoire (e.g. its file name and content hash).
    """
    path = Path(path)
    st = path.stat()
    source = {"path": str(path.resolve()), "size": st.st_size, "mtime_ns": st.st_mtime_ns}
    payload = json.dumps({"input": source, "settings": settings.fingerprint(),
                          "repertoire": repertoire_id, "software": __version__},
                         sort_keys=True)
    return hashlib.sha256(payload.encode()).hexdigest()[:16]


def load_clip(source: str | os.PathLike | Tracks, *, tracks_out: str | os.PathLike | None = None,
              progress: bool = False, setup: TrackingSetup | None = None) -> Tracks:
    """The tracks of a clip: tracked from a video, loaded from a tracks file, or as given.

    Parameters
    ----------
    source : str, os.PathLike or Tracks
        A video file, a ``.tracks.h5`` file, or tracks in memory.
    tracks_out : str or os.PathLike, optional
        Where a video's tracks are written (default: ``<stem>.tracks.h5``
        beside the video).
    progress : bool
        Show a progress bar while tracking.
    setup : TrackingSetup, optional
        Colour models and marker sizes for tracking a video.

    Raises
    ------
    InputError
        A file that is neither a video nor a tracks file, or that cannot be
        read, tracked or loaded.
    """
    if isinstance(source, Tracks):
        return source
    path = Path(source)
    kind = clip_name(path)[1]
    if kind == "unknown":
        raise InputError("not a video or tracks file", path)
    if kind == "tracks":
        return Tracks.load(path)
    from perception.tracking.tracker import track_video  # OpenCV only when there is video

    out = tracks_path_for(path) if tracks_out is None else Path(tracks_out)
    kw = {} if setup is None else {"markers": setup.markers, "params": setup.params}
    return Tracks.load(track_video(path, out, progress=progress, **kw))


def recognize_clip(source: str | os.PathLike | Tracks, repertoire: Repertoire,
                   settings: RecognitionSettings | None = None, *, clip: str | None = None,
                   tracks_out: str | os.PathLike | None = None,
                   progress: bool = False) -> Recognition:
    """Track (if a video), observe, plan for the clip's scene and recognise one clip.

    Parameters
    ----------
    source : str, os.PathLike or Tracks
        A video, a tracks file or tracks in memory (see :func:`load_clip`).
    repertoire : Repertoire
        The models to score against.
    settings : RecognitionSettings, optional
        Observation and engine settings.
    clip : str, optional
        Clip name (default: from the file name).
    tracks_out : str or os.PathLike, optional
        Where a video's tracks are written (see :func:`load_clip`).
    progress : bool
        Show a progress bar while tracking.

    Returns
    -------
    Recognition

    Raises
    ------
    InputError
        Bad input at any stage, in one message naming the input file.
    """
    settings = RecognitionSettings() if settings is None else settings
    is_file = not isinstance(source, Tracks)
    name = clip or (clip_name(source)[0] if is_file else None)
    tracks = load_clip(source, tracks_out=tracks_out, progress=progress,
                       setup=settings.tracking)
    try:
        obs = observe(tracks, settings.observe, clip=name)
    except InputError as exc:
        if not is_file:
            raise
        raise InputError(exc.problem, source) from None  # name the file the user gave
    try:
        models = repertoire.for_scene(SceneSpec.of(obs))
    except ValueError as exc:
        raise InputError(f"cannot plan the models for this clip's scene (distance "
                         f"{obs.start_distance:.3f} m; check the scale: --px-per-m, "
                         f"--object-diameter): {exc}", source if is_file else name) from None
    return recognize(obs, models, settings.hammer)

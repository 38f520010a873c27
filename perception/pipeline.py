"""The recognition pipeline of one clip: video -> tracks -> observation -> models -> recognition.

:func:`recognize_clip` is the one place the chain is assembled; the
``recognize`` and ``batch`` commands and :func:`perception.batch.run_batch`
all go through it:

1. **tracks** — a video is tracked (:func:`perception.tracking.track_video`)
   into a tracks file, unless a current one is at hand (:func:`current_tracks`);
   a tracks file is loaded; a :class:`Tracks` object is used as it is;
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

from perception import __version__
from perception.errors import InputError
from perception.io.tracks import Tracks, tracks_path_for
from perception.observation import ObserveParams, observe
from perception.recognition.engine import HammerParams, recognize
from perception.recognition.models import SceneSpec
from perception.recognition.repertoire import PlanCache, Repertoire
from perception.recognition.result import Recognition

__all__ = [
    "RecognitionSettings",
    "TRACKS_SUFFIX",
    "VIDEO_SUFFIXES",
    "clip_fingerprint",
    "clip_name",
    "current_tracks",
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
    """

    observe: ObserveParams = field(default_factory=ObserveParams)
    hammer: HammerParams = field(default_factory=HammerParams)

    def fingerprint(self) -> dict:
        """JSON-able settings that change results."""
        return {"observe": dataclasses.asdict(self.observe),
                "hammer": dataclasses.asdict(self.hammer)}


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
              progress: bool = False) -> Tracks:
    """The tracks of a clip: tracked from a video, loaded from a tracks file, or as given.

    Parameters
    ----------
    source : str, os.PathLike or Tracks
        A video file, a ``.tracks.h5`` file, or tracks in memory.
    tracks_out : str or os.PathLike, optional
        Where a video's tracks are written (default: ``<stem>.tracks.h5``
        beside the video). A current tracks file of the video there, or
        beside the video, is loaded instead of tracking again
        (:func:`current_tracks`).
    progress : bool
        Show a progress bar while tracking.

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
    out = tracks_path_for(path) if tracks_out is None else Path(tracks_out)
    current = current_tracks(path, [out, tracks_path_for(path)])
    if current is not None:
        return current
    from perception.tracking.tracker import track_video  # OpenCV only when there is video

    return Tracks.load(track_video(path, out, progress=progress))


#: ``/tracker`` attributes that describe what a tracker learned from the clip
#: (not its settings): they do not decide whether a tracks file is current.
_LEARNED = frozenset({"reference_mass_px", "diameter_px"})


def _plain(value):
    """An attribute value as plain JSON-able data (arrays and numpy scalars unwrapped)."""
    import numpy as np

    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    return value


def _settings(attrs: dict) -> str:
    return json.dumps({k: _plain(v) for k, v in attrs.items() if k not in _LEARNED},
                      sort_keys=True, default=str)


def current_tracks(video: str | os.PathLike, candidates) -> Tracks | None:
    """The first of ``candidates`` that is a current tracks file of ``video``, loaded.

    Current means: written by this software version, of this very video
    (``/video`` attribute ``sha256``: hashing reads the file once, far
    cheaper than decoding and tracking it) and with the default tracker
    settings (colour models, ROIs, criteria and parameters of ``/tracker``;
    ``recognize`` and ``batch`` track with those). Anything else (missing,
    unreadable, stale) is not reused.

    Parameters
    ----------
    video : str or os.PathLike
        The video.
    candidates : iterable of path
        Tracks files to consider, in order of preference.
    """
    import h5py

    from perception.io.video import sha256_file

    digest = None
    for cand in candidates:
        cand = Path(cand)
        if not cand.is_file():
            continue
        try:
            with h5py.File(cand, "r") as fh:
                version = fh.attrs.get("software_version")
            tracks = Tracks.load(cand)
        except (InputError, OSError, ValueError):
            continue
        if _plain(version) != __version__ and version != __version__.encode():
            continue
        digest = digest or sha256_file(video)
        if tracks.video.get("sha256") != digest:
            continue
        if _settings(tracks.tracker) != _settings(_default_tracker_attrs()):
            continue
        return tracks
    return None


def _default_tracker_attrs() -> dict:
    """The ``/tracker`` settings a default tracker writes."""
    from perception.tracking.markers import default_markers
    from perception.tracking.tracker import Tracker

    return Tracker(default_markers()).attrs()


def recognize_clip(source: str | os.PathLike | Tracks, repertoire: Repertoire,
                   settings: RecognitionSettings | None = None, *, clip: str | None = None,
                   tracks_out: str | os.PathLike | None = None,
                   progress: bool = False, plan_cache: PlanCache | None = None) -> Recognition:
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
    plan_cache : PlanCache, optional
        Models re-planned for a scene, shared with other processes.

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
    tracks = load_clip(source, tracks_out=tracks_out, progress=progress)
    try:
        obs = observe(tracks, settings.observe, clip=name)
    except InputError as exc:
        if not is_file:
            raise
        raise InputError(exc.problem, source) from None  # name the file the user gave
    try:
        models = repertoire.for_scene(SceneSpec.of(obs), cache=plan_cache)
    except ValueError as exc:
        raise InputError(f"cannot plan the models for this clip's scene (distance "
                         f"{obs.start_distance:.3f} m; check the scale: --px-per-m, "
                         f"--object-diameter): {exc}", source if is_file else name) from None
    return recognize(obs, models, settings.hammer)

"""The recognition pipeline of one clip: video -> tracks -> observation -> models -> verdict.

:func:`load_clip` (step 1) and :func:`recognize_tracks` (steps 2-5) are the
chain; :func:`recognize_clip` is the two in one call (the Python API's).
The ``recognize`` and ``batch`` commands call the two apart, since they
report the tracking too; a motion-capture reach enters at step 2 through
:func:`perception.recordings.recognize_reach`, and the online recogniser
calls step 2-5 on the rows received so far (docs/architecture.md):

1. **tracks** — a video is tracked (:func:`perception.tracking.track_video`)
   into a tracks file, unless a current one is at hand (:func:`current_tracks`);
   a tracks file is loaded; a :class:`Tracks` object is used as it is;
2. **observation** — :func:`perception.observation.observe` maps the tracks to
   the model frame and finds the movement;
3. **reference scale** — the movement is brought to the repertoire's
   reference scene (:mod:`perception.recognition.shape`), whose models are
   planned once (:meth:`Repertoire.for_scene`);
4. **scoring** — :func:`perception.recognition.engine.score_clip` scores
   every model once, and the transport alone against the reach models;
5. **verdict** — :mod:`perception.recognition.evidence` builds the evidence
   and :func:`perception.recognition.rules.judge` decides, once.

"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import importlib
import json
import numbers
import os
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from perception.errors import InputError, PlanningError
from perception.io.files import input_file
from perception.io.tracks import Tracks, tracks_path_for
from perception.landmarks import MeasuredPaths, movement_landmarks
from perception.observation import ObserveParams, observe
from perception.provenance import code_digest
from perception.recognition.engine import HammerParams, score_clip
from perception.recognition.evidence import (
    clip_landmarks,
    grip_course,
    judged_models,
    movement_evidence,
)
from perception.recognition.models import SceneSpec
from perception.recognition.repertoire import PlanCache, Repertoire
from perception.recognition.result import Recognition
from perception.recognition.rules import VerdictRules, judge
from perception.recognition.verdict import misfit
from perception.sources import TRACKS_SUFFIX, VIDEO_SUFFIXES, clip_name

if TYPE_CHECKING:  # the tracker (OpenCV) and movement are imported only when needed
    from perception.io.frame_sample import FrameSample
    from perception.io.pose import PoseImport
    from perception.recordings import MocapImport
    from perception.tracking.setup import TrackingSetup

__all__ = [
    "RecognitionSettings",
    "TRACKS_SUFFIX",
    "VIDEO_SUFFIXES",
    "clip_fingerprint",
    "clip_name",
    "current_tracks",
    "load_clip",
    "recognize_clip",
    "recognize_tracks",
]

@dataclass(frozen=True)
class RecognitionSettings:
    """Everything that decides a clip's recognition besides its input and the repertoire.

    Parameters
    ----------
    observe : ObserveParams
        Tracks -> observation settings.
    hammer : HammerParams
        Rule and weights of the engine.
    rules : VerdictRules
        Every threshold of the verdict (``--verdict-rules``).
    tracking : TrackingSetup, optional
        Colour models and marker sizes for tracking videos (``--setup``).
    pose : PoseImport, optional
        How pose files become tracks (keypoint mapping, likelihood cutoff,
        frame rate, object size); default: :class:`~perception.io.pose.PoseImport`.
    keep_truncated : bool
        Track the frames a truncated video decodes instead of refusing it
        (``--keep-truncated``).
    fps : float, optional
        The true frame rate of videos whose header is wrong, frames/s (``--fps``).
    mocap : MocapImport, optional
        How motion-capture recordings become reaches (markers, rate, units,
        object size); default: :class:`~perception.recordings.MocapImport`.
    decoder_threads : int
        Threads FFmpeg decodes a video with (0: FFmpeg's choice; a batch's
        worker processes use 1). Changes no result.
    planning_threads : int, optional
        Threads that plan a scene's models (default: the cores this process
        may use, at most 4; a batch's worker processes use 1). Changes no result.
    """

    observe: ObserveParams = field(default_factory=ObserveParams)
    hammer: HammerParams = field(default_factory=HammerParams)
    rules: VerdictRules = field(default_factory=VerdictRules)
    tracking: TrackingSetup | None = None
    pose: PoseImport | None = None
    keep_truncated: bool = False
    fps: float | None = None
    mocap: MocapImport | None = None
    decoder_threads: int = 0
    planning_threads: int | None = None

    def __post_init__(self):
        # each refused here, not as an AttributeError where a clip first reads it
        from perception.boundary import expect

        for name, kind in (("observe", ObserveParams), ("hammer", HammerParams),
                           ("rules", VerdictRules)):
            expect(getattr(self, name), kind, f"RecognitionSettings({name}=)")
        for name, module, kind in (("tracking", "perception.tracking.setup", "TrackingSetup"),
                                   ("pose", "perception.io.pose", "PoseImport"),
                                   ("mocap", "perception.recordings", "MocapImport")):
            if getattr(self, name) is not None:  # imported only where one is given
                expect(getattr(self, name), getattr(importlib.import_module(module), kind),
                       f"RecognitionSettings({name}=)", optional=True)
        if self.fps is not None and not isinstance(self.fps, numbers.Real):
            raise TypeError(f"RecognitionSettings(fps=): expected a number (frames/s) or None, "
                            f"got {type(self.fps).__name__} {self.fps!r}"[:200])

    def video_options(self) -> dict:
        """How to read videos, as keyword arguments of :func:`load_clip`."""
        return {"keep_truncated": self.keep_truncated, "fps": self.fps,
                "decoder_threads": self.decoder_threads}

    def fingerprint(self) -> dict:
        """JSON-able settings that change results."""
        out = {"observe": dataclasses.asdict(self.observe),
               "hammer": dataclasses.asdict(self.hammer), "rules": self.rules.to_dict()}
        # only when set, so that reports made without them stay current
        if self.tracking is not None:
            out["tracking"] = self.tracking.to_dict()
        if self.pose is not None:
            out["pose"] = self.pose.to_dict()
        if self.mocap is not None:
            out["mocap"] = self.mocap.to_dict()
        if self.keep_truncated or self.fps is not None:
            out["video"] = {"keep_truncated": self.keep_truncated, "fps": self.fps}
        return out


def clip_fingerprint(path: str | os.PathLike, settings: RecognitionSettings,
                     repertoire_id: str) -> str:
    """A short hash of what decides a clip's recognition report.

    The input file's content (its SHA-256, not its size and time: a
    different video of the same size is a different clip), the settings,
    the repertoire's identity and the code: a report carrying the same
    fingerprint is current and need not be made again. Settings that only label
    the clip's rows (``mocap.factors_from_name``) are left out. The code is
    :func:`~perception.provenance.code_digest`: any change to
    scoring, tracking, planning or the shipped calibration makes every
    report stale.

    Parameters
    ----------
    path : str or os.PathLike
        The clip's input file.
    settings : RecognitionSettings
        Observation and engine settings.
    repertoire_id : str
        Identity of the repertoire (e.g. its file name and content hash).
    """
    source = {"sha256": file_sha256(path)}
    decided = settings.fingerprint()
    # a file name's factors label a clip's rows (taken fresh from its item on every run),
    # they score nothing: renaming a group must not score a study again
    decided.get("mocap", {}).pop("factors_from_name", None)
    payload = json.dumps({"input": source, "settings": decided,
                          "repertoire": repertoire_id, "code": code_digest()},
                         sort_keys=True)
    return hashlib.sha256(payload.encode()).hexdigest()[:16]


def file_sha256(path: str | os.PathLike) -> str:
    """The SHA-256 of a file's content, computed once per process for a file that has not changed.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    """
    key = _file_key(path)
    known = _HASHES.get(key)
    if known is None:
        from perception.io.files import sha256_file

        known = sha256_file(key[0])
        _hashed(key, known)
    return known


def _file_key(path: str | os.PathLike) -> tuple[Path, int, int]:
    """A file as its hash is kept: its path, size and time (a changed file is a new key)."""
    p = Path(path).resolve()
    st = p.stat()
    return p, st.st_size, st.st_mtime_ns


#: SHA-256s by :func:`_file_key`, the newest last: the files this process hashed, and the
#: videos the tracker hashed while it decoded them (:func:`load_clip`).
_HASHES: dict[tuple[Path, int, int], str] = {}
_HASHES_LOCK = threading.Lock()


def _hashed(key: tuple[Path, int, int], sha256: str) -> None:
    """Keep a file's hash, the 256 newest at most (a batch worker hashes many files)."""
    with _HASHES_LOCK:
        _HASHES.pop(key, None)
        _HASHES[key] = sha256
        while len(_HASHES) > 256:
            del _HASHES[next(iter(_HASHES))]


def load_clip(source: str | os.PathLike | Tracks, *, tracks_out: str | os.PathLike | None = None,
              progress: bool = False, setup: TrackingSetup | None = None,
              pose: PoseImport | None = None, keep_truncated: bool = False,
              fps: float | None = None, frames: FrameSample | None = None,
              decoder_threads: int = 0) -> Tracks:
    """The tracks of a clip: tracked from a video, read from a tracks or pose file, or as given.

    Parameters
    ----------
    source : str, os.PathLike or Tracks
        A video file, a ``.tracks.h5`` file, a pose file, or tracks in memory.
    tracks_out : str or os.PathLike, optional
        Where a video's tracks are written (default: ``<stem>.tracks.h5``
        beside the video). A current tracks file of the video there, or
        beside the video, is loaded instead of tracking again
        (:func:`current_tracks`).
    progress : bool
        Show a progress bar while tracking.
    setup : TrackingSetup, optional
        Colour models and marker sizes for tracking a video.
    pose : PoseImport, optional
        How a pose file becomes tracks.
    keep_truncated : bool
        Track the frames a truncated video decodes instead of refusing it.
    fps : float, optional
        A video's true frame rate, frames/s, whatever its header says. With
        this or ``keep_truncated``, a video is always tracked afresh (its
        existing tracks file may have been made without them).
    frames : FrameSample, optional
        Keeps a few frames of a video as it is tracked, for the contact sheet
        (:func:`~perception.report.tracking.contact_sheet`); left empty when
        the tracks are not tracked now.
    decoder_threads : int
        Threads FFmpeg decodes a video with (0: FFmpeg's choice).

    Raises
    ------
    InputError
        A file that is neither a video, a tracks file nor a pose file, or that
        cannot be read, tracked or loaded.
    """
    if isinstance(source, Tracks):
        return source
    path = Path(source)
    kind = clip_name(path)[1]
    if kind == "unknown":
        input_file(path, "video, tracks or pose file", empty=False)  # an empty one says so
        raise InputError("not a video, tracks or pose file", path)
    if kind == "tracks":
        return Tracks.load(path)
    if kind == "mocap":
        raise InputError("a motion-capture recording holds reaches, not one clip's tracks: "
                         "read them with read_reaches and score each with recognize_reach",
                         path)
    if kind == "pose":
        from perception.io.pose import read_pose  # movement only for pose files

        return read_pose(path, pose)
    if not path.exists():  # as the tracker says it, not the FileNotFoundError of its key
        raise InputError("no such file", path)
    out = tracks_path_for(path) if tracks_out is None else Path(tracks_out)
    if not keep_truncated and fps is None:
        current = current_tracks(path, [out, tracks_path_for(path)], setup)
        if current is not None:
            return current
    from perception.tracking.video_tracks import track_video  # OpenCV only when there is video

    kw = {} if setup is None else {"markers": setup.markers, "params": setup.params}
    key = _file_key(path)  # before decoding: a file changed meanwhile is hashed again
    tracks = Tracks.load(track_video(path, out, progress=progress,
                                     keep_truncated=keep_truncated, fps=fps, frames=frames,
                                     decoder_threads=decoder_threads, **kw))
    if tracks.video.get("sha256") and _file_key(path) == key:
        _hashed(key, tracks.video["sha256"])
    return tracks


#: ``/tracker`` attributes that describe what a tracker learned from the clip
#: (not its settings): they do not decide whether a tracks file is current.
_LEARNED = frozenset({"reference_mass_px", "diameter_px"})


def _settings(attrs: dict) -> str:
    from perception.io.atomic import jsonable

    return json.dumps({k: v for k, v in attrs.items() if k not in _LEARNED},
                      sort_keys=True, default=jsonable)


def current_tracks(video: str | os.PathLike, candidates,
                   setup: TrackingSetup | None = None) -> Tracks | None:
    """The first of ``candidates`` that is a current tracks file of ``video``, loaded.

    Current means: written by this very code (:func:`~perception.provenance.code_digest`),
    of this very video
    (``/video`` attribute ``sha256``: hashing reads the file once, far
    cheaper than decoding and tracking it) and with the tracker settings a
    tracker of ``setup`` (default: the default colour models and parameters)
    would write (``/tracker`` colour models, ROIs, criteria and parameters).
    Anything else (missing, unreadable, stale) is not reused.

    Parameters
    ----------
    video : str or os.PathLike
        The video.
    candidates : iterable of path
        Tracks files to consider, in order of preference.
    setup : TrackingSetup, optional
        The tracking setup the tracks must have been made with.
    """
    import h5py

    expected = None
    for cand in map(Path, candidates):
        if not cand.is_file():
            continue
        try:
            with h5py.File(cand, "r") as fh:
                digest = fh.attrs.get("software_digest")
            tracks = Tracks.load(cand)
        except (InputError, OSError, ValueError):
            continue
        digest = digest.decode() if isinstance(digest, bytes) else digest
        if digest != code_digest() or tracks.video.get("sha256") != file_sha256(video):
            continue
        expected = expected or _settings(_tracker_attrs(setup))
        if _settings(tracks.tracker) == expected:
            return tracks
    return None


def _tracker_attrs(setup: TrackingSetup | None) -> dict:
    """The ``/tracker`` settings a tracker of ``setup`` writes."""
    from perception.tracking.markers import default_markers
    from perception.tracking.tracker import Tracker

    if setup is None:
        return Tracker(default_markers()).attrs()
    return Tracker(setup.markers, setup.params).attrs()


def recognize_tracks(tracks: Tracks, repertoire: Repertoire,
                     settings: RecognitionSettings | None = None, *, clip: str | None = None,
                     source: str | os.PathLike | None = None,
                     plan_cache: PlanCache | None = None,
                     paths: MeasuredPaths | None = None) -> Recognition:
    """Observe tracks, bring them to the repertoire's scale, score every model and judge.

    One planning pass (the repertoire's reference scene, with the clip's
    object size), one scoring pass of every model (the verdict's and the
    winner's), one of the transport alone (the digits held closed, against
    the reach models), and the verdict judged once
    (:mod:`perception.recognition.evidence`).

    Parameters
    ----------
    tracks : Tracks
        The clip's tracks (see :func:`load_clip`).
    repertoire : Repertoire
        The models to score against.
    settings : RecognitionSettings, optional
        Observation and engine settings.
    clip : str, optional
        Clip name.
    source : str or os.PathLike, optional
        The file the user gave, named in errors (default: the clip's name).
    plan_cache : PlanCache, optional
        Models re-planned for a scene, shared with other processes.
    paths : MeasuredPaths, optional
        The movement's transport and aperture on better data than the tracks
        (a motion-capture reach's 3D paths): its landmarks are measured on
        them, and its clock is the recording's.

    Raises
    ------
    InputError
        The tracks cannot be observed.
    PlanningError
        Their scene cannot be planned (out of the models' reach: often a wrong scale).
    """
    from perception.recognition.shape import is_mirrored, opens
    from perception.settling import settle_start

    settings = RecognitionSettings() if settings is None else settings
    rules = settings.rules
    try:
        # a clip that does not start still is scored from the scene its data give
        tracks, settled = settle_start(tracks, settings.observe, clip=clip)
        obs = observe(tracks, settings.observe, clip=clip)
        mirrored = is_mirrored(obs, rules)
        if mirrored:  # the other hand, or the camera on the other side: score its mirror image
            obs = observe(tracks, dataclasses.replace(settings.observe,
                                                      mirror=not settings.observe.mirror),
                          clip=clip)
    except InputError as exc:
        if source is None:
            raise
        # name the file the user gave; keep the kind (TrackingError) and the field
        raise exc.at(source) from None
    # brought to the reference scale first: a clip that cannot be judged is
    # refused before its scene is planned
    scored_obs, norm = _canonical(obs, repertoire, source, rules)
    try:
        models = repertoire.for_scene(SceneSpec.of(scored_obs), cache=plan_cache,
                                      threads=settings.planning_threads)
    except PlanningError as exc:  # the scene, not the software: name the clip and the scale
        raise PlanningError(f"{exc.problem} (check the scale: `px_per_m`, `object_diameter`)",
                            source or obs.clip, field=exc.field) from None
    # the clip's own tracking noise, where it exceeds what the rule assumes
    hammer = _replaced(settings.hammer, "obs_sd", max(settings.hammer.obs_sd, scored_obs.noise))
    scores = score_clip(scored_obs, models, hammer)
    judged = judged_models(scores.kinds, "grasp" if opens(scored_obs, rules) else "reach")
    models, familiarity = _calibrated(repertoire, models, scores, judged, scored_obs.dt)
    transport = _transport_familiarity(scored_obs, models, repertoire, hammer)
    # the tracks' clock at the observation's zero (both end on the last row:
    # settling only trims the first)
    shift = float(tracks.time[-1] - obs.clip_time[-1])
    measured = None if paths is None else movement_landmarks(
        paths.time - shift, paths.transport, paths.aperture, rules.landmarks,
        bounds=paths.bounds)
    landmarks = clip_landmarks(obs, models, scores.log_likelihood[:, -1], rules, measured)
    share = scores.scored[list(judged)].sum(axis=1).max() / max(scores.scored.shape[1] - 1, 1)
    evidence = movement_evidence(
        obs, [scores.kinds[i] for i in judged], scores.log_likelihood[judged, -1],
        familiarity[list(judged)], landmarks, transport, float(share),
        grip_course(obs, rules, norm.wrist_offset))
    return Recognition(
        clip=obs.clip, time=scored_obs.time / norm.time_scale, frame=scored_obs.frame,
        **{**scores._asdict(), "familiarity": familiarity}, observation=obs, models=models,
        rules=rules, scored_observation=scored_obs, normalisation=norm, judged=judged,
        evidence=evidence, decision=judge(evidence, rules), landmarks=landmarks,
        transport_familiarity=transport, mirrored=mirrored,
        notes=(*obs.notes, *((settled,) if settled else ())),
        time_origin=shift + (0.0 if paths is None else paths.clock_offset))


def _canonical(obs, repertoire: Repertoire, source, rules: VerdictRules):
    """``obs`` at the repertoire's reference scale (see :mod:`perception.recognition.shape`).

    The reference scene keeps the clip's object size (the grip's targets
    are on the object).
    """
    from perception.recognition.shape import canonical

    scene, durations = repertoire.reference()
    scene = _replaced(scene, "object_size", obs.object_diameter)
    try:
        return canonical(obs, scene, durations, rules, repertoire.wrist_offset())
    except InputError as exc:
        raise exc.at(source or obs.clip) from None


@functools.lru_cache(maxsize=32, typed=True)
def _replaced(settings, name: str, value):
    """``dataclasses.replace(settings, name=value)`` of frozen settings, made once per
    settings and value: a stream asks for the same ones at every row, and each
    validation cost 15 us."""
    return dataclasses.replace(settings, **{name: value})


def _calibrated(repertoire: Repertoire, models: list, scores, among, frame_period: float):
    """The models and their familiarities, the best of ``among`` calibrated now if it has
    no calibration yet (the default repertoire calibrates only the models a verdict rests
    on): familiarity is read off it."""
    best = scores.best(among)
    familiarity = scores.familiarity.copy()
    if np.isfinite(familiarity[best]):
        return models, familiarity
    models = repertoire.calibrated(models, best)
    fit = misfit(scores.mahalanobis, scores.scored)
    familiarity[best] = models[best].calibration.familiarity(float(fit[best]), frame_period)
    return models, familiarity


def _transport_familiarity(obs, models: list, repertoire: Repertoire, hammer: HammerParams
                           ) -> float:
    """The familiarity of the transport alone (the digits held closed at their rest place)
    to the best reach model: NaN without reach models."""
    from perception.recognition.shape import closed_hand

    reach = [m for m in models if m.kind == "reach"]
    if not reach:
        return float("nan")
    scores = score_clip(closed_hand(obs), reach, hammer)
    _, familiarity = _calibrated(repertoire, reach, scores, range(len(reach)), obs.dt)
    return float(familiarity[scores.best()])


def recognize_clip(source: str | os.PathLike | Tracks, repertoire: Repertoire,
                   settings: RecognitionSettings | None = None, *, clip: str | None = None,
                   tracks_out: str | os.PathLike | None = None, progress: bool = False,
                   plan_cache: PlanCache | None = None) -> Recognition:
    """Track (if a video), observe, plan for the clip's scene and recognise one clip.

    :func:`load_clip` then :func:`recognize_tracks`.

    Parameters
    ----------
    source : str, os.PathLike or Tracks
        A video, a tracks file, a pose file or tracks in memory (see :func:`load_clip`).
    repertoire : Repertoire
        The models to score against.
    settings : RecognitionSettings, optional
        Observation, engine, tracking and pose settings.
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
    from perception.boundary import expect

    expect(repertoire, Repertoire, "recognize_clip(repertoire=)",
           hint="Repertoire.load or Repertoire.build")
    expect(settings, RecognitionSettings, "recognize_clip(settings=)", optional=True)
    settings = RecognitionSettings() if settings is None else settings
    is_file = not isinstance(source, Tracks)
    name = clip or (clip_name(source)[0] if is_file else None)
    tracks = load_clip(source, tracks_out=tracks_out, progress=progress,
                       setup=settings.tracking, pose=settings.pose,
                       **settings.video_options())
    return recognize_tracks(tracks, repertoire, settings, clip=name,
                            source=source if is_file else None, plan_cache=plan_cache)

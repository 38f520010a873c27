"""Recognition while the movement unfolds: a frame (or a pose row) in, a judgement out.

:class:`OnlineRecognizer` takes one frame at a time (tracked here, frame by
frame, as ``hammer-mv track`` does) or one row of marker positions, and
after each returns an :class:`OnlineState`. What it knows when (docs/online.md):

* **the scene**, once the first ``2 x rest_frames`` rows are in: the
  pixel-to-model transform, the scale, the rest posture, the tracking noise
  and the frame period — the same functions and the same frames as the
  offline observation (:mod:`perception.observation`); the repertoire is
  planned for it then, once, before the movement begins;
* **the onset**, the first frame at which the offline onset rule can
  already be applied: the wrist held beyond its threshold for
  ``onset_hold_frames`` frames (a few frames' delay, none of guessing);
* **every model's score so far**, from the onset on
  (:class:`~perception.recognition.online.StepScorer`): the offline
  arrays' columns, frame by frame;
* **a provisional verdict**: the offline verdict rule on what has been seen
  (see :func:`provisional`), and **settled** once the :class:`SettleRule`
  holds. What the offline verdict needs the whole movement for — its end,
  its movement time (the time scale of the shape pass), its landmarks —
  the provisional one does without; that is why it is provisional.

When the stream ends, :meth:`OnlineRecognizer.finish` runs the offline
computation (:func:`perception.pipeline.recognize_tracks`) on the rows
accumulated: the final result is ``recognize``'s on the same clip.
"""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np

from perception.errors import InputError
from perception.filtering import AlphaBeta
from perception.io.tracks import Status, Tracks
from perception.observation import DIGIT_MARKERS, check_hand, onset_time, rest_scene
from perception.pipeline import RecognitionSettings, recognize_tracks
from perception.recognition.models import SceneSpec
from perception.recognition.online import StepScorer
from perception.recognition.provisional import (
    Decision,
    OnlineState,
    SettleRule,
    decision_summary,
    provisional,
)
from perception.recognition.repertoire import PlanCache, Repertoire
from perception.recognition.result import Recognition
from perception.recognition.shape import MIN_TRANSPORT, WRIST_GOAL_OFFSET

__all__ = ["Decision", "OnlineRecognizer", "OnlineState", "SettleRule", "decision_summary"]


class OnlineRecognizer:
    """Recognise a movement frame by frame (see the module docstring).

    Parameters
    ----------
    repertoire : Repertoire
        The models.
    settings : RecognitionSettings, optional
        Observation, engine and tracking settings (as ``recognize``'s).
    clip : str
        Clip name (the report's).
    markers : sequence of str, optional
        Marker names of the rows given to :meth:`update` as positions (default:
        the tracker's, ``thumb, finger, wrist, object``).
    tracker_attrs : dict, optional
        ``/tracker`` attributes of rows given as positions: the object's
        apparent size (``diameter_px``) sets the scale unless ``px_per_m`` does.
    settle : SettleRule, optional
        When a verdict settles.
    plan_cache : PlanCache, optional
        Plans shared with other processes.
    """

    def __init__(self, repertoire: Repertoire, settings: RecognitionSettings | None = None, *,
                 clip: str = "stream", markers=None, tracker_attrs: dict | None = None,
                 settle: SettleRule | None = None, plan_cache: PlanCache | None = None):
        self.repertoire = repertoire
        self.settings = RecognitionSettings() if settings is None else settings
        self.clip = clip
        self.settle = SettleRule() if settle is None else settle
        self.plan_cache = plan_cache
        self._tracker = None
        self._tracker_attrs = dict(tracker_attrs or {})
        if markers is None:
            from perception.tracking.markers import MARKER_NAMES

            markers = (MARKER_NAMES if self.settings.tracking is None
                       else self.settings.tracking.markers.names)
        self.markers = tuple(markers)
        self._ahead: list[tuple[int, float, np.ndarray]] = []
        self._rows: dict[str, list] = {k: [] for k in ("frame", "time", "position",
                                                       "likelihood", "status")}
        self._scene = None  # SimpleNamespace once fixed
        self._scorer: StepScorer | None = None
        self._onset: float | None = None
        self._obs: list[np.ndarray] = []  # (3, 2) m per row: wrist, finger tip, thumb tip
        self._aperture: list[float] = []
        self._walked: list[float] = []  # progress at each scored frame
        self._verdicts: list[tuple[float, str]] = []  # (since onset, verdict) since it changed
        self._progress = 0.0
        self._decision: Decision | None = None
        self.state: OnlineState | None = None

    # -- input ----------------------------------------------------------------
    def update(self, frame_or_points: np.ndarray, t: float,
               index: int | None = None) -> OnlineState:
        """Take the next frame (H, W, 3) uint8 BGR, or marker positions (M, 2) px; the state.

        Parameters
        ----------
        frame_or_points : array
            A video frame (tracked here), or one row of positions in the order
            of :attr:`markers` (NaN where lost).
        t : float
            Its time, s (increasing).
        index : int, optional
            Its frame index (default: rows received so far).
        """
        data = np.asarray(frame_or_points)
        index = len(self._rows["time"]) + len(self._ahead) if index is None else int(index)
        if data.ndim == 3:
            return self._frame(data, float(t), index)
        if data.shape != (len(self.markers), 2):
            raise InputError(f"expected a frame (H, W, 3) or positions ({len(self.markers)}, 2),"
                             f" got shape {data.shape}", field="frame_or_points")
        pos = data.astype(float)
        seen = np.isfinite(pos).all(axis=1)
        return self._row(index, float(t), pos, seen.astype(np.float32),
                         np.where(seen, Status.TRACKED, Status.LOST).astype(np.int8))

    def _frame(self, image: np.ndarray, t: float, index: int) -> OnlineState:
        """Track a frame; the first ``init_frames`` wait for the tracker's look-ahead."""
        if self._tracker is None:
            from perception.tracking.tracker import Tracker  # OpenCV only for frames

            setup = self.settings.tracking
            self._tracker = (Tracker() if setup is None else Tracker(setup.markers, setup.params))
        tracker = self._tracker
        if tracker.n_frames == 0 and len(self._ahead) < max(tracker.params.init_frames, 1):
            self._ahead.append((index, t, image))
            if len(self._ahead) < max(tracker.params.init_frames, 1):
                return self._waiting(index, t)
            if len(self._ahead) > 1:
                tracker.look_ahead(self._ahead[-1][2])
        todo, self._ahead = self._ahead or [(index, t, image)], []
        for i, ti, img in todo:
            state = self._row(i, ti, *tracker.update(img, ti))
        return state

    def _waiting(self, index: int, t: float) -> OnlineState:
        zeros = np.zeros(len(self.repertoire.names))
        self.state = OnlineState(index, t, "start", list(self.repertoire.names), zeros, zeros)
        return self.state

    # -- the stream -------------------------------------------------------------
    def _row(self, index: int, t: float, position, likelihood, status) -> OnlineState:
        for key, value in zip(self._rows, (index, t, position, likelihood, status)):
            self._rows[key].append(value)
        params = self.settings.observe
        if self._scene is None:
            if len(self._rows["time"]) < 2 * params.rest_frames:
                return self._waiting(index, t)
            self._fix_scene()
        self._filter(len(self._rows["time"]) - 1)
        if self._onset is None:
            self._find_onset()
        elif self._scorer is not None:
            self._score(len(self._obs) - 1)
        return self._judge(index, t)

    def tracks(self, video: dict | None = None) -> Tracks:
        """The rows received so far as :class:`Tracks` (what :meth:`finish` recognises).

        Parameters
        ----------
        video : dict, optional
            ``/video`` attributes to carry.
        """
        rows = self._rows
        tracker = self._tracker.attrs() if self._tracker is not None else self._tracker_attrs
        m = len(self.markers)
        return Tracks(frame=np.asarray(rows["frame"], dtype=np.int64),
                      time=np.asarray(rows["time"], dtype=float),
                      markers=self.markers,
                      position=np.reshape(rows["position"], (-1, m, 2)),
                      likelihood=np.reshape(rows["likelihood"], (-1, m)),
                      status=np.reshape(rows["status"], (-1, m)),
                      video=video or {}, tracker=tracker)

    def _fix_scene(self) -> None:
        """Scene, rest posture, noise and models from the rest frames, as offline; plan once."""
        params = self.settings.observe
        first = rest_scene(self.tracks(), params, clip=self.clip)
        check_hand(first, params)
        transform, rest, noise, dt = first.transform, first.rest, first.noise, first.dt
        half = 0.5 * (rest[1] - rest[2])
        scene = SceneSpec(distance=float(np.linalg.norm(rest[0])),
                          object_size=params.object_diameter, frame_period=dt,
                          tip_start=float((0.5 * (rest[1] + rest[2]) - rest[0])[1]))
        # planned for the scene now, before the movement: the final, offline
        # pass finds them planned
        self.repertoire.for_scene(scene, cache=self.plan_cache)
        # the provisional verdict judges the movement as the shape pass does, at
        # the repertoire's reference scale (perception.recognition.shape)
        ref, _ = self.repertoire.reference()
        ref = dataclasses.replace(ref, object_size=params.object_diameter)
        models = self.repertoire.for_scene(ref, cache=self.plan_cache)
        cols = [self.markers.index(m) for m in DIGIT_MARKERS]
        hand = 0.5 * (rest[1] + rest[2]) - rest[0]
        self._scene = SimpleNamespace(
            transform=transform, cols=cols, noise=noise, rest=rest, half=half, dt=dt,
            models=models, kinds=[m.kind for m in models],
            filt=AlphaBeta((3, 2), params.alpha, params.beta), filtered=[],
            way=max(scene.distance - WRIST_GOAL_OFFSET, 1e-6),
            scale=(ref.distance - WRIST_GOAL_OFFSET) / max(scene.distance - WRIST_GOAL_OFFSET,
                                                           MIN_TRANSPORT),
            tip=np.array([0.0, ref.tip_start]) - hand)
        hammer = self.settings.hammer  # the clip's own noise, as the shape pass
        self._scene.scorer = StepScorer(models, dataclasses.replace(  # built before the onset
            hammer, obs_sd=max(hammer.obs_sd, noise * self._scene.scale)))

    def _filter(self, upto: int) -> None:
        """Filter the rows not filtered yet, up to row ``upto``, in the model frame."""
        sc, rows = self._scene, self._rows
        for i in range(len(sc.filtered), upto + 1):
            z = sc.transform.to_model(np.asarray(rows["position"][i], dtype=float)[sc.cols])
            dt = sc.dt if i == 0 else rows["time"][i] - rows["time"][i - 1]
            f = sc.filt(z, dt)
            sc.filtered.append(f)
            self._obs.append(np.stack([f[0], f[1] - sc.half, f[2] + sc.half]))

    def _find_onset(self) -> None:
        """The offline onset rule on the rows so far; once it holds, score from the onset."""
        sc, params = self._scene, self.settings.observe
        time = np.asarray(self._rows["time"], dtype=float)
        try:
            onset = onset_time(np.asarray(sc.filtered), time, sc.noise, params, self.clip)
        except InputError:  # no movement yet
            return
        self._onset = onset
        self._start = int(np.searchsorted(time, onset))
        self._scorer = sc.scorer
        for i in range(self._start, len(time)):
            self._score(i)

    def _score(self, i: int) -> None:
        w, f, th = self._obs[i]
        sc = self._scene
        goal = np.array([0.0, -WRIST_GOAL_OFFSET])
        wrist = goal + (w - goal) * sc.scale  # as shape.canonical: the transport scaled,
        self._scorer.step(self._rows["time"][i] - self._onset, wrist,  # the grip kept
                          f - w + wrist + sc.tip, th - w + wrist + sc.tip)
        self._aperture.append(float(np.linalg.norm(f - th)))
        self._progress = max(self._progress, float(
            np.nan_to_num(np.linalg.norm(w - sc.rest[0]) / sc.way)))
        self._walked.append(self._progress)

    def _judge(self, index: int, t: float) -> OnlineState:
        sc, names = self._scene, [m.name for m in self._scene.models]
        if self._scorer is None:
            zeros = np.zeros(len(names))
            self.state = OnlineState(index, t, "rest", names, zeros, zeros)
            return self.state
        since = t - self._onset
        hammer = self.settings.hammer
        best, verdict, detail, fam = provisional(
            sc.kinds, self._scorer, np.asarray(self._aperture), np.asarray(self._walked),
            self.settings.observe.object_diameter, sc.dt, hammer.familiarity_threshold)
        if not self._verdicts or self._verdicts[-1][1] != verdict:
            self._verdicts.append((since, verdict))
        evidence = (math.inf if detail else abs(math.log(max(fam, 1e-300)
                                                         / hammer.familiarity_threshold))
                    if math.isfinite(fam) else 0.0)
        if self._decision is None and self._settles(since, verdict, evidence):
            self._decision = Decision(verdict, detail, t, since, index)
        self.state = OnlineState(
            index, t, "moving", names, self._scorer.confidence.copy(),
            self._scorer.log_likelihood.copy(), since, min(self._progress, 1.0),
            names[best], verdict, detail, fam, evidence, self._decision)
        return self.state

    def _settles(self, since: float, verdict: str, evidence: float) -> bool:
        rule = self.settle
        progress = rule.reach_progress if verdict == "reach" else rule.min_progress
        return (self._progress >= progress and evidence >= rule.margin
                and since - self._verdicts[-1][0] >= rule.hold)

    @property
    def last_row(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The last row received: positions (M, 2) px, likelihood (M,), status (M,); None before one."""
        rows = self._rows
        if not rows["time"]:
            return None
        return rows["position"][-1], rows["likelihood"][-1], rows["status"][-1]

    # -- the end ----------------------------------------------------------------
    @property
    def decision(self) -> Decision | None:
        """The first settled verdict (None until one settles)."""
        return self._decision

    def finish(self, video: dict | None = None, *, source=None) -> Recognition:
        """The offline recognition of every row received: ``recognize``'s result.

        Parameters
        ----------
        video : dict, optional
            ``/video`` attributes of the tracks.
        source : str or os.PathLike, optional
            What errors name (default: the clip).

        Raises
        ------
        InputError
            As :func:`perception.pipeline.recognize_tracks` (a stream without a
            movement, too short, ...).
        """
        if self._ahead:  # a stream shorter than the tracker's look-ahead
            todo, self._ahead = self._ahead, []
            if len(todo) > 1:
                self._tracker.look_ahead(todo[-1][2])
            for i, ti, img in todo:
                self._row(i, ti, *self._tracker.update(img, ti))
        if not self._rows["time"]:
            raise InputError("no frames received", source or self.clip)
        return recognize_tracks(self.tracks(video), self.repertoire, self.settings,
                                clip=self.clip, source=source, plan_cache=self.plan_cache)


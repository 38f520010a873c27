"""Recognition while the movement unfolds: a frame (or a pose row) in, a judgement out.

:class:`OnlineRecognizer` takes one frame at a time (tracked here, frame by
frame, as ``hammer-mv track`` does) or one row of marker positions, and
after each returns an :class:`OnlineState`. It drives the offline engine
and rules, causally (docs/online.md):

* **the scene**, once the first ``2 x rest_frames`` rows are in: the same
  functions on the same frames as the offline observation
  (:mod:`perception.observation`); the repertoire is planned for it then,
  once, before the movement begins;
* **the onset**: the offline rule, applied as each row arrives;
* **the reference pass**: the movement brought to the repertoire's
  reference scale as the offline shape pass brings it
  (:mod:`perception.recognition.shape`), resampled frame by frame, and
  scored by :class:`~perception.recognition.engine.StepScorer` — against
  the grasp models, the reach models, and (digits held closed) the reach
  models again for the transport's familiarity. Its two unknowns until
  the movement is over — whether the scene is mirrored and the movement
  time's scale — are estimated as they become known (the side the finger
  opens on; the wrist's 10 %-90 % crossings of its way to the models'
  goal), and the pass is replayed from the onset whenever the estimate
  changes: with the offline scene and scale, its scores are the offline ones;
* **a provisional verdict**: :func:`perception.recognition.rules.judge`
  on the evidence so far, **settled** once the :class:`SettleRule` holds.

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
from perception.landmarks import MODEL_SPAN_FRACTION, Landmarks, count_peaks
from perception.observation import DIGIT_MARKERS, check_hand, onset_time, rest_scene
from perception.pipeline import RecognitionSettings, recognize_tracks
from perception.recognition.engine import StepScorer
from perception.recognition.models import SceneSpec
from perception.recognition.provisional import (
    Decision,
    OnlineState,
    SettleRule,
    decision_summary,
)
from perception.recognition.repertoire import PlanCache, Repertoire
from perception.recognition.result import Recognition
from perception.recognition.rules import Evidence, judge
from perception.recognition.shape import WRIST_GOAL_OFFSET, mirror_votes, rest_and_opening

__all__ = ["Decision", "OnlineRecognizer", "OnlineState", "SettleRule", "decision_summary"]

#: The share of a minimum-jerk movement's time (Flash & Hogan 1985) at which it has
#: covered each share of its way: the causal estimate of "when, in the movement" the
#: grip starts to open, from how far the wrist has come by then.
_TAU = np.linspace(0.0, 1.0, 201)
_WAY = 10 * _TAU**3 - 15 * _TAU**4 + 6 * _TAU**5


class _ReferencePass:
    """The shape pass of :mod:`perception.pipeline`, frame by frame, for one scene guess.

    Parameters
    ----------
    models : list of MotorModel
        The repertoire's models at the reference scene.
    scorers : (StepScorer, StepScorer or None), optional
        The scorers of all models and of the reach models (with the digits
        closed) to start over with (default: new ones).
    hammer : HammerParams
        The engine's settings (the clip's noise already in ``obs_sd``).
    scale, tip, hand : float, (2,) array, (2,) array
        The transport's scale about the wrist's goal, the digits' shift to the
        reference hand, and the reference hand's rest offset ahead of the wrist.
    alpha, step : float
        Time scale and the reference frame period, s.
    sign : float
        -1 for a mirrored scene.
    """

    def __init__(self, models, hammer, scale, tip, hand, alpha, step, sign, scorers=None):
        reach = [m for m in models if m.kind == "reach"]
        if scorers is None:
            scorers = StepScorer(models, hammer), StepScorer(reach, hammer) if reach else None
        for scorer in scorers:  # a replay reuses the stacked gains
            if scorer is not None:
                scorer.restart()
        self.scorer, self.closed = scorers
        every = list(range(len(models)))
        self.kinds = {k: [i for i in every if models[i].kind == k] or every
                      for k in ("grasp", "reach")}
        self.scale, self.tip, self.hand = scale, tip, hand
        self.alpha, self.step, self.sign = alpha, step, sign
        self.last = None  # (scaled time, wrist, finger, thumb) of the last frame
        self.fed = 0  # rows fed

    def feed(self, rows: list[tuple]) -> None:
        """The next rows: ``(t s since the onset, wrist, finger, thumb)``, filtered tips (2,) m
        in the clip's frame; scored together (a replay is one vectorised pass)."""
        goal = np.array([0.0, -WRIST_GOAL_OFFSET])
        flip = np.array([self.sign, 1.0])
        grid: list[tuple] = []
        for t, w, f, th in rows:
            w, f, th = w * flip, f * flip, th * flip
            wrist = goal + (w - goal) * self.scale  # as shape.canonical: the transport scaled,
            now = (t * self.alpha, wrist, f - w + wrist + self.tip, th - w + wrist + self.tip)
            last, self.last = self.last, now
            if last is None:  # the grid starts at the first frame, its points need two
                self.t0 = now[0]
                continue
            # resampled at the reference frame period as shape.canonical resamples
            first = max(math.floor(last[0] / self.step) + 1, math.ceil(self.t0 / self.step))
            for k in range(first, math.floor(now[0] / self.step) + 1):
                a = (k * self.step - last[0]) / (now[0] - last[0])
                grid.append((k * self.step, *(p0 + a * (p1 - p0)
                                              for p0, p1 in zip(last[1:], now[1:]))))
        self.fed += len(rows)
        if not grid:
            return
        t, w, f, th = (np.array(c) for c in zip(*grid))
        self.scorer.score(t, w, f, th)
        if self.closed is not None:
            tips = w + self.hand
            self.closed.score(t, w, tips, tips)


class OnlineRecognizer:
    """Recognise a movement frame by frame (see the module docstring).

    Parameters
    ----------
    repertoire : Repertoire
        The models.
    settings : RecognitionSettings, optional
        Observation, engine, verdict and tracking settings (as ``recognize``'s).
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
        if not isinstance(repertoire, Repertoire):  # not an AttributeError frames later
            raise TypeError(f"expected a Repertoire (Repertoire.load or Repertoire.build), "
                            f"got {type(repertoire).__name__}")
        if settings is not None and not isinstance(settings, RecognitionSettings):
            raise TypeError(f"expected RecognitionSettings, got {type(settings).__name__}")
        if settle is not None and not isinstance(settle, SettleRule):
            raise TypeError(f"expected a SettleRule, got {type(settle).__name__}")
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
        self._rows: dict[str, list] = {k: [] for k in ("frame", "time", "position",
                                                       "likelihood", "status")}
        self._received = 0  # frames or rows given to update
        self._last_time: float | None = None  # the last one's time, s
        self._scene = None  # SimpleNamespace once fixed
        self._onset: float | None = None
        self._moving: list[tuple] = []  # (since onset, wrist, finger tip, thumb tip) from the onset
        self._verdicts: list[tuple[float, str]] = []  # (since onset, verdict) since it changed
        self._decision: Decision | None = None
        self.state: OnlineState | None = None

    # -- input ----------------------------------------------------------------
    def update(self, frame_or_points: np.ndarray, t: float, index: int | None = None, *,
               likelihood: np.ndarray | None = None, status: np.ndarray | None = None
               ) -> OnlineState:
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
        likelihood, status : (M,) arrays, optional
            A row's own likelihood and status (a pose file's; default: 1 and
            tracked where seen, 0 and lost where not).
        """
        t = self._next_time(t)
        data = np.asarray(frame_or_points)
        if data.ndim != 3 and data.shape != (len(self.markers), 2):
            raise InputError(f"expected a frame (H, W, 3) or positions ({len(self.markers)}, 2),"
                             f" got shape {data.shape}", field="frame_or_points")
        index = self._received if index is None else int(index)
        self._received += 1
        self._last_time = t
        if data.ndim == 3:
            return self._frame(data, t, index)
        pos = data.astype(float)
        seen = np.isfinite(pos).all(axis=1)
        return self._row(index, t, pos,
                         seen.astype(np.float32) if likelihood is None else likelihood,
                         np.where(seen, Status.TRACKED, Status.LOST).astype(np.int8)
                         if status is None else status)

    def _next_time(self, t) -> float:
        """``t`` as a float, refused unless finite and after the last frame's.

        A NaN would reach the onset's frame search as an index, and a repeated
        or backward time a step of zero or negative length: both are refused
        here, where the caller can still tell which frame it was.
        """
        try:
            t = float(t)
        except (TypeError, ValueError):
            raise InputError(f"expected a time in s, got {t!r}"[:120], field="t") from None
        if not math.isfinite(t):
            raise InputError(f"the time {t} s is not finite", field="t")
        if self._last_time is not None and t <= self._last_time:
            raise InputError(f"the time {t:g} s comes after {self._last_time:g} s: "
                             "times must increase", field="t")
        return t

    def _frame(self, image: np.ndarray, t: float, index: int) -> OnlineState:
        """Track a frame (the tracker's look-ahead spread over the next frames)."""
        if self._tracker is None:
            from perception.tracking.tracker import Tracker  # OpenCV only for frames

            setup = self.settings.tracking
            self._tracker = (Tracker() if setup is None else Tracker(setup.markers, setup.params))
        state = self.state if self.state is not None else self._waiting(index, t)
        for row in self._tracker.feed(image, t, index):
            state = self._row(*row[:5])
        return state

    def _waiting(self, index: int, t: float, phase: str = "start") -> OnlineState:
        names = self._scene.names if self._scene is not None else list(self.repertoire.names)
        zeros = np.zeros(len(names))
        self.state = OnlineState(index, t, phase, names, zeros, zeros)
        return self.state

    # -- the stream -------------------------------------------------------------
    def _row(self, index: int, t: float, position, likelihood, status) -> OnlineState:
        for key, value in zip(self._rows, (index, t, position, likelihood, status)):
            self._rows[key].append(value)
        if self._scene is None:
            if len(self._rows["time"]) < 2 * self.settings.observe.rest_frames:
                return self._waiting(index, t)
            self._fix_scene()
        self._filter(len(self._rows["time"]) - 1)
        if self._onset is None:
            self._find_onset()
        else:
            self._take(len(self._scene.filtered) - 1)
        if self._onset is None:
            return self._waiting(index, t, "rest")
        self._score()
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
        params, rules = self.settings.observe, self.settings.rules
        first = rest_scene(self.tracks(), params, clip=self.clip)
        check_hand(first, params)
        rest = first.rest
        half = 0.5 * (rest[1] - rest[2])
        scene = SceneSpec(distance=float(np.linalg.norm(rest[0])),
                          object_size=params.object_diameter, frame_period=first.dt,
                          tip_start=float((0.5 * (rest[1] + rest[2]) - rest[0])[1]))
        way = scene.distance - WRIST_GOAL_OFFSET
        if way < rules.min_transport:  # as the offline shape pass refuses it
            raise InputError(f"starts {scene.distance * 1000:.0f} mm from the object: too near "
                             "to judge a reach", self.clip, field="wrist")
        # planned for the scene now, before the movement: the final pass finds them planned
        self.repertoire.for_scene(scene, cache=self.plan_cache)
        ref, durations = self.repertoire.reference()
        ref = dataclasses.replace(ref, object_size=params.object_diameter)
        models = self.repertoire.for_scene(ref, cache=self.plan_cache)
        cols = [self.markers.index(m) for m in DIGIT_MARKERS]
        scale = (ref.distance - WRIST_GOAL_OFFSET) / way
        hammer = self.settings.hammer  # the clip's own noise, as the shape pass
        hammer = dataclasses.replace(hammer, obs_sd=max(hammer.obs_sd, first.noise * scale))
        self._scene = SimpleNamespace(
            first=first, cols=cols, half=half, way=way, durations=durations, ref=ref,
            models=models, names=[m.name for m in models], hammer=hammer, scale=scale,
            filt=AlphaBeta((3, 2), params.alpha, params.beta), filtered=[],
            separation=float(np.linalg.norm(2 * half)), guess=None, reference=None,
            rest_wrist=None, votes=[0, 0], peak_speed=0.0, slowed=0.0, arrived=0.0, walked=[],
            aperture=[], times=[], digits_seen=[],
            # past three times the longest model's movement the movement is over: the
            # evidence is kept as it was, and no frame costs more than the one before
            window=math.ceil(3 * durations[1] / first.dt), judged=None, t10=math.nan,
            t90=math.nan, gap=(math.nan, 0.0))
        self._reference((False, 1.0))  # its gains stacked now, before the movement

    def _filter(self, upto: int) -> None:
        """Filter the rows not filtered yet, up to row ``upto``, in the model frame."""
        sc, rows = self._scene, self._rows
        for i in range(len(sc.filtered), upto + 1):
            z = sc.first.transform.to_model(np.asarray(rows["position"][i], dtype=float)[sc.cols])
            dt = sc.first.dt if i == 0 else rows["time"][i] - rows["time"][i - 1]
            sc.filtered.append(sc.filt(z, dt))
            sc.digits_seen.append(bool(np.isfinite(z[1:]).all()))  # the filter coasts

    def _find_onset(self) -> None:
        """The offline onset rule on the latest rows; once it holds, score from the onset."""
        sc, params = self._scene, self.settings.observe
        if sc.rest_wrist is None:  # the wrist's rest, as the offline rule takes it
            sc.rest_wrist = np.median(np.asarray(sc.filtered[:params.rest_frames])[:, 0], axis=0)
        k = max(0, len(sc.filtered) - params.onset_hold_frames - 1)
        time = np.asarray(self._rows["time"][k:], dtype=float)
        try:
            onset = onset_time(np.asarray(sc.filtered[k:]), time, sc.first.noise, params,
                               self.clip, rest=sc.rest_wrist)
        except InputError:  # no movement yet
            return
        self._onset = onset
        first = int(np.searchsorted(np.asarray(self._rows["time"], dtype=float), onset))
        for i in range(first, len(sc.filtered)):
            self._take(i)

    def _take(self, i: int) -> None:
        """Row ``i`` into the movement: its grip, progress and speed, and the scene guess."""
        sc = self._scene
        f = sc.filtered[i]
        row = (self._rows["time"][i] - self._onset, f[0], f[1] - sc.half, f[2] + sc.half)
        self._moving.append(row)
        sc.times.append(row[0])
        sc.aperture.append(float(np.linalg.norm(row[2] - row[3])))
        if sc.digits_seen[i]:
            sc.gap = (row[0], sc.gap[1] if math.isnan(sc.gap[0]) else max(sc.gap[1],
                                                                           row[0] - sc.gap[0]))
        progress = np.linalg.norm(row[1] - sc.first.rest[0]) / sc.way
        sc.walked.append(max(float(np.nan_to_num(progress)), sc.walked[-1] if sc.walked else 0.0))
        if len(self._moving) > 1:  # the transport's speed, against its peak so far
            prev = self._moving[-2]
            speed = float(np.linalg.norm(row[1] - prev[1]) / max(row[0] - prev[0], 1e-9))
            if math.isfinite(speed) and speed >= sc.peak_speed:  # a new peak
                sc.peak_speed, sc.slowed, sc.arrived = speed, 0.0, 0.0
            elif math.isfinite(speed):  # as rules.slowed reads the movement so far
                sc.slowed = 1.0 - speed / sc.peak_speed
                sc.arrived = max(sc.arrived, sc.slowed)
        if math.isnan(sc.t10) and progress >= 0.1:
            sc.t10 = row[0]
        if math.isnan(sc.t90) and progress >= 0.9:
            sc.t90 = row[0]
        sc.guess = self._guess()

    def _score(self) -> None:
        """The reference pass up to the last row; replayed from the onset, in one vectorised
        pass, when the scene guess has changed."""
        sc = self._scene
        if sc.reference.guess != sc.guess:
            self._reference(sc.guess)
        sc.reference.feed(self._moving[sc.reference.fed:])

    def _reference(self, guess: tuple[bool, float]) -> None:
        """A reference pass from the onset for a scene guess (the scorers' gains kept)."""
        sc = self._scene
        mirror, alpha = guess
        sign = -1.0 if mirror else 1.0
        tip = np.array([0.0, sc.ref.tip_start])
        hand = 0.5 * (sc.first.rest[1] + sc.first.rest[2]) - sc.first.rest[0]
        old = sc.reference
        sc.reference = _ReferencePass(sc.models, sc.hammer, sc.scale, tip - hand * [sign, 1.0],
                                      tip, alpha, sc.ref.frame_period, sign,
                                      None if old is None else (old.scorer, old.closed))
        sc.reference.guess = guess

    def _guess(self) -> tuple[bool, float]:
        """The scene's mirroring and the time scale, as far as the movement shows them."""
        sc = self._scene
        rules = self.settings.rules
        vote = mirror_votes((self._moving[-1][2] - self._moving[-1][3])[None], rules)
        if vote is not None:  # a frame with the grip open wide enough to read its side
            sc.votes[int(vote)] += 1
        mirror = sc.votes[1] > rules.mirror_majority * sum(sc.votes)
        mt = (sc.t90 - sc.t10) / MODEL_SPAN_FRACTION
        alpha = float(np.clip(mt, *sc.durations) / mt) if mt > 0 else 1.0
        if sc.guess is not None and abs(alpha / sc.guess[1] - 1) < 0.02:
            alpha = sc.guess[1]
        return mirror, alpha

    def _evidence(self) -> tuple[Evidence, SimpleNamespace]:
        """What the verdict is judged on so far, and the grip's course."""
        sc, rules = self._scene, self.settings.rules
        ref = sc.reference
        g = np.asarray(sc.aperture)
        # the markers' own: the filter coasts through a loss
        seen = np.asarray(sc.digits_seen[-len(g):]) & np.isfinite(g) if len(g) else g > 0
        grip = SimpleNamespace(opened=False, peaks=0, closing=0.0, open_at=math.nan,
                               mt=(sc.t90 - sc.t10) / MODEL_SPAN_FRACTION,
                               opening=0.0, slowed=sc.slowed)
        if seen.sum() >= 3:
            gs = g[seen]
            rest, opening = rest_and_opening(gs, rules)  # as shape.opens reads it offline
            grip.opening = opening
            grip.opened = opening >= rules.grasp_opening * self.settings.observe.object_diameter
            lp = rules.landmarks
            # as the landmarks count them: not across a gap that may hide one
            grip.peaks = None if lp.hides_a_reopening(sc.gap[1], grip.mt) else count_peaks(
                gs, max(lp.peak_prominence * opening, lp.peak_min_prominence))
            walked, ts = np.asarray(sc.walked)[seen], np.asarray(sc.times)[seen]
            k = int(np.argmax(gs > rest + lp.opening_level * opening))
            # as the landmark: a start of the opening that was not seen is not known
            unseen = k > 0 and ts[k] - ts[k - 1] > lp.max_gap + 1e-9
            grip.open_at = math.nan if unseen else float(np.interp(walked[k], _WAY, _TAU))
            grip.closing = (float(gs.max() - gs[-1]) / opening) if opening > 0 else 0.0
        # the models of the kind the grip shows, as the offline pass takes them
        grip.models = idx = ref.kinds["grasp" if grip.opened else "reach"]
        fam = ref.scorer.familiarity(sc.ref.frame_period)[idx]
        transport = math.nan
        if ref.closed is not None and ref.closed.frames > 1:
            ll = ref.closed.log_likelihood
            transport = float(ref.closed.familiarity(sc.ref.frame_period)[int(np.argmax(ll))])
        # what is known before the end: when the grip started to open, how often it did
        observed = Landmarks(movement_time=grip.mt, aperture_peaks=grip.peaks,
                             opening_time=grip.open_at if grip.opened else math.nan)
        # the digits unseen since they were last seen count too, as offline at the end
        now = self._moving[-1][0]
        gap = max(sc.gap[1], now - (self._moving[0][0] if math.isnan(sc.gap[0]) else sc.gap[0]))
        scored = ref.scorer.scored.max() / max(ref.scorer.frames - 1, 1)
        evidence = Evidence([sc.models[i].kind for i in idx], ref.scorer.log_likelihood[idx],
                            fam, transport, sc.separation, observed, None, gap, sc.arrived,
                            float(scored))
        return evidence, grip

    def _judge(self, index: int, t: float) -> OnlineState:
        sc, rules = self._scene, self.settings.rules
        since = t - self._onset
        if sc.judged is None or len(self._moving) <= sc.window:
            sc.judged = self._evidence()
        evidence, grip = sc.judged
        d = judge(evidence, rules)
        verdict, detail = d.verdict or "abnormal", d.detail
        if not self._verdicts or self._verdicts[-1][1] != verdict:
            self._verdicts.append((since, verdict))
        progress = min(sc.walked[-1], 1.0)
        sure = self.settle.sure(d, evidence, grip, rules, progress)
        if self._decision is None and sure and since - self._verdicts[-1][0] >= self.settle.hold:
            self._decision = Decision(verdict, detail, t, since, index)
        scorer = sc.reference.scorer
        self.state = OnlineState(
            index, t, "moving", sc.names, scorer.confidence.copy(), scorer.log_likelihood.copy(),
            since, progress, sc.names[grip.models[d.best]], verdict, detail, d.familiarity,
            self.settle.evidence(d, evidence, rules), self._decision)
        return self.state

    @property
    def last_row(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The last row: positions (M, 2) px, likelihood (M,), status (M,); None before one."""
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
        if self._tracker is not None:  # the frames the tracker still holds
            for row in self._tracker.flush():
                self._row(*row[:5])
        if not self._rows["time"]:
            raise InputError("no frames received", source or self.clip)
        return recognize_tracks(self.tracks(video), self.repertoire, self.settings,
                                clip=self.clip, source=source, plan_cache=self.plan_cache)

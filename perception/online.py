"""Recognition while the movement unfolds: a frame (or a pose row) in, a judgement out.

:class:`OnlineRecognizer` takes one frame at a time (tracked here, frame by
frame, as ``hammer-mv track`` does) or one row of marker positions, and
after each returns an :class:`OnlineState`: the recognition of the rows
received so far — :func:`perception.pipeline.recognize_tracks` on that
prefix, nothing estimated another way — and whether its verdict has
settled (:class:`SettleRule`). ``fit`` is ``partial_fit`` run to the end:
at every frame the scores and the evidence are the offline ones of the
prefix, and :meth:`OnlineRecognizer.finish` is ``recognize`` of every row
(docs/online.md).

What streaming adds is only what a stream needs: the rows kept as they
arrive, the tracker's look-ahead for frames, when a verdict is trusted
(:class:`SettleRule`), and the state a live display draws.
"""

from __future__ import annotations

import math

import numpy as np

from perception.boundary import expect_frame
from perception.errors import InputError
from perception.io.tracks import Status, Tracks
from perception.pipeline import RecognitionSettings, recognize_tracks
from perception.recognition.provisional import (
    Decision,
    OnlineState,
    SettleRule,
    decision_summary,
)
from perception.recognition.repertoire import PlanCache, Repertoire
from perception.recognition.result import Recognition
from perception.recognition.rules import AT_END, judge
from perception.records import check_markers
from perception.resume import Grown

__all__ = ["Decision", "OnlineRecognizer", "OnlineState", "SettleRule", "decision_summary"]

_FIELDS = ("frame", "time", "position", "likelihood", "status")


class _Rows:
    """The rows received, each field a :class:`~perception.resume.Grown`: rows appended,
    never changed, so that a prefix handed to the recognition is a view, not a copy,
    and its resumed passes know it begins with the last one's rows without comparing
    them (a pass over every row at every row)."""

    def __init__(self, markers: int):
        self._markers = markers
        self._a: dict[str, Grown] = {}

    def _shapes(self) -> dict[str, tuple[tuple, type]]:
        m = self._markers
        return {"frame": ((), np.int64), "time": ((), float), "position": ((m, 2), float),
                "likelihood": ((m,), float), "status": ((m,), np.int64)}

    @property
    def n(self) -> int:
        """Rows received."""
        return self._a["time"].n if self._a else 0

    def append(self, *row) -> None:
        if not self._a:  # the first row sets the buffers (doubling as they fill)
            self._a = {k: Grown(np.empty((0, *shape), dtype), extendable=False)
                       for k, (shape, dtype) in self._shapes().items()}
        # each value as its row first (cast and broadcast as an assignment does): one
        # that cannot be leaves no field a row longer than the others
        rows = []
        for key, value in zip(_FIELDS, row):
            one = self._a[key].empty(1)
            one[0] = value
            rows.append((self._a[key], one))
        for g, one in rows:
            g.append(one)

    def arrays(self, last: bool = False, views: bool = False) -> dict | None:
        """Every row (copies; with ``views``, read-only views of the rows, which never
        change), or the last row alone (None before one)."""
        if last:
            return None if not self.n else {k: a.rows()[-1] for k, a in self._a.items()}
        if not self.n:
            return {k: np.empty((0, *shape), dtype) for k, (shape, dtype) in
                    self._shapes().items()}
        return {k: a.rows() if views else a.rows().copy() for k, a in self._a.items()}


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
        the tracker's, ``thumb, finger, wrist, object``); they must hold the
        four, in any order, among others.
    tracker_attrs : dict, optional
        ``/tracker`` attributes of rows given as positions: the object's
        apparent size (``diameter_px``) sets the scale unless ``px_per_m`` does;
        ``units`` ``"m"`` makes them metres in a plane (:attr:`Tracks.units`).
    settle : SettleRule, optional
        When a verdict settles.
    plan_cache : PlanCache, optional
        Plans shared with other processes.

    Raises
    ------
    InputError
        ``markers`` without one the recognition needs, named as ``recognize``
        names it (:func:`perception.records.check_markers`).

    Attributes
    ----------
    state : OnlineState or None
        The judgement after the last row.
    prefix : Recognition or None
        The recognition of the rows so far (None while they hold no movement).
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
        # fixed from here on: a stream without one would wait at rest until finish() refused it
        check_markers(self.markers, field="markers")
        self._rows = _Rows(len(self.markers))
        self._received = 0  # frames or rows given to update
        self._last_time: float | None = None
        self._answer: tuple[float, tuple | None] | None = None  # (since onset, settling answer)
        self._decision: Decision | None = None
        self.prefix: Recognition | None = None
        self.state: OnlineState | None = None

    # -- input ----------------------------------------------------------------
    def update(self, frame_or_points: np.ndarray, t: float, index: int | None = None, *,
               likelihood: np.ndarray | None = None, status: np.ndarray | None = None
               ) -> OnlineState:
        """Take the next frame (H, W, 3) uint8 BGR, or marker positions (M, 2); the state.

        Parameters
        ----------
        frame_or_points : array
            A video frame (tracked here), or one row of positions in the order
            of :attr:`markers` (NaN where lost): px, or m where ``tracker_attrs``
            say ``units`` m (a motion-capture reach's rows).
        t : float
            Its time, s (increasing).
        index : int, optional
            Its frame index (default: frames received so far).
        likelihood, status : (M,) arrays, optional
            A row's own likelihood and status (a pose file's; default: 1 and
            tracked where seen, 0 and lost where not).
        """
        t = self._next_time(t)
        data = np.asarray(frame_or_points)
        M = len(self.markers)
        if data.ndim != 3 and data.shape != (M, 2):
            raise InputError(f"expected a frame (H, W, 3) or positions ({M}, 2),"
                             f" got shape {data.shape}", field="frame_or_points")
        # refused here, before the row counts: not OpenCV's error from the tracker's first
        # look at the frames, nor numpy's from the rows' arrays
        if data.ndim == 3:
            expect_frame(data, "OnlineRecognizer.update", field="frame_or_points")
        if data.ndim != 3 and data.dtype.kind not in "biuf":
            raise InputError(f"expected positions as numbers, got {data.dtype}",
                             field="frame_or_points")
        for name, values in (("likelihood", likelihood), ("status", status)):
            if values is not None and np.shape(values) != (M,):
                raise InputError(f"expected one value per marker, shape ({M},), got shape "
                                 f"{np.shape(values)}", field=name)
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
        """``t`` as a float, refused unless finite and after the last frame's (a repeated or
        backward time would be a step of zero or negative length)."""
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
        state = self.state if self.state is not None else self._waiting(index, t, "start")
        for row in self._tracker.feed(image, t, index):
            state = self._row(*row[:5])
        return state

    # -- the stream -------------------------------------------------------------
    def _row(self, index: int, t: float, position, likelihood, status) -> OnlineState:
        self._rows.append(index, t, position, likelihood, status)
        if self._rows.n < 2 * self.settings.observe.rest_frames:
            return self._waiting(index, t, "start")
        try:
            self.prefix = recognize_tracks(self._tracks(views=True), self.repertoire,
                                           self.settings,
                                           clip=self.clip, plan_cache=self.plan_cache)
        except InputError as exc:  # offline, this prefix is not (yet) a movement to judge
            self.prefix = None
            return self._waiting(index, t, "rest", exc.problem)
        return self._judge(index, t, self.prefix)

    def _waiting(self, index: int, t: float, phase: str, problem: str | None = None
                 ) -> OnlineState:
        names = list(self.repertoire.names)
        zeros = np.zeros(len(names))
        self.state = OnlineState(index, t, phase, names, zeros, zeros, decision=self._decision,
                                 waiting_for=problem)
        return self.state

    def _judge(self, index: int, t: float, rec: Recognition) -> OnlineState:
        d, rules = rec.decision, self.settings.rules
        since = t - rec.time_origin  # the onset on the stream's clock
        # the verdict if the movement ends as it goes: the offline one unless a rule about
        # the movement's end gave it (only then judged again)
        ongoing = d if d.rule not in AT_END else judge(rec.evidence, rules, ongoing=True)
        answer = self.settle.settles(ongoing, rec.evidence, rules)
        if self._answer is None or self._answer[1] != answer:
            self._answer = (since, answer)
        if (self._decision is None and answer is not None
                and since - self._answer[0] >= self.settle.hold):
            self._decision = Decision(*answer, t, since, index)
        self.state = OnlineState(
            index, t, "moving", list(rec.names), rec.confidence[:, -1].copy(),
            rec.log_likelihood[:, -1].copy(), since, rec.evidence.progress, rec.verdict_model,
            d.verdict, d.detail, d.familiarity, self.settle.evidence(d, rec.evidence, rules),
            self._decision, judged_on=rec.evidence)
        return self.state

    def tracks(self, video: dict | None = None) -> Tracks:
        """The rows received so far as :class:`Tracks` (what :meth:`finish` recognises).

        Parameters
        ----------
        video : dict, optional
            ``/video`` attributes to carry.
        """
        return self._tracks(video)

    def _tracks(self, video: dict | None = None, *, views: bool = False) -> Tracks:
        """:meth:`tracks`; with ``views`` on the rows themselves (read-only, never
        changed), as the recognition of every row reads them."""
        tracker = self._tracker.attrs() if self._tracker is not None else self._tracker_attrs
        return Tracks(markers=self.markers, video=video or {}, tracker=tracker,
                      **self._rows.arrays(views=views))

    @property
    def last_row(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The last row: positions (M, 2), likelihood (M,), status (M,); None before one."""
        rows = self._rows.arrays(last=True)
        return None if rows is None else (rows["position"], rows["likelihood"], rows["status"])

    # -- the end ----------------------------------------------------------------
    @property
    def decision(self) -> Decision | None:
        """The first settled verdict (None until one settles)."""
        return self._decision

    def finish(self, video: dict | None = None, *, source=None, paths=None) -> Recognition:
        """The offline recognition of every row received: ``recognize``'s result.

        Parameters
        ----------
        video : dict, optional
            ``/video`` attributes of the tracks.
        source : str or os.PathLike, optional
            What errors name (default: the clip).
        paths : MeasuredPaths, optional
            The movement's paths on better data (a motion-capture reach's:
            :func:`perception.recordings.prepare_reach`).

        Raises
        ------
        InputError
            As :func:`perception.pipeline.recognize_tracks` (a stream without a
            movement, too short, ...).
        """
        if self._tracker is not None:  # the frames the tracker still holds
            for row in self._tracker.flush():
                self._row(*row[:5])
        if not self._rows.n:
            raise InputError("no frames received", source or self.clip)
        return recognize_tracks(self.tracks(video), self.repertoire, self.settings,
                                clip=self.clip, source=source, plan_cache=self.plan_cache,
                                paths=paths)

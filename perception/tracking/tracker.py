"""CamShift colour-marker tracker that survives real footage.

Each marker has a colour model (:mod:`perception.tracking.markers`;
``docs/markers.md``) and its own search window. :class:`Tracker` is the
per-frame loop; for each marker and frame it decides what to do and
delegates:

1. **Not found yet: first detection**
   (:mod:`perception.tracking.first_detection`, with
   :mod:`perception.tracking.candidates` and :mod:`perception.tracking.hand`).
   On the first frames (the hand at rest) every blob of a marker's colour is
   a candidate, refused when its size, shape, colour purity or stillness does
   not fit the marker; the object (largest round candidate) sets the scale
   the expected sizes follow; the hand markers are chosen together by the
   hand's structure. Two equally plausible blobs make the marker *ambiguous*
   (status 4): it is not guessed. A user-given ROI says where a marker is.
2. **Tracked: follow.** An alpha-beta filter predicts the marker's position
   (a digit's: the band's position measured in this frame plus the digit's
   offset from it and that offset's last change); the search region is the
   window around the prediction plus a margin that grows with speed.
   CamShift there gives the centroid and mass (pixel count) of the marker's
   colour, splitting off same-coloured blobs that joined the window
   (:mod:`perception.tracking.measurement`). A moving marker with too little
   of its colour there is looked for as a motion-blurred streak
   (:mod:`perception.tracking.blur`).
3. **Lost test.** A mass below ``lost_ratio`` x reference means the marker is
   hidden or gone; above ``max_area_ratio`` it was swallowed by something of
   its colour; a jump faster than a hand (``max_speed``) or a digit leaving
   its place relative to the band (``hand_drift``) is something else: the
   marker is reported lost (NaN, likelihood 0, status 2), never as a stale
   or borrowed position.
4. **Lost: re-acquisition**, only once the local search has failed and while
   the marker stays lost: a global search of a downscaled frame for the
   plausible blob nearest where the rest of the hand puts it, refined at full
   resolution, checked for shape and colour, and reported with status 1
   (:mod:`perception.tracking.reacquisition`).

Markers listed in ``still_markers`` (the object) are expected to stay put and
to be partly hidden by the hand at the end: their position is the running
mean of whole-blob measurements (restarted if the blob jumps, i.e. the
object was moved), and while less than ``hold_ratio`` of the blob is visible
the position is held, with likelihood equal to the visible fraction.
Each marker's state (motion estimate, window, reference mass) is a
:class:`~perception.tracking.marker_track.MarkerTrack`.

Likelihood is ``min(r, 1/r)`` with ``r`` the measured mass over the
reference mass: 1 for a whole, uncontaminated marker; lower when partly
hidden or merged with similar colour, and at most ``merged_likelihood``
(under 0.5) where the position may be off: merged with a neighbour of its
colour, or among more of its colour than itself. The tunables are
:class:`~perception.tracking.params.TrackerParams`; the tracks file, its
status codes and the ``/tracker`` attributes are described in
``docs/tracks-format.md``.
"""

from __future__ import annotations

import json
import math
from collections import deque
from collections.abc import Mapping
from dataclasses import asdict
from typing import Any

import numpy as np

from perception.boundary import expect_frame
from perception.errors import InputError
from perception.io.tracks import Status
from perception.tracking.blur import (
    STREAK_SLACK,
    WHOLE,
    diameter_px,
    is_fast,
    streak_mass,
    streak_width,
)
from perception.tracking.candidates import describe, reject_reason
from perception.tracking.first_detection import FirstDetection
from perception.tracking.marker_track import Located, MarkerTrack
from perception.tracking.markers import MarkerSet, default_markers, to_hsv
from perception.tracking.measurement import Measurement, likelihood, measure, measure_still
from perception.tracking.params import TrackerParams
from perception.tracking.reacquisition import ROI, downscaled_hsv, reacquire, search_scale

__all__ = ["ROI", "Measurement", "Tracker", "TrackerParams"]


class Tracker:
    """Track every marker of a :class:`MarkerSet` through a stream of frames.

    Parameters
    ----------
    markers : MarkerSet, optional
        Colour models (default :func:`perception.tracking.markers.default_markers`).
    params : TrackerParams, optional
        Tuning and the markers' physical sizes (defaults suit 25-60 fps clips
        of 1-2.5 cm markers at 300-1500 px/m).
    rois : mapping of str to (x, y, w, h), optional
        Manual initial regions per marker, px; a marker with a ROI is looked
        for only there on the first frame.

    Attributes
    ----------
    ambiguities : dict of str to list of (float, float)
        Markers found ambiguous on their first detection and the positions
        (px) of their rival blobs.
    catch_up : int
        Frames :meth:`feed` tracks at most per call once started.

    Examples
    --------
    >>> tracker = Tracker()                                   # doctest: +SKIP
    >>> for index, time, frame in FrameSource("clip.mp4"):    # doctest: +SKIP
    ...     rows = tracker.feed(frame, time, index)  # (index, time, position, ...)
    >>> rows = tracker.flush()                                # doctest: +SKIP
    """

    catch_up = 2

    def __init__(
        self,
        markers: MarkerSet | None = None,
        params: TrackerParams | None = None,
        rois: Mapping[str, ROI] | None = None,
    ):
        self.markers = default_markers() if markers is None else markers
        self.params = TrackerParams() if params is None else params
        rois = dict(rois or {})
        unknown = sorted(set(rois) - set(self.markers.names))
        if unknown:
            raise InputError(
                f"ROI for unknown marker {unknown[0]!r} (markers: {', '.join(self.markers.names)})"
            )
        self.rois = {name: _check_roi(name, roi) for name, roi in rois.items()}
        self._tracks = [
            MarkerTrack(m, m.name in self.params.still_markers, self.rois.get(m.name))
            for m in self.markers
        ]
        self._first = FirstDetection(self._tracks, self.params)
        self.n_frames = 0
        self._queue: deque[tuple[int, float, np.ndarray]] = deque()  # fed, not tracked yet
        self._frame_shape: tuple[int, int] | None = None
        self._small: tuple[np.ndarray, float, float] | None = None
        self._time = 0.0
        self._order = sorted(range(len(self._tracks)), key=lambda j: (
            not self._tracks[j].still, self._tracks[j].name != "wrist", j))
        # The rest of the hand each marker is placed against (see _anchor): the
        # digits for the wrist, the wrist for a digit; names never change.
        self._anchors = [
            [k for k, t in enumerate(self._tracks)
             if k != j and t.name in (("thumb", "finger") if tr.name == "wrist" else ("wrist",))]
            for j, tr in enumerate(self._tracks)
        ]
        m = len(self._tracks)
        self._lost_row = (np.full((m, 2), np.nan), np.zeros(m, np.float32),
                          np.full(m, Status.LOST, np.int8))

    # -- public -------------------------------------------------------------
    @property
    def found(self) -> np.ndarray:
        """(M,) bool: whether each marker has been found at least once."""
        return np.array([t.found for t in self._tracks])

    @property
    def never_found(self) -> list[str]:
        """Names of markers not found in any frame so far."""
        return [t.name for t in self._tracks if not t.found]

    @property
    def px_per_m(self) -> float | None:
        """Image scale from the object's apparent size, px/m (None until it is found)."""
        return self._first.scale

    @property
    def ambiguities(self) -> dict[str, list[tuple[float, float]]]:
        """Markers found ambiguous on their first detection and their rival blobs, px."""
        return self._first.ambiguities

    def why_not_found(self, name: str) -> str:
        """Why marker ``name`` has not been found: ambiguity or the candidates' rejections.

        Parameters
        ----------
        name : str
            A marker of this tracker.
        """
        return self._tracks[self.markers.names.index(name)].why_not_found()

    def attrs(self) -> dict[str, Any]:
        """The ``/tracker`` attributes: method, colour models, criteria, parameters."""
        return {
            **self._fixed_attrs(),
            "rois": json.dumps({k: list(v) for k, v in self.rois.items()}),
            "reference_mass_px": [float(t.ref) for t in self._tracks],
            "diameter_px": [float(t.diameter) for t in self._tracks],
            "ambiguous_rivals_px": json.dumps(
                {k: [list(map(float, c)) for c in v] for k, v in self.ambiguities.items()}),
        }

    def _fixed_attrs(self) -> dict[str, Any]:
        """The attributes of the markers and parameters, written once per pair: a stream
        asks for the attributes at every frame (``asdict`` of the parameters cost a
        twentieth of an online update)."""
        # both frozen: the same objects give the same attributes (held here, so that an
        # id is not reused by another)
        fixed = getattr(self, "_fixed", None)
        if fixed is None or fixed[0] is not self.markers or fixed[1] is not self.params:
            p = self.params
            out: dict[str, Any] = {
                "method": "camshift",
                "colour_models": self.markers.to_json(),
                "termination_criteria": json.dumps(
                    {"type": "eps+count", "eps_px": p.term_eps_px, "max_iter": p.term_max_iter}
                ),
            }
            for name, value in asdict(p).items():
                out[name] = json.dumps(value) if isinstance(value, tuple) else value
            self._fixed = (self.markers, self.params, out)
        return self._fixed[2]

    def feed(self, frame: np.ndarray, time_s: float, index: int) -> list[tuple]:
        """Take a stream's next frame; return the rows tracked meanwhile, in order.

        The first ``params.init_frames`` frames wait for the last of them
        (:meth:`look_ahead`); the call that brings it tracks the first frame
        (first detection), each later call at most :attr:`catch_up` frames:
        no call carries the whole look-ahead. A row is ``(index, time_s,
        position, likelihood, status, frame)``, with :meth:`update`'s results;
        :func:`~perception.tracking.video_tracks.track_frames` is this and :meth:`flush`.
        """
        self._queue.append((index, time_s, frame))
        if self.n_frames or len(self._queue) >= self.params.init_frames:
            return self.flush(self.catch_up if self.n_frames else 1)
        return []

    def flush(self, most: int | None = None) -> list[tuple]:
        """Track the frames :meth:`feed` holds (at most ``most``; all: the stream ended); rows."""
        if self.n_frames == 0 and len(self._queue) > 1:
            self.look_ahead(self._queue[-1][2])
        n = len(self._queue) if most is None else min(most, len(self._queue))
        todo = [self._queue.popleft() for _ in range(n)]
        return [(index, t, *self.update(frame, t), frame) for index, t, frame in todo]

    def look_ahead(self, frame: np.ndarray) -> None:
        """Show the tracker a later frame of the clip's rest before the first :meth:`update`.

        First detection then rejects candidates that move between the first
        frame and this one (clips start with the hand at rest).

        Parameters
        ----------
        frame : (H, W, 3) uint8
            BGR frame, e.g. frame ``params.init_frames - 1``.
        """
        self._first.look_ahead(frame)

    def update(self, frame: np.ndarray, time_s: float | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Track all markers in the next frame.

        Parameters
        ----------
        frame : (H, W, 3) uint8
            BGR image; frames must come in order.
        time_s : float, optional
            The frame's time, s (default: index / ``params.default_fps``); bounds how
            far a marker can have moved since it was last seen.

        Returns
        -------
        position : (M, 2) float64
            px; NaN where lost or ambiguous.
        likelihood : (M,) float32
            0..1; 0 where lost or ambiguous.
        status : (M,) int8
            :class:`~perception.io.tracks.Status` codes.
        """
        self._check_frame(frame)
        self._time = self.n_frames / self.params.default_fps if time_s is None else float(time_s)
        tracks = self._tracks
        position, lik, status = (a.copy() for a in self._lost_row)
        self._small = None
        todo = [j for j, tr in enumerate(tracks) if not tr.found]
        results: list[Located | None] = [None] * len(tracks)
        if todo:
            for j, located in self._first.detect(frame, todo, self.n_frames).items():
                results[j] = located
        for j in self._order:  # the object, the band, then the digits, which move relative to it
            tr = tracks[j]
            if tr.found and not tr.lost and j not in todo:
                results[j] = self._follow(tr, frame, results)
        # Lost markers are searched for once every followed one has moved on:
        # the hand's structure is then judged on this frame's positions.
        for j, tr in enumerate(tracks):
            if results[j] is None and tr.found:
                tr.lost = True
        centres: list[tuple[float, float] | None] = [None] * len(tracks)
        for j, tr in enumerate(tracks):
            result = results[j]
            if tr.found and result is None:
                result = self._reacquire(tr, frame)
            if result is None:
                tr.coast(self.params)
                if not tr.found and tr.rivals:
                    status[j] = Status.AMBIGUOUS
                continue
            if result[2] != Status.LOST:
                tr.seen_at = self._time
                tr.n_lost = 0
            centre, lik[j], status[j] = result
            position[j] = centre
            if math.isfinite(centre[0]) and math.isfinite(centre[1]):
                centres[j] = centre
        self._record_offsets(centres, lik)
        self._first.frame_done(self.n_frames)
        self.n_frames += 1
        return position, lik, status

    # -- steps --------------------------------------------------------------
    def _check_frame(self, frame: np.ndarray) -> None:
        expect_frame(frame, "Tracker.update", field="frame")
        if self._frame_shape is None:
            self._frame_shape = frame.shape[:2]
            for t in self._tracks:
                if t.roi is not None:
                    _roi_in_frame(t.name, t.roi, frame.shape)

    def _looks_right(self, tr: MarkerTrack, frame: np.ndarray, centre: tuple[float, float]) -> bool:
        """Whether the blob at ``centre`` has the marker's shape and colour purity."""
        half = max(tr.win) + 4
        h, w = frame.shape[:2]
        x0, y0 = max(int(centre[0] - half), 0), max(int(centre[1] - half), 0)
        x1, y1 = min(int(centre[0] + half) + 1, w), min(int(centre[1] + half) + 1, h)
        hsv = to_hsv(frame[y0:y1, x0:x1])
        cands = describe(hsv, tr.colour, self.params.min_area_px)
        if not cands:
            return False
        c = min(cands, key=lambda c: math.dist(c.blob.moved(x0, y0).centre, centre))
        return reject_reason(c, tr.name, tr.colour, None, self.params) is None

    def _anchor(self, tr: MarkerTrack,
                centres: list[tuple[float, float] | None] | None = None
                ) -> tuple[float, float] | None:
        """Where the rest of the hand is: the wrist for a digit, the digits for the wrist.

        From this frame's measured ``centres`` (None where not measured) if
        given, else from the markers tracked now.
        """
        xs, ys = [], []
        for k in self._anchors[self._tracks.index(tr)]:
            if centres is not None:
                c = centres[k]
            else:
                t = self._tracks[k]
                c = t.x if t.found and not t.lost else None
            if c is not None:
                xs.append(c[0])
                ys.append(c[1])
        # plain floats: numpy's per-call cost would exceed the arithmetic
        return (sum(xs) / len(xs), sum(ys) / len(ys)) if xs else None

    def _record_offsets(self, centres: list[tuple[float, float] | None],
                        lik: np.ndarray) -> None:
        """Each measured hand marker's offset from the rest of the hand, for re-acquisition.

        And the offset's change since the last frame (the grip opening),
        from whole measurements only (``lik`` at least 0.5): a centroid among
        clutter would send the next prediction off.
        """
        for tr, c in zip(self._tracks, centres):
            if tr.still or c is None:
                continue
            anchor = self._anchor(tr, centres)
            old, tr.offset = tr.offset, (None if anchor is None
                                         else (c[0] - anchor[0], c[1] - anchor[1]))
            # how the grip opens or closes, px/frame: with the band's motion
            # measured first, it predicts a digit better than its own velocity
            fresh = (old is not None and tr.offset is not None and tr.n_obs >= 2
                     and lik[self._tracks.index(tr)] >= 0.5)
            tr.offset_v = ((tr.offset[0] - old[0], tr.offset[1] - old[1]) if fresh
                           else (0.0, 0.0))

    def _expected_here(self, tr: MarkerTrack) -> tuple[tuple[float, float], float]:
        """Where a lost marker should be and how far from it (px) it may be found.

        With the rest of the hand tracked, the marker moved with it: it is
        looked for at the same offset from it, within ``hand_drift`` per
        frame lost (at most ``max_drift``). Otherwise around its last
        position, within what ``max_speed`` allows.
        """
        anchor = self._anchor(tr)
        if anchor is None or tr.offset is None or self.px_per_m is None or tr.still:
            return tr.x, self._reach_px(tr)
        p = self.params
        drift = min(p.hand_drift * max(tr.n_lost, 1), p.max_drift) * self.px_per_m
        return (anchor[0] + tr.offset[0], anchor[1] + tr.offset[1]), drift + max(tr.win) / 2

    def _reach_px(self, tr: MarkerTrack) -> float:
        """How far (px) a marker can have moved since it was last seen."""
        if self.px_per_m is None:
            return math.inf
        dt = max(self._time - tr.seen_at, 1 / 60)
        return self.params.max_speed * dt * self.px_per_m + max(tr.win)

    def _predict(self, tr: MarkerTrack, results: list[Located | None]) -> tuple[float, float]:
        """Where a marker should be: a digit moves with the band measured in this frame.

        At 30 frames/s a fast grasp's hand speeds up by a marker's width a
        frame: the band's own measurement in this frame, plus the digit's
        offset from it and that offset's last change (the grip opening),
        predicts a digit far better than the digit's own velocity. Other
        markers, and a digit whose band is not measured, use their velocity.
        """
        if tr.still or tr.name == "wrist" or tr.offset is None or tr.n_obs < 2:
            return tr.predicted
        xs, ys = [], []
        for k in self._anchors[self._tracks.index(tr)]:
            r = results[k]
            if r is not None and r[2] != Status.LOST:
                xs.append(r[0][0])
                ys.append(r[0][1])
        if not xs:
            return tr.predicted
        return (sum(xs) / len(xs) + tr.offset[0] + tr.offset_v[0],
                sum(ys) / len(ys) + tr.offset[1] + tr.offset_v[1])

    def _follow(self, tr: MarkerTrack, frame: np.ndarray,
                results: list[Located | None]) -> Located | None:
        """Track from the prediction; None if the marker is not in its region, or jumped.

        A jump faster than a hand (:meth:`_reach_px`), or a digit leaving
        its place relative to the band by more than ``hand_drift``, is
        something else. Run for every marker in every frame: the tests are
        written out in plain floats.
        """
        p = self.params
        pred = self._predict(tr, results)
        # the streak lies along the marker's motion this frame
        along = (pred[0] - tr.x[0], pred[1] - tr.x[1])
        if along == (0.0, 0.0):
            along = tr.v
        speed = max(tr.speed, math.hypot(along[0], along[1]))
        meas = measure_still(frame, tr.colour, tr.x, tr.win, tr.ref, p) if tr.still else None
        if meas is None and tr.n_obs < 2 and not tr.still:
            # Just (re)started, its velocity unknown: near where it was first,
            # then widely (a wide region lets CamShift's window take in
            # neighbours of the marker's colour).
            meas = measure(frame, tr.colour, pred, tr.win, tr.ref, p.search_margin_px, p)
            if meas is None or not p.lost_ratio <= meas.mass / tr.ref <= p.max_area_ratio:
                meas = None
        streak = 0.0
        if meas is None:
            meas = measure(frame, tr.colour, pred, tr.win, tr.ref, tr.margin(p), p)
            blurred = meas is None or meas.mass < WHOLE * tr.ref
            if blurred and tr.blur is not None and tr.n_obs >= 2 and not tr.still:
                # Too little of its own colour: a fast marker is a streak of
                # mixed colour (perception.tracking.blur), up to streak_mass of
                # it; one that sped up faster than its estimate (a grasp's first
                # frames) may have gone as far as the region reaches.
                streak = streak_mass(tr.ref, speed if is_fast(speed, tr.ref)
                                     else speed + tr.margin(p))
                smear = measure(frame, tr.blur, pred, tr.win, streak, tr.margin(p), p,
                                along if along != (0.0, 0.0) else None,
                                streak_width(tr.ref, p.rim_px))
                if smear is not None and smear.mass >= p.lost_ratio * tr.ref:
                    meas = smear
                else:
                    streak = 0.0
        if meas is None:
            return None
        ratio = meas.mass / tr.ref
        if ratio < p.lost_ratio or meas.mass > (STREAK_SLACK * streak if streak
                                                else p.max_area_ratio * tr.ref):
            return None  # hidden, or swallowed by something of its colour: search again
        cx, cy = meas.centre
        scale = self._first.scale
        if scale is not None:
            if math.dist(meas.centre, tr.x) > self._reach_px(tr):
                return None  # faster than a hand: something else
            offset = tr.offset
            if offset is not None and not tr.still and tr.name != "wrist":
                anchor = self._anchor(tr)
                near = p.hand_drift * scale + max(tr.win) / 2
                ox, oy = offset[0] + tr.offset_v[0], offset[1] + tr.offset_v[1]
                if anchor is not None and not (
                        math.hypot(cx - anchor[0] - offset[0], cy - anchor[1] - offset[1])
                        <= near or math.hypot(cx - anchor[0] - ox, cy - anchor[1] - oy) <= near):
                    return None  # left the rest of the hand: something else
        if tr.still:
            if ratio < p.hold_ratio:
                # Partly hidden (the hand closing on the object): the visible
                # part's centroid is biased, the object has not moved.
                return tr.x, min(ratio, 1.0), Status.TRACKED
            tr.observe(meas, p)
            return tr.x, likelihood(ratio), Status.TRACKED
        tr.observe(meas, p, blurred=bool(streak))
        tr.n_merged = tr.n_merged + 1 if meas.merged else 0
        if tr.n_merged > p.max_merged_frames:
            # Followed by prediction among its neighbour's pixels for a while:
            # where it is is no longer known, though the window stays on it.
            return (math.nan, math.nan), 0.0, Status.LOST
        lik = tr.likelihood(meas, p, streak)
        if streak and math.dist(meas.centre, pred) > diameter_px(tr.ref):
            # A streak a marker's width or more from where the motion puts it:
            # the streak or the motion estimate is wrong (a grasp speeding up).
            lik = min(lik, p.merged_likelihood)
        return meas.centre, lik, Status.TRACKED

    def _plausible_here(self, tr: MarkerTrack, centre: tuple[float, float]) -> bool:
        """Whether a re-acquired hand marker lies within the hand of the others tracked."""
        if tr.still or self.px_per_m is None:
            return True
        span = self.params.hand_span * self.px_per_m
        others = [t.x for t in self._tracks
                  if t is not tr and t.found and not t.lost and not t.still]
        return all(math.dist(centre, other) <= span for other in others)

    def _reacquire(self, tr: MarkerTrack, frame: np.ndarray) -> Located | None:
        """Global search while lost (see :func:`perception.tracking.reacquisition.reacquire`)."""
        p = self.params
        where, reach = self._expected_here(tr)

        def accept(meas: Measurement) -> bool:
            return (math.dist(meas.centre, where) <= reach and self._plausible_here(tr, meas.centre)
                    and self._looks_right(tr, frame, meas.centre))

        meas = reacquire(frame, self._small_hsv(frame), tr.colour, tr.ref, where, tr.win, p,
                         accept=accept)
        if meas is None:
            return None
        tr.n_obs = 0
        tr.v = (0.0, 0.0)
        tr.observe(meas, p)
        return meas.centre, tr.likelihood(meas, self.params), Status.REACQUIRED

    def _small_hsv(self, frame: np.ndarray) -> tuple[np.ndarray, float, float]:
        """Downscaled HSV of the whole frame, once per frame, for the global search."""
        if self._small is None:
            refs = [t.ref for t in self._tracks if t.found and t.ref > 0]
            self._small = downscaled_hsv(frame, search_scale(refs, self.params))
        return self._small


def _check_roi(name: str, roi: Any) -> ROI:
    try:
        x, y, w, h = (int(v) for v in roi)
    except (TypeError, ValueError):
        raise InputError(f"ROI for {name}: expected 4 integers x y w h, got {roi!r}") from None
    if x < 0 or y < 0 or w <= 0 or h <= 0:
        raise InputError(f"ROI for {name}: expected x, y >= 0 and w, h > 0, got {x} {y} {w} {h}")
    return x, y, w, h


def _roi_in_frame(name: str, roi: ROI, shape: tuple[int, ...]) -> None:
    x, y, w, h = roi
    if x + w > shape[1] or y + h > shape[0]:
        raise InputError(
            f"ROI for {name}: {x} {y} {w} {h} extends past the {shape[1]}x{shape[0]} frame"
        )

"""CamShift colour-marker tracker that survives real footage.

Each marker has a colour model (:mod:`perception.tracking.markers`;
``docs/markers.md``) and its own search window. :class:`Tracker` is the
per-frame loop; for each marker and frame it decides what to do and
delegates:

1. **Not found yet: first detection** (:mod:`perception.tracking.candidates`,
   :mod:`perception.tracking.hand`). On the first frames (the hand at rest)
   every blob of a marker's colour is a candidate, refused when its size,
   shape, colour purity or stillness does not fit the marker; the object
   (largest round candidate) sets the scale the expected sizes follow; the
   hand markers are chosen together by the hand's structure. Two equally
   plausible blobs make the marker *ambiguous* (status 4): it is not guessed.
   A user-given ROI says where a marker is.
2. **Tracked: follow.** An alpha-beta filter predicts the marker's position;
   the search region is the window around the prediction plus a margin that
   grows with speed. CamShift there gives the centroid and mass (pixel
   count) of the marker's colour, splitting off same-coloured blobs that
   joined the window (:mod:`perception.tracking.measurement`).
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

import contextlib
import itertools
import json
import logging
import math
import os
import sys
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from perception.errors import InputError
from perception.io.tracks import Status, TracksWriter, tracks_path_for
from perception.io.video import FrameSource
from perception.tracking.blobs import Blob, find_blobs
from perception.tracking.candidates import (
    Candidate,
    describe,
    expected_area,
    own_gate,
    reject_reason,
    strict,
)
from perception.tracking.hand import choose_hand
from perception.tracking.markers import MarkerColour, MarkerSet, default_markers
from perception.tracking.measurement import (
    Measurement,
    clamp_window,
    likelihood,
    measure,
    measure_still,
    soft_diameter,
)
from perception.tracking.params import TrackerParams
from perception.tracking.reacquisition import ROI, downscaled_hsv, reacquire, search_scale

__all__ = ["ROI", "Measurement", "Tracker", "TrackerParams", "track_frames", "track_video"]

logger = logging.getLogger(__name__)

#: What locating a marker in a frame gives: centre (x, y) px, likelihood, status.
_Located = tuple[tuple[float, float], float, int]


class _Track:
    """Mutable state of one marker's track (private to one :class:`Tracker`).

    ``x`` and ``v`` are the alpha-beta filter's position and velocity (px,
    px/frame) as ``(x, y)`` float pairs: on two numbers numpy's per-call
    cost would exceed the arithmetic. ``win`` is the CamShift window (px),
    ``ref`` the reference mass (px), ``n_obs`` the measurements since the
    track (re)started, ``seen_at`` the time (s) of its last measurement,
    ``rivals`` the blobs (px) it could be while ambiguous, ``rejected`` why
    candidates were not taken for it (reason -> count).
    """

    __slots__ = ("colour", "still", "roi", "found", "lost", "x", "v", "win", "ref", "n_obs",
                 "diameter", "seen_at", "rivals", "rejected", "offset", "n_lost", "n_merged")

    def __init__(self, colour: MarkerColour, still: bool, roi: ROI | None):
        self.colour = colour
        self.still = still
        self.roi = roi
        self.found = False
        self.lost = True
        self.x = (0.0, 0.0)
        self.v = (0.0, 0.0)
        self.win = (0, 0)
        self.ref = 0.0
        self.n_obs = 0
        self.diameter = float("nan")  # apparent diameter of a still round marker, px
        self.seen_at = 0.0
        self.rivals: list[tuple[float, float]] = []
        self.rejected: Counter = Counter()
        self.offset: tuple[float, float] | None = None  # from the rest of the hand, px
        self.n_lost = 0
        self.n_merged = 0  # consecutive frames measured merged with a neighbour

    @property
    def name(self) -> str:
        """The marker's name."""
        return self.colour.name

    @property
    def predicted(self) -> tuple[float, float]:
        """Where the marker should be in the next frame, px."""
        return self.x[0] + self.v[0], self.x[1] + self.v[1]

    def margin(self, p: TrackerParams) -> float:
        """Search margin around the predicted window, px."""
        if self.n_obs < 2 and not self.still:
            return p.initial_margin_px
        return p.search_margin_px + p.velocity_margin * math.hypot(self.v[0], self.v[1])

    def observe(self, meas: Measurement, p: TrackerParams) -> None:
        """Feed a measurement to the motion estimate, the window and the reference mass."""
        zx, zy = meas.centre
        x, y = self.x
        if self.still:
            # A still marker's position is the running mean of its whole-blob
            # measurements, restarted when it jumps (it was moved): slight,
            # unnoticed occlusions then barely move it.
            if self.n_obs == 0 or np.hypot(zx - x, zy - y) > p.still_jump_px:
                self.x = (zx, zy)
            else:
                rate = max(1.0 / (self.n_obs + 1), p.still_min_rate)
                self.x = (x + rate * (zx - x), y + rate * (zy - y))
            self.v = (0.0, 0.0)
        elif self.n_obs == 0:
            self.x, self.v = (zx, zy), (0.0, 0.0)
        elif self.n_obs == 1:
            self.v = (zx - x, zy - y)
            self.x = (zx, zy)
        elif meas.merged:
            # A merged blob's centroid is unreliable: keep the velocity.
            self.x = (zx, zy)
        else:
            (px, py), (vx, vy) = self.predicted, self.v
            rx, ry = zx - px, zy - py
            self.x = (px + p.alpha * rx, py + p.alpha * ry)
            self.v = (vx + p.beta * rx, vy + p.beta * ry)
        self.n_obs += 1
        self.lost = False
        if not meas.merged:
            self.win = clamp_window(meas.window, self.ref, p)
            ratio = meas.mass / self.ref
            if 1 / p.ref_update_band < ratio < p.ref_update_band:
                self.ref += p.ref_update * (meas.mass - self.ref)

    def coast(self, p: TrackerParams) -> None:
        """Not seen this frame: the prediction moves on, slowing down."""
        if self.found:
            self.x = self.predicted
            self.v = (self.v[0] * p.lost_velocity_decay, self.v[1] * p.lost_velocity_decay)
        self.lost = True
        self.n_obs = 0
        self.n_lost += 1


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

    Examples
    --------
    >>> tracker = Tracker()                                   # doctest: +SKIP
    >>> for index, time, frame in FrameSource("clip.mp4"):    # doctest: +SKIP
    ...     position, likelihood, status = tracker.update(frame, time)
    """

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
            _Track(m, m.name in self.params.still_markers, self.rois.get(m.name))
            for m in self.markers
        ]
        self.n_frames = 0
        self.ambiguities: dict[str, list[tuple[float, float]]] = {}
        self._frame_shape: tuple[int, int] | None = None
        self._small: tuple[np.ndarray, float, float] | None = None
        self._hsv: np.ndarray | None = None
        self._later: np.ndarray | None = None
        self._scale: float | None = None
        self._time = 0.0
        self._rest: dict[str, tuple[float, float]] | None = None  # hand markers at frame 0
        self._order = sorted(range(len(self._tracks)), key=lambda j: (
            not self._tracks[j].still, self._tracks[j].name != "wrist", j))

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
        return self._scale

    def why_not_found(self, name: str) -> str:
        """Why marker ``name`` has not been found: ambiguity or the candidates' rejections.

        Parameters
        ----------
        name : str
            A marker of this tracker.
        """
        tr = self._tracks[self.markers.names.index(name)]
        if tr.rivals:
            where = ", ".join(f"({x:.0f}, {y:.0f})" for x, y in tr.rivals[:3])
            return f"ambiguous: {len(tr.rivals)} blobs of its colour fit it equally, at {where} px"
        if tr.rejected:
            counts = ", ".join(f"{n} {why}" for why, n in tr.rejected.most_common())
            return f"no blob of its colour fits it ({counts})"
        return "nothing of its colour seen"

    def attrs(self) -> dict[str, Any]:
        """The ``/tracker`` attributes: method, colour models, criteria, parameters."""
        p = self.params
        out: dict[str, Any] = {
            "method": "camshift",
            "colour_models": self.markers.to_json(),
            "termination_criteria": json.dumps(
                {"type": "eps+count", "eps_px": p.term_eps_px, "max_iter": p.term_max_iter}
            ),
            "rois": json.dumps({k: list(v) for k, v in self.rois.items()}),
            "reference_mass_px": [float(t.ref) for t in self._tracks],
            "diameter_px": [float(t.diameter) for t in self._tracks],
            "ambiguous_rivals_px": json.dumps(
                {k: [list(map(float, c)) for c in v] for k, v in self.ambiguities.items()}),
        }
        for key, value in asdict(p).items():
            out[key] = json.dumps(value) if isinstance(value, tuple) else value
        return out

    def look_ahead(self, frame: np.ndarray) -> None:
        """Show the tracker a later frame of the clip's rest before the first :meth:`update`.

        First detection then rejects candidates that move between the first
        frame and this one (clips start with the hand at rest).

        Parameters
        ----------
        frame : (H, W, 3) uint8
            BGR frame, e.g. frame ``params.init_frames - 1``.
        """
        self._later = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)

    def update(self, frame: np.ndarray, time_s: float | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Track all markers in the next frame.

        Parameters
        ----------
        frame : (H, W, 3) uint8
            BGR image; frames must come in order.
        time_s : float, optional
            The frame's time, s (default: index / 30 frames/s); bounds how
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
        self._time = self.n_frames / 30.0 if time_s is None else float(time_s)
        m = len(self._tracks)
        position = np.full((m, 2), np.nan)
        lik = np.zeros(m, np.float32)
        status = np.full(m, Status.LOST, np.int8)
        self._small = self._hsv = None
        todo = [j for j, tr in enumerate(self._tracks) if not tr.found]
        started = self._initialise(frame, todo) if todo else {}
        results = {}
        for j in self._order:  # the object, the band, then the digits, which move relative to it
            tr = self._tracks[j]
            results[j] = started[j] if j in started else (self._follow(tr, frame) if not tr.lost
                                                          else None)
        # Lost markers are searched for once every followed one has moved on:
        # the hand's structure is then judged on this frame's positions.
        for j, tr in enumerate(self._tracks):
            if results[j] is None and tr.found:
                tr.lost = True
        for j, tr in enumerate(self._tracks):
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
            (position[j, 0], position[j, 1]), lik[j], status[j] = result
        self._record_offsets(position)
        if self.n_frames == 0:
            self._rest = {t.name: t.x for t in self._tracks if t.found and not t.still}
        self.n_frames += 1
        self._later = None
        return position, lik, status

    # -- steps --------------------------------------------------------------
    def _check_frame(self, frame: np.ndarray) -> None:
        if frame.ndim != 3 or frame.shape[2] != 3 or frame.dtype != np.uint8:
            raise ValueError(
                f"Tracker.update: expected an (H, W, 3) uint8 BGR frame, got {frame.shape} "
                f"{frame.dtype}"
            )
        if self._frame_shape is None:
            self._frame_shape = frame.shape[:2]
            for t in self._tracks:
                if t.roi is not None:
                    _roi_in_frame(t.name, t.roi, frame.shape)

    def _full_hsv(self, frame: np.ndarray) -> np.ndarray:
        """The whole frame in HSV, once per frame, for every marker not yet found."""
        if self._hsv is None:
            self._hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)
        return self._hsv

    def _scale_or_guess(self) -> float:
        """px/m: from the object, or a frame height spanning 0.6 m of table."""
        if self._scale is not None:
            return self._scale
        return self._frame_shape[0] / 0.6

    def _initialise(self, frame: np.ndarray, todo: list[int]) -> dict[int, _Located | None]:
        """Find markers for the first time (see :mod:`perception.tracking.candidates`).

        The still markers (the object) first: the object's apparent size
        sets the scale the hand markers' expected sizes follow. Hand markers
        are then chosen together by the hand's structure
        (:mod:`perception.tracking.hand`).
        """
        tracks = self._tracks
        found: dict[int, _Located | None] = {}
        for j in [j for j in todo if tracks[j].still]:
            found[j] = self._find_still(tracks[j], frame)
        hand = [j for j in todo if not tracks[j].still]
        if hand:
            found.update(self._find_hand(frame, hand))
        return found

    def _candidates(self, tr: _Track, frame: np.ndarray, later: bool) -> list[Candidate]:
        # A ROI says where the marker is on the first frame only.
        if tr.roi is not None and self.n_frames > 0:
            return []
        cands = describe(self._full_hsv(frame), tr.colour, self.params.min_area_px, tr.roi,
                         self._later if later else None)
        if tr.roi is not None and not cands:
            raise InputError(f"{tr.name}: nothing of its colour in the ROI {list(tr.roi)} "
                             "on the first frame")
        return cands

    def _survivors(self, tr: _Track, cands: list[Candidate], expected: float | None,
                   frame: np.ndarray, later: bool) -> list[Candidate]:
        """The candidates that may be the marker; rejections are counted on the track.

        A marker every candidate of which is too big may be touching a large
        thing of its hue: it is looked for again with the narrower gate of
        pure pixels (:func:`~perception.tracking.candidates.strict`), which
        its track then keeps.
        """
        p = self.params
        keep, too_big = [], False
        for c in cands:
            why = reject_reason(c, tr.name, tr.colour, expected, p)
            if why is None:
                keep.append(c)
            else:
                tr.rejected[why] += 1
                too_big |= why == "too big"
        if keep or not too_big or tr.roi is not None:
            return keep
        narrow = strict(tr.colour, p)
        pure = describe(self._full_hsv(frame), narrow, p.min_area_px, None,
                        self._later if later else None)
        keep = [c for c in pure if reject_reason(c, tr.name, narrow, expected, p) is None]
        if keep:
            tr.colour = narrow
        return keep

    def _own_gate(self, tr: _Track, frame: np.ndarray, blob: Blob) -> MarkerColour:
        """The track's gate narrowed to its marker's own pixels (see :func:`own_gate`)."""
        x, y, w, h = blob.box
        hsv = self._full_hsv(frame)[y:y + h, x:x + w]
        found = find_blobs(tr.colour.backproject(hsv))
        mask = tr.colour.backproject(hsv) > 0
        if found:  # only the component of the blob, not neighbours in its box
            n, labels = cv2.connectedComponents(mask.astype(np.uint8))
            cx, cy = int(blob.centre[0]) - x, int(blob.centre[1]) - y
            lab = labels[min(max(cy, 0), h - 1), min(max(cx, 0), w - 1)]
            if lab:
                mask = labels == lab
        return own_gate(tr.colour, hsv, mask, self.params)

    def _looks_right(self, tr: _Track, frame: np.ndarray, centre: tuple[float, float]) -> bool:
        """Whether the blob at ``centre`` has the marker's shape and colour purity."""
        half = max(tr.win) + 4
        h, w = frame.shape[:2]
        x0, y0 = max(int(centre[0] - half), 0), max(int(centre[1] - half), 0)
        x1, y1 = min(int(centre[0] + half) + 1, w), min(int(centre[1] + half) + 1, h)
        hsv = cv2.cvtColor(frame[y0:y1, x0:x1], cv2.COLOR_BGR2HSV)
        cands = describe(hsv, tr.colour, self.params.min_area_px)
        if not cands:
            return False
        c = min(cands, key=lambda c: math.hypot(c.centre[0] + x0 - centre[0],
                                                c.centre[1] + y0 - centre[1]))
        return reject_reason(c, tr.name, tr.colour, None, self.params) is None

    def _find_still(self, tr: _Track, frame: np.ndarray) -> _Located | None:
        """The object: the largest round, pure, still blob of its colour; it sets the scale."""
        cands = self._candidates(tr, frame, later=True)
        keep = self._survivors(tr, cands, None, frame, True) or (
            [cands[0]] if tr.roi and cands else [])
        if not keep:
            return None
        best = keep[0]
        rivals = [c for c in keep[1:] if c.area >= 0.5 * best.area]
        if rivals and tr.roi is None:
            return self._ambiguous(tr, [best, *rivals])
        located = self._start(tr, frame, best.blob)
        if located is not None:
            d = tr.diameter if np.isfinite(tr.diameter) else 2 * math.sqrt(tr.ref / math.pi)
            self._scale = d / self.params.object_diameter
        return located

    def _find_hand(self, frame: np.ndarray, todo: list[int], moving: bool = False
                   ) -> dict[int, _Located | None]:
        """Thumb, finger and wrist together: survivors of the tests, then the hand's structure.

        ``moving``: the clip does not start at rest; the hand's looser rules apply.
        """
        p, tracks = self.params, self._tracks
        scale = self._scale_or_guess()
        at_rest = self._hand_at_rest() and not moving
        cands = {j: self._not_rivals(tracks[j], self._candidates(tracks[j], frame,
                                                                later=at_rest))
                 for j in todo}
        survivors = {}
        for j in todo:
            tr = tracks[j]
            keep = self._survivors(tr, cands[j], expected_area(tr.name, scale, p), frame,
                                   at_rest)
            if tr.roi is not None and not keep and cands[j]:
                keep = cands[j][:1]  # the user pointed at it
            target = expected_area(tr.name, scale, p) or 1.0
            keep.sort(key=lambda c: abs(math.log(c.area / target)))
            survivors[j] = keep[: p.init_candidates]
        if self._later is not None and any(
                not survivors[j] and tracks[j].rejected["moving"] for j in todo):
            # A hand marker is there but moving: the clip does not start at rest, and
            # stillness cannot tell the markers from the rest.
            self._later = None
            return self._find_hand(frame, todo, moving=True)
        anchors = {t.name: t.x for t in tracks if t.found and not t.lost and not t.still}
        free = {tracks[j].name: survivors[j] for j in todo if tracks[j].roi is None}
        for j in todo:
            if tracks[j].roi is not None and survivors[j]:
                anchors[tracks[j].name] = survivors[j][0].centre
        choice = choose_hand(free, anchors, scale, p, at_rest=at_rest)
        out: dict[int, _Located | None] = {}
        for j in todo:
            tr = tracks[j]
            if tr.roi is not None:
                out[j] = self._start(tr, frame, survivors[j][0].blob) if survivors[j] else None
            elif tr.name in choice.chosen:
                out[j] = self._start(tr, frame, choice.chosen[tr.name].blob)
            elif tr.name in choice.ambiguous:
                out[j] = self._ambiguous(tr, choice.ambiguous[tr.name])
            else:
                out[j] = None
        return out

    def _hand_at_rest(self) -> bool:
        """Whether the hand has not moved yet: the first frame, or its tracked markers still."""
        if self.n_frames == 0:
            return True
        tracked = [t for t in self._tracks if t.found and not t.still]
        if not tracked or self._rest is None:
            return False
        near = 2 * self.params.rest_motion_px
        return all(t.name in self._rest and not t.lost
                   and math.hypot(t.x[0] - self._rest[t.name][0],
                                  t.x[1] - self._rest[t.name][1]) <= near for t in tracked)

    def _not_rivals(self, tr: _Track, cands: list[Candidate]) -> list[Candidate]:
        """Candidates of an ambiguous marker that have left every rival blob's place.

        The rivals were still when the marker became ambiguous; a blob still
        there is a thing on the table, or the marker of a hand that has not
        moved yet. The marker is told from the rest once it moves with the hand.
        """
        if not tr.rivals:
            return cands
        near = self.params.rest_motion_px
        return [c for c in cands
                if all(math.hypot(c.centre[0] - x, c.centre[1] - y) > near for x, y in tr.rivals)]

    def _ambiguous(self, tr: _Track, rivals: list[Candidate]) -> None:
        """Say once that a marker has rivals; it is reported ambiguous until resolved."""
        tr.rivals = [c.centre for c in rivals]
        if tr.name not in self.ambiguities:
            self.ambiguities[tr.name] = tr.rivals
            logger.warning("%s: %s; reported ambiguous (status %d) until it can be told "
                           "from them; give --roi %s X Y W H or a setup file (--setup)",
                           tr.name, self.why_not_found(tr.name), Status.AMBIGUOUS, tr.name)
        return None

    def _start(self, tr: _Track, frame: np.ndarray, blob: Blob) -> _Located | None:
        """Begin a track on a blob found by first detection."""
        p = self.params
        if not tr.still and p.own_saturation_margin > 0:
            tr.colour = self._own_gate(tr, frame, blob)
        tr.ref = blob.area
        tr.win = clamp_window(blob.size, tr.ref, p)
        meas = measure(frame, tr.colour, blob.centre, tr.win, tr.ref, p.search_margin_px, p)
        if meas is None:
            if tr.roi is not None:
                raise InputError(f"{tr.name}: something of its colour is in the ROI "
                                 f"{list(tr.roi)} but no marker could be measured there "
                                 "(make the ROI hold the whole marker)")
            return None
        tr.found = True
        tr.rivals = []
        tr.ref = meas.mass
        tr.n_obs = 0
        if tr.still and not np.isfinite(tr.diameter):
            tr.diameter = soft_diameter(frame, tr.colour, meas.centre, meas.window)
        tr.observe(meas, p)
        logger.info(
            "%s found at (%.1f, %.1f) px on frame %d, %d px of its colour",
            tr.name,
            *meas.centre,
            self.n_frames,
            meas.mass,
        )
        status = Status.TRACKED if self.n_frames == 0 else Status.REACQUIRED
        return meas.centre, self._likelihood(tr, meas), status

    def _anchor(self, tr: _Track, position: np.ndarray | None = None
                ) -> tuple[float, float] | None:
        """Where the rest of the hand is: the wrist for a digit, the digits for the wrist."""
        names = ("thumb", "finger") if tr.name == "wrist" else ("wrist",)
        xs, ys = [], []
        for j, t in enumerate(self._tracks):
            if t.name not in names or t is tr:
                continue
            if position is not None:
                x, y = float(position[j, 0]), float(position[j, 1])
                if math.isfinite(x) and math.isfinite(y):
                    xs.append(x)
                    ys.append(y)
            elif t.found and not t.lost:
                xs.append(t.x[0])
                ys.append(t.x[1])
        # plain floats: numpy's per-call cost would exceed the arithmetic
        return (sum(xs) / len(xs), sum(ys) / len(ys)) if xs else None

    def _record_offsets(self, position: np.ndarray) -> None:
        """Each measured hand marker's offset from the rest of the hand, for re-acquisition."""
        for j, tr in enumerate(self._tracks):
            x, y = float(position[j, 0]), float(position[j, 1])
            if tr.still or not (math.isfinite(x) and math.isfinite(y)):
                continue
            anchor = self._anchor(tr, position)
            tr.offset = None if anchor is None else (x - anchor[0], y - anchor[1])

    def _expected_here(self, tr: _Track) -> tuple[tuple[float, float], float]:
        """Where a lost marker should be and how far from it (px) it may be found.

        With the rest of the hand tracked, the marker moved with it: it is
        looked for at the same offset from it, within ``hand_drift`` per
        frame lost (at most ``max_drift``). Otherwise around its last
        position, within what ``max_speed`` allows.
        """
        anchor = self._anchor(tr)
        if anchor is None or tr.offset is None or self._scale is None or tr.still:
            return tr.x, self._reach_px(tr)
        p = self.params
        drift = min(p.hand_drift * max(tr.n_lost, 1), p.max_drift) * self._scale
        return (anchor[0] + tr.offset[0], anchor[1] + tr.offset[1]), drift + max(tr.win) / 2

    def _with_the_hand(self, tr: _Track, centre: tuple[float, float]) -> bool:
        """Whether a digit marker kept its place relative to the band (within ``hand_drift``)."""
        if tr.still or tr.name == "wrist" or tr.offset is None or self._scale is None:
            return True
        anchor = self._anchor(tr)
        if anchor is None:
            return True
        p = self.params
        allowed = p.hand_drift * self._scale + max(tr.win) / 2
        return math.hypot(centre[0] - anchor[0] - tr.offset[0],
                          centre[1] - anchor[1] - tr.offset[1]) <= allowed

    def _reach_px(self, tr: _Track) -> float:
        """How far (px) a marker can have moved since it was last seen."""
        if self._scale is None:
            return math.inf
        dt = max(self._time - tr.seen_at, 1 / 60)
        return self.params.max_speed * dt * self._scale + max(tr.win)

    def _follow(self, tr: _Track, frame: np.ndarray) -> _Located | None:
        """Track from the prediction; None if the marker is not in its region, or jumped."""
        p = self.params
        meas = measure_still(frame, tr.colour, tr.x, tr.win, tr.ref, p) if tr.still else None
        if meas is None:
            meas = measure(frame, tr.colour, tr.predicted, tr.win, tr.ref, tr.margin(p), p)
        if meas is None:
            return None
        ratio = meas.mass / tr.ref
        if ratio < p.lost_ratio or ratio > p.max_area_ratio:
            return None  # hidden, or swallowed by something of its colour: search again
        if math.hypot(meas.centre[0] - tr.x[0], meas.centre[1] - tr.x[1]) > self._reach_px(tr):
            return None  # faster than a hand: something else
        if not self._with_the_hand(tr, meas.centre):
            return None  # left the rest of the hand: something else
        if tr.still:
            if ratio < p.hold_ratio:
                # Partly hidden (the hand closing on the object): the visible
                # part's centroid is biased, the object has not moved.
                return tr.x, min(ratio, 1.0), Status.TRACKED
            tr.observe(meas, p)
            return tr.x, likelihood(ratio), Status.TRACKED
        tr.observe(meas, p)
        tr.n_merged = tr.n_merged + 1 if meas.merged else 0
        if tr.n_merged > p.max_merged_frames:
            # Followed by prediction among its neighbour's pixels for a while:
            # where it is is no longer known, though the window stays on it.
            return (math.nan, math.nan), 0.0, Status.LOST
        return meas.centre, self._likelihood(tr, meas), Status.TRACKED

    def _plausible_here(self, tr: _Track, centre: tuple[float, float]) -> bool:
        """Whether a re-acquired hand marker lies within the hand of the others tracked."""
        if tr.still or self._scale is None:
            return True
        span = self.params.hand_span * self._scale
        others = [t.x for t in self._tracks
                  if t is not tr and t.found and not t.lost and not t.still]
        return all(math.hypot(centre[0] - x, centre[1] - y) <= span for x, y in others)

    def _reacquire(self, tr: _Track, frame: np.ndarray) -> _Located | None:
        """Global search while lost (see :func:`perception.tracking.reacquisition.reacquire`)."""
        p = self.params
        where, reach = self._expected_here(tr)

        def accept(meas: Measurement) -> bool:
            jump = math.hypot(meas.centre[0] - where[0], meas.centre[1] - where[1])
            return (jump <= reach and self._plausible_here(tr, meas.centre)
                    and self._looks_right(tr, frame, meas.centre))

        meas = reacquire(frame, self._small_hsv(frame), tr.colour, tr.ref, where, tr.win, p,
                         accept=accept)
        if meas is None:
            return None
        tr.n_obs = 0
        tr.v = (0.0, 0.0)
        tr.observe(meas, p)
        return meas.centre, self._likelihood(tr, meas), Status.REACQUIRED

    def _likelihood(self, tr: _Track, meas: Measurement) -> float:
        """``min(r, 1/r)``; at most ``merged_likelihood`` when merged or among clutter."""
        lik = likelihood(meas.mass / tr.ref)
        crowded = not tr.still and meas.clutter > self.params.clutter_ratio * tr.ref
        return min(lik, self.params.merged_likelihood) if meas.merged or crowded else lik

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


def track_frames(
    frames: Iterable[tuple[int, float, np.ndarray]],
    writer: TracksWriter,
    tracker: Tracker,
    *,
    progress: Any = None,
    each_frame: Any = None,
) -> Tracker:
    """Track a stream of frames into an open :class:`TracksWriter`.

    The first ``tracker.params.init_frames`` frames are read ahead (the
    hand at rest) so that first detection can reject candidates that move
    (:meth:`Tracker.look_ahead`); memory holds those few frames only.

    Parameters
    ----------
    frames : iterable of (int, float, (H, W, 3) uint8)
        ``(index, time_s, frame)``, as :class:`~perception.io.video.FrameSource` yields.
    writer : TracksWriter
        Open writer whose markers are the tracker's.
    tracker : Tracker
        Tracker state (updated in place).
    progress : callable, optional
        Called with no arguments after each frame.
    each_frame : callable, optional
        Called as ``each_frame(index, time_s, frame, position, likelihood,
        status)`` after each frame (a labelled video, a contact sheet).

    Returns
    -------
    Tracker
        ``tracker``, for chaining.
    """
    it = iter(frames)
    ahead = list(itertools.islice(it, max(tracker.params.init_frames, 1)))
    if len(ahead) > 1 and tracker.n_frames == 0:
        tracker.look_ahead(ahead[-1][2])
    for index, time_s, frame in itertools.chain(ahead, it):
        position, likelihood, status = tracker.update(frame, time_s)
        writer.append(index, time_s, position, likelihood, status)
        if each_frame is not None:
            each_frame(index, time_s, frame, position, likelihood, status)
        if progress is not None:
            progress()
    return tracker


def track_video(
    video: str | os.PathLike,
    out: str | os.PathLike | None = None,
    *,
    markers: MarkerSet | None = None,
    params: TrackerParams | None = None,
    rois: Mapping[str, ROI] | None = None,
    progress: bool = False,
    prefetch: int = 8,
    labelled_video: str | os.PathLike | None = None,
) -> Path:
    """Track a video file into a tracks file (``<stem>.tracks.h5`` beside it by default).

    Parameters
    ----------
    video : str or os.PathLike
        Input video.
    out : str or os.PathLike, optional
        Output tracks file.
    markers, params, rois
        See :class:`Tracker`.
    progress : bool
        Show a progress bar on stderr.
    prefetch : int
        Frames decoded ahead in a background thread.
    labelled_video : str or os.PathLike, optional
        Also write the video with the markers drawn on it
        (:class:`~perception.tracking.overlay.Labeller`), atomically.

    Returns
    -------
    Path
        The tracks file, written atomically.

    Raises
    ------
    InputError
        Bad video (see :class:`~perception.io.video.FrameSource`), a bad ROI, or a
        marker never found (the message says why: rejected candidates, or
        ambiguity); no output file is left behind.
    """
    markers = default_markers() if markers is None else markers
    out_path = tracks_path_for(video) if out is None else Path(out)
    tracker = Tracker(markers, params, rois)
    with contextlib.ExitStack() as stack:
        src = stack.enter_context(FrameSource(video, prefetch=prefetch))
        w = stack.enter_context(TracksWriter(out_path, markers.names, video=src.attrs(),
                                             tracker=tracker.attrs()))
        each = None
        if labelled_video is not None:
            from perception.io.video import VideoWriter
            from perception.tracking.overlay import Labeller

            vw = stack.enter_context(VideoWriter(labelled_video, src.info.fps_nominal or 30.0,
                                                 (src.info.width, src.info.height)))
            labeller = Labeller(markers.names, [m.bgr for m in markers])

            def each(index, time_s, frame, position, likelihood, status):
                vw.write(labeller.draw(frame, position, likelihood, status))

        bar = None
        if progress:
            from tqdm import tqdm

            bar = stack.enter_context(tqdm(total=src.info.n_frames_header or None, unit="frame",
                                           file=sys.stderr, desc=Path(video).name,
                                           leave=False))
        try:
            track_frames(src, w, tracker, progress=bar.update if bar else None, each_frame=each)
        except InputError as exc:
            if exc.path is None:
                raise InputError(exc.problem, video) from None
            raise
        missing = tracker.never_found
        if missing:
            why = "; ".join(f"{m}: {tracker.why_not_found(m)}" for m in missing)
            raise InputError(
                f"marker{'s' if len(missing) > 1 else ''} {', '.join(missing)} never found "
                f"in {src.n_decoded} frames ({why}); check the colour models and marker "
                "sizes (hammer-mv calibrate, --setup), or give --roi MARKER X Y W H",
                video,
            )
        w.update(video=src.attrs(), tracker=tracker.attrs())
    logger.info("%s: tracked %d frames -> %s", video, src.n_decoded, out_path)
    return out_path

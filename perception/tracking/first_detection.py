"""First detection: finding markers that have no track yet.

On the first frames (the hand at rest) every blob of a marker's colour is a
candidate (:mod:`perception.tracking.candidates`), refused when its size,
shape, colour purity or stillness does not fit the marker. The still markers
(the object) come first: the object's apparent size sets the scale the hand
markers' expected sizes follow. The hand markers are then chosen together by
the hand's structure (:mod:`perception.tracking.hand`). Two equally plausible
blobs make a marker *ambiguous* (status 4): it is not guessed, and it is
looked for again, among the candidates that have left its rivals' places,
until it can be told from them. A user-given ROI says where a marker is on
the first frame.

:class:`FirstDetection` holds what this needs across frames (the look-ahead
frame, the hand's rest positions, the scale, the ambiguities) and starts the
:class:`~perception.tracking.marker_track.MarkerTrack` objects it is given;
:class:`~perception.tracking.tracker.Tracker` calls it for the markers not
found yet.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence

import cv2
import numpy as np

from perception.errors import InputError
from perception.io.tracks import Status
from perception.tracking.blobs import Blob, blob_at
from perception.tracking.blur import StreakGate, blur_gate
from perception.tracking.candidates import (
    Candidate,
    describe,
    expected_area,
    own_gate,
    reject_reason,
    strict,
)
from perception.tracking.hand import choose_hand
from perception.tracking.marker_track import Located, MarkerTrack
from perception.tracking.markers import MarkerColour
from perception.tracking.measurement import clamp_window, measure, soft_diameter
from perception.tracking.params import TrackerParams
from perception.tracking.reacquisition import ROI

__all__ = ["FirstDetection"]

# Under the tracker's name: a clip's tracking log (and any filter on it) stays in one place.
logger = logging.getLogger("perception.tracking.tracker")


class FirstDetection:
    """Start the tracks of markers not found yet, frame after frame.

    Parameters
    ----------
    tracks : sequence of MarkerTrack
        Every marker's track, in the markers' order (shared with the
        tracker, and started in place).
    params : TrackerParams
        Tuning and the markers' physical sizes.

    Attributes
    ----------
    scale : float or None
        px/m from the object's apparent size (None until it is found).
    ambiguities : dict of str to list of (float, float)
        Markers found ambiguous and the positions (px) of their rival blobs.
    """

    def __init__(self, tracks: Sequence[MarkerTrack], params: TrackerParams):
        self.tracks = tracks
        self.params = params
        self.scale: float | None = None
        self.ambiguities: dict[str, list[tuple[float, float]]] = {}
        self._later: np.ndarray | None = None  # HSV of a later frame of the rest
        self._rest: dict[str, tuple[float, float]] | None = None  # hand markers at frame 0
        self._height: int | None = None  # of the first frame, px
        self._hsv: np.ndarray | None = None
        self._index = 0

    def look_ahead(self, frame: np.ndarray) -> None:
        """Reject candidates that move between the first frame and ``frame`` (BGR)."""
        self._later = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)

    def detect(self, frame: np.ndarray, todo: list[int], index: int
               ) -> dict[int, Located | None]:
        """Find the markers ``todo`` (indices into the tracks) in frame ``index``.

        Parameters
        ----------
        frame : (H, W, 3) uint8
            BGR frame.
        todo : list of int
            The tracks not found yet.
        index : int
            The frame's index in the clip (0: the first frame, where ROIs apply).

        Returns
        -------
        dict of int to (centre, likelihood, status) or None
            For each of ``todo``: where it was found, or None (not found, or
            ambiguous).
        """
        self._index = index
        self._hsv = None
        if self._height is None:
            self._height = frame.shape[0]
        tracks = self.tracks
        found: dict[int, Located | None] = {
            j: self._find_still(tracks[j], frame) for j in todo if tracks[j].still}
        hand = [j for j in todo if not tracks[j].still]
        if hand:
            found.update(self._find_hand(frame, hand))
        return found

    def frame_done(self, index: int) -> None:
        """After frame ``index``: remember where the hand rests; the look-ahead is spent."""
        if index == 0:
            self._rest = {t.name: t.x for t in self.tracks if t.found and not t.still}
        self._later = None

    # -- steps --------------------------------------------------------------
    def _full_hsv(self, frame: np.ndarray) -> np.ndarray:
        """The whole frame in HSV, once per frame, for every marker not yet found."""
        if self._hsv is None:
            self._hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)
        return self._hsv

    def _scale_or_guess(self) -> float:
        """px/m: from the object, or a frame height spanning ``table_height_m`` of table."""
        return self._height / self.params.table_height_m if self.scale is None else self.scale

    def _describe(self, frame: np.ndarray, colour: MarkerColour, roi: ROI | None,
                  later: bool) -> list[Candidate]:
        p = self.params
        return describe(self._full_hsv(frame), colour, p.min_area_px, roi,
                        self._later if later else None, p.max_blobs, p.rest_area_ratio)

    def _candidates(self, tr: MarkerTrack, frame: np.ndarray, later: bool) -> list[Candidate]:
        # A ROI says where the marker is on the first frame only.
        if tr.roi is not None and self._index > 0:
            return []
        cands = self._describe(frame, tr.colour, tr.roi, later)
        if tr.roi is not None and not cands:
            raise InputError(f"{tr.name}: nothing of its colour in the ROI {list(tr.roi)} "
                             "on the first frame")
        return cands

    def _survivors(self, tr: MarkerTrack, cands: list[Candidate], expected: float | None,
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
        pure = self._describe(frame, narrow, None, later)
        keep = [c for c in pure if reject_reason(c, tr.name, narrow, expected, p) is None]
        if keep:
            tr.colour = narrow
        return keep

    def _own_gate(self, tr: MarkerTrack, frame: np.ndarray, blob: Blob) -> MarkerColour:
        """The track's gate narrowed to its marker's own pixels (see :func:`own_gate`)."""
        x, y, w, h = blob.box
        hsv = self._full_hsv(frame)[y:y + h, x:x + w]
        bp = tr.colour.backproject(hsv)
        # only the component of the blob, not neighbours in its box
        mask = blob_at(bp, (int(blob.centre[0]) - x, int(blob.centre[1]) - y))
        return own_gate(tr.colour, hsv, bp > 0 if mask is None else mask, self.params)

    def _find_still(self, tr: MarkerTrack, frame: np.ndarray) -> Located | None:
        """The object: the largest round, pure, still blob of its colour; it sets the scale."""
        cands = self._candidates(tr, frame, later=True)
        keep = self._survivors(tr, cands, None, frame, True) or (
            [cands[0]] if tr.roi and cands else [])
        if not keep:
            return None
        best = keep[0]
        rivals = [c for c in keep[1:] if c.area >= self.params.object_rival_ratio * best.area]
        if rivals and tr.roi is None:
            return self._ambiguous(tr, [best, *rivals])
        located = self._start(tr, frame, best.blob)
        if located is not None:
            d = tr.diameter if np.isfinite(tr.diameter) else 2 * math.sqrt(tr.ref / math.pi)
            self.scale = d / self.params.object_diameter
        return located

    def _find_hand(self, frame: np.ndarray, todo: list[int], moving: bool = False
                   ) -> dict[int, Located | None]:
        """Thumb, finger and wrist together: survivors of the tests, then the hand's structure.

        ``moving``: the clip does not start at rest; the hand's looser rules apply.
        """
        p, tracks = self.params, self.tracks
        scale = self._scale_or_guess()
        at_rest = self._hand_at_rest() and not moving
        cands = {j: self._not_rivals(tracks[j], self._candidates(tracks[j], frame,
                                                                later=at_rest))
                 for j in todo}
        survivors = {}
        for j in todo:
            tr = tracks[j]
            expected = expected_area(tr.name, scale, p)
            keep = self._survivors(tr, cands[j], expected, frame, at_rest)
            if tr.roi is not None and not keep and cands[j]:
                keep = cands[j][:1]  # the user pointed at it
            target = expected or 1.0
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
        out: dict[int, Located | None] = dict.fromkeys(todo)
        for j in todo:
            tr = tracks[j]
            if tr.roi is not None:
                out[j] = self._start(tr, frame, survivors[j][0].blob) if survivors[j] else None
            elif tr.name in choice.chosen:
                out[j] = self._start(tr, frame, choice.chosen[tr.name].blob)
            elif tr.name in choice.ambiguous:
                self._ambiguous(tr, choice.ambiguous[tr.name])
        return out

    def _hand_at_rest(self) -> bool:
        """Whether the hand has not moved yet: the first frame, or its tracked markers still."""
        if self._index == 0:
            return True
        tracked = [t for t in self.tracks if t.found and not t.still]
        if not tracked or self._rest is None:
            return False
        near = 2 * self.params.rest_motion_px
        return all(t.name in self._rest and not t.lost
                   and math.dist(t.x, self._rest[t.name]) <= near for t in tracked)

    def _not_rivals(self, tr: MarkerTrack, cands: list[Candidate]) -> list[Candidate]:
        """Candidates of an ambiguous marker that have left every rival blob's place.

        The rivals were still when the marker became ambiguous; a blob still
        there is a thing on the table, or the marker of a hand that has not
        moved yet. The marker is told from the rest once it moves with the hand.
        """
        if not tr.rivals:
            return cands
        near = self.params.rest_motion_px
        return [c for c in cands if all(math.dist(c.centre, r) > near for r in tr.rivals)]

    def _ambiguous(self, tr: MarkerTrack, rivals: list[Candidate]) -> None:
        """Say once that a marker has rivals; it is reported ambiguous until resolved."""
        tr.rivals = [c.centre for c in rivals]
        if tr.name not in self.ambiguities:
            self.ambiguities[tr.name] = tr.rivals
            logger.warning("%s: %s; reported ambiguous (status %d) until it can be told "
                           "from them; give `rois` %s X Y W H or a setup file "
                           "(hammer-mv calibrate)",
                           tr.name, tr.why_not_found(), Status.AMBIGUOUS, tr.name)

    def _start(self, tr: MarkerTrack, frame: np.ndarray, blob: Blob) -> Located | None:
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
        if not tr.still:
            x, y, w, h = blob.box
            own = tr.colour.backproject(self._full_hsv(frame)[y:y + h, x:x + w]) > 0
            hsv = blur_gate(tr.colour, self._full_hsv(frame), blob.box, meas.mass, p.lost_ratio)
            if own.any():
                bgr = np.median(frame[y:y + h, x:x + w][own], axis=0)
                tr.blur = StreakGate(tuple(float(v) for v in bgr),
                                     tr.colour if hsv is None else hsv)
        tr.n_obs = 0
        if tr.still and not np.isfinite(tr.diameter):
            tr.diameter = soft_diameter(frame, tr.colour, meas.centre, meas.window, p)
        tr.observe(meas, p)
        logger.info("%s found at (%.1f, %.1f) px on frame %d, %d px of its colour",
                    tr.name, *meas.centre, self._index, meas.mass)
        status = Status.TRACKED if self._index == 0 else Status.REACQUIRED
        return meas.centre, tr.likelihood(meas, p), status

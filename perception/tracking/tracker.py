"""CamShift colour-marker tracker that survives real footage.

Each marker has a colour model (:mod:`perception.tracking.markers`) and its own
search window. Per frame and marker:

1. **Prediction.** An alpha-beta filter predicts the marker's position; the
   search region is the window around the prediction plus a margin that
   grows with speed. Only this region is converted to HSV and
   back-projected, so decoding, not tracking, limits throughput.
2. **CamShift** on the back-projection (hue range, saturation and value
   minimums) from the predicted window, with a minimum window size.
3. **Measurement.** Centroid and mass (pixel count) of the back-projection in
   the converged window. If the mass is well above the marker's reference
   mass, same-coloured pixels joined the window (a distractor): connected
   components in the region split them and the component nearest the
   prediction is kept; if the blobs touch, the centroid is taken in a
   reference-sized window at the prediction and the likelihood drops.
4. **Lost test.** A mass below ``lost_ratio`` x reference means the marker is
   hidden or gone: it is reported lost (NaN, likelihood 0, status 2), never
   as a stale position.
5. **Re-acquisition**, only once the local search has failed and while the
   marker stays lost: connected components of the thresholded
   back-projection of a downscaled full frame (computed once per frame for
   all lost markers); the one nearest the prediction with a plausible area is
   refined at full resolution and reported with status 1.

Markers are found automatically on the first frames (the largest blob of
each colour; among blobs of comparable size a hand marker takes the one
nearest the other hand markers) or inside user-given ROIs. Markers listed in
``still_markers`` (the object) are expected to stay put and to be partly
hidden by the hand at the end: their position is the running mean of
whole-blob measurements (restarted if the blob jumps, i.e. the object was
moved), and while less than ``hold_ratio`` of the blob is visible the
position is held, with likelihood equal to the visible fraction.

Likelihood is ``min(r, 1/r)`` with ``r`` the measured mass over the
reference mass: 1 for a whole, uncontaminated marker; lower when partly
hidden or merged with similar colour.
"""

from __future__ import annotations

import itertools
import json
import logging
import math
import os
import sys
from collections.abc import Iterable, Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any, NamedTuple

import cv2
import numpy as np

from perception.errors import InputError
from perception.io.tracks import Status, TracksWriter, tracks_path_for
from perception.io.video import FrameSource
from perception.tracking.markers import MarkerColour, MarkerSet, default_markers
from perception.tracking.params import TrackerParams

logger = logging.getLogger(__name__)
#: A region of interest: ``(x, y, width, height)``, px.
ROI = tuple[int, int, int, int]


class Measurement(NamedTuple):
    """One marker located in one frame: centre (x, y) px, mass px, window (w, h) px."""

    centre: tuple[float, float]
    mass: float
    window: tuple[int, int]
    merged: bool = False


class _Track:
    """Mutable state of one marker's track (private to one :class:`Tracker`)."""

    __slots__ = ("colour", "still", "roi", "found", "lost", "x", "v", "win", "ref", "n_obs",
                 "diameter")

    def __init__(self, colour: MarkerColour, still: bool, roi: ROI | None):
        self.colour = colour
        self.still = still
        self.roi = roi
        self.found = False
        self.lost = True
        self.x = np.zeros(2)
        self.v = np.zeros(2)
        self.win = (0, 0)
        self.ref = 0.0
        self.n_obs = 0
        self.diameter = float("nan")  # apparent diameter of a still round marker, px


class Tracker:
    """Track every marker of a :class:`MarkerSet` through a stream of frames.

    Parameters
    ----------
    markers : MarkerSet, optional
        Colour models (default :func:`perception.tracking.markers.default_markers`).
    params : TrackerParams, optional
        Tuning (defaults suit 25-60 fps clips of 2 cm markers at 500-1500 px/m).
    rois : mapping of str to (x, y, w, h), optional
        Manual initial regions per marker, px; a marker with a ROI is looked
        for only there on the first frame.

    Examples
    --------
    >>> tracker = Tracker()                                   # doctest: +SKIP
    >>> for index, time, frame in FrameSource("clip.mp4"):    # doctest: +SKIP
    ...     position, likelihood, status = tracker.update(frame)
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
        self._criteria = self.params.criteria
        self.n_frames = 0
        self._frame_shape: tuple[int, int] | None = None
        self._small: tuple[np.ndarray, float, float] | None = None

    # -- public -------------------------------------------------------------
    @property
    def found(self) -> np.ndarray:
        """(M,) bool: whether each marker has been found at least once."""
        return np.array([t.found for t in self._tracks])

    @property
    def never_found(self) -> list[str]:
        """Names of markers not found in any frame so far."""
        return [t.colour.name for t in self._tracks if not t.found]

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
        }
        for key, value in asdict(p).items():
            out[key] = json.dumps(value) if isinstance(value, tuple) else value
        return out

    def update(self, frame: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Track all markers in the next frame.

        Parameters
        ----------
        frame : (H, W, 3) uint8
            BGR image; frames must come in order.

        Returns
        -------
        position : (M, 2) float64
            px; NaN where lost.
        likelihood : (M,) float32
            0..1; 0 where lost.
        status : (M,) int8
            :class:`~perception.io.tracks.Status` codes.
        """
        if frame.ndim != 3 or frame.shape[2] != 3 or frame.dtype != np.uint8:
            raise ValueError(
                f"Tracker.update: expected an (H, W, 3) uint8 BGR frame, got {frame.shape} "
                f"{frame.dtype}"
            )
        if self._frame_shape is None:
            self._frame_shape = frame.shape[:2]
            for t in self._tracks:
                if t.roi is not None:
                    _roi_in_frame(t.colour.name, t.roi, frame.shape)
        m = len(self._tracks)
        position = np.full((m, 2), np.nan)
        likelihood = np.zeros(m, np.float32)
        status = np.full(m, Status.LOST, np.int8)
        self._small = None
        todo = [j for j, tr in enumerate(self._tracks) if not tr.found]
        started = self._initialise(frame, todo) if todo else {}
        for j, tr in enumerate(self._tracks):
            if j in started:
                result = started[j]
            elif not tr.lost:
                result = self._follow(tr, frame)
            else:
                result = None
            if tr.found and result is None:
                result = self._reacquire(tr, frame)
            if result is None:
                self._mark_lost(tr)
                continue
            (cx, cy), lik, st = result
            position[j, 0] = cx
            position[j, 1] = cy
            likelihood[j] = lik
            status[j] = st
        self.n_frames += 1
        return position, likelihood, status

    # -- steps --------------------------------------------------------------
    def _margin(self, tr: _Track) -> float:
        p = self.params
        if tr.n_obs < 2 and not tr.still:
            return p.initial_margin_px
        return p.search_margin_px + p.velocity_margin * math.hypot(tr.v[0], tr.v[1])

    def _follow(self, tr: _Track, frame: np.ndarray):
        """Track from the prediction; None if the marker is not in its region."""
        p = self.params
        meas = self._measure_still(tr, frame) if tr.still else None
        if meas is None:
            meas = self._measure(tr, frame, tr.x + tr.v, self._margin(tr), tr.win)
        if meas is None:
            return None
        ratio = meas.mass / tr.ref
        if ratio < p.lost_ratio:
            return None
        if tr.still:
            if ratio < p.hold_ratio:
                # Partly hidden (the hand closing on the object): the visible
                # part's centroid is biased, the object has not moved.
                return (tr.x[0], tr.x[1]), min(ratio, 1.0), Status.TRACKED
            self._observe(tr, meas)
            return (tr.x[0], tr.x[1]), _likelihood(ratio), Status.TRACKED
        self._observe(tr, meas)
        return meas.centre, _likelihood(ratio), Status.TRACKED

    def _observe(self, tr: _Track, meas: Measurement) -> None:
        """Feed a measurement to the alpha-beta filter and the reference mass."""
        p = self.params
        z = np.asarray(meas.centre)
        if tr.still:
            # A still marker's position is the running mean of its whole-blob
            # measurements, restarted when it jumps (it was moved): slight,
            # unnoticed occlusions then barely move it.
            if tr.n_obs == 0 or np.hypot(*(z - tr.x)) > p.still_jump_px:
                tr.x = z
            else:
                tr.x = tr.x + max(1.0 / (tr.n_obs + 1), p.still_min_rate) * (z - tr.x)
            tr.v = np.zeros(2)
        elif tr.n_obs == 0:
            tr.x, tr.v = z, np.zeros(2)
        elif tr.n_obs == 1:
            tr.v = z - tr.x
            tr.x = z
        elif meas.merged:
            # A merged blob's centroid is unreliable: keep the velocity.
            tr.x = z
        else:
            pred = tr.x + tr.v
            r = z - pred
            tr.x = pred + p.alpha * r
            tr.v = tr.v + p.beta * r
        tr.n_obs += 1
        tr.lost = False
        if not meas.merged:
            tr.win = _clamp_window(meas.window, tr.ref, p)
            ratio = meas.mass / tr.ref
            if 1 / p.ref_update_band < ratio < p.ref_update_band:
                tr.ref += p.ref_update * (meas.mass - tr.ref)

    def _mark_lost(self, tr: _Track) -> None:
        if tr.found:
            tr.x = tr.x + tr.v
            tr.v = tr.v * self.params.lost_velocity_decay
        tr.lost = True
        tr.n_obs = 0

    def _measure(
        self,
        tr: _Track,
        frame: np.ndarray,
        centre: np.ndarray,
        margin: float,
        window: tuple[int, int],
        recentre: bool = True,
    ) -> Measurement | None:
        """CamShift in the region around ``centre``; centroid and mass of the result.

        If the blob reaches the region's edge (the marker moved further than
        the margin allowed for), the region is centred on it and measured once
        more, so a cut-off blob never biases the centroid.
        """
        p = self.params
        h, w = frame.shape[:2]
        ww, wh = window
        cx, cy = float(centre[0]), float(centre[1])
        if not (math.isfinite(cx) and math.isfinite(cy)):
            return None
        x0 = max(int(cx - ww / 2 - margin), 0)
        x1 = min(int(cx + ww / 2 + margin) + 1, w)
        y0 = max(int(cy - wh / 2 - margin), 0)
        y1 = min(int(cy + wh / 2 + margin) + 1, h)
        if x1 - x0 < 3 or y1 - y0 < 3:
            return None  # the prediction left the frame
        hsv = cv2.cvtColor(frame[y0:y1, x0:x1], cv2.COLOR_BGR2HSV)
        bp = tr.colour.backproject(hsv)
        rw, rh = x1 - x0, y1 - y0
        wx = min(max(int(round(cx - ww / 2)) - x0, 0), rw - 1)
        wy = min(max(int(round(cy - wh / 2)) - y0, 0), rh - 1)
        win = (wx, wy, max(min(ww, rw - wx), 1), max(min(wh, rh - wy), 1))
        box, (bx, by, bw, bh) = cv2.CamShift(bp, win, self._criteria)
        if box[1][0] <= 0 or bw <= 0 or bh <= 0:
            # Nothing of the colour in the window: look for it in the region.
            found = self._nearest_component(bp, (cx - x0, cy - y0), tr.ref)
            if found is None:
                return None
            box, (bx, by, bw, bh) = cv2.CamShift(bp, found, self._criteria)
            if box[1][0] <= 0 or bw <= 0 or bh <= 0:
                return None
        # CamShift's window of a round blob can be as small as 0.71 x its
        # diameter (it boxes the rotated ellipse axis by axis): measure in a
        # square 1.5 x larger around its centre so the whole blob counts.
        half = 0.75 * max(bw, bh) + 2
        bcx, bcy = box[0]
        mx0, my0 = max(int(bcx - half), 0), max(int(bcy - half), 0)
        mx1, my1 = min(int(bcx + half) + 2, rw), min(int(bcy + half) + 2, rh)
        mo = cv2.moments(bp[my0:my1, mx0:mx1], True)
        mass = mo["m00"]
        if mass <= 0:
            return None
        # Next window: the blob's extent (4 sigma per axis, 2r for a disc).
        extent = (
            int(4 * math.sqrt(mo["mu20"] / mass)) + 4,
            int(4 * math.sqrt(mo["mu02"] / mass)) + 4,
        )
        meas = Measurement((mo["m10"] / mass + x0 + mx0, mo["m01"] / mass + y0 + my0), mass, extent)
        if tr.ref > 0 and mass > p.split_ratio * tr.ref:
            meas = self._split(tr, bp, (x0, y0), (cx - x0, cy - y0)) or meas
        if recentre and not meas.merged and _cut_off(bp, meas, (x0, y0, x1, y1), (w, h)):
            again = self._measure(tr, frame, meas.centre, p.search_margin_px, meas.window, False)
            if again is not None:
                return again
        return meas

    def _measure_still(self, tr: _Track, frame: np.ndarray) -> Measurement | None:
        """Moments in the window of a marker that has not moved; None if it seems to have.

        A still object needs no mean-shift search while it stays put: one
        moments call at its position costs a third of a CamShift. Any sign
        of motion or of a neighbour of its colour falls back to :meth:`_measure`.
        """
        p = self.params
        h, w = frame.shape[:2]
        half = 0.5 * max(tr.win) + 4
        cx, cy = float(tr.x[0]), float(tr.x[1])
        x0, y0 = max(int(cx - half), 0), max(int(cy - half), 0)
        x1, y1 = min(int(cx + half) + 2, w), min(int(cy + half) + 2, h)
        if x1 - x0 < 3 or y1 - y0 < 3:
            return None
        bp = tr.colour.backproject(cv2.cvtColor(frame[y0:y1, x0:x1], cv2.COLOR_BGR2HSV))
        mo = cv2.moments(bp, True)
        mass = mo["m00"]
        if mass <= 0 or mass > p.split_ratio * tr.ref:
            return None
        centre = (mo["m10"] / mass + x0, mo["m01"] / mass + y0)
        shift = math.hypot(centre[0] - cx, centre[1] - cy)
        if mass >= p.hold_ratio * tr.ref and shift > p.still_shift_px:
            return None  # whole but off-centre: it is moving
        # A blob touching the region's edge may extend beyond it: search properly.
        rh, rw = bp.shape
        if (
            (x0 > 0 and cv2.countNonZero(bp[:, 0]))
            or (y0 > 0 and cv2.countNonZero(bp[0, :]))
            or (x1 < w and cv2.countNonZero(bp[:, rw - 1]))
            or (y1 < h and cv2.countNonZero(bp[rh - 1, :]))
        ):
            return None
        extent = (
            int(4 * math.sqrt(mo["mu20"] / mass)) + 4,
            int(4 * math.sqrt(mo["mu02"] / mass)) + 4,
        )
        return Measurement(centre, mass, extent)

    def _nearest_component(
        self, bp: np.ndarray, centre: tuple[float, float], ref: float
    ) -> tuple[int, int, int, int] | None:
        """Bounding box of the plausible blob nearest ``centre`` (region coords)."""
        n, _, stats, cents = cv2.connectedComponentsWithStats(bp, connectivity=8)
        if n <= 1:
            return None
        areas = stats[1:, cv2.CC_STAT_AREA]
        ok = areas >= max(self.params.lost_ratio * ref, 1)
        if not ok.any():
            return None
        d = np.hypot(cents[1:, 0] - centre[0], cents[1:, 1] - centre[1])
        k = int(np.argmin(np.where(ok, d, np.inf))) + 1
        x, y, bw, bh = (int(v) for v in stats[k, :4])
        return x, y, bw, bh

    def _split(
        self, tr: _Track, bp: np.ndarray, offset: tuple[int, int], pred: tuple[float, float]
    ) -> Measurement | None:
        """Separate same-coloured blobs that joined the window; keep the nearest."""
        p = self.params
        n, _, stats, cents = cv2.connectedComponentsWithStats(bp, connectivity=8)
        if n <= 1:
            return None
        areas = stats[1:, cv2.CC_STAT_AREA].astype(np.float64)
        ok = areas >= p.lost_ratio * tr.ref
        if not ok.any():
            return None
        d = np.hypot(cents[1:, 0] - pred[0], cents[1:, 1] - pred[1])
        k = int(np.argmin(np.where(ok, d, np.inf)))
        area = areas[k]
        if area <= p.merge_ratio * tr.ref:
            c = cents[k + 1]
            w, h = int(stats[k + 1, cv2.CC_STAT_WIDTH]), int(stats[k + 1, cv2.CC_STAT_HEIGHT])
            return Measurement((c[0] + offset[0], c[1] + offset[1]), area, (w, h))
        # Touching blobs: take the centroid in a reference-sized window at the
        # prediction, so the neighbour can pull the estimate only partly.
        side = _ref_side(tr.ref)
        x0 = max(int(round(pred[0] - side / 2)), 0)
        y0 = max(int(round(pred[1] - side / 2)), 0)
        mo = cv2.moments(bp[y0 : y0 + side, x0 : x0 + side], True)
        if mo["m00"] <= 0:
            return None
        centre = (mo["m10"] / mo["m00"] + x0 + offset[0], mo["m01"] / mo["m00"] + y0 + offset[1])
        return Measurement(centre, area, tr.win, merged=True)

    def _candidates(self, tr: _Track, frame: np.ndarray) -> list[tuple[np.ndarray, float, tuple]]:
        """Blobs of a marker's colour (in its ROI, if any), largest first.

        Each is ``(centre (2,) px, area px, (w, h) px)``.
        """
        if tr.roi is not None:
            if self.n_frames > 0:
                return []
            x, y, w, h = tr.roi
            region, offset = frame[y : y + h, x : x + w], np.array([x, y])
        else:
            region, offset = frame, np.zeros(2)
        bp = tr.colour.backproject(cv2.cvtColor(region, cv2.COLOR_BGR2HSV))
        n, _, stats, cents = cv2.connectedComponentsWithStats(bp, connectivity=8)
        out = [
            (
                cents[k] + offset,
                float(stats[k, cv2.CC_STAT_AREA]),
                (int(stats[k, cv2.CC_STAT_WIDTH]), int(stats[k, cv2.CC_STAT_HEIGHT])),
            )
            for k in range(1, n)
            if stats[k, cv2.CC_STAT_AREA] >= self.params.min_area_px
        ]
        if not out and tr.roi is not None:
            raise InputError(
                f"{tr.colour.name}: nothing of its colour in the ROI {list(tr.roi)} "
                "on the first frame"
            )
        return sorted(out, key=lambda c: -c[1])

    def _initialise(self, frame: np.ndarray, todo: list[int]) -> dict[int, Any]:
        """Find markers for the first time.

        The hand's markers sit within a hand's width of each other, while
        same-coloured things on the table need not: of the few largest blobs
        of each hand marker's colour, the combination whose markers lie
        closest together (with any hand marker already tracked) wins, however
        large a distant blob is. A still marker (the object), or a marker
        without rivals, takes its largest blob.
        """
        n_cands = self.params.init_candidates
        cands = {j: self._candidates(self._tracks[j], frame)[:n_cands] for j in todo}
        free = [j for j in todo if cands[j] and not self._tracks[j].still
                and self._tracks[j].roi is None]
        anchors = [t.x for t in self._tracks if t.found and not t.lost and not t.still] + [
            cands[j][0][0] for j in todo if cands[j] and not self._tracks[j].still
            and self._tracks[j].roi is not None]
        chosen: dict[int, tuple] = {}
        if free and len(free) + len(anchors) >= 2:

            def spread(combo):
                pts = [cands[j][k][0] for j, k in zip(free, combo)] + anchors
                return sum(float(np.hypot(*(p - q))) for i, p in enumerate(pts)
                           for q in pts[i + 1:])

            best = min(itertools.product(*(range(len(cands[j])) for j in free)), key=spread)
            chosen = {j: cands[j][k] for j, k in zip(free, best)}
        results: dict[int, Any] = {}
        for j in todo:
            if not cands[j]:
                results[j] = None
                continue
            results[j] = self._start(self._tracks[j], frame, chosen.get(j, cands[j][0]))
        return results

    def _start(self, tr: _Track, frame: np.ndarray, blob: tuple[np.ndarray, float, tuple]):
        """Begin a track on a blob found by :meth:`_candidates`."""
        p = self.params
        centre, area, win = blob
        tr.ref = area
        tr.win = _clamp_window(win, tr.ref, p)
        meas = self._measure(tr, frame, centre, p.search_margin_px, tr.win)
        if meas is None:
            return None
        tr.found = True
        tr.ref = meas.mass
        tr.n_obs = 0
        if tr.still and not np.isfinite(tr.diameter):
            tr.diameter = _soft_diameter(frame, tr.colour, meas.centre, meas.window)
        self._observe(tr, meas)
        logger.info(
            "%s found at (%.1f, %.1f) px on frame %d, %d px of its colour",
            tr.colour.name,
            *meas.centre,
            self.n_frames,
            meas.mass,
        )
        status = Status.TRACKED if self.n_frames == 0 else Status.REACQUIRED
        return meas.centre, 1.0, status

    def _small_hsv(self, frame: np.ndarray) -> tuple[np.ndarray, float, float]:
        """Downscaled HSV of the whole frame, once per frame, for the global search."""
        if self._small is None:
            k = self.params.search_scale or self._auto_scale()
            h, w = frame.shape[:2]
            sw, sh = max(w // k, 1), max(h // k, 1)
            small = cv2.resize(frame, (sw, sh), interpolation=cv2.INTER_AREA)
            self._small = (cv2.cvtColor(small, cv2.COLOR_BGR2HSV), w / sw, h / sh)
        return self._small

    def _auto_scale(self) -> int:
        # Keep the smallest marker >= ~5 px across after downscaling.
        p = self.params
        refs = [t.ref for t in self._tracks if t.found and t.ref > 0]
        if not refs:
            return 1
        diameter = 2 * math.sqrt(min(refs) / math.pi)
        return int(min(max(diameter // p.search_marker_px, 1), p.search_max_scale))

    def _reacquire(self, tr: _Track, frame: np.ndarray):
        """Global search while lost: nearest plausible blob to the prediction."""
        p = self.params
        hsv, fx, fy = self._small_hsv(frame)
        bp = tr.colour.backproject(hsv)
        n, _, stats, cents = cv2.connectedComponentsWithStats(bp, connectivity=8)
        if n <= 1:
            return None
        areas = stats[1:, cv2.CC_STAT_AREA] * (fx * fy)
        # Downscaled areas are rough; the full-resolution refinement decides.
        ok = (areas >= p.search_min_ratio * tr.ref) & (areas <= p.max_area_ratio * tr.ref)
        if not ok.any():
            return None
        centres = np.column_stack(
            ((cents[1:, 0] + 0.5) * fx - 0.5, (cents[1:, 1] + 0.5) * fy - 0.5)
        )
        pred = tr.x
        d = np.hypot(centres[:, 0] - pred[0], centres[:, 1] - pred[1])
        for k in np.argsort(np.where(ok, d, np.inf))[: p.search_tries]:
            if not ok[k]:
                break
            meas = self._measure(tr, frame, centres[k], p.search_margin_px, tr.win)
            if meas is None or meas.merged:
                continue
            ratio = meas.mass / tr.ref
            if p.reacquire_ratio <= ratio <= p.max_area_ratio:
                tr.n_obs = 0
                tr.v = np.zeros(2)
                self._observe(tr, meas)
                return meas.centre, _likelihood(ratio), Status.REACQUIRED
        return None


def _cut_off(
    bp: np.ndarray, meas: Measurement, region: tuple[int, int, int, int], size: tuple[int, int]
) -> bool:
    """Whether the measured blob reaches an edge of its region that is not the frame's."""
    x0, y0, x1, y1 = region
    w, h = size
    rh, rw = bp.shape
    cx, cy = meas.centre[0] - x0, meas.centre[1] - y0
    hx, hy = meas.window[0] / 2 + 1, meas.window[1] / 2 + 1
    lx, hx_ = max(int(cx - hx), 0), min(int(cx + hx) + 1, rw)
    ly, hy_ = max(int(cy - hy), 0), min(int(cy + hy) + 1, rh)
    if lx >= hx_ or ly >= hy_:
        return False
    return bool(
        (lx == 0 < x0 and cv2.countNonZero(bp[ly:hy_, 0]))
        or (ly == 0 < y0 and cv2.countNonZero(bp[0, lx:hx_]))
        or (hx_ == rw and x1 < w and cv2.countNonZero(bp[ly:hy_, rw - 1]))
        or (hy_ == rh and y1 < h and cv2.countNonZero(bp[rh - 1, lx:hx_]))
    )


def _soft_diameter(frame: np.ndarray, colour: MarkerColour, centre: np.ndarray,
                   window: tuple[int, int]) -> float:
    """Apparent diameter (px) of a round blob, from its colour-unmixed area.

    The colour gate counts every rim pixel the blur or the codec has partly
    coloured, which makes a 10 cm ball about 3 % too large and every length
    measured against it 3 % too small. Here each pixel near the blob counts
    by how far its colour lies from the surrounding table toward the blob's
    own (0 to 1): the area is then unbiased under any symmetric blur.
    """
    h, w = frame.shape[:2]
    half = int(max(window) * 0.75 + 12)
    cx, cy = int(round(centre[0])), int(round(centre[1]))
    x0, y0 = max(cx - half, 0), max(cy - half, 0)
    x1, y1 = min(cx + half + 1, w), min(cy + half + 1, h)
    region = frame[y0:y1, x0:x1]
    gate = colour.backproject(cv2.cvtColor(region, cv2.COLOR_BGR2HSV))
    n, labels = cv2.connectedComponents((gate > 0).astype(np.uint8))
    lab = labels[min(cy - y0, labels.shape[0] - 1), min(cx - x0, labels.shape[1] - 1)]
    if n < 2 or lab == 0:
        return float("nan")
    blob = (labels == lab).astype(np.uint8)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
    inner = cv2.erode(blob, kernel, iterations=2).astype(bool)
    near = cv2.dilate(blob, kernel, iterations=3).astype(bool)
    ring = cv2.dilate(blob, kernel, iterations=7).astype(bool) & ~cv2.dilate(
        blob, kernel, iterations=4).astype(bool)
    if inner.sum() < 10 or ring.sum() < 10:
        return float("nan")
    pix = region.astype(np.float64)
    obj, bg = np.median(pix[inner], axis=0), np.median(pix[ring], axis=0)
    axis = obj - bg
    norm = float(axis @ axis)
    if norm < 100.0:  # the blob hardly differs from its surroundings
        return float("nan")
    alpha = np.clip((pix[near] - bg) @ axis / norm, 0.0, 1.0)
    return float(2.0 * np.sqrt(alpha.sum() / np.pi))


def _likelihood(ratio: float) -> float:
    return float(min(ratio, 1.0 / ratio)) if ratio > 0 else 0.0


def _ref_side(ref: float) -> int:
    """Side of a square window about the size of a blob of ``ref`` px."""
    return max(int(round(2 * math.sqrt(ref / math.pi))) + 4, 3)


def _clamp_window(win: tuple[int, int], ref: float, p: TrackerParams) -> tuple[int, int]:
    # Never below the minimum, never much larger than the marker itself: a
    # window allowed to grow over a same-coloured neighbour would stay on it.
    min_side = p.min_window_px
    cap = max(int(p.max_window_ratio * _ref_side(ref)), min_side) if ref > 0 else 10**6
    return (min(max(int(win[0]), min_side), cap), min(max(int(win[1]), min_side), cap))


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
) -> Tracker:
    """Track a stream of frames into an open :class:`TracksWriter`.

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

    Returns
    -------
    Tracker
        ``tracker``, for chaining.
    """
    for index, time_s, frame in frames:
        position, likelihood, status = tracker.update(frame)
        writer.append(index, time_s, position, likelihood, status)
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

    Returns
    -------
    Path
        The tracks file, written atomically.

    Raises
    ------
    InputError
        Bad video (see :class:`~perception.io.video.FrameSource`), a bad ROI, or a
        marker never found; no output file is left behind.
    """
    markers = default_markers() if markers is None else markers
    out_path = tracks_path_for(video) if out is None else Path(out)
    tracker = Tracker(markers, params, rois)
    with FrameSource(video, prefetch=prefetch) as src:
        with TracksWriter(out_path, markers.names, video=src.attrs(), tracker=tracker.attrs()) as w:
            bar = None
            if progress:
                from tqdm import tqdm

                bar = tqdm(
                    total=src.info.n_frames_header or None,
                    unit="frame",
                    file=sys.stderr,
                    desc=Path(video).name,
                    leave=False,
                )
            try:
                track_frames(src, w, tracker, progress=bar.update if bar else None)
            except InputError as exc:
                if exc.path is None:
                    raise InputError(exc.problem, video) from None
                raise
            finally:
                if bar is not None:
                    bar.close()
            missing = tracker.never_found
            if missing:
                raise InputError(
                    f"marker{'s' if len(missing) > 1 else ''} {', '.join(missing)} never found "
                    f"in {src.n_decoded} frames (check the colour models, or give a ROI)",
                    video,
                )
            w.update(video=src.attrs(), tracker=tracker.attrs())
    logger.info("%s: tracked %d frames -> %s", video, src.n_decoded, out_path)
    return out_path

"""CamShift colour-marker tracker that survives real footage.

Each marker has a colour model (:mod:`perception.tracking.markers`;
``docs/markers.md``) and its own search window. :class:`Tracker` is the
per-frame loop; for each marker and frame it decides what to do and
delegates:

1. **Not found yet: first detection** (:mod:`perception.tracking.detection`).
   Markers are found automatically on the first frames (the largest blob of
   each colour; among blobs of comparable size a hand marker takes the one
   nearest the other hand markers) or inside user-given ROIs.
2. **Tracked: follow.** An alpha-beta filter predicts the marker's position;
   the search region is the window around the prediction plus a margin that
   grows with speed. CamShift there gives the centroid and mass (pixel
   count) of the marker's colour, splitting off same-coloured blobs that
   joined the window (:mod:`perception.tracking.measurement`).
3. **Lost test.** A mass below ``lost_ratio`` x reference means the marker is
   hidden or gone: it is reported lost (NaN, likelihood 0, status 2), never
   as a stale position.
4. **Lost: re-acquisition**, only once the local search has failed and while
   the marker stays lost: a global search of a downscaled frame for the
   plausible blob nearest the prediction, refined at full resolution and
   reported with status 1 (:mod:`perception.tracking.detection`).

Markers listed in ``still_markers`` (the object) are expected to stay put and
to be partly hidden by the hand at the end: their position is the running
mean of whole-blob measurements (restarted if the blob jumps, i.e. the
object was moved), and while less than ``hold_ratio`` of the blob is visible
the position is held, with likelihood equal to the visible fraction.

Likelihood is ``min(r, 1/r)`` with ``r`` the measured mass over the
reference mass: 1 for a whole, uncontaminated marker; lower when partly
hidden or merged with similar colour. The tunables are
:class:`~perception.tracking.params.TrackerParams`; the tracks file, its
status codes and the ``/tracker`` attributes are described in
``docs/tracks-format.md``.
"""

from __future__ import annotations

import json
import logging
import math
import os
import sys
from collections.abc import Iterable, Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from perception.errors import InputError
from perception.io.tracks import Status, TracksWriter, tracks_path_for
from perception.io.video import FrameSource
from perception.tracking.blobs import Blob
from perception.tracking.detection import (
    ROI,
    closest_combination,
    downscaled_hsv,
    find_candidates,
    reacquire,
    search_scale,
)
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
    track (re)started.
    """

    __slots__ = ("colour", "still", "roi", "found", "lost", "x", "v", "win", "ref", "n_obs",
                 "diameter")

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
        self._check_frame(frame)
        m = len(self._tracks)
        position = np.full((m, 2), np.nan)
        lik = np.zeros(m, np.float32)
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
                tr.coast(self.params)
                continue
            (position[j, 0], position[j, 1]), lik[j], status[j] = result
        self.n_frames += 1
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
                    _roi_in_frame(t.colour.name, t.roi, frame.shape)

    def _initialise(self, frame: np.ndarray, todo: list[int]) -> dict[int, _Located | None]:
        """Find markers for the first time (see :mod:`perception.tracking.detection`).

        Hand markers without a ROI are chosen together, as the combination
        lying closest together and to the hand markers already placed
        (tracked ones, and those given a ROI).
        """
        p, tracks = self.params, self._tracks
        cands = {j: self._candidates(tracks[j], frame)[: p.init_candidates] for j in todo}
        hand = [j for j in todo if cands[j] and not tracks[j].still]
        free = [j for j in hand if tracks[j].roi is None]
        anchors = [t.x for t in tracks if t.found and not t.lost and not t.still] + [
            cands[j][0].centre for j in hand if tracks[j].roi is not None
        ]
        chosen: dict[int, Blob] = {}
        if free and len(free) + len(anchors) >= 2:
            best = closest_combination([cands[j] for j in free], anchors)
            chosen = {j: cands[j][k] for j, k in zip(free, best)}
        return {
            j: self._start(tracks[j], frame, chosen.get(j, cands[j][0])) if cands[j] else None
            for j in todo
        }

    def _candidates(self, tr: _Track, frame: np.ndarray) -> list[Blob]:
        # A ROI says where the marker is on the first frame only.
        if tr.roi is not None and self.n_frames > 0:
            return []
        return find_candidates(frame, tr.colour, self.params.min_area_px, tr.roi)

    def _start(self, tr: _Track, frame: np.ndarray, blob: Blob) -> _Located | None:
        """Begin a track on a blob found by first detection."""
        p = self.params
        tr.ref = blob.area
        tr.win = clamp_window(blob.size, tr.ref, p)
        meas = measure(frame, tr.colour, blob.centre, tr.win, tr.ref, p.search_margin_px, p)
        if meas is None:
            return None
        tr.found = True
        tr.ref = meas.mass
        tr.n_obs = 0
        if tr.still and not np.isfinite(tr.diameter):
            tr.diameter = soft_diameter(frame, tr.colour, meas.centre, meas.window)
        tr.observe(meas, p)
        logger.info(
            "%s found at (%.1f, %.1f) px on frame %d, %d px of its colour",
            tr.colour.name,
            *meas.centre,
            self.n_frames,
            meas.mass,
        )
        status = Status.TRACKED if self.n_frames == 0 else Status.REACQUIRED
        return meas.centre, 1.0, status

    def _follow(self, tr: _Track, frame: np.ndarray) -> _Located | None:
        """Track from the prediction; None if the marker is not in its region."""
        p = self.params
        meas = measure_still(frame, tr.colour, tr.x, tr.win, tr.ref, p) if tr.still else None
        if meas is None:
            meas = measure(frame, tr.colour, tr.predicted, tr.win, tr.ref, tr.margin(p), p)
        if meas is None:
            return None
        ratio = meas.mass / tr.ref
        if ratio < p.lost_ratio:
            return None
        if tr.still:
            if ratio < p.hold_ratio:
                # Partly hidden (the hand closing on the object): the visible
                # part's centroid is biased, the object has not moved.
                return tr.x, min(ratio, 1.0), Status.TRACKED
            tr.observe(meas, p)
            return tr.x, likelihood(ratio), Status.TRACKED
        tr.observe(meas, p)
        return meas.centre, likelihood(ratio), Status.TRACKED

    def _reacquire(self, tr: _Track, frame: np.ndarray) -> _Located | None:
        """Global search while lost (see :func:`perception.tracking.detection.reacquire`)."""
        p = self.params
        meas = reacquire(frame, self._small_hsv(frame), tr.colour, tr.ref, tr.x, tr.win, p)
        if meas is None:
            return None
        ratio = meas.mass / tr.ref
        tr.n_obs = 0
        tr.v = (0.0, 0.0)
        tr.observe(meas, p)
        return meas.centre, likelihood(ratio), Status.REACQUIRED

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

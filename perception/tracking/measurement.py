"""Measuring one marker in one region of one frame.

Given where a marker should be (a centre and a window), these functions
return where it is and how much of its colour is there, as a
:class:`Measurement`. Only the region around the prediction is converted to
HSV and back-projected, so decoding, not tracking, takes most of the time.

* :func:`measure` runs **CamShift** on the back-projection (hue range,
  saturation and value minimums) from the given window, then takes the
  centroid and mass (pixel count) in a square around the converged window.
  If the mass is well above the marker's reference mass, same-coloured
  pixels joined the window (a distractor): :func:`split_merged` separates
  the blobs and keeps the one nearest the prediction; if the blobs touch,
  the centroid is taken in a reference-sized window at the prediction and
  the measurement is flagged ``merged``. If the blob reaches the region's
  edge (the marker moved further than the margin allowed for), the region
  is centred on it and measured once more, so a cut-off blob never biases
  the centroid.
* :func:`measure_still` is the fast path of a marker that has not moved
  (the object): one moments call in its window, or None at any sign of
  motion or of a neighbour of its colour.
* :func:`soft_diameter` measures a round marker's apparent diameter from
  its colour-unmixed area (the object's size sets the tracks' scale).
* :func:`likelihood` is ``min(r, 1/r)`` with ``r`` the measured mass over
  the reference mass: 1 for a whole, uncontaminated marker; lower when
  partly hidden or merged with similar colour.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import cv2
import numpy as np

from perception.tracking.blobs import (
    blob_at,
    find_blobs,
    label_type,
    nearest_blob,
    principal_axes,
)
from perception.tracking.markers import MarkerColour, to_hsv
from perception.tracking.params import TrackerParams

#: CamShift's window of a round blob can be as small as 0.71 x its diameter
#: (it boxes the rotated ellipse axis by axis): mass and centroid are taken in
#: a square of half-side ``_GROW x`` the window's larger side ``+ _GROW_PX``
#: (1.5 x larger) around its centre, so the whole blob counts.
_GROW, _GROW_PX = 0.75, 2
#: :func:`soft_diameter` looks this far around the blob: ``_SOFT_GROW x`` its
#: window plus ``_SOFT_PAD_PX`` px, enough for the background ring below.
_SOFT_GROW, _SOFT_PAD_PX = 0.75, 12


class Measurement(NamedTuple):
    """One marker located in one frame: centre (x, y) px, mass px, window (w, h) px.

    ``merged`` marks a centroid taken among touching same-coloured blobs: it
    is unreliable, and its window is the marker's previous one. ``clutter``
    is the mass (px) of the marker's colour elsewhere in the searched region:
    a marker among things of its colour.
    """

    centre: tuple[float, float]
    mass: float
    window: tuple[int, int]
    merged: bool = False
    clutter: float = 0.0


def likelihood(ratio: float) -> float:
    """``min(r, 1/r)`` of the mass ratio ``r`` (0 for ``r <= 0``): 1 for a whole marker."""
    return float(min(ratio, 1.0 / ratio)) if ratio > 0 else 0.0


def ref_side(ref: float, params: TrackerParams) -> int:
    """Side (px) of a square window about the size of a blob of ``ref`` px.

    Parameters
    ----------
    ref : float
        The blob's mass (area), px.
    params : TrackerParams
        ``rim_px``: added to the disc's diameter for its blurred rim.
    """
    return max(int(round(2 * math.sqrt(ref / math.pi))) + params.rim_px, 3)


def clamp_window(win: tuple[int, int], ref: float, params: TrackerParams) -> tuple[int, int]:
    """A window never below ``min_window_px``, never much larger than the marker itself.

    Parameters
    ----------
    win : (int, int)
        Proposed (width, height), px.
    ref : float
        The marker's reference mass, px (0: not known yet, no upper bound).
    params : TrackerParams
        ``min_window_px`` and ``max_window_ratio``.
    """
    min_side = params.min_window_px
    cap = max(int(params.max_window_ratio * ref_side(ref, params)), min_side) if ref > 0 else 10**6
    return (min(max(int(win[0]), min_side), cap), min(max(int(win[1]), min_side), cap))


def _extent(mo: dict[str, float], mass: float, rim_px: int) -> tuple[int, int]:
    """A blob's window from its central moments: 2r for a disc, plus ``rim_px`` for the rim."""
    return (int(4 * math.sqrt(mo["mu20"] / mass)) + rim_px,
            int(4 * math.sqrt(mo["mu02"] / mass)) + rim_px)


def measure(
    frame: np.ndarray,
    colour: MarkerColour,
    centre: np.ndarray | tuple[float, float],
    window: tuple[int, int],
    ref: float,
    margin: float,
    params: TrackerParams,
    along: tuple[float, float] | None = None,
    width: float = math.inf,
) -> Measurement | None:
    """CamShift in the region around ``centre``; centroid and mass of the result.

    Parameters
    ----------
    frame : (H, W, 3) uint8
        BGR frame.
    colour : MarkerColour
        The marker's colour model.
    centre : (float, float)
        Predicted centre (x, y), px.
    window : (int, int)
        The marker's window (width, height), px: CamShift's start, and the
        window reported for a merged measurement.
    ref : float
        Reference mass, px.
    margin : float
        The region searched is ``window`` plus this margin each side, px.
    params : TrackerParams
        Termination criteria and the split ratios.
    along : (float, float), optional
        The direction (x, y) the marker moves in, when it is measured as a
        motion-blurred streak (:mod:`perception.tracking.blur`): its centre
        is then the mid-point of the streak along it, not the centroid.
    width : float
        A streak wider than this across its motion (px) holds something
        else too: it is measured ``merged`` (not to be trusted).

    Returns
    -------
    Measurement or None
        None when nothing of the colour is in the region, or the region
        left the frame.
    """
    found = _measure_region(frame, colour, centre, window, ref, margin, params, window, along,
                            width)
    if found is None:
        return None
    meas, bp, region = found
    if not meas.merged and _cut_off(bp, meas, region, frame.shape):
        # The blob goes on beyond the region: measure again centred on it.
        again = _measure_region(frame, colour, meas.centre, meas.window, ref,
                                params.search_margin_px, params, window, along, width)
        if again is not None:
            return again[0]
    return meas


def _measure_region(
    frame: np.ndarray,
    colour: MarkerColour,
    centre: np.ndarray | tuple[float, float],
    window: tuple[int, int],
    ref: float,
    margin: float,
    params: TrackerParams,
    merged_window: tuple[int, int],
    along: tuple[float, float] | None = None,
    width: float = math.inf,
) -> tuple[Measurement, np.ndarray, tuple[int, int, int, int]] | None:
    """One CamShift measurement; also the region's back-projection and bounds.

    Run for every marker in every frame: the region and CamShift's start are
    worked out inline, in plain ints and floats.
    """
    cx, cy = float(centre[0]), float(centre[1])
    if not (math.isfinite(cx) and math.isfinite(cy)):
        return None
    h, w = frame.shape[:2]
    ww, wh = window
    x0, y0 = int(cx - ww / 2 - margin), int(cy - wh / 2 - margin)
    x0, y0 = (x0 if x0 > 0 else 0), (y0 if y0 > 0 else 0)
    x1, y1 = int(cx + ww / 2 + margin) + 1, int(cy + wh / 2 + margin) + 1
    x1, y1 = (x1 if x1 < w else w), (y1 if y1 < h else h)
    rw, rh = x1 - x0, y1 - y0
    if rw < params.min_region_px or rh < params.min_region_px:
        return None  # the prediction left the frame
    region = x0, y0, x1, y1
    crop = frame[y0:y1, x0:x1]
    bp = (colour.backproject(to_hsv(crop))
          if isinstance(colour, MarkerColour) else colour.backproject_bgr(crop))
    wx = round(cx - ww / 2) - x0
    wx = 0 if wx < 0 else (rw - 1 if wx >= rw else wx)
    wy = round(cy - wh / 2) - y0
    wy = 0 if wy < 0 else (rh - 1 if wy >= rh else wy)
    sw = ww if ww < rw - wx else rw - wx
    sh = wh if wh < rh - wy else rh - wy
    start = (wx, wy, sw if sw > 1 else 1, sh if sh > 1 else 1)
    pred = (cx - x0, cy - y0)
    if along is not None:
        meas = _streak(bp, pred, along, width, params)
        if meas is None:
            return None
        return meas._replace(centre=(meas.centre[0] + x0, meas.centre[1] + y0)), bp, region
    box, (_, _, bw, bh) = cv2.CamShift(bp, start, params.criteria)
    if box[1][0] <= 0 or bw <= 0 or bh <= 0:
        converged = _camshift_again(bp, pred, ref, params)
        if converged is None:
            return None
        box, (_, _, bw, bh) = converged
    bcx, bcy = box[0]
    half = _GROW * (bw if bw > bh else bh) + _GROW_PX
    mx0, my0 = int(bcx - half), int(bcy - half)
    mx0, my0 = (mx0 if mx0 > 0 else 0), (my0 if my0 > 0 else 0)
    mo = cv2.moments(bp[my0:int(bcy + half) + 2, mx0:int(bcx + half) + 2], True)
    mass = mo["m00"]
    if mass <= 0:
        return None
    total = cv2.countNonZero(bp)
    if ref > 0 and mass > params.split_ratio * ref:
        meas = split_merged(bp, pred, (x0, y0), ref, params, merged_window)
        if meas is not None:
            return meas._replace(clutter=max(total - meas.mass, 0.0)), bp, region
    meas = Measurement((mo["m10"] / mass + x0 + mx0, mo["m01"] / mass + y0 + my0), mass,
                       _extent(mo, mass, params.rim_px), False, max(total - mass, 0.0))
    return meas, bp, region


def _streak(bp: np.ndarray, pred: tuple[float, float], along: tuple[float, float],
            width: float, params: TrackerParams) -> Measurement | None:
    """A motion-blurred marker: the blob of ``bp`` nearest ``pred``, at :func:`streak_centre`.

    Its blob alone, not a CamShift window: a loose gate (the blur gate) also
    takes thin edges elsewhere in the region (a band's blurred rim against
    the skin), which a window growing along the streak would take in.
    None when no blob of ``min_area_px`` is there; ``merged`` when the blob
    is wider than ``width`` across the motion (it holds something else too).
    """
    n, labels, stats, cents = cv2.connectedComponentsWithStats(bp, connectivity=8,
                                                               ltype=label_type(bp.shape))
    best, dist = 0, math.inf
    for k in range(1, n):
        if stats[k, cv2.CC_STAT_AREA] >= params.min_area_px:
            d = math.dist(cents[k], pred)
            if d < dist:
                best, dist = k, d
    if not best:
        return None
    x, y, w, h, area = (int(v) for v in stats[best])
    mask = (labels[y:y + h, x:x + w] == best).astype(np.uint8)
    mo = cv2.moments(mask, True)
    total = cv2.countNonZero(bp)
    major, minor, angle = principal_axes(mask)
    if major > _ELONGATED * max(minor, 0.0):
        # a streak's own long axis: the motion's direction as this frame shows it
        along = (math.cos(angle), math.sin(angle))
    across = 4.0 * math.sqrt(max(minor, 0.0))  # a disc's diameter, a streak's width
    return Measurement(streak_centre(mask, along, (x, y)), float(area),
                       _extent(mo, area, params.rim_px), across > width,
                       float(max(total - area, 0)))


#: A blob whose major axis variance is this many times its minor one is
#: long enough for its own axis to give the motion's direction.
_ELONGATED = 4.0
#: The ends of a streak are its pixels' projections at these percentiles: a
#: few stray pixels of the colour beside it do not move them.
_STREAK_ENDS = (1.0, 99.0)


def streak_centre(mask: np.ndarray, along: tuple[float, float],
                  offset: tuple[int, int] = (0, 0)) -> tuple[float, float]:
    """Mid-point of a motion-blurred streak along its motion; its median across it.

    A marker smeared over skin at one end and table at the other passes a
    colour gate further into its faint end on the skin: the centroid leans
    that way by a good part of the streak's length, while its two ends move
    by a fraction of the marker's size only.

    Parameters
    ----------
    mask : (h, w) uint8
        The streak's pixels (non-zero).
    along : (float, float)
        The motion's direction (x, y), any length but 0.
    offset : (int, int)
        Added to the result (the mask's corner), px.

    Returns
    -------
    (float, float)
        The centre (x, y), px (NaN for an empty mask).
    """
    ys, xs = np.nonzero(mask)
    norm = math.hypot(along[0], along[1])
    if xs.size == 0 or norm == 0:
        return math.nan, math.nan
    ux, uy = along[0] / norm, along[1] / norm
    a = xs * ux + ys * uy
    c = xs * -uy + ys * ux
    lo, hi = np.percentile(a, _STREAK_ENDS)
    mid, across = (lo + hi) / 2, float(np.median(c))
    return (mid * ux - across * uy + offset[0], mid * uy + across * ux + offset[1])


def _camshift_again(
    bp: np.ndarray, pred: tuple[float, float], ref: float, params: TrackerParams
) -> tuple[tuple[tuple[float, float], tuple[float, float], float],
           tuple[int, int, int, int]] | None:
    """CamShift's second try when its start window held nothing of the colour.

    It starts again on the plausible blob nearest ``pred``; returns what
    ``cv2.CamShift`` does, or None if there is no such blob or it fails too.
    """
    blob = nearest_blob(find_blobs(bp, min_area=max(params.lost_ratio * ref, 1)), pred)
    if blob is None:
        return None
    box, rect = cv2.CamShift(bp, blob.box, params.criteria)
    if box[1][0] <= 0 or rect[2] <= 0 or rect[3] <= 0:
        return None
    return box, rect


def split_merged(
    bp: np.ndarray,
    pred: tuple[float, float],
    offset: tuple[int, int],
    ref: float,
    params: TrackerParams,
    merged_window: tuple[int, int],
) -> Measurement | None:
    """Separate same-coloured blobs that joined the window; measure the nearest.

    Parameters
    ----------
    bp : (h, w) uint8
        Back-projection of the search region.
    pred : (float, float)
        Predicted centre, px, in region coordinates.
    offset : (int, int)
        The region's top-left corner in the frame, px.
    ref : float
        Reference mass, px; blobs under ``lost_ratio x ref`` are ignored.
    params : TrackerParams
        ``lost_ratio`` and ``merge_ratio``.
    merged_window : (int, int)
        Window reported if the nearest blob is the marker merged with a
        neighbour (it is larger than ``merge_ratio x ref``).

    Returns
    -------
    Measurement or None
        In frame coordinates; None if no blob is plausible. A merged
        measurement's centroid is taken in a reference-sized window at the
        prediction, so the neighbour can pull the estimate only partly.
    """
    blob = nearest_blob(find_blobs(bp, min_area=params.lost_ratio * ref), pred)
    if blob is None:
        return None
    if blob.area <= params.merge_ratio * ref:
        c = blob.centre
        return Measurement((c[0] + offset[0], c[1] + offset[1]), blob.area, blob.size)
    side = ref_side(ref, params)
    x0 = max(int(round(pred[0] - side / 2)), 0)
    y0 = max(int(round(pred[1] - side / 2)), 0)
    mo = cv2.moments(bp[y0 : y0 + side, x0 : x0 + side], True)
    if mo["m00"] <= 0:
        return None
    centre = (mo["m10"] / mo["m00"] + x0 + offset[0], mo["m01"] / mo["m00"] + y0 + offset[1])
    return Measurement(centre, blob.area, merged_window, merged=True)


def _cut_off(
    bp: np.ndarray, meas: Measurement, region: tuple[int, int, int, int], shape: tuple[int, ...]
) -> bool:
    """Whether the measured blob reaches an edge of its region that is not the frame's."""
    rh, rw = bp.shape
    cx, cy = meas.centre[0] - region[0], meas.centre[1] - region[1]
    hx, hy = meas.window[0] / 2 + 1, meas.window[1] / 2 + 1
    lx, hx_ = max(int(cx - hx), 0), min(int(cx + hx) + 1, rw)
    ly, hy_ = max(int(cy - hy), 0), min(int(cy + hy) + 1, rh)
    return lx < hx_ and ly < hy_ and _touches_edge(bp, region, shape, (lx, ly, hx_, hy_))


def measure_still(
    frame: np.ndarray,
    colour: MarkerColour,
    centre: np.ndarray | tuple[float, float],
    window: tuple[int, int],
    ref: float,
    params: TrackerParams,
) -> Measurement | None:
    """Moments in the window of a marker that has not moved; None if it seems to have.

    A still object needs no mean-shift search while it stays put: one
    moments call at its position costs a third of a CamShift. Any sign of
    motion or of a neighbour of its colour returns None, and the caller
    falls back to :func:`measure`.

    Parameters
    ----------
    frame : (H, W, 3) uint8
        BGR frame.
    colour : MarkerColour
        The marker's colour model.
    centre : (float, float)
        The marker's estimated centre (x, y), px.
    window : (int, int)
        Its window (width, height), px.
    ref : float
        Reference mass, px.
    params : TrackerParams
        ``split_ratio``, ``hold_ratio``, ``still_shift_px``, ``still_pad_px``
        (the region: the window plus this each side) and ``rim_px``.
    """
    h, w = frame.shape[:2]
    half = 0.5 * max(window) + params.still_pad_px
    cx, cy = float(centre[0]), float(centre[1])
    x0, y0 = max(int(cx - half), 0), max(int(cy - half), 0)
    x1, y1 = min(int(cx + half) + 2, w), min(int(cy + half) + 2, h)
    if x1 - x0 < params.min_region_px or y1 - y0 < params.min_region_px:
        return None
    bp = colour.backproject(to_hsv(frame[y0:y1, x0:x1]))
    mo = cv2.moments(bp, True)
    mass = mo["m00"]
    if mass <= 0 or mass > params.split_ratio * ref:
        return None
    found = (mo["m10"] / mass + x0, mo["m01"] / mass + y0)
    if (
        mass >= params.hold_ratio * ref
        and math.dist(found, (cx, cy)) > params.still_shift_px
    ):
        return None  # whole but off-centre: it is moving
    if _touches_edge(bp, (x0, y0, x1, y1), (h, w)):
        return None  # the blob may extend beyond the region: search properly
    return Measurement(found, mass, _extent(mo, mass, params.rim_px))


def _touches_edge(
    bp: np.ndarray, region: tuple[int, int, int, int], shape: tuple[int, ...],
    span: tuple[int, int, int, int] | None = None,
) -> bool:
    """Whether any pixel of the colour lies on an edge of the region that is not the frame's.

    ``span`` (x0, y0, x1, y1), in the region, limits the search to the edges it reaches.
    """
    x0, y0, x1, y1 = region
    h, w = shape[:2]
    rh, rw = bp.shape
    lx, ly, hx, hy = (0, 0, rw, rh) if span is None else span
    return bool(
        (lx == 0 < x0 and cv2.countNonZero(bp[ly:hy, 0]))
        or (ly == 0 < y0 and cv2.countNonZero(bp[0, lx:hx]))
        or (hx == rw and x1 < w and cv2.countNonZero(bp[ly:hy, rw - 1]))
        or (hy == rh and y1 < h and cv2.countNonZero(bp[rh - 1, lx:hx]))
    )


def soft_diameter(
    frame: np.ndarray,
    colour: MarkerColour,
    centre: np.ndarray | tuple[float, float],
    window: tuple[int, int],
    params: TrackerParams | None = None,
) -> float:
    """Apparent diameter (px) of a round blob, from its colour-unmixed area.

    The colour gate counts every rim pixel the blur or the codec has partly
    coloured, which makes a 10 cm ball about 3 % too large and every length
    measured against it 3 % too small. Here each pixel near the blob counts
    by how far its colour lies from the surrounding table toward the blob's
    own (0 to 1): the area is then unbiased under any symmetric blur.

    Parameters
    ----------
    frame : (H, W, 3) uint8
        BGR frame.
    colour : MarkerColour
        The blob's colour model.
    centre : (float, float)
        A point inside the blob (x, y), px.
    window : (int, int)
        The blob's window (width, height), px.
    params : TrackerParams, optional
        ``min_soft_contrast`` (default: the default parameters').

    Returns
    -------
    float
        NaN when the blob is not found at ``centre``, is too small to have
        an inside, or hardly differs from its surroundings.
    """
    h, w = frame.shape[:2]
    half = int(max(window) * _SOFT_GROW + _SOFT_PAD_PX)
    cx, cy = int(round(centre[0])), int(round(centre[1]))
    x0, y0 = max(cx - half, 0), max(cy - half, 0)
    x1, y1 = min(cx + half + 1, w), min(cy + half + 1, h)
    region = frame[y0:y1, x0:x1]
    gate = colour.backproject(cv2.cvtColor(region, cv2.COLOR_BGR2HSV))
    blob = blob_at(gate, (cx - x0, cy - y0))
    zones = None if blob is None else _rim_zones(blob.astype(np.uint8))
    if zones is None:
        return float("nan")
    inner, near, ring = zones
    pix = region.astype(np.float64)
    obj, bg = np.median(pix[inner], axis=0), np.median(pix[ring], axis=0)
    axis = obj - bg
    norm = float(axis @ axis)
    contrast = (TrackerParams() if params is None else params).min_soft_contrast
    if norm < contrast * contrast:  # the blob hardly differs from its surroundings
        return float("nan")
    alpha = np.clip((pix[near] - bg) @ axis / norm, 0.0, 1.0)
    return float(2.0 * np.sqrt(alpha.sum() / np.pi))


def _rim_zones(blob: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Masks around a blob: its pure inside, the pixels it may colour, the table beyond.

    The inside (eroded twice) and the ring (dilated 4 to 7 times) lie clear
    of the blurred rim, so their medians are the blob's and the table's own
    colours; ``near`` (dilated 3 times) holds every partly coloured pixel.
    None if the inside or the ring is too small for a median.
    """
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
    inner = cv2.erode(blob, kernel, iterations=2).astype(bool)
    near = cv2.dilate(blob, kernel, iterations=3).astype(bool)
    ring = cv2.dilate(blob, kernel, iterations=7).astype(bool) & ~cv2.dilate(
        blob, kernel, iterations=4).astype(bool)
    if inner.sum() < 10 or ring.sum() < 10:
        return None
    return inner, near, ring

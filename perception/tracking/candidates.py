"""Candidates for a marker on the first frames, and why one is not the marker.

A blob of a marker's colour is only a *candidate*: a red saucer, a flag's
stripe, a blue car seat or a sleeve pass the same colour gate. Everything
else known about the marker decides (:func:`reject_reason`):

* **size** — its area against the area expected from the marker's physical
  size (``TrackerParams.marker_diameter``, ``band_size``) at the clip's scale,
  which the object's apparent size against its known diameter gives
  (``object_diameter``); within a factor ``size_tolerance`` either way;
* **shape** — digit markers and the object are round (minor / major axis
  ``>= min_roundness``); the wrist band is elongated across the forearm
  (major / minor within ``band_elongation``);
* **colour purity** — the median saturation and value of its pixels against
  the marker's own colour (``MarkerColour.hsv``): a thing that only just
  passes the gate is not the marker;
  A marker that only joins a large thing of its hue under the ordinary
  gate is looked for again among the pure pixels (:func:`strict`), and is
  then followed with that narrower gate;
* **stillness** — clips start with the hand at rest: a candidate that moves
  between the first frame and a later one of the rest (``init_frames``) is
  not a marker of a resting hand.

:mod:`perception.tracking.hand` then chooses among the survivors by the
hand's structure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import cv2
import numpy as np

from perception.tracking.blobs import Blob, find_blobs, label_type, nearest_blob, principal_axes
from perception.tracking.markers import MarkerColour
from perception.tracking.params import TrackerParams

__all__ = ["REASONS", "Candidate", "describe", "expected_area", "own_gate", "reject_reason",
           "strict"]

#: Why a candidate is not the marker, in the order they are tested.
REASONS = ("too small", "too big", "not round", "not band-like", "impure colour", "moving")


@dataclass(frozen=True)
class Candidate:
    """A blob of a marker's colour with what is known of its look.

    Parameters
    ----------
    blob : Blob
        Centre, area and box, px.
    roundness : float
        Minor over major axis of its second moments (1: a disc).
    axis : (float, float)
        Unit vector of its major axis, image frame.
    saturation, value : float
        Median saturation and value (0..255) of its pixels.
    moved : float
        Shift of its centroid (px) between the first frame and the later
        look (``inf`` if it vanished or changed size; NaN if not looked).
    purity : float
        How near its colour is to the marker's own, 0..1: the mean of its
        saturation and value as fractions (at most 1) of the marker's.
    """

    blob: Blob
    roundness: float
    axis: tuple[float, float]
    saturation: float
    value: float
    moved: float = math.nan
    purity: float = 1.0

    @property
    def centre(self) -> tuple[float, float]:
        """Centroid (x, y), px."""
        return self.blob.centre

    @property
    def area(self) -> float:
        """Pixel count."""
        return self.blob.area


def _moved(later: np.ndarray, colour: MarkerColour, blob: Blob, size_change: float) -> float:
    """How far a blob moved in a later HSV frame, px (inf: gone or changed size).

    The later blob is the component of the colour nearest the blob's centre
    in its padded box: neighbours of the same colour do not count; one
    larger or smaller than ``size_change`` x the blob is not the blob.
    """
    x, y, w, h = blob.box
    pad = max(4, (w + h) // 4)
    H, W = later.shape[:2]
    x0, y0, x1, y1 = max(x - pad, 0), max(y - pad, 0), min(x + w + pad, W), min(y + h + pad, H)
    found = nearest_blob(find_blobs(colour.backproject(later[y0:y1, x0:x1])),
                         (blob.centre[0] - x0, blob.centre[1] - y0))
    if found is None or not blob.area / size_change <= found.area <= size_change * blob.area:
        return math.inf
    return math.dist(found.moved(x0, y0).centre, blob.centre)


def strict(colour: MarkerColour, params: TrackerParams) -> MarkerColour:
    """The marker's colour gate narrowed to pixels as saturated and bright as a pure marker.

    A marker touching a large thing of its hue (a blue band against a blue
    sky) joins it under the ordinary gate; the pure pixels of the marker
    still stand apart.

    Parameters
    ----------
    colour : MarkerColour
        The marker's colour model.
    params : TrackerParams
        ``strict_saturation_ratio`` and ``strict_value_ratio`` of the
        marker's own saturation and value.
    """
    _, sat, val = colour.hsv
    return replace(colour, sat_min=max(colour.sat_min, int(params.strict_saturation_ratio * sat)),
                   val_min=max(colour.val_min, int(params.strict_value_ratio * val)))


def describe(hsv: np.ndarray, colour: MarkerColour, min_area: float,
             roi: tuple[int, int, int, int] | None = None,
             later: np.ndarray | None = None, max_blobs: int = 64,
             size_change: float = 2.0) -> list[Candidate]:
    """The blobs of a marker's colour with their shape, purity and stillness, largest first.

    Parameters
    ----------
    hsv : (H, W, 3) uint8
        The first frame in OpenCV HSV (converted once for every marker).
    colour : MarkerColour
        The marker's colour model.
    min_area : float
        Smallest blob counted, px.
    roi : (x, y, w, h), optional
        Look only in this region, px.
    later : (H, W, 3) uint8, optional
        A later frame of the clip's rest, in HSV, for the stillness test.
    max_blobs : int
        At most this many blobs (the largest) are described
        (``TrackerParams.max_blobs``).
    size_change : float
        Stillness test: a blob whose later area differs from its own by more
        than this factor, either way, has gone (``TrackerParams.rest_area_ratio``).

    Returns
    -------
    list of Candidate
        In frame coordinates.
    """
    x0, y0 = (roi[0], roi[1]) if roi is not None else (0, 0)
    region = hsv if roi is None else hsv[y0:y0 + roi[3], x0:x0 + roi[2]]
    mask = colour.backproject(region)
    # Labelled within the box of the colour's pixels, from an even corner: the
    # same blobs in the same order as over the region, in a fraction of the time.
    bx, by, bw, bh = cv2.boundingRect(mask)
    bx, by = bx - bx % 2, by - by % 2
    mask, region = mask[by:by + bh + 1, bx:bx + bw + 1], region[by:by + bh + 1, bx:bx + bw + 1]
    n, labels, stats, cents = cv2.connectedComponentsWithStats(
        mask, connectivity=8, ltype=label_type(mask.shape))
    order = [k for k in np.argsort(-stats[1:, cv2.CC_STAT_AREA], kind="stable") + 1
             if stats[k, cv2.CC_STAT_AREA] >= min_area][:max_blobs]
    out = []
    _, ref_s, ref_v = colour.hsv
    for k in order:
        x, y, w, h, area = (int(v) for v in stats[k])
        sub = labels[y:y + h, x:x + w] == k
        pix = region[y:y + h, x:x + w][sub]
        major, minor, angle = principal_axes(sub.astype(np.uint8))
        roundness = math.sqrt(max(minor, 0.0) / major) if major > 0 else 1.0
        axis = math.cos(angle), math.sin(angle)
        # OpenCV's centroid over the region: its exact pixel sum over the area
        cx, cy = ((round(c * area) + b * area) / area for c, b in zip(cents[k], (bx, by)))
        blob = Blob((cx + x0, cy + y0), float(area), (x + bx + x0, y + by + y0, w, h))
        moved = _moved(later, colour, blob, size_change) if later is not None else math.nan
        sat, val = float(np.median(pix[:, 1])), float(np.median(pix[:, 2]))
        purity = (min(sat / max(ref_s, 1), 1.0) + min(val / max(ref_v, 1), 1.0)) / 2
        out.append(Candidate(blob, roundness, axis, sat, val, moved, purity))
    return out


def expected_area(name: str, px_per_m: float, params: TrackerParams) -> float | None:
    """Area (px) a hand marker should have at ``px_per_m``; None for other markers.

    Parameters
    ----------
    name : str
        ``thumb``, ``finger`` (discs of ``marker_diameter``) or ``wrist``
        (a band of ``band_size``).
    px_per_m : float
        Image scale, px/m.
    params : TrackerParams
        The physical sizes.
    """
    if name == "wrist":
        return params.band_size[0] * params.band_size[1] * px_per_m**2
    if name in ("thumb", "finger"):
        return math.pi * (params.marker_diameter * px_per_m / 2) ** 2
    return None


def reject_reason(c: Candidate, name: str, colour: MarkerColour, expected: float | None,
                  params: TrackerParams) -> str | None:
    """Why candidate ``c`` cannot be marker ``name`` (one of :data:`REASONS`), or None.

    Parameters
    ----------
    c : Candidate
        The blob.
    name : str
        The marker (``wrist`` is a band; the others are round).
    colour : MarkerColour
        Its colour model; ``hsv`` is the colour a pure marker has.
    expected : float or None
        Expected area, px (None: size unknown, not tested).
    params : TrackerParams
        The tolerances.
    """
    if expected is not None:
        if c.area < expected / params.size_tolerance:
            return "too small"
        if c.area > expected * params.size_tolerance:
            return "too big"
    if name == "wrist":
        lo, hi = params.band_elongation
        if not lo <= 1 / max(c.roundness, 1e-6) <= hi:
            return "not band-like"
    elif c.roundness < params.min_roundness:
        return "not round"
    _, sat, val = colour.hsv
    if c.saturation < params.min_saturation_ratio * sat or c.value < params.min_value_ratio * val:
        return "impure colour"
    if c.moved > params.rest_motion_px:
        return "moving"
    return None


def own_gate(colour: MarkerColour, hsv: np.ndarray, mask: np.ndarray,
             params: TrackerParams) -> MarkerColour:
    """The marker's gate narrowed to the saturation and value its own pixels show.

    Set when a marker is first found: a background of its hue that only
    just passes the ordinary gate (a greyish blue sky behind a saturated
    band) no longer joins it as it moves. Saturation does not change with
    the light, so its minimum follows the marker closely; value does, so
    its minimum stays well below what the marker shows.

    Parameters
    ----------
    colour : MarkerColour
        The marker's colour model.
    hsv : (h, w, 3) uint8
        A region of the frame in HSV.
    mask : (h, w) bool
        The marker's pixels in that region.
    params : TrackerParams
        ``own_saturation_margin`` and ``own_value_ratio``.
    """
    pix = hsv[mask]
    if len(pix) < 10:
        return colour
    sat = int(np.percentile(pix[:, 1], 10)) - params.own_saturation_margin
    val = int(params.own_value_ratio * np.percentile(pix[:, 2], 5))
    return replace(colour, sat_min=min(max(colour.sat_min, sat), 255),
                   val_min=min(max(colour.val_min, val), 255))

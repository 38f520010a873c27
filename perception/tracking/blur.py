"""Motion blur: how a fast marker looks, and the colour gate that still sees it.

A marker that moves ``s`` px during a frame's exposure is smeared into a
streak about ``s`` px longer than it is wide; each pixel of the streak holds
the marker's colour for only part of the exposure and the background's (the
table, the skin of the hand) for the rest. The mix is less saturated than
the marker and its hue slides toward the background's: a green finger
marker smeared over the skin reads hue 35-47 (OpenCV units) at saturation
80-120 where the marker itself reads 60 and 200, so the marker's own gate
(:func:`~perception.tracking.candidates.own_gate`) keeps a sliver of the
streak or nothing, and the marker is lost exactly while the grasp is fast.

The **blur gate** (:func:`blur_gate`) is the marker's gate widened by
:data:`HUE_MARGIN` hue units each side and with its saturation minimum
lowered to :data:`SATURATION_RATIO` of the own gate's, made only as loose as
the scene allows: on the first frame (the hand at rest) a gate that would
light up a blob of ``lost_ratio`` x the marker's mass anywhere but on the
marker itself, or scatter pixels around it (a red thumb's gate taking the
skin), is tightened step by step (:data:`STEPS`), and a marker whose
tightest step still does is given its own gate. The **streak gate**
(:class:`StreakGate`) adds the pixels whose colour lies between the
marker's own and the background's, however washed out.

The tracker looks for a moving marker as a streak when its own gate shows
less than :data:`WHOLE` of its reference mass, and expects up to
:func:`streak_mass` px of colour then (a whole frame's exposure), in a
streak at most :func:`streak_width` wide; the measurement itself is
:func:`perception.tracking.measurement.measure` with a motion direction
(the streak's ends, not its centroid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import cv2
import numpy as np

from perception.tracking.blobs import find_blobs
from perception.tracking.markers import MarkerColour, to_hsv

__all__ = ["FAST", "HUE_MARGIN", "MAX_RESIDUAL", "MIN_SHARE", "NEAR", "NEAR_SHARE",
           "SATURATION_RATIO", "STEPS", "STREAK_SLACK", "STREAK_WIDTH", "WHOLE", "StreakGate",
           "blur_gate", "diameter_px", "is_fast", "streak_mass", "streak_width"]

#: Hue units (OpenCV, 0..179) the blur gate widens the marker's hue ranges by,
#: each side: a marker's colour mixed half and half with skin or table moves
#: its hue by 10-15 units.
HUE_MARGIN = 13
#: The blur gate's saturation minimum, as a fraction of the own gate's: a
#: streak at least a third marker keeps about half the marker's saturation.
SATURATION_RATIO = 0.5
#: How far toward the blur gate each step goes in hue and in saturation (1:
#: all the way), loosest first; the first that finds no rival in the rest
#: frame is kept. The hue is given up first: a red marker mixed with skin
#: slides toward the skin's own hue, which no gate of the marker may take,
#: while its saturation still stands well above the skin's.
STEPS = ((1.0, 1.0), (0.5, 1.0), (0.0, 1.0), (0.0, 0.5))
#: A marker predicted to move more than this many of its own diameters a
#: frame is fast: its streak is as long as its predicted displacement; a
#: slower one may have sped up as far as its search region reaches.
FAST = 0.5
#: A moving marker measured with less than this share of its reference mass
#: under its own gate is looked for as a streak: its colour is smeared.
WHOLE = 0.7
#: A streak with more than this multiple of :func:`streak_mass` of colour
#: holds something else as well (the other digit's streak, the band).
STREAK_SLACK = 1.25
#: A streak's width across its motion, in its marker's diameters, beyond
#: which it is not the marker alone (:func:`streak_width`).
STREAK_WIDTH = 2.0
#: Around a marker (this many of its sizes each side) at most this share of
#: the pixels, besides its own, may pass its blur gate on the rest frame.
NEAR, NEAR_SHARE = 3, 0.01


def diameter_px(ref: float) -> float:
    """Diameter (px) of a disc of ``ref`` px: the marker's size across its motion."""
    return 2.0 * math.sqrt(max(ref, 0.0) / math.pi)


def is_fast(speed: float, ref: float) -> bool:
    """Whether a marker of ``ref`` px moving ``speed`` px/frame is measured blurred."""
    return speed > FAST * diameter_px(ref)


def streak_mass(ref: float, speed: float) -> float:
    """The most px of colour a marker of ``ref`` px moving ``speed`` px/frame covers.

    Its disc swept over a whole frame's exposure: ``ref`` plus a band of
    its diameter by ``speed``. A shorter shutter covers less, down to ``ref``.
    """
    return ref + diameter_px(ref) * speed


def streak_width(ref: float, rim_px: int) -> float:
    """The widest a streak of a marker of ``ref`` px may be across its motion, px.

    ``rim_px``: its blurred rim's width (``TrackerParams.rim_px``).

    :data:`STREAK_WIDTH` of its diameter plus its blurred rim: a streak
    wider than that holds something else too (the skin beside a red thumb,
    the other digit).
    """
    return STREAK_WIDTH * diameter_px(ref) + rim_px


def _widened(colour: MarkerColour, hue_k: float, sat_k: float) -> MarkerColour:
    """The gate ``hue_k`` of the way (0..1) to the blur gate's hue, ``sat_k`` to its saturation."""
    margin = int(round(hue_k * HUE_MARGIN))
    hue = tuple(((lo - margin) % 180, (hi + margin) % 180) for lo, hi in colour.hue)
    sat = int(round(colour.sat_min * (1.0 - sat_k * (1.0 - SATURATION_RATIO))))
    return replace(colour, hue=hue, sat_min=sat)


def blur_gate(colour: MarkerColour, hsv: np.ndarray, box: tuple[int, int, int, int],
              mass: float, min_ratio: float) -> MarkerColour | None:
    """The loosest step of the marker's blur gate that sees no rival on the rest frame.

    Parameters
    ----------
    colour : MarkerColour
        The marker's own gate.
    hsv : (H, W, 3) uint8
        The frame the marker was found on, in HSV (the hand at rest).
    box : (x, y, w, h)
        The marker's bounding box on it, px: its own pixels, which any gate
        of its colour takes.
    mass : float
        Its mass, px.
    min_ratio : float
        A blob of at least this fraction of ``mass`` elsewhere is a rival
        (``TrackerParams.lost_ratio``: what the tracker would follow).

    Returns
    -------
    MarkerColour or None
        None when even the tightest step takes something else.
    """
    x, y, w, h = box
    H, W = hsv.shape[:2]

    def around(pad: int) -> tuple[int, int, int, int]:
        return max(x - pad, 0), max(y - pad, 0), min(x + w + pad, W), min(y + h + pad, H)

    x0, y0, x1, y1 = around(max(w, h) // 2 + 2)
    n0, m0, n1, m1 = around(NEAR * max(w, h))
    near = (n1 - n0) * (m1 - m0) - (x1 - x0) * (y1 - y0)
    for hue_k, sat_k in STEPS:
        gate = _widened(colour, hue_k, sat_k)
        mask = gate.backproject(hsv)
        mask[y0:y1, x0:x1] = 0  # the marker itself, and its blurred rim
        # Only whether a rival exists matters: labelled within the box of the
        # gate's pixels, a fraction of the frame (a third of the first frame's
        # cost), the same blobs with the same areas.
        bx, by, bw, bh = cv2.boundingRect(mask)
        if find_blobs(mask[by:by + bh + 1, bx:bx + bw + 1], min_area=min_ratio * mass):
            continue
        # scattered pixels around it (the skin beside a red marker) would
        # pull a streak's window off it
        if cv2.countNonZero(mask[m0:m1, n0:n1]) <= NEAR_SHARE * near:
            return gate
    return None


#: Unmixing: a pixel counts as the streak's when at least this share of its
#: colour is the marker's, the rest the region's background ...
MIN_SHARE = 0.22
#: ... and what is left of its colour, besides that mix, is at most this
#: fraction of the marker's contrast with the background (another colour).
MAX_RESIDUAL = 0.45


@dataclass(frozen=True)
class StreakGate:
    """Which pixels of a region hold some of a moving marker's colour.

    Each pixel ``p`` is taken as a mix ``a m + (1 - a) b`` of the marker's
    own colour ``m`` (BGR, measured when it was found) and the region's
    background ``b`` (its median: most of a search region is table or
    skin). A pixel with ``a >= MIN_SHARE`` and little colour off that line
    is the streak's, however washed out: the hue of a green marker smeared
    over skin slides to a yellow no hue range of the marker holds, but its
    colour still lies between the marker's and the skin's. The marker's
    ``hsv`` gate (its blur gate, or its own) is added to it.

    Parameters
    ----------
    bgr : (float, float, float)
        The marker's own colour.
    hsv : MarkerColour
        The colour gate whose pixels count as well.
    """

    bgr: tuple[float, float, float]
    hsv: MarkerColour

    def backproject_bgr(self, bgr: np.ndarray) -> np.ndarray:
        """255 where a pixel of the BGR region ``bgr`` is the streak's, 0 elsewhere."""
        pix = bgr.reshape(-1, 3).astype(np.float32)
        b = np.median(pix, axis=0)
        axis = np.asarray(self.bgr, np.float32) - b
        norm2 = float(axis @ axis)
        gate = self.hsv.backproject(to_hsv(bgr))
        if norm2 < 100.0:  # the background has the marker's colour: nothing to unmix
            return gate
        d = pix - b
        a = d @ axis / norm2
        off = d - a[:, None] * axis
        resid2 = (off * off).sum(axis=1)
        ok = (a >= MIN_SHARE) & (resid2 <= (MAX_RESIDUAL ** 2) * norm2 * np.minimum(a, 1.0))
        mask = ok.reshape(bgr.shape[:2]).astype(np.uint8) * 255
        return cv2.bitwise_or(mask, gate)

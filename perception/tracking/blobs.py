"""Blobs: connected components of a colour back-projection.

A marker's colour model (:mod:`perception.tracking.markers`) turns an image
into a mask of the pixels it accepts; the connected components (8-connected)
of that mask are the blobs. Every step of the tracker that has to tell one
same-coloured thing from another works on blobs: first detection takes the
candidates of each colour, splitting keeps the blob nearest the prediction
when a neighbour of the marker's colour joined its window, and re-acquisition
looks for the plausible blob nearest the last prediction in a downscaled
frame.

"Plausible" is always an area bound: below it the blob is noise or a sliver
of the marker, above it something larger than the marker.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np


@dataclass(frozen=True)
class Blob:
    """One connected component of a back-projection.

    Parameters
    ----------
    centre : (float, float)
        Centroid (x, y), px.
    area : float
        Pixel count, px (in full-resolution px for a downscaled search).
    box : (int, int, int, int)
        Bounding box (x, y, width, height), px.
    """

    centre: tuple[float, float]
    area: float
    box: tuple[int, int, int, int]

    @property
    def size(self) -> tuple[int, int]:
        """Bounding-box (width, height), px."""
        return self.box[2], self.box[3]

    def moved(self, dx: int, dy: int) -> Blob:
        """The same blob in coordinates shifted by ``(dx, dy)`` px (region -> frame)."""
        x, y, w, h = self.box
        return Blob((self.centre[0] + dx, self.centre[1] + dy), self.area, (x + dx, y + dy, w, h))


#: Masks with fewer pixels than this are labelled in 16 bits: every
#: provisional label of OpenCV's scan fits, and labelling runs about twice as
#: fast as in 32 bits (the components and their statistics are the same).
_LABELS_16_BELOW = 65535


def label_type(shape: tuple[int, ...]) -> int:
    """OpenCV label type for the connected components of a mask of ``shape``."""
    return cv2.CV_16U if shape[0] * shape[1] < _LABELS_16_BELOW else cv2.CV_32S


def find_blobs(
    mask: np.ndarray,
    *,
    min_area: float = 0.0,
    max_area: float = math.inf,
    scale: tuple[float, float] | None = None,
) -> list[Blob]:
    """The plausible blobs of a mask, in label order.

    Parameters
    ----------
    mask : (H, W) uint8
        Back-projection (non-zero: the colour).
    min_area, max_area : float
        Keep blobs with ``min_area <= area <= max_area`` px (after scaling).
    scale : (float, float), optional
        ``(fx, fy)``: the mask is a downscaled image and ``fx``, ``fy`` the
        full-resolution px per mask px; centres, areas and boxes are returned
        in full-resolution px (pixel centres map to pixel centres).

    Returns
    -------
    list of Blob
        In mask coordinates (scaled if ``scale``).
    """
    n, _, stats, cents = cv2.connectedComponentsWithStats(mask, connectivity=8,
                                                          ltype=label_type(mask.shape))
    if n <= 1:
        return []
    areas = stats[1:, cv2.CC_STAT_AREA]
    centres = cents[1:]
    boxes = stats[1:, :4]
    if scale is not None:
        fx, fy = scale
        areas = areas * (fx * fy)
        centres = (centres + 0.5) * (fx, fy) - 0.5
        boxes = np.rint(boxes * np.array([fx, fy, fx, fy])).astype(np.int64)
    keep = np.flatnonzero((areas >= min_area) & (areas <= max_area))
    centres, areas, boxes = centres[keep].tolist(), areas[keep].tolist(), boxes[keep].tolist()
    return [Blob((c[0], c[1]), float(a), tuple(b)) for c, a, b in zip(centres, areas, boxes)]


def blob_at(mask: np.ndarray, point: tuple[int, int]) -> np.ndarray | None:
    """The blob of ``mask`` at ``point`` (x, y) px, as a bool mask; None on background.

    A point outside the mask is moved onto its nearest pixel.
    """
    _, labels = cv2.connectedComponents(mask, ltype=label_type(mask.shape))
    h, w = mask.shape
    lab = labels[min(max(point[1], 0), h - 1), min(max(point[0], 0), w - 1)]
    return labels == lab if lab else None


def principal_axes(mask: np.ndarray) -> tuple[float, float, float]:
    """Variances (px^2) of a binary mask along its major and minor axes; the major's angle, rad.

    The minor variance of a line may be a rounding error below 0.
    """
    mo = cv2.moments(mask, True)
    m = max(mo["m00"], 1.0)
    a, b, c = mo["mu20"] / m, mo["mu11"] / m, mo["mu02"] / m
    root = math.sqrt(max((a - c) ** 2 / 4 + b * b, 0.0))
    return (a + c) / 2 + root, (a + c) / 2 - root, 0.5 * math.atan2(2 * b, a - c)


def by_distance(blobs: Sequence[Blob], point: Sequence[float]) -> list[Blob]:
    """Blobs sorted by the distance of their centres from ``point``, nearest first.

    Parameters
    ----------
    blobs : sequence of Blob
        Candidates (already filtered for plausibility).
    point : (float, float)
        (x, y), px, in the blobs' coordinates.

    Returns
    -------
    list of Blob
        Ties keep their input order.
    """
    if not blobs:
        return []
    order = np.argsort(_distances(blobs, point), kind="stable")
    return [blobs[k] for k in order]


def nearest_blob(blobs: Sequence[Blob], point: Sequence[float]) -> Blob | None:
    """The blob whose centre lies nearest ``point`` (the first of ties); None if none.

    Parameters
    ----------
    blobs : sequence of Blob
        Candidates (already filtered for plausibility).
    point : (float, float)
        (x, y), px, in the blobs' coordinates.
    """
    if not blobs:
        return None
    return blobs[int(np.argmin(_distances(blobs, point)))]


def _distances(blobs: Sequence[Blob], point: Sequence[float]) -> np.ndarray:
    xy = np.array([b.centre for b in blobs])
    return np.hypot(xy[:, 0] - point[0], xy[:, 1] - point[1])

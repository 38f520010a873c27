"""Finding markers without a prediction: first detection and re-acquisition.

Both searches work in two steps, kept apart so that either can grow: a
*search* that lists the candidate blobs of the marker's colour
(:class:`~perception.tracking.blobs.Blob`), and a *choice* among them.

**First detection.** :func:`find_candidates` lists the blobs of a marker's
colour in the whole frame (or in its user-given ROI), largest first.
:func:`closest_combination` chooses for the hand's markers: they sit within
a hand's width of each other, while same-coloured things on the table need
not, so of the few largest blobs of each hand marker's colour the
combination whose markers lie closest together (with any hand marker
already tracked) wins, however large a distant blob is. A still marker (the
object), or a marker without rivals, takes its largest blob.

**Re-acquisition**, only once the local search has failed and while the
marker stays lost: :func:`search_blobs` lists the blobs of plausible area in
the thresholded back-projection of a downscaled full frame
(:func:`downscaled_hsv`, computed once per frame for all lost markers),
nearest the prediction first; :func:`reacquire` refines them at full
resolution and takes the first whose refined mass is plausible.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence

import cv2
import numpy as np

from perception.errors import InputError
from perception.tracking.blobs import Blob, by_distance, find_blobs
from perception.tracking.markers import MarkerColour
from perception.tracking.measurement import Measurement, measure
from perception.tracking.params import TrackerParams

#: A region of interest: ``(x, y, width, height)``, px.
ROI = tuple[int, int, int, int]


def find_candidates(
    frame: np.ndarray, colour: MarkerColour, min_area: float, roi: ROI | None = None
) -> list[Blob]:
    """Blobs of a marker's colour in the frame (or its ROI), largest first.

    Parameters
    ----------
    frame : (H, W, 3) uint8
        BGR frame.
    colour : MarkerColour
        The marker's colour model.
    min_area : float
        Smallest blob counted, px.
    roi : (x, y, w, h), optional
        Look only in this region, px.

    Returns
    -------
    list of Blob
        In frame coordinates; ties in area keep label order.

    Raises
    ------
    InputError
        A ROI holding nothing of the colour.
    """
    if roi is not None:
        x, y, w, h = roi
        region = frame[y : y + h, x : x + w]
    else:
        region = frame
    bp = colour.backproject(cv2.cvtColor(region, cv2.COLOR_BGR2HSV))
    blobs = find_blobs(bp, min_area=min_area)
    if roi is not None:
        if not blobs:
            raise InputError(
                f"{colour.name}: nothing of its colour in the ROI {list(roi)} on the first frame"
            )
        blobs = [b.moved(roi[0], roi[1]) for b in blobs]
    return sorted(blobs, key=lambda b: -b.area)


def spread(points: Sequence[Sequence[float]]) -> float:
    """Sum of the pairwise distances of some points, px: how far apart they lie.

    Parameters
    ----------
    points : sequence of (float, float)
        (x, y), px.
    """
    return sum(
        float(np.hypot(p[0] - q[0], p[1] - q[1]))
        for i, p in enumerate(points)
        for q in points[i + 1 :]
    )


def closest_combination(
    candidates: Sequence[Sequence[Blob]], anchors: Sequence[Sequence[float]] = ()
) -> tuple[int, ...]:
    """One candidate per marker: the combination lying closest together.

    Parameters
    ----------
    candidates : sequence of sequences of Blob
        Per marker, its candidate blobs (each non-empty).
    anchors : sequence of (float, float)
        Positions (px) of markers already placed, which the chosen blobs
        should lie near too.

    Returns
    -------
    tuple of int
        Per marker, the index of the chosen candidate; of equally close
        combinations, the first (in order of the candidates).
    """

    def cost(combo: tuple[int, ...]) -> float:
        chosen = [blobs[k].centre for blobs, k in zip(candidates, combo)]
        return spread(chosen + list(anchors))

    return min(itertools.product(*(range(len(blobs)) for blobs in candidates)), key=cost)


def search_scale(refs: Sequence[float], params: TrackerParams) -> int:
    """Downscale factor of the global search.

    ``params.search_scale`` if set; else the largest factor (at most
    ``search_max_scale``) that keeps the smallest marker at least
    ``search_marker_px`` across.

    Parameters
    ----------
    refs : sequence of float
        Reference masses (px) of the markers found so far.
    params : TrackerParams
        The search settings.
    """
    if params.search_scale:
        return params.search_scale
    if not refs:
        return 1
    diameter = 2 * math.sqrt(min(refs) / math.pi)
    return int(min(max(diameter // params.search_marker_px, 1), params.search_max_scale))


def downscaled_hsv(frame: np.ndarray, scale: int) -> tuple[np.ndarray, float, float]:
    """The whole frame downscaled by ``scale`` (area averaging), in HSV.

    Parameters
    ----------
    frame : (H, W, 3) uint8
        BGR frame.
    scale : int
        Downscale factor.

    Returns
    -------
    hsv : (h, w, 3) uint8
        The small image.
    fx, fy : float
        Full-resolution px per small px, horizontally and vertically.
    """
    h, w = frame.shape[:2]
    sw, sh = max(w // scale, 1), max(h // scale, 1)
    small = cv2.resize(frame, (sw, sh), interpolation=cv2.INTER_AREA)
    return cv2.cvtColor(small, cv2.COLOR_BGR2HSV), w / sw, h / sh


def search_blobs(
    small: tuple[np.ndarray, float, float],
    colour: MarkerColour,
    ref: float,
    pred: Sequence[float],
    params: TrackerParams,
) -> list[Blob]:
    """Blobs of plausible area in a downscaled frame, nearest the prediction first.

    Parameters
    ----------
    small : (hsv, fx, fy)
        As :func:`downscaled_hsv` returns.
    colour : MarkerColour
        The marker's colour model.
    ref : float
        Reference mass, px; areas from ``search_min_ratio`` to
        ``max_area_ratio`` times it are plausible.
    pred : (float, float)
        Predicted position (x, y), px.
    params : TrackerParams
        The search settings.

    Returns
    -------
    list of Blob
        At most ``search_tries``, in full-resolution px.
    """
    hsv, fx, fy = small
    blobs = find_blobs(
        colour.backproject(hsv),
        min_area=params.search_min_ratio * ref,
        max_area=params.max_area_ratio * ref,
        scale=(fx, fy),
    )
    return by_distance(blobs, pred)[: params.search_tries]


def reacquire(
    frame: np.ndarray,
    small: tuple[np.ndarray, float, float],
    colour: MarkerColour,
    ref: float,
    pred: Sequence[float],
    window: tuple[int, int],
    params: TrackerParams,
    accept: Callable[[Measurement], bool] | None = None,
) -> Measurement | None:
    """Global search for a lost marker: the nearest blob that refines to a plausible mass.

    Parameters
    ----------
    frame : (H, W, 3) uint8
        BGR frame.
    small : (hsv, fx, fy)
        The frame as :func:`downscaled_hsv` returns it.
    colour : MarkerColour
        The marker's colour model.
    ref : float
        Reference mass, px.
    pred : (float, float)
        Predicted position (x, y), px.
    window : (int, int)
        The marker's window (width, height), px.
    params : TrackerParams
        The search settings.
    accept : callable, optional
        ``accept(measurement) -> bool``: the caller's own plausibility test
        (how far the marker can have moved, the hand's structure).

    Returns
    -------
    Measurement or None
        A whole (not merged) measurement with mass from ``reacquire_ratio``
        to ``max_area_ratio`` times ``ref`` that ``accept`` accepts; None if
        no candidate has one.
    """
    for blob in search_blobs(small, colour, ref, pred, params):
        meas = measure(frame, colour, blob.centre, window, ref, params.search_margin_px, params)
        if meas is None or meas.merged:
            continue
        if not params.reacquire_ratio <= meas.mass / ref <= params.max_area_ratio:
            continue
        if accept is None or accept(meas):
            return meas
    return None

"""Finding a lost marker again: a search of the whole frame where the hand puts it.

Only once the local search around its prediction has failed, and while the
marker stays lost: :func:`reacquire` takes the blobs of plausible area in
the thresholded back-projection of a downscaled full frame
(:func:`downscaled_hsv`, computed once per frame for all lost markers),
nearest the expected position first, refines them at full resolution and
keeps the first whose refined mass — and whatever else the caller checks
(shape, colour, place in the hand) — is plausible. First detection is in
:mod:`perception.tracking.candidates` and :mod:`perception.tracking.hand`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import cv2
import numpy as np

from perception.tracking.blobs import by_distance, find_blobs
from perception.tracking.markers import MarkerColour, to_hsv
from perception.tracking.measurement import Measurement, measure
from perception.tracking.params import TrackerParams

#: A region of interest: ``(x, y, width, height)``, px.
ROI = tuple[int, int, int, int]


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
    return to_hsv(small), w / sw, h / sh


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
        Reference mass, px; downscaled blobs of ``search_min_ratio`` to
        ``max_area_ratio`` times it are refined, the ``search_tries``
        nearest ``pred``.
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
    hsv, fx, fy = small  # plausible blobs of the downscaled frame, the nearest first
    blobs = find_blobs(colour.backproject(hsv), min_area=params.search_min_ratio * ref,
                       max_area=params.max_area_ratio * ref, scale=(fx, fy))
    for blob in by_distance(blobs, pred)[: params.search_tries]:
        meas = measure(frame, colour, blob.centre, window, ref, params.search_margin_px, params)
        if meas is None or meas.merged:
            continue
        if not params.reacquire_ratio <= meas.mass / ref <= params.max_area_ratio:
            continue
        if accept is None or accept(meas):
            return meas
    return None

"""Abnormal grasps made from real normal ones: the real transport kept, the grip changed.

No recordings of abnormal grasps exist to test the verdict on, so they are
made from real healthy ones. The hand's path (the grip midpoint) is kept
sample for sample; only the aperture changes, and the digits are placed
back symmetrically about the midpoint at the new aperture, along the line
they had. Both variants work on the movement the field's landmarks bound
(:func:`perception.landmarks.movement_landmarks`: onset and end at 5 % of
the peak transport speed), with ``s`` the share of that movement:

* :func:`late_opening` — the opening moved late: the aperture stays at its
  rest value until ``at`` (default 70 % of the movement), then the real
  opening, from the moment it began to the end, is replayed compressed
  into what is left (the thesis's "delayed opening", chapter 5, after
  Gangitano et al. 2004);
* :func:`reopening` — a closing and re-opening inserted: when the grip has
  first opened to ``level`` (default 60 %) of its opening, the real profile
  pauses while the aperture closes by ``depth`` (default 80 %) of that
  opening and opens again (a raised-cosine dip over ``width``, default 30 %
  of the movement); then the rest of the real profile is replayed,
  compressed into what is left (the thesis's open-close-open). A grip that
  has not yet opened has nothing to close, so the dip is placed by the
  grip's own progress rather than at a fixed share of the movement.

docs/mocap.md describes both, for those who evaluate the verdict this way.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from perception.landmarks import LandmarkParams, movement_landmarks
from perception.reaches import Reach

__all__ = ["late_opening", "reopening"]


def _with_aperture(reach: Reach, g: np.ndarray, name: str) -> Reach:
    """The reach with its digits placed at aperture ``g`` about the same midpoint."""
    mid = 0.5 * (reach.finger + reach.thumb)
    axis = reach.finger - reach.thumb
    norm = np.linalg.norm(axis, axis=1, keepdims=True)
    unit = np.divide(axis, norm, out=np.zeros_like(axis), where=norm > 0)
    half = 0.5 * g[:, None] * unit
    return dataclasses.replace(reach, name=name, finger=mid + half, thumb=mid - half)


def _movement(reach: Reach, params: LandmarkParams | None):
    lm = movement_landmarks(reach.time, reach.transport, reach.aperture, params)
    if not (math.isfinite(lm.onset_time) and math.isfinite(lm.end_time)):
        raise ValueError(f"{reach.name}: the movement's onset or end is not in the recording")
    s = (reach.time - lm.onset_time) / lm.movement_time
    return lm, s


def late_opening(reach: Reach, at: float = 0.70,
                 params: LandmarkParams | None = None) -> Reach:
    """The reach with its grip opening moved late (see the module docstring).

    Parameters
    ----------
    reach : Reach
        A real normal reach.
    at : float
        Share of the movement at which the grip now starts to open.
    params : LandmarkParams, optional
        The landmarks' definitions (onset, end, filter).
    """
    lm, s = _movement(reach, params)
    g = reach.aperture
    seen = np.isfinite(g)
    start = lm.opening_time if math.isfinite(lm.opening_time) else 0.0
    # the real opening began a little before it crossed 10 % of its height
    start = max(0.0, start - 0.05)
    source = np.where(s < at, 0.0, start + (s - at) * (1 - start) / (1 - at))
    source = np.where(s > 1, s, source)
    rest = lm.rest_aperture
    new = np.interp(source, s[seen], g[seen])
    new = np.where((s >= 0) & (s < at), rest, new)
    new = np.where(s < 0, g, new)
    return _with_aperture(reach, new, f"{reach.name}-late")


def reopening(reach: Reach, level: float = 0.6, width: float = 0.3, depth: float = 0.8,
              params: LandmarkParams | None = None) -> Reach:
    """The reach with a closing and re-opening inserted (see the module docstring).

    Parameters
    ----------
    reach : Reach
        A real normal reach.
    level : float
        The closing begins when the grip has opened this share of its
        opening (MGA less rest) for the first time.
    width : float
        Share of the movement the closing and re-opening take together.
    depth : float
        How far the grip closes, as a share of its opening above rest when
        the closing begins.
    params : LandmarkParams, optional
    """
    lm, s = _movement(reach, params)
    g = reach.aperture
    seen = np.isfinite(g)
    rest = lm.rest_aperture
    inside = np.flatnonzero(seen & (s >= 0) & (g >= rest + level * lm.opening))
    if not len(inside):
        raise ValueError(f"{reach.name}: the grip never opens to {level:.0%} of its opening")
    s_c = float(s[inside[0]])
    width = min(width, 0.9 * (1 - s_c))
    # the real profile up to s_c, the dip, then the rest of it compressed into what is left
    source = np.where(s < s_c, s, np.where(s < s_c + width, s_c,
                                           s_c + (s - s_c - width) * (1 - s_c) / (1 - s_c - width)))
    source = np.where(s > 1, s, source)
    new = np.interp(source, s[seen], g[seen])
    u = np.clip((s - s_c) / width, 0, 1)
    dip = 0.5 * (1 - np.cos(2 * np.pi * u))
    new = new - depth * dip * (np.interp(s_c, s[seen], g[seen]) - rest)
    return _with_aperture(reach, new, f"{reach.name}-reopen")

"""Why a landmark is doubtful: the flags of :func:`perception.landmarks.movement_landmarks`.

``ok``, or ``inside a gap: …`` (taken where a marker was lost), ``not seen: …``
(with why), ``bound raised to N % of peak`` (docs/glossary.md).
"""

from __future__ import annotations

import numpy as np

from perception.rowwise import run_edges

__all__ = ["APERTURE_LANDMARKS", "NEEDS", "all_flags", "bound_flags", "gap_near", "why_not_open"]


#: The landmarks measured on the aperture.
APERTURE_LANDMARKS = ("mga", "mga_time", "contact_aperture", "aperture_peaks", "rest_aperture",
                       "opening_time", "peak_opening_speed", "closing_time")
#: The landmarks measured against the onset, the end or both.
NEEDS = {"onset": ("onset_time", "movement_time", "peak_speed_time", "mga_time",
                    "opening_time", "rest_aperture"),
          "end": ("end_time", "movement_time", "peak_speed_time", "mga_time", "opening_time",
                  "deceleration_time", "closing_time", "contact_aperture")}


def all_flags(names, said: str) -> dict[str, str]:
    """Each of ``names`` (every landmark) flagged ``said``: a movement with none measurable."""
    return dict.fromkeys(names, said)


def bound_flags(onset: int | None, end: int | None, raised: list[tuple[str, float]],
                 threshold: float) -> dict[str, str]:
    """The flags of a movement's bounds: missing (the recording starts or ends in it), or
    raised above the asked share of the peak speed.

    Parameters
    ----------
    onset, end : int or None
        Rows of the movement's onset and end (None: not in the recording).
    raised : list of (str, float)
        Each side (``onset``, ``end``) and the share of the peak speed it was bounded at.
    threshold : float
        The share asked for (``LandmarkParams.threshold``).
    """
    flags: dict[str, str] = {}
    for side, row, where in (("onset", onset, "starts"), ("end", end, "ends")):
        if row is None:
            for name in NEEDS[side]:
                flags.setdefault(name, f"not seen: the recording {where} in the movement")
    for side, share in raised:
        if round(share * 100) <= round(threshold * 100):  # the asked share, as printed
            continue
        said = f"bound raised to {share * 100:.0f} % of peak"
        for name in (f"{side}_time", "movement_time"):
            flags.setdefault(name, said)
    return flags


def gap_near(time: np.ndarray, lost: np.ndarray, at: float, reach: float) -> float | None:
    """The longest lost stretch within ``reach`` s of time ``at``, s (None if none)."""
    near = np.flatnonzero(lost & (np.abs(time - at) <= reach + 1e-9))
    if not len(near):
        return None
    a, b = run_edges(lost)
    # the stretches that reach within ``reach``, as arrays (a stream's many short losses
    # were a Python loop at every row)
    close = (a <= near[-1]) & (b > near[0])
    lo, hi = np.maximum(a[close] - 1, 0), np.minimum(b[close], len(time) - 1)
    return max(0.0, float((time[hi] - time[lo]).max()))


def why_not_open(time: np.ndarray, g: np.ndarray, level: float) -> str:
    """Why the grip's opening time is missing, in words (the opening is read where the
    aperture first crosses ``level``).

    Parameters
    ----------
    time : (N,) array
        Sample times of the movement, s.
    g : (N,) array
        The grip aperture, m (NaN where a digit was lost).
    level : float
        The opening level, m.
    """
    ok = np.isfinite(g)
    above = np.flatnonzero(g[ok] > level)
    if not len(above):
        return "not seen: the grip never crossed the opening level"
    i = int(above[0])
    t = time[ok]
    before = t[i - 1] if i else time[0]
    return (f"not seen: the grip opened while a digit was lost "
            f"({(t[i] - before) * 1000:.0f} ms unseen)")

"""Lost samples in recorded marker paths: found, marked, and bridged only where short.

Motion-capture systems lose markers in three ways that a raw file does not
mark: a sample far off the path for one to a few samples (a *spike*: a
reflection taken for the marker, common on a trial's first sample), a
marker *held* at its last position while it is occluded (the same
coordinates, to the last digit, sample after sample — a real marker at rest
still jitters by a few micrometres), and plain dropouts (NaN, or zeros,
which the readers already turn into NaN). :func:`clean_path` marks all
three as lost and bridges a gap only when it is short
(:attr:`CleaningParams.max_bridge`); every repair is counted in a
:class:`Repairs` so the report can say what was done.

The spike test is a Hampel filter: a sample more than
:attr:`CleaningParams.spike_distance` from the running median of its
neighbours (:attr:`CleaningParams.spike_window` either side) is off the
path. A reach's path bends smoothly enough that the median of a 0.1 s
window stays within a few millimetres of it (measured on real Optotrak
reaches at 1 m/s), while the spikes seen in real recordings are 15-80 mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from pydantic import Field
from scipy.interpolate import PchipInterpolator
from scipy.ndimage import median_filter

from perception.validation import Int, NonNegative, declared

__all__ = ["CleaningParams", "Repairs", "clean_path", "spikes"]


@declared
class CleaningParams:
    """How lost samples are found and which gaps are bridged.

    Parameters
    ----------
    spike_distance : float
        A sample this far from the running median of its neighbours is a spike, m.
    spike_window : float
        Half-width of the running median's window, s.
    held_samples : int
        This many identical consecutive samples (3 coordinates, exactly)
        mark the marker as held by the system while lost: all but the
        first count as lost.
    max_bridge : float
        Gaps up to this long are bridged (shape-preserving cubic
        interpolation, PCHIP); longer ones stay lost, s.
    """

    spike_distance: NonNegative = 0.010
    spike_window: NonNegative = 0.05
    held_samples: Annotated[Int, Field(ge=2)] = 3
    max_bridge: NonNegative = 0.05


@dataclass(frozen=True)
class Repairs:
    """What :func:`clean_path` did to one marker's path.

    Attributes
    ----------
    spikes, held, missing : int
        Samples found off the path, held, and missing in the file.
    bridged : int
        Lost samples filled by interpolation (in gaps up to ``max_bridge``).
    longest_gap : float
        The longest gap left lost, s (0 if none).
    """

    spikes: int = 0
    held: int = 0
    missing: int = 0
    bridged: int = 0
    longest_gap: float = 0.0

    def describe(self, marker: str) -> str | None:
        """One line for the report, or None when nothing was found."""
        parts = [f"{n} {what}" for n, what in ((self.spikes, "spike(s)"),
                                               (self.held, "held sample(s)"),
                                               (self.missing, "missing sample(s)")) if n]
        if not parts:
            return None
        line = f"{marker}: {', '.join(parts)} marked lost"
        if self.bridged:
            line += f", {self.bridged} bridged"
        if self.longest_gap > 0:
            line += f"; longest gap left {self.longest_gap * 1000:.0f} ms"
        return line


def _held(path: np.ndarray, run: int) -> np.ndarray:
    """Samples that repeat the previous one exactly, in runs of ``run`` or more."""
    same = np.r_[False, (np.diff(path, axis=0) == 0).all(axis=1)]
    out = np.zeros(len(path), dtype=bool)
    for start, stop in _runs(same):
        if stop - start + 1 >= run:  # the run's first sample is the last real one
            out[start:stop] = True
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of each run of True in ``mask`` (stop exclusive)."""
    edges = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def spikes(time: np.ndarray, path: np.ndarray, ok: np.ndarray | None = None,
           params: CleaningParams | None = None) -> np.ndarray:
    """(N,) samples off the running median of the seen samples around them: spikes.

    Parameters
    ----------
    time : (N,) array
        Sample times, s.
    path : (N, D) array
        Positions, m (NaN where lost).
    ok : (N,) bool array, optional
        The samples to read (default: the finite ones).
    params : CleaningParams, optional
        Its ``spike_distance`` and ``spike_window``.
    """
    params = CleaningParams() if params is None else params
    ok = np.isfinite(path).all(axis=1) if ok is None else ok
    dt = float(np.median(np.diff(time))) if len(time) > 1 else 1.0
    half = max(1, int(round(params.spike_window / dt)))
    idx = np.flatnonzero(ok)
    if len(idx) < 2 * half + 1:
        return np.zeros(len(path), dtype=bool)
    seen = path[idx]
    # mirrored at the ends, so that a first sample off the path meets the
    # samples after it, not copies of itself
    med = median_filter(seen, size=(2 * half + 1, 1), mode="mirror")
    off = np.linalg.norm(seen - med, axis=1) > params.spike_distance
    out = np.zeros(len(path), dtype=bool)
    out[idx[off]] = True
    return out


def clean_path(time: np.ndarray, path: np.ndarray,
               params: CleaningParams | None = None) -> tuple[np.ndarray, Repairs]:
    """A marker's path with spikes, held and missing samples lost, short gaps bridged.

    Parameters
    ----------
    time : (N,) array
        Sample times, s, increasing.
    path : (N, D) array
        Positions, m; NaN where the file has none.
    params : CleaningParams, optional

    Returns
    -------
    (N, D) array, Repairs
        The cleaned path (NaN where lost) and what was done.
    """
    params = CleaningParams() if params is None else params
    time = np.asarray(time, dtype=float)
    path = np.array(path, dtype=float)
    missing = ~np.isfinite(path).all(axis=1)
    held = _held(np.where(missing[:, None], np.nan, path), params.held_samples) & ~missing
    spiked = spikes(time, path, ~missing & ~held, params)
    lost = missing | held | spiked
    path[lost] = np.nan
    bridged = 0
    longest = 0.0
    ok = ~lost
    if ok.sum() >= 2:
        fill = PchipInterpolator(time[ok], path[ok], axis=0, extrapolate=False)
        for a, b in _runs(lost):
            inside = a > 0 and b < len(time)
            span = (time[b] - time[a - 1]) if inside else math.inf
            if inside and span <= params.max_bridge + 1e-9:
                path[a:b] = fill(time[a:b])
                bridged += b - a
            else:
                longest = max(longest, float(span if inside else
                                             time[min(b, len(time) - 1)] - time[max(a - 1, 0)]))
    return path, Repairs(int(spiked.sum()), int(held.sum()), int(missing.sum()), bridged,
                         longest)

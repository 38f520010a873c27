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

A marker seen again where it was held, within
:attr:`CleaningParams.held_distance` (5 mm), did not move on meanwhile: its
held samples were right, and it is not lost (a tracker's own output repeats
a still marker exactly: a rendered rest, a blob's centroid on whole pixels).
A file whose positions are rounded (a 1 mm export) repeats its samples
exactly whenever the marker moves less than the rounding step: such a
*quantised* live marker is not held either. :func:`quantum` finds the step ``q``
from the data (every change of every coordinate is a whole multiple of it),
and then a run of repeated samples counts as held only where the marker
would have had to move more than the step during it: where it comes back
(the nearest of the next few samples) more than 1.5 ``q`` from where it was
held, or, for a run that lasts to the end, where it entered the run by
more than that in one sample (it was moving fast, then froze). A run that
spans the whole path is a still marker, never a held one; a caller that
knows the other markers (:mod:`perception.track_cleaning`) also spares the
runs during which every other marker repeats too (the whole scene still: a
rendered or rounded rest).

The spike test is a Hampel filter: a sample more than
:attr:`CleaningParams.spike_distance` from the running median of its
neighbours (:attr:`CleaningParams.spike_window` either side) is off the
path, unless it lies within that distance of the path of the neighbours
not found off (the line between the nearest on either side, within twice
the window: a spike shifts the median its neighbours are judged by, by a
frame's motion at video rates). A reach's path bends smoothly enough that the median of a 0.1 s
window stays within a few millimetres of it (measured on real Optotrak
reaches at 1 m/s), while the spikes seen in real recordings are 15-80 mm.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from pydantic import Field
from scipy.interpolate import PchipInterpolator
from scipy.ndimage import median_filter

from perception.resume import Kept
from perception.rowwise import finite_rows, row_norm, run_edges
from perception.validation import Int, NonNegative, declared

__all__ = ["CleaningParams", "Repairs", "clean_path", "held", "quantum", "spikes"]

#: A quantised marker counts as held only if it moved more than this many steps
#: during the run: a live one steps by one at a time while it is slower than the step.
HELD_STEPS = 1.5
#: Fewest changes of a path's coordinates from which its rounding step is read.
MIN_CHANGES = 10


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
    quantum : float, optional
        The step the file's positions are rounded to, m (0.001 for a 1 mm
        export): repeated samples count as held only where the marker would
        have had to move more than it. Default: found from the data
        (:func:`quantum`); 0 treats every run of ``held_samples`` as held.
    held_distance : float
        Repeated samples count as held only where the marker is seen again
        (or, for a run to the end, came into it) further than this from where
        it was held, m: nearer, it did not move on meanwhile, and the repeats
        were its true place (within half the spike distance). Real systems'
        holds end 6.7-170 mm away (Optotrak, 23 of them, median 69 mm); a
        tracker's still marker starts to move within a pixel or two. 0: every
        run is held.
    """

    spike_distance: NonNegative = 0.010
    spike_window: NonNegative = 0.05
    held_samples: Annotated[Int, Field(ge=2)] = 3
    max_bridge: NonNegative = 0.05
    quantum: NonNegative | None = None
    held_distance: NonNegative = 0.005


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


def quantum(path: np.ndarray) -> float | None:
    """The step a path's positions are rounded to, if they are: None if not.

    Every change of every coordinate between consecutive samples is then a
    whole multiple of the smallest one. Positions written with all their
    digits (or a file's six decimals) give a step far below any motion, for
    which the held rule is today's; a 1 mm export gives 0.001 m.

    Parameters
    ----------
    path : (N, D) array
        Positions (NaN where lost).
    """
    steps = np.abs(np.diff(np.asarray(path, dtype=float), axis=0)).ravel()
    steps = steps[np.isfinite(steps) & (steps > 0)]
    if len(steps) < MIN_CHANGES:
        return None
    q = float(steps.min())
    k = steps / q
    # float error of a rounded value read and rescaled stays far below 1e-3 of a step
    return q if bool(np.all(np.abs(k - np.round(k)) < 1e-3)) else None


def held(path: np.ndarray, run: int, step: float | None = None,
         still: np.ndarray | None = None, near: float = 0.0) -> np.ndarray:
    """(N,) samples that repeat the previous one seen exactly while the marker was lost.

    A run of ``run`` or more identical seen samples (all coordinates; samples
    missing between them are passed over) is held (all but its first, the
    last real sample), unless

    * it spans every seen sample (a marker that never moves);
    * ``still`` is true through it (every other marker repeats too: the
      whole scene is still);
    * the marker would not have had to move more than ``near`` (or, where the
      positions are rounded to ``step``, :data:`HELD_STEPS` steps if more)
      during it: the nearest of the next ``run`` seen samples lies within
      that of the held position (or, for a run that lasts to the end, the
      sample before it does).

    Parameters
    ----------
    path : (N, D) array
        Positions (NaN where lost).
    run : int
        Fewest identical samples that can be a held run.
    step : float, optional
        The rounding step (:func:`quantum`); None: every run is held.
    still : (N,) bool array, optional
        Samples at which every other marker repeats its previous sample too.
    near : float
        Distance within which a marker seen again where it was held did not
        move on (``CleaningParams.held_distance``), in the path's units.
    """
    path = np.asarray(path, dtype=float)
    seen = np.flatnonzero(np.isfinite(path).all(axis=1))
    # a sample that repeats the last one seen, across any samples missing between them:
    # a system that holds a lost marker may also leave some of its samples empty
    same = np.zeros(len(seen), dtype=bool)
    same[1:] = (path[seen[1:]] == path[seen[:-1]]).all(axis=1)
    out = np.zeros(len(path), dtype=bool)
    for start, stop in _runs(same):
        first = seen[start - 1]  # the run's first sample is the last real one
        if stop - start + 1 < run:
            continue
        before = seen[seen < first]
        after = seen[stop:stop + run]
        start, stop = seen[start], seen[stop - 1] + 1  # rows, the missing ones among them
        if not len(before) and not len(after):
            continue
        if still is not None and still[start:stop].all():
            continue
        tolerance = max(near, HELD_STEPS * step if step is not None else 0.0)
        if tolerance > 0:
            v = path[first]
            if len(after):
                moved = float(np.abs(path[after] - v).max(axis=1).min())
            else:
                moved = float(np.abs(v - path[before[-1]]).max())
            if moved <= tolerance:
                continue
        out[start:stop] = True
    return out


@functools.cache
def _default_params() -> CleaningParams:
    """The default settings, made once (frozen): validating them anew cost 15 us at each
    of three paths a stream's row."""
    return CleaningParams()


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of each run of True in ``mask`` (stop exclusive)."""
    starts, stops = run_edges(mask)
    return list(zip(starts.tolist(), stops.tolist()))


def spikes(time: np.ndarray, path: np.ndarray, ok: np.ndarray | None = None,
           params: CleaningParams | None = None, *, step: float | None = None) -> np.ndarray:
    """(N,) samples off the running median of the seen samples around them: spikes.

    A path that begins with one tested before in this thread (the same
    times, positions and samples to read, bitwise, the same window) is
    tested again only from ``3 x window`` seen samples before that one's end:
    a sample's flag reads the samples within three windows of it, so those
    before are as they were (a stream's landmarks test a path one row longer
    at every row). Only those samples are gathered again, not the whole
    path's.

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
    step : float, optional
        The median of ``time``'s steps, s, where the caller has it (the
        landmarks test three paths on one clock); default: found here.
    """
    params = _default_params() if params is None else params
    time, path = np.asarray(time, dtype=float), np.asarray(path)
    ok = finite_rows(path) if ok is None else np.asarray(ok, dtype=bool)
    dt = step if step is not None else float(np.median(np.diff(time))) if len(time) > 1 else 1.0
    half = max(1, int(round(params.spike_window / dt)))
    kept = _SPIKES.longest((half, params), (time, path, ok))
    # the seen samples: those of the kept rows as they were, then the new rows'
    rows = 0 if kept is None else len(kept[0][0])
    idx = np.flatnonzero(ok[rows:]) + rows
    if kept is not None:
        idx = np.concatenate([kept[1][0], idx])
    if len(idx) < 2 * half + 1:
        return np.zeros(len(path), dtype=bool)
    # A sample's first flag reads the ``half`` samples either side (the median; mirrored
    # at the path's end), and its final flag the first flags within ``2 x half`` of it
    # and the final flags before it: those ``3 x half`` or more before the kept path's
    # end never read past it, and their flags are that path's
    start = 0 if kept is None else max(0, len(kept[1][0]) - 3 * half - 1)
    before = np.zeros(0, dtype=bool) if kept is None else kept[1][1][:start]
    # the seen samples read from here on: within twice the window before ``start``
    r0 = max(0, start - 2 * half)
    seen, ts = path[idx[r0:]], time[idx[r0:]]
    # mirrored at the ends, so that a first sample off the path meets the
    # samples after it, not copies of itself; a sample's median reads ``half``
    # either side, so from ``start - half`` on the medians from ``start`` are
    # those of the whole path
    lo = max(0, start - half)
    med = median_filter(seen[lo - r0:], size=(2 * half + 1, 1), mode="mirror")[start - lo:]
    off = np.concatenate([before, row_norm(seen[start - r0:] - med) > params.spike_distance])
    # A spike in the window shifts its neighbours' median by one sample's motion,
    # which at video rates (33 ms a frame) is a centimetre of a fast reach: a
    # sample found off is judged again against the samples around it that are
    # not (the line between the nearest on either side, within twice the window;
    # at an end of the path the median of those within the window), and
    # kept if it lies on their path.
    for i in np.flatnonzero(off[start:]) + start:
        # the nearest samples not found off, within twice the window either side
        near = np.arange(max(0, i - 2 * half), min(len(idx), i + 2 * half + 1))
        near = near[~off[near]]
        lo, hi = near[near < i] - r0, near[near > i] - r0
        j = i - r0
        if len(lo) and len(hi):
            a, b = lo[-1], hi[0]
            ref = seen[a] + (ts[j] - ts[a]) / (ts[b] - ts[a]) * (seen[b] - seen[a])
        else:  # at an end of the path: the median of those within the window
            close = near[np.abs(near - i) <= half] - r0
            ref = np.median(seen[close], axis=0) if len(close) else None
        if ref is not None and np.linalg.norm(seen[j] - ref) <= params.spike_distance:
            off[i] = False
    # the path it resumed superseded
    _SPIKES.keep((half, params), (time, path, ok), (idx, off), kept)
    out = np.zeros(len(path), dtype=bool)
    out[idx[off]] = True
    return out


#: Paths kept per thread: a recognition's landmarks test three markers' paths.
KEPT_PATHS = 6
#: Paths tested for spikes in this thread with their flags (:func:`spikes`).
_SPIKES = Kept(KEPT_PATHS)


def clean_path(time: np.ndarray, path: np.ndarray, params: CleaningParams | None = None, *,
               still: np.ndarray | None = None) -> tuple[np.ndarray, Repairs]:
    """A marker's path with spikes, held and missing samples lost, short gaps bridged.

    Parameters
    ----------
    time : (N,) array
        Sample times, s, increasing.
    path : (N, D) array
        Positions, m; NaN where the file has none.
    params : CleaningParams, optional
    still : (N,) bool array, optional
        Samples at which every other marker repeats its previous sample
        exactly (see :func:`held`): no evidence that this one was held.

    Returns
    -------
    (N, D) array, Repairs
        The cleaned path (NaN where lost) and what was done.
    """
    params = CleaningParams() if params is None else params
    time = np.asarray(time, dtype=float)
    path = np.array(path, dtype=float)
    missing = ~np.isfinite(path).all(axis=1)
    path[missing] = np.nan
    step = quantum(path) if params.quantum is None else (params.quantum or None)
    frozen = held(path, params.held_samples, step, still, params.held_distance) & ~missing
    spiked = spikes(time, path, ~missing & ~frozen, params)
    lost = missing | frozen | spiked
    path[lost] = np.nan
    bridged = 0
    longest = 0.0
    ok = ~lost
    if ok.sum() >= 2:
        fill = None  # built at the first gap it bridges: most trials have none
        for a, b in _runs(lost):
            inside = a > 0 and b < len(time)
            span = (time[b] - time[a - 1]) if inside else math.inf
            if inside and span <= params.max_bridge + 1e-9:
                if fill is None:
                    fill = PchipInterpolator(time[ok], path[ok], axis=0, extrapolate=False)
                path[a:b] = fill(time[a:b])
                bridged += b - a
            else:
                longest = max(longest, float(span if inside else
                                             time[min(b, len(time) - 1)] - time[max(a - 1, 0)]))
    return path, Repairs(int(spiked.sum()), int(frozen.sum()), int(missing.sum()), bridged,
                         longest)

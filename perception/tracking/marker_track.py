"""One marker's track: motion estimate, CamShift window, reference mass, history.

:class:`MarkerTrack` is the state the tracker keeps per marker and that
first detection (:mod:`perception.tracking.first_detection`) starts; it is
mutable and belongs to one :class:`~perception.tracking.tracker.Tracker`.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from perception.tracking.blur import StreakGate
from perception.tracking.markers import MarkerColour
from perception.tracking.measurement import Measurement, clamp_window, likelihood
from perception.tracking.params import TrackerParams
from perception.tracking.reacquisition import ROI

__all__ = ["Located", "MarkerTrack"]

#: What locating a marker in a frame gives: centre (x, y) px, likelihood, status.
Located = tuple[tuple[float, float], float, int]


class MarkerTrack:
    """Mutable state of one marker's track (private to one tracker).

    Parameters
    ----------
    colour : MarkerColour
        The marker's colour model (first detection may narrow it).
    still : bool
        Whether the marker stays put (the object): its position is then a
        running mean of whole-blob measurements, not an alpha-beta filter's.
    roi : (x, y, w, h) or None
        Where the user says the marker is on the first frame, px.

    Notes
    -----
    ``x`` and ``v`` are the alpha-beta filter's position and velocity (px,
    px/frame) as ``(x, y)`` float pairs: on two numbers numpy's per-call
    cost would exceed the arithmetic. ``win`` is the CamShift window (px),
    ``ref`` the reference mass (px), ``n_obs`` the measurements since the
    track (re)started, ``seen_at`` the time (s) of its last measurement,
    ``rivals`` the blobs (px) it could be while ambiguous, ``rejected`` why
    candidates were not taken for it (reason -> count), ``blur`` the gate it
    is measured with while fast (:func:`~perception.tracking.blur.blur_gate`;
    None: none the scene allows).
    """

    __slots__ = ("colour", "still", "roi", "found", "lost", "x", "v", "win", "ref", "n_obs",
                 "diameter", "seen_at", "rivals", "rejected", "offset", "n_lost", "n_merged",
                 "blur", "offset_v")

    def __init__(self, colour: MarkerColour, still: bool, roi: ROI | None):
        self.colour = colour
        self.still = still
        self.roi = roi
        self.found = False
        self.lost = True
        self.x = (0.0, 0.0)
        self.v = (0.0, 0.0)
        self.win = (0, 0)
        self.ref = 0.0
        self.n_obs = 0
        self.diameter = float("nan")  # apparent diameter of a still round marker, px
        self.seen_at = 0.0
        self.rivals: list[tuple[float, float]] = []
        self.rejected: Counter = Counter()
        self.offset: tuple[float, float] | None = None  # from the rest of the hand, px
        self.n_lost = 0
        self.n_merged = 0  # consecutive frames measured merged with a neighbour
        self.blur: StreakGate | None = None
        self.offset_v = (0.0, 0.0)  # the offset's change over the last frame, px

    @property
    def name(self) -> str:
        """The marker's name."""
        return self.colour.name

    @property
    def predicted(self) -> tuple[float, float]:
        """Where the marker should be in the next frame, px."""
        return self.x[0] + self.v[0], self.x[1] + self.v[1]

    def margin(self, p: TrackerParams) -> float:
        """Search margin around the predicted window, px."""
        if self.n_obs < 2 and not self.still:
            return p.initial_margin_px
        return p.search_margin_px + p.velocity_margin * math.hypot(self.v[0], self.v[1])

    @property
    def speed(self) -> float:
        """Predicted displacement, px/frame."""
        return math.hypot(self.v[0], self.v[1])

    def observe(self, meas: Measurement, p: TrackerParams, *, blurred: bool = False) -> None:
        """Feed a measurement to the motion estimate, the window and the reference mass.

        A ``blurred`` measurement (a streak, :mod:`perception.tracking.blur`)
        moves the estimate and the window but does not teach the reference
        mass a streak's size.
        """
        zx, zy = meas.centre
        x, y = self.x
        if self.still:
            # A still marker's position is the running mean of its whole-blob
            # measurements, restarted when it jumps (it was moved): slight,
            # unnoticed occlusions then barely move it.
            if self.n_obs == 0 or np.hypot(zx - x, zy - y) > p.still_jump_px:
                self.x = (zx, zy)
            else:
                rate = max(1.0 / (self.n_obs + 1), p.still_min_rate)
                self.x = (x + rate * (zx - x), y + rate * (zy - y))
            self.v = (0.0, 0.0)
        elif self.n_obs == 0:
            self.x, self.v = (zx, zy), (0.0, 0.0)
        elif self.n_obs == 1:
            self.v = (zx - x, zy - y)
            self.x = (zx, zy)
        elif meas.merged:
            # A merged blob's centroid is unreliable: keep the velocity.
            self.x = (zx, zy)
        else:
            vx, vy = self.v
            px, py = x + vx, y + vy  # the prediction
            rx, ry = zx - px, zy - py
            self.x = (px + p.alpha * rx, py + p.alpha * ry)
            self.v = (vx + p.beta * rx, vy + p.beta * ry)
        self.n_obs += 1
        self.lost = False
        if not meas.merged:
            self.win = clamp_window(meas.window, self.ref, p)
            if blurred:
                return
            ratio = meas.mass / self.ref
            if 1 / p.ref_update_band < ratio < p.ref_update_band:
                self.ref += p.ref_update * (meas.mass - self.ref)

    def coast(self, p: TrackerParams) -> None:
        """Not seen this frame: the prediction moves on, slowing down."""
        if self.found:
            self.x = self.predicted
            self.v = (self.v[0] * p.lost_velocity_decay, self.v[1] * p.lost_velocity_decay)
        self.lost = True
        self.n_obs = 0
        self.n_lost += 1

    def likelihood(self, meas: Measurement, p: TrackerParams, streak: float = 0.0) -> float:
        """``min(r, 1/r)``; at most ``merged_likelihood`` when merged or among clutter.

        ``streak``: the most mass a blurred measurement may have (px,
        :func:`~perception.tracking.blur.streak_mass`); from the reference
        mass to it counts as whole.
        """
        mass = meas.mass
        if streak > self.ref and mass > self.ref:
            mass = max(self.ref, mass * self.ref / streak)
        lik = likelihood(mass / self.ref)
        crowded = not self.still and meas.clutter > p.clutter_ratio * self.ref
        return min(lik, p.merged_likelihood) if meas.merged or crowded else lik

    def why_not_found(self) -> str:
        """Why first detection has not started this track: ambiguity or rejections."""
        if self.rivals:
            where = ", ".join(f"({x:.0f}, {y:.0f})" for x, y in self.rivals[:3])
            return (f"ambiguous: {len(self.rivals)} blobs of its colour fit it equally, "
                    f"at {where} px")
        if self.rejected:
            counts = ", ".join(f"{n} {why}" for why, n in self.rejected.most_common())
            return f"no blob of its colour fits it ({counts})"
        return "nothing of its colour seen"

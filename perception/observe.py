"""Tracks -> observations in the model frame.

The model frame (DESIGN.md): origin at the object centre, +y from the
demonstrator's start toward the object, metres. Pixels map to metres by a
similarity transform fixed from the first frames of the clip (the scene):
the object's position, its known diameter (or a given pixel scale), and the
direction from the wrist's rest position to the object.

The movement is scored from its onset (found from the wrist's displacement
from rest) to the end of activity; the trimmed frames stay in the tracks.
Marker positions are smoothed by a causal alpha-beta filter before their
changes are compared with predictions: with raw tracks half a pixel of noise
randomises the sign of the small per-frame changes the confidence rule
counts (DESIGN.md, finding 2).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from perception.errors import InputError

__all__ = [
    "ObserveParams",
    "PixelTransform",
    "Observation",
    "observe",
    "alpha_beta",
    "DIGIT_MARKERS",
]

log = logging.getLogger(__name__)

#: Markers the recognition needs, in the order of the model's effectors.
DIGIT_MARKERS = ("wrist", "finger", "thumb")


@dataclass(frozen=True)
class ObserveParams:
    """How tracks become observations.

    Parameters
    ----------
    object_diameter : float
        Real diameter of the object, m (the thesis's ball: 0.10 m).
    px_per_m : float, optional
        Image scale; default: the object's apparent diameter in pixels
        (from the tracks) divided by ``object_diameter``.
    mirror : bool
        Mirror the image x axis, for views in which the finger lies on the
        model's -x side (the model puts the finger at +x).
    rest_frames : int
        Frames at the start used to fix the scene (object position, rest posture).
    onset_displacement : float
        Wrist displacement from rest that marks a movement, m (raised above
        the tracking noise on noisy tracks).
    onset_profile : tuple of (float, float)
        ``(displacement m, time s)`` pairs: how long after a movement's
        command onset the wrist has moved that far. Visible motion lags the
        command (the muscle filter), so the onset is the crossing time less
        this latency. The default is the 1 s minimum variance grasp's
        (``tests/test_observe.py`` checks it against the model).
    max_rest_noise : float
        Largest position noise at rest, m, for a clip to be scored: a clip must
        start with the hand still and visible.
    max_rest_aperture : float
        Largest distance between the finger and thumb markers at rest, m: the
        digits touch at the start (as in the model).
    alpha, beta : float
        Gains of the causal alpha-beta filter applied to every marker.
    min_frames : int
        Fewest frames of movement that can be scored.
    """

    object_diameter: float = 0.10
    px_per_m: float | None = None
    mirror: bool = False
    rest_frames: int = 5
    onset_displacement: float = 0.002
    onset_profile: tuple[tuple[float, float], ...] = (
        (0.001, 0.091), (0.002, 0.110), (0.003, 0.123), (0.004, 0.133),
        (0.006, 0.151), (0.008, 0.166), (0.012, 0.190))
    max_rest_noise: float = 0.003
    max_rest_aperture: float = 0.04
    alpha: float = 0.5
    beta: float = 0.15
    min_frames: int = 8

    def __post_init__(self):
        if not (np.isfinite(self.object_diameter) and self.object_diameter > 0):
            raise ValueError(
                f"object_diameter: expected a positive size in m, got {self.object_diameter}"
            )
        if self.px_per_m is not None and not (np.isfinite(self.px_per_m) and self.px_per_m > 0):
            raise ValueError(f"px_per_m: expected a positive scale, got {self.px_per_m}")
        if not (0 < self.alpha <= 1 and 0 <= self.beta < 2):
            raise ValueError(f"alpha/beta: expected 0 < alpha <= 1, 0 <= beta < 2, "
                             f"got {self.alpha}, {self.beta}")
        prof = np.asarray(self.onset_profile, dtype=float)
        if not (self.onset_displacement > 0 and prof.ndim == 2 and prof.shape[1] == 2
                and np.all(np.diff(prof, axis=0) > 0)):
            raise ValueError("onset_displacement must be > 0 and onset_profile increasing "
                             "(displacement m, time s) pairs")

    def onset_latency(self, displacement: float) -> float:
        """Time after the command onset at which the wrist has moved ``displacement`` m."""
        d, t = np.asarray(self.onset_profile, dtype=float).T
        return float(np.interp(displacement, d, t))
        if self.rest_frames < 1 or self.min_frames < 3:
            raise ValueError("rest_frames must be >= 1 and min_frames >= 3")


@dataclass(frozen=True)
class PixelTransform:
    """The similarity transform from pixels to the model frame.

    Attributes
    ----------
    origin_px : (2,) array
        Object centre in the image, px.
    px_per_m : float
        Image scale.
    rotation : float
        Angle of the model's +y axis in the image after the y flip, rad.
    mirror : bool
        Whether the image x axis is mirrored.
    """

    origin_px: np.ndarray
    px_per_m: float
    rotation: float
    mirror: bool = False

    def _basis(self) -> np.ndarray:
        # columns: model x and y axes expressed in (image x, -image y) coordinates
        c, s = np.cos(self.rotation), np.sin(self.rotation)
        ey = np.array([c, s])
        ex = np.array([s, -c])
        if self.mirror:
            ex = -ex
        return np.stack([ex, ey], axis=1)

    def to_model(self, px: np.ndarray) -> np.ndarray:
        """Pixels (..., 2) (x right, y down) -> model frame (..., 2), m."""
        rel = np.asarray(px, dtype=float) - self.origin_px
        up = np.stack([rel[..., 0], -rel[..., 1]], axis=-1) / self.px_per_m
        return up @ self._basis()

    def to_pixels(self, m: np.ndarray) -> np.ndarray:
        """Model frame (..., 2), m -> pixels (..., 2)."""
        up = np.asarray(m, dtype=float) @ self._basis().T * self.px_per_m
        return np.stack([up[..., 0], -up[..., 1]], axis=-1) + self.origin_px


def alpha_beta(z: np.ndarray, dt: np.ndarray | float, alpha: float, beta: float) -> np.ndarray:
    """Causal alpha-beta filter of positions, coasting through gaps.

    Parameters
    ----------
    z : (N, ..., 2) array
        Positions; NaN where missing.
    dt : float or (N,) array
        Frame period(s), s (``dt[i]`` is the time from frame i-1 to i).
    alpha, beta : float
        Position and velocity gains.

    Returns
    -------
    (N, ..., 2) array
        Filtered positions; NaN where the input is missing (a gap is not filled;
        the filter restarts from the first measurement after it).
    """
    z = np.asarray(z, dtype=float)
    dt = np.broadcast_to(np.asarray(dt, dtype=float), (z.shape[0],))
    out = np.full_like(z, np.nan)
    x = np.full(z.shape[1:], np.nan)
    v = np.zeros(z.shape[1:])
    shape = z.shape[1:-1] + (1,)
    missing_before = np.ones(shape, dtype=bool)
    second = np.zeros(shape, dtype=bool)  # first measurement after a (re)start
    for i in range(z.shape[0]):
        zi = z[i]
        have = np.isfinite(zi).all(axis=-1, keepdims=True)
        pred = x + v * dt[i]
        resid = zi - pred
        x_new = np.where(have, pred + alpha * resid, pred)
        v_new = np.where(have, v + beta / max(dt[i], 1e-9) * resid, v)
        # After a gap, start again from the measurement (coasting on an old
        # velocity lands far from the marker), and take the velocity from the
        # first two measurements back (two-point initiation).
        fresh = have & missing_before
        two = have & second & ~fresh
        v_new = np.where(two, (zi - x) / max(dt[i], 1e-9), np.where(fresh, 0.0, v_new))
        x_new = np.where(fresh | two, zi, x_new)
        second = fresh | (second & ~have)
        missing_before = ~have
        x, v = x_new, v_new
        out[i] = np.where(have, x, np.nan)
    return out


@dataclass(frozen=True, eq=False)
class Observation:
    """A demonstration in the model frame, from movement onset to the end of activity.

    Attributes
    ----------
    clip : str
        Clip name.
    frame : (N,) int array
        Video frame of each sample.
    time : (N,) array
        Time since the movement's onset, s (from the container's time stamps;
        the first sample is at or just after the onset).
    wrist, finger, thumb : (N, 2) arrays
        Causally filtered positions, m; NaN where the marker is lost. The digit
        markers' separation at rest (digits touching) is taken off, so finger
        and thumb are the tips.
    raw : dict of (N, 2) arrays
        Unfiltered positions of the same markers.
    scene : PixelTransform
        The pixel-to-model transform.
    dt : float
        Median frame period, s.
    onset_frame, end_frame : int
        Frames where the scored movement starts and ends (inclusive).
    start_distance : float
        Distance from the wrist at rest to the object centre, m.
    hand_offset : (2,) array
        Grip midpoint relative to the wrist at rest, m (the hand's size and posture).
    marker_separation : float
        Distance between the digit markers at rest, m (removed from finger and thumb).
    noise : float
        Tracking noise of the positions at rest (robust SD), m.
    object_diameter : float
        Object diameter, m.
    """

    clip: str
    frame: np.ndarray
    time: np.ndarray
    wrist: np.ndarray = field(repr=False)
    finger: np.ndarray = field(repr=False)
    thumb: np.ndarray = field(repr=False)
    raw: dict = field(repr=False)
    scene: PixelTransform = field(repr=False)
    dt: float = 1 / 30
    onset_frame: int = 0
    end_frame: int = 0
    start_distance: float = 0.0
    hand_offset: np.ndarray = field(default_factory=lambda: np.zeros(2), repr=False)
    object_diameter: float = 0.10
    marker_separation: float = 0.0
    noise: float = 0.0

    @property
    def n_frames(self) -> int:
        """Number of scored samples N."""
        return len(self.time)

    @property
    def midpoint(self) -> np.ndarray:
        """(N, 2) grip midpoint (finger + thumb) / 2, m (thesis eq. 5.3)."""
        return 0.5 * (self.finger + self.thumb)

    @property
    def r(self) -> np.ndarray:
        """(N,) distance from grip midpoint to object centre, m (thesis eq. 5.4)."""
        return np.linalg.norm(self.midpoint, axis=-1)

    @property
    def g(self) -> np.ndarray:
        """(N,) grip aperture |finger - thumb|, m (thesis eq. 5.5)."""
        return np.linalg.norm(self.finger - self.thumb, axis=-1)


def observe(tracks, params: ObserveParams | None = None, *, clip: str | None = None) -> Observation:
    """Turn marker tracks into an :class:`Observation` in the model frame.

    Parameters
    ----------
    tracks : Tracks
        Tracks with ``time`` (T,) s, ``frame`` (T,), ``markers`` (names),
        ``position`` (T, M, 2) px with NaN where lost, and the object's apparent
        size (``object_diameter_px()``); the markers ``wrist``, ``finger``,
        ``thumb`` and ``object`` are needed.
    params : ObserveParams, optional
        Scale, filter and onset settings.
    clip : str, optional
        Clip name for messages and results (default: from the tracks).

    Returns
    -------
    Observation

    Raises
    ------
    InputError
        If a needed marker is missing or never seen, the object is never seen,
        the scale is unknown, the time stamps are not finite seconds, the clip
        does not start with a still, visible hand that looks like a hand, no
        movement is found, or the movement is too short to score.
    """
    params = ObserveParams() if params is None else params
    name = clip or getattr(tracks, "name", None) or "clip"
    markers = list(tracks.markers)
    pos = np.asarray(tracks.position, dtype=float)
    time = np.asarray(tracks.time, dtype=float)
    frames = np.asarray(getattr(tracks, "frame", np.arange(len(time))))
    for m in (*DIGIT_MARKERS, "object"):
        if m not in markers:
            raise InputError(f"marker '{m}' is not in the tracks (have {', '.join(markers)})",
                             name)
        if not np.isfinite(pos[:, markers.index(m)]).all(axis=1).any():
            what = "object" if m == "object" else f"marker '{m}'"
            raise InputError(f"{what} is never seen in the clip", name)
    if len(time) < params.min_frames:
        raise InputError(f"clip too short to score: {len(time)} frames "
                         f"(need at least {params.min_frames})", name)
    px = {m: pos[:, markers.index(m)] for m in (*DIGIT_MARKERS, "object")}

    time_ok = np.isfinite(time)
    if not time_ok.all():
        raise InputError(f"{int((~time_ok).sum())} time stamps are not finite", name)
    dts = np.diff(time)
    if np.any(dts <= 0):
        raise InputError("time stamps do not increase", name)
    dt_med = float(np.median(dts))
    if not 0.001 <= dt_med <= 0.5:
        raise InputError(f"implausible frame period {dt_med:g} s (time stamps must be in "
                         "seconds, 2-1000 frames/s)", name)
    for m in (*DIGIT_MARKERS, "object"):
        bad = ~np.isfinite(px[m]).all(axis=1) & np.isinf(px[m]).any(axis=1)
        if bad.any():
            raise InputError(f"marker '{m}' has infinite positions", name)

    # The scene, from the first frames only: the hand must be still and seen.
    rest = slice(0, params.rest_frames)
    for m in (*DIGIT_MARKERS, "object"):
        if not np.isfinite(px[m][rest]).all():
            what = "object" if m == "object" else f"marker '{m}'"
            raise InputError(f"the clip must start with the hand at rest and visible: the "
                             f"{what} is lost in its first {params.rest_frames} frames", name)
    origin = np.median(px["object"][: 2 * params.rest_frames], axis=0)
    scale = params.px_per_m
    if scale is None:
        dpx = tracks.object_diameter_px()
        if dpx is None:
            raise InputError("image scale unknown: the tracks carry no object size; "
                             "give px_per_m (--px-per-m)", name)
        scale = dpx / params.object_diameter
    wrist_rest_px = np.median(px["wrist"][rest], axis=0)
    d = wrist_rest_px - origin
    approach = np.array([-d[0], d[1]])  # from wrist toward object, in y-up image coordinates
    if np.linalg.norm(approach) < 1e-6:
        raise InputError("impossible geometry: the wrist starts on the object", name)
    scene = PixelTransform(origin_px=origin, px_per_m=float(scale),
                           rotation=float(np.arctan2(approach[1], approach[0])),
                           mirror=params.mirror)

    model = {m: scene.to_model(px[m]) for m in DIGIT_MARKERS}
    raw = np.stack([model[m] for m in DIGIT_MARKERS], axis=1)  # (T, 3, 2)
    # Tracking noise, robustly, from the frame-to-frame changes at rest.
    steps = np.diff(raw[rest], axis=0).ravel()
    noise = 1.4826 * np.median(np.abs(steps - np.median(steps))) / np.sqrt(2)
    rest_mean = raw[rest].mean(axis=0)
    drift = np.linalg.norm(raw[rest] - rest_mean, axis=-1).max()
    if noise > params.max_rest_noise or drift > max(3 * params.onset_displacement, 6 * noise):
        raise InputError(f"the clip must start with the hand at rest: its markers move "
                         f"{drift * 1000:.1f} mm (noise {noise * 1000:.1f} mm) over the first "
                         f"{params.rest_frames} frames", name)
    dt_series = np.concatenate([[dt_med], dts])
    filt = alpha_beta(raw, dt_series, params.alpha, params.beta)

    # Onset: when the wrist's displacement from rest crosses a threshold
    # (interpolated between frames, and held for three frames), less the
    # time the model's own movements take to get that far.
    w = filt[:, 0]
    disp = np.linalg.norm(w - np.median(w[rest], axis=0), axis=1)
    threshold = max(params.onset_displacement, 4 * noise)
    above = np.nan_to_num(disp, nan=0.0) > threshold
    held = above & np.roll(above, -1) & np.roll(above, -2)
    held[-2:] = False
    if not held.any():
        raise InputError("no movement found: the wrist never leaves its rest position", name)
    i = int(np.argmax(held))
    if i > 0 and np.isfinite(disp[i - 1]):
        frac = (threshold - disp[i - 1]) / (disp[i] - disp[i - 1])
        crossing = time[i - 1] + frac * (time[i] - time[i - 1])
    else:
        crossing = time[i]
    onset_time = crossing - params.onset_latency(threshold)
    onset = int(np.searchsorted(time, onset_time))
    # End: the last frame any hand marker still moves faster than its noise allows.
    speed = np.linalg.norm(np.diff(filt, axis=0), axis=-1) / dts[:, None]
    speed_floor = max(0.02, 6 * noise / dt_med)
    active = np.flatnonzero(np.nanmax(np.where(np.isfinite(speed), speed, 0), axis=1)
                            > speed_floor)
    end = int(min(len(time) - 1, active[-1] + 2)) if len(active) else len(time) - 1
    if end - onset + 1 < params.min_frames:
        raise InputError(f"movement too short to score: {end - onset + 1} frames "
                         f"(need at least {params.min_frames})", name)
    sl = slice(onset, end + 1)
    start = rest_mean[0]
    finger0, thumb0 = rest_mean[1], rest_mean[2]
    mid0 = 0.5 * (finger0 + thumb0)
    # The rest posture must look like a hand: digits touching, in front of the wrist.
    apart = float(np.linalg.norm(finger0 - thumb0))
    reach = float(np.linalg.norm(mid0 - start))
    if apart > params.max_rest_aperture or not 0.01 <= reach <= 0.25:
        raise InputError(f"the hand at rest does not look like a hand: finger and thumb "
                         f"markers {apart * 100:.1f} cm apart, {reach * 100:.1f} cm from the "
                         "wrist (a same-coloured object taken for a marker? give --roi when "
                         "tracking, or check --px-per-m)", name)
    # The digits touch at rest (as in the model), so the markers' separation
    # then is where they sit on the digits, outside the tips: take it off.
    half = 0.5 * (finger0 - thumb0)
    filt[:, 1] -= half
    filt[:, 2] += half
    log.info("%s: onset at frame %d, %d frames scored, start distance %.3f m",
             name, frames[onset], end - onset + 1, np.linalg.norm(start))
    return Observation(
        clip=name,
        frame=frames[sl],
        time=time[sl] - onset_time,
        wrist=filt[sl, 0],
        finger=filt[sl, 1],
        thumb=filt[sl, 2],
        raw={m: model[m][sl] for m in DIGIT_MARKERS},
        noise=float(noise),
        scene=scene,
        dt=dt_med,
        onset_frame=int(frames[onset]),
        end_frame=int(frames[end]),
        start_distance=float(np.linalg.norm(start)),
        hand_offset=mid0 - start,
        object_diameter=params.object_diameter,
        marker_separation=float(np.linalg.norm(2 * half)),
    )

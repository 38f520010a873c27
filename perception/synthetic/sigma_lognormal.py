"""A second generator of reach-to-grasp clips, used only to evaluate: nobody tunes on it.

The recogniser's rules are chosen on the minimum variance model's own clips
(:mod:`perception.synthetic.stimuli`) and on the independent generator
(:mod:`perception.synthetic.independent`: beta-function speed profiles,
minimum-jerk grip segments, uniform draws). This one shares neither family,
nor a draw: nothing here imports :mod:`minvar` or
:mod:`perception.synthetic.independent` (a test scans the imports), so a rule
that holds on both generators was not fitted to one of them.

* **Transport: sigma-lognormal strokes** (Plamondon 1995, "A kinematic theory
  of rapid human movements"; Plamondon & Djioua 2006; O'Reilly & Plamondon
  2009). Each stroke's speed is a lognormal function of time,
  ``v(t) ∝ exp(-(ln(t - t0) - μ)² / 2σ²) / (t - t0)``, its direction turning
  steadily along the stroke (a circular arc). The primary stroke carries the
  hand most of the way, its speed peaking at 28–41 % of it (σ 0.10–0.26) with
  a long tail; in a share of the movements it falls a few cm short and off to
  the side and a second, corrective lognormal stroke overlapping its tail
  finishes the reach (the primary and corrective sub-movements of aimed
  movements: Meyer et al. 1988; Milner 1992, in 30–60 % of movements).
* **Grip: a sum of pulses.** The aperture rises as a truncated Gaussian flank
  from the opening onset to the maximum grip aperture (MGA) and falls as
  another to the object's size; the open-close-open grasp adds a first
  Gaussian pulse that dies out before the second opening begins. MGA
  timing is drawn from a truncated normal around 70 % of the movement
  (Wing, Turton & Fraser 1986; Paulignan et al. 1991; Chieffi & Gentilucci
  1993: 60–80 %), its size lognormally around object + 2.5 cm (Jakobson &
  Goodale 1991; Smeets & Brenner 1999: 1.5–4 cm), the opening onset from a
  beta skewed to the movement's start (Jeannerod 1984: grip formation begins
  with or soon after the transport). A healthy grasp's aperture also wobbles
  (a pulse of up to ±3 mm during the opening).
* **Conditions** (thesis 5.4.1, after Gangitano et al. 2004): ``normal``;
  ``delayed`` (the digits closed through the early transport: the opening
  starts at 40–60 % of the movement, the MGA at 80–94 %);
  ``open-close-open`` (a first opening, a closing to 25–60 % of it at
  55–72 %, a re-opening to the MGA at 80–94 %); ``reach`` (digits closed;
  the closed tips stop on the object's near surface).
* **Noise** as a tracker reports it, added to the marker paths: white jitter
  (0.2–1.2 mm), coloured drift (an AR(1) process, 0.5–2 mm, correlation time
  50–250 ms: skin and marker movement), one-frame spikes (0–1 % of frames,
  4–12 mm) and one-frame dropouts of a digit (0–1 % of frames; a rendered
  clip hides the marker for that frame).
* **Filming**: 25, 30, 50 or 60 frames/s; scale 500–950 px/m (shrunk until
  the markers stay in the frame); the camera turned ±15 degrees, the object
  placed anywhere in the upper middle of the frame; camera noise, optical and
  motion blur (exposure up to 60 % of the frame period) and lighting drawn
  per clip.

Distributions are in :data:`DISTRIBUTIONS` (each with its bounds, which a
test keeps draws within); the fast population (movement times 0.45–0.65 s,
:data:`FAST_DURATION`) is the same with the movement time replaced.

API as :mod:`perception.synthetic.independent`: :func:`draw_sigma_lognormal`
(one movement), :func:`sigma_lognormal_paths` (world paths at frame times);
the filming, in-memory tracks and rendered sets are
:mod:`perception.synthetic.sigma_lognormal_clips`'
(``draw_sigma_lognormal_clip``, ``sigma_lognormal_tracks``, ``clip_tracks``,
``render_sigma_lognormal_set``). World frame as everywhere (docs/coordinates.md): metres,
object centre at the origin, the hand starting ``distance`` away in direction
``-y`` rotated by ``approach_angle_deg``.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field
from scipy.ndimage import maximum_filter1d, uniform_filter1d
from scipy.special import ndtr

from perception.errors import InputError
from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.validation import NonNegative, Positive, declared

__all__ = ["CONDITIONS", "CORRECTIVE_SHARE", "DISTRIBUTIONS", "FAST_DURATION", "FPS_CHOICES",
           "GENERATOR", "SigmaLognormalParams", "draw_sigma_lognormal", "lognormal_stroke",
           "sigma_lognormal_aperture", "sigma_lognormal_paths"]

#: Name written in manifests and truth files.
GENERATOR = "sigma-lognormal"
#: The four conditions, written out (the other generators' modules are not imported).
CONDITIONS = ("normal", "delayed", "open-close-open", "reach")
#: Frame rates a clip is filmed at (one drawn per clip).
FPS_CHOICES: tuple[float, ...] = (25.0, 30.0, 50.0, 60.0)
#: Movement times of the fast population, s.
FAST_DURATION = (0.45, 0.65)
#: Quantile (in σ) taken as a lognormal stroke's practical start and end:
#: its speed there is about 2 % of its peak.
_Z = 3.0

_Inside = Annotated[float, Field(gt=0, lt=1)]
_Share = Annotated[float, Field(ge=0, lt=1)]
_Shape = Annotated[float, Field(ge=0.5, le=6)]


@declared
class SigmaLognormalParams:
    """One movement of the sigma-lognormal generator (times are fractions of the movement).

    Parameters
    ----------
    condition : str
        ``normal``, ``delayed``, ``open-close-open`` or ``reach``.
    object_size : float
        Object diameter, m.
    distance : float
        Wrist start to object centre, m.
    duration : float
        Movement time, s (the strokes' practical start to end).
    hand_size : float
        How far ahead of the wrist band the closed digit tips rest, m.
    sigma1 : float
        Log-time spread of the primary stroke (its speed peaks earlier the larger).
    arc_deg : float
        Direction change along the primary stroke, degrees (a bowed path).
    corrective : float
        Share of the distance left to a corrective stroke (0: one stroke).
    corrective_start : float
        When the corrective stroke starts; the primary one ends at
        ``corrective_start + 0.3`` (or at 1 when there is none).
    sigma2 : float
        Log-time spread of the corrective stroke.
    aim_error : float
        Sideways miss of the primary stroke, m (made good by the corrective one).
    approach_angle_deg : float
        Direction the hand comes from, rotated from ``-y``, degrees.
    grip_axis_deg : float
        Rotation of the grip axis from perpendicular to the approach, degrees.
    thumb_share : float
        Share of the aperture made by the thumb.
    mga_excess : float
        Maximum grip aperture above the object size, m.
    mga_time : float
        Time of the maximum grip aperture of a normal grasp.
    open_onset : float
        When the digits start to open (normal and open-close-open).
    rise_shape, fall_shape : float
        Steepness of the opening and closing flanks (their Gaussian's SD is
        the flank's length over this).
    grip_wobble : float
        Height of a healthy grasp's aperture wobble, m (signed).
    grip_wobble_time : float
        Its time.
    delayed_onset, delayed_mga_time : float
        Opening onset and MGA time of a ``delayed`` grasp.
    oco_first_time, oco_first_fraction : float
        First opening's peak time and height (a fraction of the MGA).
    oco_close_time, oco_depth : float
        Time of the deepest closing and the first pulse's share left there.
    oco_reopen_time : float
        Time of the MGA after re-opening.
    jitter : float
        SD of white marker jitter, m.
    drift : float
        SD of coloured (AR(1)) marker drift, m.
    drift_time : float
        Correlation time of the drift, s.
    spike_rate : float
        Share of frames in which a marker jumps for one frame.
    spike_size : float
        Size of such a jump, m.
    dropout_rate : float
        Share of frames in which a digit marker is lost for one frame.
    rest_before, rest_after : float
        Still periods around the movement, s.
    marker_offset : float
        How far each digit's marker sits outside its tip, across the grip, m.
    """

    condition: Literal[CONDITIONS] = "normal"
    object_size: Positive = DEFAULT_OBJECT_DIAMETER
    distance: Positive = 0.28
    duration: Positive = 0.92
    hand_size: Positive = 0.06
    sigma1: Annotated[float, Field(gt=0.02, le=0.6)] = 0.18
    arc_deg: Annotated[float, Field(ge=-60, le=60)] = 4.0
    corrective: _Share = 0.0
    corrective_start: _Inside = 0.6
    sigma2: Annotated[float, Field(gt=0.02, le=0.6)] = 0.22
    aim_error: float = 0.0
    approach_angle_deg: float = 0.0
    grip_axis_deg: float = 0.0
    thumb_share: _Inside = 0.4
    mga_excess: NonNegative = 0.025
    mga_time: _Inside = 0.70
    open_onset: NonNegative = 0.05
    rise_shape: _Shape = 2.4
    fall_shape: _Shape = 2.4
    grip_wobble: float = 0.0
    grip_wobble_time: _Inside = 0.35
    delayed_onset: NonNegative = 0.50
    delayed_mga_time: _Inside = 0.87
    oco_first_time: _Inside = 0.40
    oco_first_fraction: _Inside = 0.7
    oco_close_time: _Inside = 0.63
    oco_depth: _Inside = 0.4
    oco_reopen_time: _Inside = 0.87
    jitter: NonNegative = 0.0
    drift: NonNegative = 0.0
    drift_time: Positive = 0.1
    spike_rate: _Share = 0.0
    spike_size: NonNegative = 0.008
    dropout_rate: _Share = 0.0
    rest_before: NonNegative = 0.4
    rest_after: NonNegative = 0.4
    marker_offset: NonNegative = 0.0065

    def __post_init__(self):
        order = {"normal": (self.open_onset, self.mga_time),
                 "delayed": (self.delayed_onset, self.delayed_mga_time),
                 "open-close-open": (self.open_onset, self.oco_first_time, self.oco_close_time,
                                     self.oco_reopen_time)}.get(self.condition, ())
        if order and not all(a < b for a, b in zip(order, order[1:])):
            raise InputError(f"{self.condition}: aperture key times must increase, got {order}",
                             location=("SigmaLognormalParams", "condition"))
        if self.corrective > 0 and self.corrective_start + 0.3 > 1:
            raise InputError(f"expected a corrective stroke starting by 0.7 of the movement, "
                             f"got {self.corrective_start}",
                             location=("SigmaLognormalParams", "corrective_start"))

    @property
    def mga(self) -> float:
        """Maximum grip aperture, m."""
        return self.object_size + self.mga_excess


# -- transport: lognormal strokes ---------------------------------------------------

def lognormal_stroke(u: np.ndarray, start: float, end: float, sigma: float) -> np.ndarray:
    """Progress 0..1 of a lognormal stroke whose practical span is ``[start, end]``.

    The stroke's speed is lognormal in time (Plamondon 1995); its
    :data:`_Z`-σ quantiles are placed at ``start`` and ``end`` and the
    cumulative renormalised between them, so it is exactly 0 before and 1
    after.

    Parameters
    ----------
    u : array
        Times (any unit, as ``start`` and ``end``).
    start, end : float
        The stroke's practical start and end.
    sigma : float
        Log-time spread.
    """
    scale = (end - start) / (2.0 * math.sinh(_Z * sigma))  # exp(mu)
    t0 = start - scale * math.exp(-_Z * sigma)
    lag = np.clip(np.asarray(u, dtype=float) - t0, 1e-12, None)
    cdf = ndtr((np.log(lag) - math.log(scale)) / sigma)
    lo, hi = ndtr(-_Z), ndtr(_Z)
    return np.clip((cdf - lo) / (hi - lo), 0.0, 1.0)


def _arc(s: np.ndarray, chord: np.ndarray, turn: float) -> np.ndarray:
    """(F, 2) points a share ``s`` along a circular arc over ``chord`` turning by ``turn`` rad."""
    length = float(np.linalg.norm(chord))
    along = chord / length if length > 0 else np.array([0.0, 1.0])
    side = np.array([-along[1], along[0]])
    if abs(turn) < 1e-9:
        return s[:, None] * chord
    arc_length = length * (turn / 2) / math.sin(turn / 2)
    phi = -turn / 2 + turn * s
    x = arc_length / turn * (np.sin(phi) + math.sin(turn / 2))
    y = -arc_length / turn * (np.cos(phi) - math.cos(turn / 2))
    return x[:, None] * along + y[:, None] * side


def _transport(p: SigmaLognormalParams, tau: np.ndarray, start: np.ndarray,
               goal: np.ndarray) -> np.ndarray:
    """(F, 2) wrist positions: a primary arc stroke to an aim point, a corrective one on."""
    if p.corrective > 0:
        primary_end = p.corrective_start + 0.3
        reach = goal - start
        perp = np.array([-reach[1], reach[0]]) / np.linalg.norm(reach)
        aim = goal - p.corrective * reach + p.aim_error * perp
    else:
        primary_end, aim = 1.0, goal
    s1 = lognormal_stroke(tau, 0.0, primary_end, p.sigma1)
    wrist = start + _arc(s1, aim - start, math.radians(p.arc_deg))
    if p.corrective > 0:
        s2 = lognormal_stroke(tau, p.corrective_start, 1.0, p.sigma2)
        wrist = wrist + s2[:, None] * (goal - aim)
    return wrist


# -- grip: a sum of pulses ----------------------------------------------------------

def _gauss(tau, centre, sd):
    return np.exp(-0.5 * ((tau - centre) / sd) ** 2)


def _rise(tau: np.ndarray, t0: float, peak: float, shape: float) -> np.ndarray:
    """0 before ``t0``, a truncated Gaussian flank to 1 at ``peak``, 1 after."""
    sd = (peak - t0) / shape
    floor = _gauss(t0, peak, sd)
    out = (_gauss(tau, peak, sd) - floor) / (1.0 - floor)
    return np.where(tau <= t0, 0.0, np.where(tau >= peak, 1.0, out))


def _fall(tau: np.ndarray, peak: float, t1: float, shape: float) -> np.ndarray:
    """1 before ``peak``, a truncated Gaussian flank to 0 at ``t1``, 0 after."""
    sd = (t1 - peak) / shape
    floor = _gauss(t1, peak, sd)
    out = (_gauss(tau, peak, sd) - floor) / (1.0 - floor)
    return np.where(tau <= peak, 1.0, np.where(tau >= t1, 0.0, out))


def _pulse(tau, onset, peak, height, final, rise, fall):
    """Rise from 0 at ``onset`` to ``height`` at ``peak``, fall to ``final`` at the end."""
    up = height * _rise(tau, onset, peak, rise)
    down = final + (height - final) * _fall(tau, peak, 1.0, fall)
    return np.where(tau <= peak, up, down)


def sigma_lognormal_aperture(p: SigmaLognormalParams, tau: np.ndarray) -> np.ndarray:
    """Grip aperture (tip to tip, m) at movement fractions ``tau`` (clipped to [0, 1]).

    Parameters
    ----------
    p : SigmaLognormalParams
        The movement.
    tau : array
        Fractions of the movement time.
    """
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)
    if p.condition == "reach":
        return np.zeros_like(tau)
    if p.condition == "delayed":
        return _pulse(tau, p.delayed_onset, p.delayed_mga_time, p.mga, p.object_size,
                      p.rise_shape, p.fall_shape)
    if p.condition == "normal":
        g = _pulse(tau, p.open_onset, p.mga_time, p.mga, p.object_size, p.rise_shape,
                   p.fall_shape)
        # the wobble lives inside the opening, never at its ends
        inside = _rise(tau, p.open_onset, p.mga_time, 2.0) * (tau < p.mga_time)
        return np.clip(g + p.grip_wobble * _gauss(tau, p.grip_wobble_time, 0.05) * inside,
                       0.0, None)
    # open-close-open: a first pulse dying out to oco_depth of itself at the closing,
    # then a second opening from there to the MGA
    first = p.oco_first_fraction * p.mga
    decay = (p.oco_close_time - p.oco_first_time) / math.sqrt(-2.0 * math.log(p.oco_depth))
    p1 = first * np.where(tau <= p.oco_first_time,
                          _rise(tau, p.open_onset, p.oco_first_time, p.rise_shape),
                          _gauss(tau, p.oco_first_time, decay))
    left_at_peak = first * _gauss(p.oco_reopen_time, p.oco_first_time, decay)
    left_at_end = first * _gauss(1.0, p.oco_first_time, decay)
    p2 = _pulse(tau, p.oco_close_time, p.oco_reopen_time, p.mga - left_at_peak,
                p.object_size - left_at_end, p.rise_shape, p.fall_shape)
    return p1 + p2


# -- noise --------------------------------------------------------------------------

def _ar1(n: int, fps: float, sd: float, time_constant: float,
         rng: np.random.Generator) -> np.ndarray:
    """(n, 2) stationary AR(1) noise of SD ``sd`` and correlation time ``time_constant`` s."""
    a = math.exp(-1.0 / (fps * time_constant))
    e = rng.standard_normal((n, 2)) * sd * math.sqrt(1 - a * a)
    out = np.empty((n, 2))
    out[0] = rng.standard_normal(2) * sd
    for i in range(1, n):
        out[i] = a * out[i - 1] + e[i]
    return out


def _held_back(finger: np.ndarray, thumb: np.ndarray, radius: float, fps: float) -> np.ndarray:
    """(F,) how far (m, along -y) the hand waits short of the object so no digit enters it.

    Widened by a running maximum, then smoothed by a triangular kernel of the
    same width (about 60 ms), so the smoothed hold-back still covers every
    frame that needs it.
    """
    need = np.zeros(len(finger))
    for xy in (finger, thumb):
        chord = np.sqrt(np.clip(radius**2 - xy[:, 0] ** 2, 0.0, None))
        inside = np.hypot(xy[:, 0], xy[:, 1]) < radius
        need = np.maximum(need, np.where(inside, xy[:, 1] + chord, 0.0))
    half = max(1, int(round(0.03 * fps)))
    widened = maximum_filter1d(need, size=4 * half + 1, mode="nearest")
    once = uniform_filter1d(widened, size=2 * half + 1, mode="nearest")
    return uniform_filter1d(once, size=2 * half + 1, mode="nearest")


def sigma_lognormal_paths(p: SigmaLognormalParams, fps: float, *,
                          seed: int | np.random.Generator = 0) -> tuple[np.ndarray, dict]:
    """World-frame marker paths of one movement, with its noise, sampled at frame times.

    Parameters
    ----------
    p : SigmaLognormalParams
        The movement.
    fps : float
        Frame rate, frames/s.
    seed : int or numpy.random.Generator
        Randomness of the noise.

    Returns
    -------
    time : (F,) array
        Frame times, s.
    paths : dict
        ``wrist``, ``finger``, ``thumb`` (F, 2) marker positions with their
        jitter, drift and spikes, m; ``clean`` the same without noise (a dict);
        ``aperture`` (F,) the tip-to-tip aperture, m; ``dropped`` marker ->
        (F,) bool, the frames in which a digit marker is lost; ``tau`` (F,)
        the movement fraction.
    """
    if not (math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps: expected a positive frame rate, got {fps!r}")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    n = int(round((p.rest_before + p.duration + p.rest_after) * fps)) + 1
    t = np.arange(n) / fps
    tau = np.clip((t - p.rest_before) / p.duration, 0.0, 1.0)
    start = np.array([0.0, -p.distance])
    goal = np.array([0.0, -p.hand_size - (p.object_size / 2 if p.condition == "reach" else 0.0)])
    wrist = _transport(p, tau, start, goal)
    g = sigma_lognormal_aperture(p, tau)
    axis = math.radians(p.grip_axis_deg)
    across = np.array([math.cos(axis), math.sin(axis)])
    tips = wrist + np.array([0.0, p.hand_size])
    # the wrist carries the grip midpoint to the object: shift by the digits' asymmetry
    shift = ((0.5 - p.thumb_share) * g)[:, None] * across
    parts = {"wrist": wrist - shift,
             "finger": tips + ((1 - p.thumb_share) * g)[:, None] * across - shift,
             "thumb": tips - (p.thumb_share * g)[:, None] * across - shift}
    back = _held_back(parts["finger"], parts["thumb"], p.object_size / 2, fps)
    parts = {k: xy - back[:, None] * [0.0, 1.0] for k, xy in parts.items()}
    aperture = np.linalg.norm(parts["finger"] - parts["thumb"], axis=1)
    rot = math.radians(p.approach_angle_deg)
    R = np.array([[math.cos(rot), -math.sin(rot)], [math.sin(rot), math.cos(rot)]])
    offset = {"wrist": 0.0, "finger": p.marker_offset, "thumb": -p.marker_offset}
    clean = {k: (xy + offset[k] * across) @ R.T for k, xy in parts.items()}
    noisy, dropped = {}, {}
    for name, xy in clean.items():
        noise = p.jitter * rng.standard_normal(xy.shape)
        if p.drift > 0:
            noise += _ar1(n, fps, p.drift, p.drift_time, rng)
        spikes = rng.random(n) < p.spike_rate
        angle = rng.uniform(0, 2 * np.pi, n)
        noise += (spikes * p.spike_size)[:, None] * np.stack([np.cos(angle), np.sin(angle)], 1)
        noisy[name] = xy + noise
        dropped[name] = (rng.random(n) < p.dropout_rate) & (name != "wrist")
    return t, {**noisy, "clean": clean, "aperture": aperture, "dropped": dropped, "tau": tau}


# -- draws --------------------------------------------------------------------------

#: How :func:`draw_sigma_lognormal` draws each field: ``(kind, a, b, low, high)``
#: with ``kind`` ``uniform`` (a, b the bounds), ``tnormal`` (mean a, SD b),
#: ``lognormal`` (median a, log-SD b), ``beta`` (shapes a, b, scaled to the
#: bounds) or ``loguniform``; every draw lies in ``[low, high]``.
DISTRIBUTIONS: dict[str, tuple[str, float, float, float, float]] = {
    "duration": ("lognormal", 0.92, 0.2, 0.65, 1.4),
    "distance": ("beta", 2.0, 2.0, 0.20, 0.38),
    "hand_size": ("tnormal", 0.060, 0.004, 0.052, 0.068),
    "sigma1": ("uniform", 0.10, 0.26, 0.10, 0.26),
    "arc_deg": ("tnormal", 4.0, 8.0, -15.0, 20.0),
    "corrective": ("tnormal", 0.05, 0.02, 0.02, 0.10),
    "corrective_start": ("beta", 2.0, 2.0, 0.45, 0.70),
    "sigma2": ("uniform", 0.15, 0.30, 0.15, 0.30),
    "aim_error": ("tnormal", 0.0, 0.006, -0.015, 0.015),
    "approach_angle_deg": ("uniform", -25.0, 25.0, -25.0, 25.0),
    "grip_axis_deg": ("tnormal", 0.0, 5.0, -12.0, 12.0),
    "thumb_share": ("beta", 5.0, 7.0, 0.25, 0.50),
    "mga_excess": ("lognormal", 0.025, 0.2, 0.015, 0.040),
    "mga_time": ("tnormal", 0.70, 0.055, 0.56, 0.84),
    "open_onset": ("beta", 1.5, 4.0, 0.0, 0.25),
    "rise_shape": ("uniform", 1.8, 3.0, 1.8, 3.0),
    "fall_shape": ("uniform", 1.8, 3.0, 1.8, 3.0),
    "grip_wobble": ("tnormal", 0.0, 0.0015, -0.003, 0.003),
    "grip_wobble_time": ("uniform", 0.20, 0.50, 0.20, 0.50),
    "delayed_onset": ("beta", 2.0, 2.0, 0.40, 0.60),
    "delayed_mga_time": ("tnormal", 0.87, 0.03, 0.80, 0.94),
    "oco_first_time": ("beta", 2.0, 2.0, 0.30, 0.50),
    "oco_first_fraction": ("uniform", 0.55, 0.85, 0.55, 0.85),
    "oco_close_time": ("beta", 2.0, 2.0, 0.55, 0.72),
    "oco_depth": ("uniform", 0.25, 0.60, 0.25, 0.60),
    "oco_reopen_time": ("tnormal", 0.87, 0.03, 0.80, 0.94),
    "jitter": ("loguniform", 0.0002, 0.0012, 0.0002, 0.0012),
    "drift": ("loguniform", 0.0005, 0.002, 0.0005, 0.002),
    "drift_time": ("uniform", 0.05, 0.25, 0.05, 0.25),
    "spike_rate": ("uniform", 0.0, 0.01, 0.0, 0.01),
    "spike_size": ("uniform", 0.004, 0.012, 0.004, 0.012),
    "dropout_rate": ("uniform", 0.0, 0.01, 0.0, 0.01),
    "rest_before": ("uniform", 0.3, 0.5, 0.3, 0.5),
    "rest_after": ("uniform", 0.3, 0.5, 0.3, 0.5),
}
#: Share of movements with a corrective stroke (Meyer et al. 1988; Milner 1992).
CORRECTIVE_SHARE = 0.45
def _draw(spec: tuple[str, float, float, float, float], rng: np.random.Generator) -> float:
    kind, a, b, lo, hi = spec
    if kind == "uniform":
        return float(rng.uniform(a, b))
    if kind == "loguniform":
        return float(math.exp(rng.uniform(math.log(a), math.log(b))))
    if kind == "beta":
        return float(lo + (hi - lo) * rng.beta(a, b))
    for _ in range(1000):  # truncated by rejection
        x = a + b * rng.standard_normal() if kind == "tnormal" else a * math.exp(
            b * rng.standard_normal())
        if lo <= x <= hi:
            return float(x)
    return float(min(max(a, lo), hi))


def draw_sigma_lognormal(condition: str, rng: np.random.Generator, *, fast: bool = False,
                         **fixed: Any) -> SigmaLognormalParams:
    """One movement with every field drawn from :data:`DISTRIBUTIONS`.

    Parameters
    ----------
    condition : str
        ``normal``, ``delayed``, ``open-close-open`` or ``reach``.
    rng : numpy.random.Generator
        Source of the draws.
    fast : bool
        A fast grasp: movement time uniform in :data:`FAST_DURATION`.
    **fixed
        :class:`SigmaLognormalParams` fields to set instead of drawing them.
    """
    drawn = {k: _draw(spec, rng) for k, spec in DISTRIBUTIONS.items()}
    if fast:
        drawn["duration"] = float(rng.uniform(*FAST_DURATION))
    if rng.random() >= CORRECTIVE_SHARE:
        drawn["corrective"], drawn["aim_error"] = 0.0, 0.0
    return SigmaLognormalParams(condition=condition, **{**drawn, **fixed})

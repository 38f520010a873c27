"""Reach-to-grasp demonstrations made *without* the minimum variance model.

The recognition engine scores demonstrations with minimum variance plans, so
clips made by the same model (:mod:`perception.synthetic.stimuli`) are an easy
test. This generator builds grasps from published human kinematics only —
nothing here imports :mod:`minvar`:

* **Transport.** The wrist follows a straight (optionally bowed) path whose
  progress is a regularised incomplete beta function: the speed profile
  ``v ∝ τ^2 (1 - τ)^(b - 1)`` is minimum jerk (Flash & Hogan 1985) when
  ``b = 3`` and skewed otherwise, with its peak at ``peak_velocity_time`` of
  the movement; prehension movements peak at about 35–45 % of the movement,
  with a long deceleration (Marteniuk et al. 1987; Jeannerod 1984).
* **Grip.** The aperture is a chain of minimum-jerk segments between key
  points: closed at rest, maximal (about object + 2–3 cm) at 60–75 % of the
  movement, then closing on the object (Jeannerod 1984; Castiello 2005;
  Gangitano et al. 2004 for the three conditions). The thumb makes a smaller
  share of the opening than the index finger (``thumb_share``; Wing &
  Fraser 1983).
* **Conditions** (thesis 5.4.1, after Gangitano et al. 2004): ``normal``;
  ``delayed`` (the digits stay closed until ``delayed_onset``, maximal
  aperture late); ``open-close-open`` (a first opening as a normal grasp's,
  an unexpected closing to ``oco_depth`` of it at ``oco_close_time``, where a
  normal grasp's maximum aperture is expected, thesis line 1081; a
  re-opening); ``reach``
  (digits kept closed; the closed tips stop on the object's near surface).
* **Variability.** :func:`draw_independent` draws every timing and size from
  ranges around those values, and a smooth random wobble (a few mm, below
  3 Hz) is added to every marker, so no two demonstrations are alike.

World frame as everywhere (docs/coordinates.md): metres, object centre at the
origin; the wrist starts ``distance`` from it in direction ``-y`` rotated by
``approach_angle_deg``. :func:`independent_paths` samples the marker paths at
frame times (renderable with :class:`~perception.synthetic.scene.Scene` and
:func:`~perception.synthetic.render.render_clip`); :func:`independent_tracks`
turns them into in-memory tracks like :func:`~perception.synthetic.demos.demo_tracks`;
:func:`render_independent_set` renders a set of clips with a ``manifest.csv``.

**A population of healthy adults.** :data:`RANGES` vary one person's grasps
around one scene (1 s, 0.25 m, 800 px/m, 30 frames/s), the scene the default
repertoire is planned and calibrated for; :mod:`perception.synthetic.population`
widens every range to what the prehension literature reports across healthy
adults and renders such populations for evaluating the verdict.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pandas as pd
from pydantic import Field
from scipy.ndimage import gaussian_filter1d, maximum_filter1d
from scipy.special import betainc

from perception.errors import InputError
from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.io.atomic import write_csv
from perception.io.tracks import Status, Tracks
from perception.synthetic.scene import Camera, RenderStyle, Scene, min_jerk
from perception.tracking.markers import MARKER_NAMES
from perception.validation import NonNegative, Positive, declared

__all__ = ["CONDITIONS", "RANGES", "IndependentParams", "draw_independent",
           "independent_aperture", "independent_paths", "independent_tracks",
           "render_independent_set"]

#: The conditions of :data:`perception.synthetic.stimuli.CONDITIONS`, written
#: out: that module imports minvar, which this generator must not (a test
#: keeps the two equal).
CONDITIONS = ("normal", "delayed", "open-close-open", "reach")


_Inside = Annotated[float, Field(gt=0, lt=1)]


@declared
class IndependentParams:
    """One demonstration of the independent generator (all times are fractions of the movement).

    Parameters
    ----------
    condition : str
        ``normal``, ``delayed``, ``open-close-open`` or ``reach``.
    object_size : float
        Object diameter, m.
    distance : float
        Wrist start to object centre, m.
    duration : float
        Movement time, s.
    hand_size : float
        How far ahead of the wrist band the closed digit tips rest, m; the
        wrist stops this far short of the object centre.
    peak_velocity_time : float
        When the wrist's speed peaks (0.5: minimum jerk).
    curvature : float
        Sideways bow of the wrist path at mid-movement, m (positive: +x).
    approach_angle_deg : float
        Direction the hand comes from, rotated from ``-y``, degrees.
    grip_axis_deg : float
        Rotation of the grip axis from perpendicular to the approach, degrees.
    mga_excess : float
        Maximum grip aperture above the object size, m.
    mga_time : float
        Time of the maximum grip aperture.
    open_onset : float
        When the digits start to open (normal and open-close-open).
    thumb_share : float
        Share of the aperture made by the thumb (0.5: both digits alike).
    delayed_onset : float
        When the digits start to open in a ``delayed`` grasp.
    delayed_mga_time : float
        Its maximum aperture's time.
    oco_first_time : float
        Time of the first opening's peak (``open-close-open``).
    oco_first_fraction : float
        The first peak as a fraction of the maximum aperture.
    oco_close_time : float
        Time of the deepest point of the unexpected closing: where a normal
        grasp's maximum aperture is expected (thesis line 1081), so by
        default ``mga_time``'s.
    oco_depth : float
        Aperture at that point as a fraction of the first peak.
    oco_reopen_time : float
        Time of the maximum aperture after re-opening.
    wobble : float
        SD of the smooth random deviation of every marker, m.
    rest_before, rest_after : float
        Still periods around the movement, s.
    marker_offset : float
        How far each digit's marker sits outside its tip, across the grip, m.
    """

    condition: Literal[CONDITIONS] = "normal"
    object_size: Positive = DEFAULT_OBJECT_DIAMETER
    distance: Positive = 0.25
    duration: Positive = 1.0
    hand_size: Positive = 0.06
    peak_velocity_time: _Inside = 0.40
    curvature: float = 0.0
    approach_angle_deg: float = 0.0
    grip_axis_deg: float = 0.0
    mga_excess: NonNegative = 0.025
    mga_time: _Inside = 0.68
    open_onset: NonNegative = 0.05
    thumb_share: _Inside = 0.4
    delayed_onset: NonNegative = 0.55
    delayed_mga_time: _Inside = 0.88
    oco_first_time: _Inside = 0.46
    oco_first_fraction: _Inside = 0.8
    oco_close_time: _Inside = 0.68
    oco_depth: _Inside = 0.45
    oco_reopen_time: _Inside = 0.88
    wobble: NonNegative = 0.001
    rest_before: NonNegative = 0.3
    rest_after: NonNegative = 0.3
    marker_offset: NonNegative = 0.0065

    def __post_init__(self):
        order = {"normal": (self.open_onset, self.mga_time),
                 "delayed": (self.delayed_onset, self.delayed_mga_time),
                 "open-close-open": (self.open_onset, self.oco_first_time, self.oco_close_time,
                                     self.oco_reopen_time)}.get(self.condition, ())
        if order and not (0 <= order[0] and all(a < b for a, b in zip(order, order[1:]))):
            raise InputError(f"{self.condition}: aperture key times must increase, got {order}",
                             location=("IndependentParams", "condition"))

    @property
    def mga(self) -> float:
        """Maximum grip aperture, m."""
        return self.object_size + self.mga_excess


def _keyframes(p: IndependentParams) -> list[tuple[float, float]]:
    """(time fraction, aperture m) key points of the grip, joined by minimum-jerk segments."""
    closed, final = 0.0, p.object_size
    if p.condition == "reach":
        return [(0.0, closed), (1.0, closed)]
    if p.condition == "normal":
        return [(0.0, closed), (p.open_onset, closed), (p.mga_time, p.mga), (1.0, final)]
    if p.condition == "delayed":
        return [(0.0, closed), (p.delayed_onset, closed), (p.delayed_mga_time, p.mga),
                (1.0, final)]
    first = p.oco_first_fraction * p.mga
    return [(0.0, closed), (p.open_onset, closed), (p.oco_first_time, first),
            (p.oco_close_time, p.oco_depth * first), (p.oco_reopen_time, p.mga), (1.0, final)]


def independent_aperture(p: IndependentParams, tau: np.ndarray) -> np.ndarray:
    """Grip aperture (tip to tip, m) at movement fractions ``tau`` (clipped to [0, 1]).

    Parameters
    ----------
    p : IndependentParams
        The demonstration.
    tau : array
        Fractions of the movement time.
    """
    keys = _keyframes(p)
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)
    g = np.full(tau.shape, keys[0][1])
    for (t0, g0), (t1, g1) in zip(keys, keys[1:]):
        if t1 > t0:
            g = np.where(tau >= t0, g0 + (g1 - g0) * min_jerk((tau - t0) / (t1 - t0)), g)
    return g


def _progress(p: IndependentParams, tau: np.ndarray) -> np.ndarray:
    """Transport progress 0..1: incomplete beta, speed ∝ τ²(1-τ)^(b-1), peaking when asked."""
    b = 2.0 / p.peak_velocity_time - 1.0
    return betainc(3.0, b, np.clip(tau, 0.0, 1.0))


def _wobble(p: IndependentParams, t: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """(F, 2) smooth random deviation (< 3 Hz), zero while the hand rests before and after."""
    if p.wobble == 0:
        return np.zeros((len(t), 2))
    freqs = rng.uniform(0.5, 3.0, size=(4, 2))
    phase = rng.uniform(0, 2 * np.pi, size=(4, 2))
    amp = rng.standard_normal((4, 2))
    tm = np.clip(t - p.rest_before, 0.0, None)
    wave = (amp * np.sin(2 * np.pi * freqs * tm[:, None, None] + phase)
            - amp * np.sin(phase)).sum(axis=1)  # starts at 0
    # grows in as the hand gets going and dies out as it closes on the object
    window = min_jerk(tm / (0.3 * p.duration)) * (1 - min_jerk((tm / p.duration - 0.7) / 0.3))
    return p.wobble / 2.0 * window[:, None] * wave


def _held_back(finger: np.ndarray, thumb: np.ndarray, radius: float, fps: float) -> np.ndarray:
    """(F,) how far (m, along -y) the hand must stay back so no digit enters the object.

    Real digits stop at the surface: a grip that opens late makes the hand wait
    short of the object. The hold-back is smoothed over about 25 ms, widened
    first so the smoothing never lets a digit in by more than a fraction of a mm,
    and so ends within about 0.15 s of the grip opening wide enough.
    """
    need = np.zeros(len(finger))
    for xy in (finger, thumb):
        # a digit inside goes back out through the near surface, y = -sqrt(r^2 - x^2)
        chord = np.sqrt(np.clip(radius**2 - xy[:, 0] ** 2, 0.0, None))
        inside = np.hypot(xy[:, 0], xy[:, 1]) < radius
        need = np.maximum(need, np.where(inside, xy[:, 1] + chord, 0.0))
    sigma = 0.025 * fps
    widened = maximum_filter1d(need, size=2 * math.ceil(3 * sigma) + 1, mode="nearest")
    return gaussian_filter1d(widened, sigma, mode="nearest")


def independent_paths(p: IndependentParams, fps: float, *,
                      seed: int | np.random.Generator = 0) -> tuple[np.ndarray, dict]:
    """World-frame marker paths of one demonstration, sampled at frame times.

    Parameters
    ----------
    p : IndependentParams
        The demonstration.
    fps : float
        Frame rate, frames/s.
    seed : int or numpy.random.Generator
        Randomness of the wobble.

    Returns
    -------
    time : (F,) array
        Frame times, s.
    paths : dict of (F, 2) arrays
        ``wrist``, ``finger``, ``thumb`` marker positions, m (object centre at
        the origin); ``aperture`` (F,) is the tip-to-tip aperture (markers' offsets
        taken off), m.
    """
    if not (math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps: expected a positive frame rate, got {fps!r}")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    n = int(round((p.rest_before + p.duration + p.rest_after) * fps)) + 1
    t = np.arange(n) / fps
    tau = np.clip((t - p.rest_before) / p.duration, 0.0, 1.0)
    # in the approach frame: +y toward the object, the object at the origin
    start = np.array([0.0, -p.distance])
    # a grasp's digit tips close on the object's centre; a reach touches its near surface
    goal = np.array([0.0, -p.hand_size - (p.object_size / 2 if p.condition == "reach" else 0.0)])
    s = _progress(p, tau)
    wrist = start + s[:, None] * (goal - start)
    wrist[:, 0] += p.curvature * np.sin(np.pi * s)
    g = independent_aperture(p, tau)
    axis_angle = math.radians(p.grip_axis_deg)
    across = np.array([math.cos(axis_angle), math.sin(axis_angle)])
    tips = wrist + np.array([0.0, p.hand_size])
    finger = tips + ((1 - p.thumb_share) * g)[:, None] * across
    thumb = tips - (p.thumb_share * g)[:, None] * across
    # the wrist carries the grip midpoint to the object: shift it by the digits' asymmetry
    shift = ((0.5 - p.thumb_share) * g)[:, None] * across
    tips = {"wrist": wrist - shift, "finger": finger - shift, "thumb": thumb - shift}
    back = _held_back(tips["finger"], tips["thumb"], p.object_size / 2, fps)
    tips = {name: xy - back[:, None] * [0.0, 1.0] + _wobble(p, t, rng)
            for name, xy in tips.items()}
    rot = math.radians(p.approach_angle_deg)
    R = np.array([[math.cos(rot), -math.sin(rot)], [math.sin(rot), math.cos(rot)]])
    marker = {"wrist": 0.0, "finger": p.marker_offset, "thumb": -p.marker_offset}
    paths = {name: (xy + marker[name] * across) @ R.T for name, xy in tips.items()}
    paths["aperture"] = np.linalg.norm(tips["finger"] - tips["thumb"], axis=1)
    return t, paths


#: Ranges :func:`draw_independent` draws from, uniformly (fractions of the movement, m, s).
RANGES: dict[str, tuple[float, float]] = {
    "duration": (0.85, 1.15),
    "distance": (0.242, 0.258),
    "peak_velocity_time": (0.35, 0.47),
    "curvature": (-0.015, 0.015),
    "approach_angle_deg": (-10.0, 10.0),
    "grip_axis_deg": (-8.0, 8.0),
    "mga_excess": (0.020, 0.030),
    "mga_time": (0.60, 0.75),
    "open_onset": (0.0, 0.12),
    "thumb_share": (0.3, 0.5),
    "delayed_onset": (0.48, 0.62),
    "delayed_mga_time": (0.84, 0.92),
    # open-close-open: closed at the normal grasp's expected maximum aperture (thesis
    # line 1081), so its closing time is drawn as a normal grasp's mga_time is
    "oco_first_time": (0.40, 0.52),
    "oco_first_fraction": (0.7, 0.9),
    "oco_close_time": (0.60, 0.75),
    "oco_depth": (0.3, 0.65),
    "oco_reopen_time": (0.84, 0.92),
}


def draw_independent(condition: str, rng: np.random.Generator, **fixed: Any) -> IndependentParams:
    """One demonstration with every timing and size drawn from :data:`RANGES`.

    Parameters
    ----------
    condition : str
        ``normal``, ``delayed``, ``open-close-open`` or ``reach``.
    rng : numpy.random.Generator
        Source of the draws.
    **fixed
        :class:`IndependentParams` fields to set instead of drawing them.
    """
    drawn = {k: float(rng.uniform(*r)) for k, r in RANGES.items()}
    return IndependentParams(condition=condition, **{**drawn, **fixed})


def tracked_paths(t: np.ndarray, world: dict, camera: Camera, object_size: float, method: str,
                  *, seed: int, noise_px: float, lost: dict[str, slice] | None = None) -> Tracks:
    """``world`` (marker -> (F, 2) m) as a tracker would report it: pixel noise drawn from
    ``seed + 1000``; ``lost`` frames NaN, likelihood 0, status lost."""
    rng = np.random.default_rng(seed + 1000)
    pos = np.stack([camera.world_to_pixel(world[m]) for m in MARKER_NAMES], axis=1)
    pos = pos + noise_px * rng.standard_normal(pos.shape)
    for marker, frames in (lost or {}).items():
        pos[frames, MARKER_NAMES.index(marker)] = np.nan
    ok = np.isfinite(pos).all(axis=-1)
    diameter = [object_size * camera.px_per_m if m == "object" else math.nan
                for m in MARKER_NAMES]
    return Tracks(frame=np.arange(len(t)), time=t, markers=MARKER_NAMES, position=pos,
                  likelihood=ok.astype(np.float32),
                  status=np.where(ok, Status.TRACKED, Status.LOST).astype(np.int8),
                  tracker={"method": method, "diameter_px": diameter})


def independent_tracks(p: IndependentParams, seed: int = 0, *, fps: float = 30.0,
                       camera: Camera | None = None,
                       noise_px: float = 0.4) -> tuple[Tracks, dict[str, Any]]:
    """In-memory tracks of one demonstration, as a tracker would report it (no video).

    Parameters
    ----------
    p : IndependentParams
        The demonstration.
    seed : int
        Seed of the wobble; the pixel noise uses ``seed + 1000``.
    fps : float
        Frame rate, frames/s.
    camera : Camera, optional
        World to pixels (default: 800 px/m, the object near the top of a 640 x 480 frame).
    noise_px : float
        SD of the tracking noise added to every position, px.

    Returns
    -------
    tracks : Tracks
        Positions (px) of thumb, finger, wrist and object.
    truth : dict
        ``world`` (marker -> (F, 2) m), ``aperture`` (F,) m, ``onset_frame``, ``params``.
    """
    t, paths = independent_paths(p, fps, seed=seed)
    world = {m: paths[m] for m in ("wrist", "finger", "thumb")}
    world["object"] = np.zeros_like(paths["wrist"])
    tracks = tracked_paths(t, world, Camera() if camera is None else camera, p.object_size,
                      "independent", seed=seed, noise_px=noise_px)
    truth = {"world": world, "aperture": paths["aperture"],
             "onset_frame": int(round(p.rest_before * fps)), "params": p}
    return tracks, truth


def render_independent_set(out: str | os.PathLike, counts: dict[str, int], *, seed: int = 0,
                           style: RenderStyle | None = None,
                           camera_angle_deg: tuple[float, float] = (-20.0, 20.0)
                           ) -> pd.DataFrame:
    """Render clips of the independent generator into ``out`` with a ``manifest.csv``.

    Clip *i* of a condition draws its movement, camera angle and rendering
    seed from its own stream (seed, condition, i), as recipes do.

    Parameters
    ----------
    out : str or os.PathLike
        Output folder.
    counts : dict of str to int
        Clips per condition.
    seed : int
        Master seed.
    style : RenderStyle, optional
        How the clips look (default: 640 x 480 at 30 frames/s, a skin-coloured
        hand, noise, blur and a lighting gradient).
    camera_angle_deg : (float, float)
        Range of camera rotations, degrees.

    Returns
    -------
    pandas.DataFrame
        The manifest: clip, condition, seed, video, truth, parameters (JSON).
    """
    from perception.synthetic.render import render_clip  # OpenCV only when rendering

    style = style or RenderStyle(hand=True, marker_diameter=0.012, noise_sd=3.0,
                                 blur_sigma=0.6, lighting=0.25)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for c, cond in enumerate(CONDITIONS):
        for i in range(counts.get(cond, 0)):
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(100 + c, i)))
            p = draw_independent(cond, rng)
            t, paths = independent_paths(p, style.fps, seed=rng)
            scene = Scene(wrist=paths["wrist"], finger=paths["finger"], thumb=paths["thumb"],
                          object_diameter=p.object_size)
            angle = float(rng.uniform(*camera_angle_deg))
            camera = Camera.for_frame(style.width, style.height, angle_deg=angle)
            clip, clip_seed = f"{cond}-{i + 1:02d}", int(rng.integers(2**31))
            meta = {**dataclasses.asdict(p), "camera_angle_deg": angle,
                    "generator": "independent"}
            result = render_clip(scene, camera, style, out / f"{clip}.mp4", seed=clip_seed,
                                 label=cond, params=meta)
            rows.append({"clip": clip, "condition": cond, "seed": clip_seed,
                         "video": result.video.name, "truth": result.truth.name,
                         "parameters": json.dumps(meta)})
    manifest = pd.DataFrame(rows)
    write_csv(out / "manifest.csv", manifest)
    return manifest

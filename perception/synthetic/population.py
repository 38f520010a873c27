"""A population of healthy adults: the independent generator at the literature's ranges.

:data:`~perception.synthetic.independent.RANGES` vary one person's grasps
around one scene, the scene the default repertoire is planned and calibrated
for. :data:`POPULATION_RANGES` and :func:`draw_population` widen every range
to what the prehension literature reports across healthy adults, objects and
distances, and draw each clip's camera (scale, rotation, frame rate) too;
:func:`render_population_set` renders such a population, each clip with its
own scale and frame rate, for evaluating the verdict where it was not tuned
(``tools/evaluate_verdict.py``). Like :mod:`perception.synthetic.independent`,
nothing here imports :mod:`minvar`.
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.io.atomic import write_csv
from perception.synthetic.independent import (
    CONDITIONS,
    RANGES,
    IndependentParams,
    independent_paths,
)
from perception.synthetic.scene import Camera, RenderStyle, Scene

__all__ = ["POPULATION_FPS", "POPULATION_RANGES", "POPULATION_STYLE", "PopulationDraw",
           "draw_population", "population_camera", "render_population_set"]


#: Ranges :func:`draw_population` draws from, uniformly: what the prehension
#: literature reports across healthy adults, objects and distances (wider
#: than :data:`RANGES`, which vary one person around one scene).
#:
#: * ``duration`` 0.65-1.4 s: reach-to-grasp movement times of healthy adults
#:   for objects at 20-40 cm, natural to slow-accurate (Jeannerod 1984;
#:   Marteniuk et al. 1987; Castiello 2005).
#: * ``peak_velocity_time`` 0.36-0.50: the wrist's peak speed comes at
#:   35-50 % of the movement, earlier the more precise the grasp and with a
#:   long deceleration (Marteniuk et al. 1987; Jeannerod 1984).
#: * ``mga_excess`` 1.5-3.5 cm beyond the object, ``mga_time`` 60-80 % of the
#:   movement: maximum grip aperture scales with object size, about 2-3 cm
#:   over it, later and smaller for slower movements (Jeannerod 1984; Marteniuk
#:   et al. 1987; Smeets & Brenner 1999; Castiello 2005).
#: * ``curvature`` -1 to +3 cm: hand paths are slightly curved, mostly bowed
#:   outward (Smeets & Brenner 1999; Gangitano et al. 2004).
#: * ``distance`` 0.22-0.40 m: the reach distances of the prehension
#:   experiments (Jeannerod 1984: 25-40 cm; Gangitano et al. 2004: ~30 cm).
#: * ``approach_angle_deg`` +-20 degrees: objects placed off the body's midline.
#: * ``px_per_m`` 550-900, ``camera_angle_deg`` +-10 degrees: the camera,
#:   farther or nearer, rotated a little (see :data:`POPULATION_FPS` for the
#:   frame rate).
#: * the condition timings (``delayed_*``, ``oco_*``), grip axis, thumb share
#:   and opening onset as in :data:`RANGES` (after Gangitano et al. 2004).
POPULATION_RANGES: dict[str, tuple[float, float]] = {
    **RANGES,
    "duration": (0.65, 1.4),
    "distance": (0.22, 0.40),
    "peak_velocity_time": (0.36, 0.50),
    "curvature": (-0.010, 0.030),
    "approach_angle_deg": (-20.0, 20.0),
    "mga_excess": (0.015, 0.035),
    "mga_time": (0.60, 0.80),
    "px_per_m": (550.0, 900.0),
    "camera_angle_deg": (-10.0, 10.0),
}

#: Frame rates a population clip is filmed at, frames/s (one drawn per clip):
#: PAL video, NTSC-like webcams and the 60 frames/s of phones and action cameras.
POPULATION_FPS: tuple[float, ...] = (25.0, 30.0, 60.0)

#: The camera keys of :data:`POPULATION_RANGES` (the rest are
#: :class:`IndependentParams` fields).
_CAMERA_KEYS = ("px_per_m", "camera_angle_deg")

#: How a population clip looks (the frame rate is each clip's own): 640 x 480,
#: a skin-coloured hand, camera noise, blur and a lighting gradient, as
#: :func:`render_independent_set`.
POPULATION_STYLE = RenderStyle(hand=True, marker_diameter=0.012, noise_sd=3.0, blur_sigma=0.6,
                               lighting=0.25)

#: Where the object sits in a population frame (fractions of width and
#: height): high enough that a 0.40 m reach at 900 px/m, rotated by the
#: approach and the camera together (30 degrees), stays in a 640 x 480 frame.
_POPULATION_ORIGIN = (0.5, 0.17)


@dataclass(frozen=True)
class PopulationDraw:
    """One clip of a population: its movement and its camera.

    Attributes
    ----------
    params : IndependentParams
        The movement.
    px_per_m : float
        Camera scale, px/m.
    fps : float
        Frame rate, frames/s.
    camera_angle_deg : float
        Camera rotation, degrees (:class:`~perception.synthetic.scene.Camera`).
    """

    params: IndependentParams
    px_per_m: float
    fps: float
    camera_angle_deg: float

    def row(self) -> dict[str, Any]:
        """The drawn parameters a manifest carries, by their manifest names."""
        p = self.params
        return {"movement_time": p.duration, "distance": p.distance,
                "px_per_m": self.px_per_m, "fps": self.fps,
                "approach_deg": p.approach_angle_deg, "mga_excess": p.mga_excess,
                "mga_time": {"delayed": p.delayed_mga_time,
                             "open-close-open": p.oco_reopen_time}.get(p.condition, p.mga_time),
                "peak_velocity_time": p.peak_velocity_time, "curvature": p.curvature,
                "camera_angle_deg": self.camera_angle_deg}


def draw_population(condition: str, rng: np.random.Generator, *,
                    ranges: dict[str, tuple[float, float]] | None = None,
                    fps_choices: tuple[float, ...] = POPULATION_FPS,
                    **fixed: Any) -> PopulationDraw:
    """One clip of a healthy-adult population, drawn from :data:`POPULATION_RANGES`.

    Parameters
    ----------
    condition : str
        ``normal``, ``delayed``, ``open-close-open`` or ``reach``.
    rng : numpy.random.Generator
        Source of the draws.
    ranges : dict, optional
        Ranges to draw from instead of :data:`POPULATION_RANGES` (a key
        missing from it is taken from there; ``(v, v)`` fixes a value).
    fps_choices : tuple of float
        Frame rates to choose from, uniformly.
    **fixed
        :class:`IndependentParams` fields to set instead of drawing them.

    Returns
    -------
    PopulationDraw
    """
    ranges = {**POPULATION_RANGES, **(ranges or {})}
    drawn = {k: float(rng.uniform(*r)) for k, r in ranges.items()}
    fps = float(fps_choices[int(rng.integers(len(fps_choices)))])
    camera = {k: drawn.pop(k) for k in _CAMERA_KEYS}
    params = IndependentParams(condition=condition, **{**drawn, **fixed})
    return PopulationDraw(params, camera["px_per_m"], fps, camera["camera_angle_deg"])


def population_camera(draw: PopulationDraw, style: RenderStyle = POPULATION_STYLE) -> Camera:
    """The camera of a population clip: its scale and rotation, the object high in the frame.

    Parameters
    ----------
    draw : PopulationDraw
        The clip.
    style : RenderStyle
        Its frame size (default :data:`POPULATION_STYLE`: 640 x 480).
    """
    return Camera.for_frame(style.width, style.height, px_per_m=draw.px_per_m,
                            angle_deg=draw.camera_angle_deg, origin=_POPULATION_ORIGIN)


def _check_in_frame(paths: dict, camera: Camera, style: RenderStyle, clip: str) -> None:
    """Every marker, with its extent (the wrist band's half-width), inside the frame."""
    k = camera.px_per_m
    digit = 0.5 * style.marker_diameter * k
    parts = {"wrist": (paths["wrist"], 0.5 * max(style.band_size) * k),
             "finger": (paths["finger"], digit), "thumb": (paths["thumb"], digit),
             "object": (np.zeros((1, 2)), 0.5 * DEFAULT_OBJECT_DIAMETER * k)}
    size = (style.width, style.height)
    for name, (xy, m) in parts.items():
        px = camera.world_to_pixel(xy)
        if (px.min(axis=0) - m < 0).any() or (px.max(axis=0) + m > size).any():
            raise ValueError(f"{clip}: the {name} marker leaves the {style.width} x "
                             f"{style.height} frame at {camera.px_per_m:.0f} px/m")


def _render_population_one(work: tuple) -> dict:
    """Render one population clip; its manifest row."""
    out, clip, cond, clip_seed, ranges, fps_choices, style = work
    from perception.synthetic.render import render_clip  # OpenCV only when rendering

    rng = np.random.default_rng(clip_seed)
    draw = draw_population(cond, rng, ranges=ranges, fps_choices=fps_choices)
    p = draw.params
    clip_style = dataclasses.replace(style, fps=draw.fps)
    t, paths = independent_paths(p, draw.fps, seed=rng)
    camera = population_camera(draw, clip_style)
    _check_in_frame(paths, camera, clip_style, clip)
    scene = Scene(wrist=paths["wrist"], finger=paths["finger"], thumb=paths["thumb"],
                  object_diameter=p.object_size)
    render_seed = int(rng.integers(2**31))
    meta = {**dataclasses.asdict(p), "px_per_m": draw.px_per_m, "fps": draw.fps,
            "camera_angle_deg": draw.camera_angle_deg, "generator": "independent-population",
            "draw_seed": int(clip_seed)}
    result = render_clip(scene, camera, clip_style, Path(out) / f"{clip}.mp4", seed=render_seed,
                         label=cond, params=meta)
    return {"clip": clip, "condition": cond, "seed": int(clip_seed), "video": result.video.name,
            "truth": result.truth.name, **draw.row(), "parameters": json.dumps(meta)}


def render_population_set(out: str | os.PathLike, counts: dict[str, int], *, seed: int = 0,
                          ranges: dict[str, tuple[float, float]] | None = None,
                          fps_choices: tuple[float, ...] = POPULATION_FPS,
                          style: RenderStyle | None = None, jobs: int = 1,
                          progress: bool = False) -> pd.DataFrame:
    """Render a population of healthy-adult grasps into ``out`` with a ``manifest.csv``.

    Clip *k* (counting over the conditions in :data:`CONDITIONS` order) draws
    its movement, camera, frame rate and rendering seed from
    ``numpy.random.default_rng(seed + k)`` alone: two sets whose seed ranges
    ``seed .. seed + n - 1`` do not overlap share no clip.

    Parameters
    ----------
    out : str or os.PathLike
        Output folder.
    counts : dict of str to int
        Clips per condition.
    seed : int
        The first clip's seed.
    ranges : dict, optional
        See :func:`draw_population`.
    fps_choices : tuple of float
        Frame rates to choose from (default :data:`POPULATION_FPS`).
    style : RenderStyle, optional
        How the clips look (default :data:`POPULATION_STYLE`; its frame rate is
        replaced by each clip's own).
    jobs : int
        Worker processes rendering clips (as ``hammer-mv synth --jobs``; 1:
        in this process); the clips do not depend on it.
    progress : bool
        Show a progress bar.

    Returns
    -------
    pandas.DataFrame
        The manifest: clip, condition, seed, video, truth, the drawn
        ``movement_time, distance, px_per_m, fps, approach_deg, mga_excess,
        mga_time, peak_velocity_time, curvature, camera_angle_deg`` and every
        parameter as JSON (``parameters``). ``mga_time`` is the time of the
        maximum aperture the clip's condition uses (``delayed_mga_time`` of a
        delayed grasp, ``oco_reopen_time`` of an open-close-open one; a reach
        does not open its digits).

    Raises
    ------
    ValueError
        If a clip's markers would leave the frame (a range too wide for it).
    """
    from tqdm import tqdm

    from perception.synthetic.render import render_rows  # OpenCV only when rendering

    style = POPULATION_STYLE if style is None else style
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    clips = [(cond, i) for cond in CONDITIONS for i in range(counts.get(cond, 0))]
    work = [(out, f"{cond}-{i + 1:02d}", cond, seed + k, ranges, fps_choices, style)
            for k, (cond, i) in enumerate(clips)]
    with tqdm(total=len(work), desc="render population", unit="clip",
              disable=not progress) as bar:
        rows = render_rows(_render_population_one, work, int(jobs), bar)
    manifest = pd.DataFrame(rows)
    write_csv(out / "manifest.csv", manifest)
    return manifest

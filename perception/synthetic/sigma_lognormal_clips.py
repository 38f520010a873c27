"""The sigma-lognormal generator's clips: a movement filmed (issue 43, used only to evaluate).

:mod:`perception.synthetic.sigma_lognormal` draws the movements; this module
draws how each is filmed (:data:`FILMING`: frame rate, scale, camera
rotation, where the object stands in the frame, camera noise, optical and
motion blur, lighting, marker size; the scale shrunk until the markers stay
in the frame) and turns a clip into in-memory tracks
(:func:`sigma_lognormal_tracks`, :func:`clip_tracks`) or rendered video with
ground truth and a ``manifest.csv`` that ``hammer-mv batch`` reads
(:func:`render_sigma_lognormal_set`). Like the movements, nothing here
imports :mod:`minvar` or the independent generator.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.io.atomic import write_csv
from perception.io.tracks import Status, Tracks
from perception.synthetic.scene import Camera, Occlusion, RenderStyle, Scene
from perception.synthetic.sigma_lognormal import (
    CONDITIONS,
    FPS_CHOICES,
    GENERATOR,
    SigmaLognormalParams,
    draw_sigma_lognormal,
    sigma_lognormal_paths,
)
from perception.tracking.markers import MARKER_NAMES

__all__ = ["FILMING", "SigmaLognormalClip", "clip_tracks", "draw_sigma_lognormal_clip",
           "render_sigma_lognormal_set", "sigma_lognormal_tracks"]

#: Filming draws: scale px/m, camera rotation degrees, object position as fractions
#: of the frame (x, y), camera noise grey levels, optical blur px, lighting
#: gradient, exposure as a share of the frame period, digit marker diameter m.
FILMING: dict[str, tuple[float, float]] = {
    "px_per_m": (500.0, 950.0), "camera_angle_deg": (-15.0, 15.0),
    "origin_x": (0.40, 0.60), "origin_y": (0.14, 0.24), "noise_sd": (1.5, 5.0),
    "blur_sigma": (0.3, 1.0), "lighting": (0.05, 0.35), "lighting_angle_deg": (0.0, 360.0),
    "exposure_share": (0.0, 0.6), "marker_diameter": (0.011, 0.014),
}



@dataclass(frozen=True)
class SigmaLognormalClip:
    """One clip of the generator: the movement and how it is filmed.

    Attributes
    ----------
    params : SigmaLognormalParams
        The movement.
    fps : float
        Frame rate, frames/s.
    camera : Camera
        World to pixels (its scale already shrunk to keep the markers in the frame).
    style : RenderStyle
        How the clip looks (640 x 480).
    """

    params: SigmaLognormalParams
    fps: float
    camera: Camera
    style: RenderStyle

    def row(self) -> dict[str, Any]:
        """The manifest's columns for the clip (as the population's, for the evaluation).

        ``peak_velocity_time`` (a share of the movement) and ``curvature`` (the
        wrist path's largest sideways distance from its chord, m) are measured
        on the noise-free path: here they follow from the strokes.
        """
        p = self.params
        t, paths = sigma_lognormal_paths(dataclasses.replace(
            p, jitter=0.0, drift=0.0, spike_rate=0.0), 500.0)
        wrist = paths["clean"]["wrist"]
        speed = np.linalg.norm(np.gradient(wrist, t, axis=0), axis=1)
        peak = (t[int(np.argmax(speed))] - p.rest_before) / p.duration
        # the path's bow as the independent generator's curvature: the largest signed
        # sideways distance from the start-to-end line, m (positive: to the left of it)
        chord = wrist[-1] - wrist[0]
        rel = wrist - wrist[0]
        side = (chord[0] * rel[:, 1] - chord[1] * rel[:, 0]) / np.linalg.norm(chord)
        bow = float(side[np.argmax(np.abs(side))])
        return {"movement_time": p.duration, "distance": p.distance,
                "px_per_m": self.camera.px_per_m, "fps": self.fps,
                "approach_deg": p.approach_angle_deg, "mga_excess": p.mga_excess,
                "mga_time": {"delayed": p.delayed_mga_time, "reach": math.nan,
                             "open-close-open": p.oco_reopen_time}.get(p.condition, p.mga_time),
                "peak_velocity_time": float(peak), "curvature": bow,
                "camera_angle_deg": self.camera.angle_deg, "corrective": p.corrective}


def _fits(paths: dict, camera: Camera, style: RenderStyle) -> bool:
    """Every marker with its extent (and the object) inside the frame."""
    k = camera.px_per_m
    digit = 0.5 * style.marker_diameter * k + 2
    parts = [(paths["wrist"], 0.5 * max(style.band_size) * k + 2),
             (paths["finger"], digit), (paths["thumb"], digit),
             (np.zeros((1, 2)), 0.5 * DEFAULT_OBJECT_DIAMETER * k + 2)]
    for xy, m in parts:
        px = camera.world_to_pixel(xy)
        if (px.min(axis=0) - m < 0).any() or (px.max(axis=0) + m > (style.width,
                                                                    style.height)).any():
            return False
    return True


def draw_sigma_lognormal_clip(condition: str, rng: np.random.Generator, *,
                              fast: bool = False, fps: float | None = None,
                              **fixed: Any) -> SigmaLognormalClip:
    """A movement (:func:`draw_sigma_lognormal`) and its filming (:data:`FILMING`, fps).

    The scale is shrunk by 5 % steps until the noise-free paths, with the
    markers' extent, stay inside the 640 x 480 frame.

    Parameters
    ----------
    condition, rng, fast, **fixed
        As :func:`draw_sigma_lognormal`.
    fps : float, optional
        Frame rate instead of one drawn from :data:`FPS_CHOICES` (the draw is
        made either way, so every other draw stays the same).
    """
    p = draw_sigma_lognormal(condition, rng, fast=fast, **fixed)
    f = {k: float(rng.uniform(*r)) for k, r in FILMING.items()}
    drawn_fps = float(FPS_CHOICES[int(rng.integers(len(FPS_CHOICES)))])
    fps = drawn_fps if fps is None else float(fps)
    style = RenderStyle(fps=fps, hand=True, marker_diameter=f["marker_diameter"],
                        noise_sd=f["noise_sd"], blur_sigma=f["blur_sigma"],
                        lighting=f["lighting"], lighting_angle_deg=f["lighting_angle_deg"],
                        exposure=f["exposure_share"] / fps, motion_samples=3)
    _, paths = sigma_lognormal_paths(dataclasses.replace(
        p, jitter=0.0, drift=0.0, spike_rate=0.0), fps)
    scale = f["px_per_m"]
    while True:
        camera = Camera.for_frame(style.width, style.height, px_per_m=scale,
                                  angle_deg=f["camera_angle_deg"],
                                  origin=(f["origin_x"], f["origin_y"]))
        if _fits(paths["clean"], camera, style) or scale < 200:
            break
        scale *= 0.95
    return SigmaLognormalClip(p, fps, camera, style)


# -- tracks and rendering -----------------------------------------------------------

def sigma_lognormal_tracks(p: SigmaLognormalParams, seed: int | np.random.Generator = 0, *,
                           fps: float = 30.0,
                           camera: Camera | None = None,
                           noise_px: float = 0.3) -> tuple[Tracks, dict[str, Any]]:
    """In-memory tracks of one movement, as a tracker would report it (no video).

    Parameters
    ----------
    p : SigmaLognormalParams
        The movement (its own noise: jitter, drift, spikes and dropouts).
    seed : int or numpy.random.Generator
        Source of that noise and of the extra pixel noise, drawn after it.
    fps : float
        Frame rate, frames/s.
    camera : Camera, optional
        World to pixels (default: 800 px/m, the object high in a 640 x 480 frame).
    noise_px : float
        SD of pixel noise added on top, px (the object's too).

    Returns
    -------
    tracks : Tracks
        Positions (px) of thumb, finger, wrist and object; a dropped digit is
        NaN with status lost.
    truth : dict
        ``world`` (marker -> (F, 2) m, noise-free), ``aperture`` (F,) m,
        ``onset_frame``, ``params``.
    """
    camera = Camera() if camera is None else camera
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    t, paths = sigma_lognormal_paths(p, fps, seed=rng)
    world = {**{m: paths[m] for m in ("wrist", "finger", "thumb")},
             "object": np.zeros_like(paths["wrist"])}
    pos = np.stack([camera.world_to_pixel(world[m]) for m in MARKER_NAMES], axis=1)
    pos = pos + noise_px * rng.standard_normal(pos.shape)
    for m, lost in paths["dropped"].items():
        pos[lost, MARKER_NAMES.index(m)] = np.nan
    ok = np.isfinite(pos).all(axis=-1)
    diameter = [p.object_size * camera.px_per_m if m == "object" else math.nan
                for m in MARKER_NAMES]
    tracks = Tracks(frame=np.arange(len(t)), time=t, markers=MARKER_NAMES, position=pos,
                    likelihood=ok.astype(np.float32),
                    status=np.where(ok, Status.TRACKED, Status.LOST).astype(np.int8),
                    tracker={"method": GENERATOR, "diameter_px": diameter})
    truth = {"world": {**paths["clean"], "object": world["object"]},
             "aperture": paths["aperture"], "onset_frame": int(round(p.rest_before * fps)),
             "params": p}
    return tracks, truth


def clip_tracks(clip: SigmaLognormalClip,
                seed: int | np.random.Generator = 0) -> tuple[Tracks, dict[str, Any]]:
    """:func:`sigma_lognormal_tracks` of a drawn clip, at its frame rate and camera.

    Parameters
    ----------
    clip : SigmaLognormalClip
        The movement and its filming.
    seed : int or numpy.random.Generator
        Source of the noise (see :func:`sigma_lognormal_tracks`).
    """
    return sigma_lognormal_tracks(clip.params, seed, fps=clip.fps, camera=clip.camera)


def _render_one(work: tuple) -> dict:
    """Render one clip of a set; its manifest row."""
    out, name, cond, clip_seed, fast = work
    from perception.synthetic.render import render_clip  # OpenCV only when rendering

    rng = np.random.default_rng(clip_seed)
    clip = draw_sigma_lognormal_clip(cond, rng, fast=fast)
    t, paths = sigma_lognormal_paths(clip.params, clip.fps, seed=rng)
    names = ("finger", "thumb")
    occlusions = tuple(Occlusion(marker=m, start=int(i), stop=int(i) + 1)
                       for m in names for i in np.flatnonzero(paths["dropped"][m]))
    style = dataclasses.replace(clip.style, occlusions=occlusions)
    scene = Scene(wrist=paths["wrist"], finger=paths["finger"], thumb=paths["thumb"],
                  object_diameter=clip.params.object_size)
    render_seed = int(rng.integers(2**31))
    meta = {**dataclasses.asdict(clip.params), "fps": clip.fps,
            "px_per_m": clip.camera.px_per_m, "camera_angle_deg": clip.camera.angle_deg,
            "generator": GENERATOR, "draw_seed": int(clip_seed)}
    result = render_clip(scene, clip.camera, style, Path(out) / f"{name}.mp4", seed=render_seed,
                         label=cond, params=meta)
    return {"clip": name, "condition": cond, "seed": int(clip_seed), "video": result.video.name,
            "truth": result.truth.name, **clip.row(), "parameters": json.dumps(meta)}


def render_sigma_lognormal_set(out: str | os.PathLike, counts: dict[str, int], *,
                               seed: int = 0, fast: bool = False, jobs: int = 1,
                               progress: bool = False) -> pd.DataFrame:
    """Render clips of the generator into ``out`` with a ``manifest.csv``.

    Clip *k* (counting over the conditions in :data:`CONDITIONS` order) draws
    its movement, filming, noise and rendering seed from
    ``numpy.random.default_rng(seed + k)`` alone, as
    :func:`perception.synthetic.population.render_population_set` does.

    Parameters
    ----------
    out : str or os.PathLike
        Output folder.
    counts : dict of str to int
        Clips per condition.
    seed : int
        The first clip's seed.
    fast : bool
        Fast grasps (:data:`FAST_DURATION`).
    jobs : int
        Worker processes rendering clips (1: in this process).
    progress : bool
        Show a progress bar.

    Returns
    -------
    pandas.DataFrame
        The manifest: clip, condition, seed, video, truth, the columns of
        :meth:`SigmaLognormalClip.row` and every parameter as JSON.
    """
    from tqdm import tqdm

    from perception.synthetic.render import render_rows  # OpenCV only when rendering

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    clips = [(cond, i) for cond in CONDITIONS for i in range(counts.get(cond, 0))]
    work = [(out, f"{cond}-{i + 1:02d}", cond, seed + k, fast)
            for k, (cond, i) in enumerate(clips)]
    with tqdm(total=len(work), desc="render sigma-lognormal", unit="clip",
              disable=not progress) as bar:
        rows = render_rows(_render_one, work, int(jobs), bar)
    manifest = pd.DataFrame(rows)
    write_csv(out / "manifest.csv", manifest)
    return manifest

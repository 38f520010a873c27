"""A realistic test set: grasps composited onto photographs, encoded as cameras encode.

Each clip of the set is one movement of the grasp model (a ``normal`` grasp
or a ``reach``) rendered twice from the same paths and camera:

* **realistic** — the table replaced by a photograph that scikit-image
  ships (a desk with a red cup and saucer, an astronaut before a flag, a red
  motorcycle in a garage, a rocket under a blue dusk sky), a skin-coloured
  hand, lit (shaded) markers, motion blur from a 1/60 s exposure, light
  flicker, camera noise, 29.97 frames/s, H.264 with 4:2:0 chroma; plus
  clutter in the markers' hues — for each hand marker a thing of its colour
  50-200 px from it (a disc like the digit markers, a bar like the band),
  and a small ball of the object's colour;
* **clean** — the same movement on the plain drawn table, mp4v.

One extra clip puts a sleeve of the band's colour against the band: the
tracker must either follow the band or refuse the wrist marker, never follow
the sleeve. :func:`render_realistic_set` writes the clips and their ground
truth; tests render small versions on the fly, ``tools/bench_tracking.py``
the full set.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from perception.synthetic.render import RenderResult, render_clip
from perception.synthetic.scene import Camera, Distractor, RenderStyle, Scene
from perception.synthetic.stimuli import StimulusParams, stimulus_paths

__all__ = ["BACKGROUNDS", "RealisticClip", "clutter", "realistic_style",
           "render_realistic_set"]

#: The photographs of the set (``photo:NAME``), each with a same-hue trap.
BACKGROUNDS = ("coffee", "astronaut", "motorcycle_left", "rocket")

#: Frame rate of NTSC-derived cameras, frames/s.
NTSC_FPS = 30000 / 1001


@dataclass(frozen=True)
class RealisticClip:
    """One clip of the set: its realistic and clean renderings.

    Attributes
    ----------
    name : str
        ``<background>-<condition>`` (``-sleeve`` for the sleeve clip).
    background : str
        The photograph.
    condition : str
        ``normal`` or ``reach``.
    realistic, clean : RenderResult
        The two renderings (video and ground truth).
    sleeve : bool
        Whether a sleeve of the band's colour touches the band.
    """

    name: str
    background: str
    condition: str
    realistic: RenderResult
    clean: RenderResult
    sleeve: bool = False


def realistic_style(background: str, *, width: int = 640, height: int = 480,
                    distractors: tuple[Distractor, ...] = (),
                    sleeve: str | None = None) -> RenderStyle:
    """How the set's realistic clips look (see the module's description).

    Parameters
    ----------
    background : str
        A photograph's name (``photo:`` is added).
    width, height : int
        Frame size, px (even: 4:2:0 chroma).
    distractors : tuple of Distractor
        The clutter (:func:`clutter`).
    sleeve : str, optional
        Colour of a sleeve touching the band (a marker name).
    """
    return RenderStyle(fps=NTSC_FPS, width=width, height=height, codec="h264", hand=True,
                       marker_diameter=0.012, noise_sd=2.0, blur_sigma=0.5, lighting=0.2,
                       background=f"photo:{background}", exposure=1 / 60, flicker=0.04,
                       shading=0.6, distractors=distractors, sleeve=sleeve)


def clutter(scene: Scene, camera: Camera, rng: np.random.Generator) -> tuple[Distractor, ...]:
    """Things of the markers' hues 50-200 px from the hand markers at rest.

    Each lies away from the hand (beyond its marker, seen from the hand's
    centre) so that it sits where a same-coloured thing on a desk would, not
    on the hand itself; sizes are the markers' own.

    Parameters
    ----------
    scene : Scene
        The movement (its first frame is the hand at rest).
    camera : Camera
        Its scale sets the distances in px.
    rng : numpy.random.Generator
        Draws distance and direction.
    """
    k = camera.px_per_m
    hand = {n: getattr(scene, n)[0] for n in ("thumb", "finger", "wrist")}
    centre = np.mean(list(hand.values()), axis=0)
    spec = {"thumb": dict(diameter=0.012), "finger": dict(diameter=0.014),
            "wrist": dict(diameter=0.07, shape="bar", aspect=0.36)}
    out = []
    for name, where in hand.items():
        away = where - centre
        base = math.atan2(away[1], away[0]) if np.hypot(*away) > 1e-9 else 0.0
        a = base + rng.uniform(-0.6, 0.6)
        dist = rng.uniform(50, 200) / k
        pos = where + dist * np.array([math.cos(a), math.sin(a)])
        out.append(Distractor(name, start=tuple(pos), angle_deg=float(rng.uniform(0, 180)),
                              **spec[name]))
    ball = (float(rng.choice([-1, 1])) * rng.uniform(0.16, 0.22), rng.uniform(-0.05, 0.05))
    out.append(Distractor("object", start=ball, diameter=0.03))
    return tuple(out)


def render_realistic_set(out: str | os.PathLike, *, width: int = 640, height: int = 480,
                         backgrounds: tuple[str, ...] = BACKGROUNDS,
                         conditions: tuple[str, ...] = ("normal", "reach"),
                         sleeve: bool = True, seed: int = 0) -> list[RealisticClip]:
    """Render the realistic set and its clean twins into ``out``.

    Parameters
    ----------
    out : str or os.PathLike
        Output folder (``<name>.mp4`` realistic, ``<name>.clean.mp4`` clean,
        each with its ``.truth.h5``).
    width, height : int
        Frame size, px; the camera spans 0.6 m of table in the height.
    backgrounds : tuple of str
        Photographs (:data:`BACKGROUNDS`).
    conditions : tuple of str
        Movements rendered on each photograph.
    sleeve : bool
        Add the sleeve clip (the first background, the first condition).
    seed : int
        Seed of the movements, cameras, clutter and rendering.

    Returns
    -------
    list of RealisticClip
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    plans = [(bg, cond, False) for bg in backgrounds for cond in conditions]
    if sleeve:
        plans.append((backgrounds[0], conditions[0], True))
    clips = []
    for i, (bg, cond, has_sleeve) in enumerate(plans):
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(i,)))
        t, paths = stimulus_paths(StimulusParams(condition=cond), NTSC_FPS, seed=rng)
        scene = Scene(paths["wrist"], paths["finger"], paths["thumb"])
        camera = Camera.for_frame(width, height, angle_deg=float(rng.uniform(-20, 20)))
        look = realistic_style(bg, width=width, height=height,
                               distractors=clutter(scene, camera, rng),
                               sleeve="wrist" if has_sleeve else None)
        clean = RenderStyle(fps=NTSC_FPS, width=width, height=height, hand=True,
                            marker_diameter=look.marker_diameter)
        name = f"{bg}-{cond}" + ("-sleeve" if has_sleeve else "")
        render_seed = int(rng.integers(2**31))
        real = render_clip(scene, camera, look, out / f"{name}.mp4", seed=render_seed,
                           label=cond, params={"background": bg, "sleeve": has_sleeve})
        twin = render_clip(scene, camera, clean, out / f"{name}.clean.mp4",
                           seed=render_seed, label=cond, params={"background": None})
        clips.append(RealisticClip(name, bg, cond, real, twin, has_sleeve))
    return clips

"""Ready-made demonstrations for tests, benchmarks and trying the pipeline out.

Two kinds, both with their ground truth:

* :func:`demo_tracks` — a demonstration of a stimulus condition as a tracker
  would report it (model paths through a camera, plus pixel noise), in
  memory, without rendering or tracking a video: fast enough for hundreds of
  recognitions in a test.
* :func:`render_demo_clip` — a short analytic reach-to-grasp rendered to a
  video file with its ``<clip>.truth.h5``, in a given style (:data:`HARD`:
  camera noise, a skin-coloured hand, a lighting gradient and blur).
"""

from __future__ import annotations

import math
import numbers
import os
from pathlib import Path
from typing import Any

import numpy as np

from perception.errors import InputError
from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.io.tracks import Tracks
from perception.limits import MAX_FPS
from perception.synthetic.independent import tracked_paths
from perception.synthetic.render import RenderResult, render_clip
from perception.synthetic.scene import Camera, RenderStyle, Scene
from perception.synthetic.stimuli import StimulusParams, stimulus_paths

__all__ = ["DEMO_CAMERA", "HARD", "demo_tracks", "render_demo_clip"]

#: The camera of :func:`demo_tracks`: 800 px/m, the object near the top of a 640 x 480 frame.
DEMO_CAMERA = Camera(px_per_m=800.0, origin_px=(320.0, 144.0), angle_deg=0.0)

#: A hard rendering style: noise, skin-coloured hand, lighting gradient, blur.
HARD: dict[str, Any] = dict(hand=True, noise_sd=6.0, lighting=0.45, blur_sigma=0.8)


def demo_tracks(condition: str, seed: int = 0, *, fps: float = 30.0, angle_deg: float = 0.0,
                noise_px: float = 0.4, distance: float = 0.25, duration: float = 1.0,
                lost: dict[str, slice] | None = None) -> tuple[Tracks, dict[str, Any]]:
    """Tracks of one demonstration as a tracker would see it, and its truth.

    Parameters
    ----------
    condition : str
        Stimulus condition (``normal``, ``delayed``, ``open-close-open``, ``reach``).
    seed : int
        Seed of the demonstrator's motor noise (the pixel noise uses ``seed + 1000``).
    fps : float
        Frame rate, frames/s.
    angle_deg : float
        Camera rotation, degrees (see :class:`~perception.synthetic.scene.Camera`).
    noise_px : float
        SD of the tracking noise added to every position, px.
    distance, duration : float
        Wrist start to object centre, m; movement time, s.
    lost : dict of str to slice, optional
        Frames where a marker is lost (NaN, likelihood 0, status lost).

    Returns
    -------
    tracks : Tracks
        Positions (px) of thumb, finger, wrist and object; the object's
        apparent diameter is recorded as a tracker would (``diameter_px``).
    truth : dict
        ``world`` (marker -> (T, 2) m), ``onset_frame`` and the ``params``
        (:class:`~perception.synthetic.stimuli.StimulusParams`).

    Raises
    ------
    InputError
        A condition, distance or duration :class:`StimulusParams` refuses, a
        frame rate outside 0-1000 frames/s, a negative or infinite noise.
    """
    p = StimulusParams(condition=condition, distance=distance, duration=duration)
    # as a recipe's: a rate of 0 gave NaN times, a negative one no frames at all
    if not (isinstance(fps, numbers.Real) and 0 < fps <= MAX_FPS):
        raise InputError(f"expected a number > 0 and <= {MAX_FPS:g}, got {fps!r}",
                         field="demo_tracks.fps")
    if not (isinstance(noise_px, numbers.Real) and 0 <= noise_px < math.inf):
        raise InputError(f"expected a number >= 0, got {noise_px!r}", field="demo_tracks.noise_px")
    t, paths = stimulus_paths(p, fps, seed=seed)
    cam = Camera(DEMO_CAMERA.px_per_m, DEMO_CAMERA.origin_px, angle_deg)
    world = {**paths, "object": np.zeros_like(paths["wrist"])}
    tracks = tracked_paths(t, world, cam, p.object_size, "demo", seed=seed, noise_px=noise_px,
                      lost=lost)
    truth = {"world": world, "onset_frame": int(round(p.rest_before * fps)), "params": p}
    return tracks, truth


def render_demo_clip(folder: str | os.PathLike, name: str = "clip.mp4", *, n: int = 60,
                     fps: float = 30.0, width: int = 640, height: int = 480,
                     angle: float = 20.0, scene: Scene | None = None, seed: int = 0,
                     **style: Any) -> tuple[RenderResult, Camera]:
    """Render a short reach-to-grasp clip and its ground truth into ``folder``.

    Parameters
    ----------
    folder : str or os.PathLike
        Output folder.
    name : str
        Video file name (the extension picks the codec).
    n : int
        Frames.
    fps : float
        Frame rate, frames/s.
    width, height : int
        Frame size, px.
    angle : float
        Camera rotation, degrees.
    scene : Scene, optional
        What moves (default: ``Scene.reach_to_grasp`` starting 0.2 s in and
        ending 0.4 s before the end, with a 0.10 m ball).
    seed : int
        Seed of the rendering noise and texture.
    **style
        :class:`~perception.synthetic.scene.RenderStyle` fields (e.g. ``**HARD``).

    Returns
    -------
    (RenderResult, Camera)
        The files written and the camera that rendered them.
    """
    camera = Camera.for_frame(width, height, angle_deg=angle)
    if scene is None:
        scene = Scene.reach_to_grasp(n, fps, onset=0.2, duration=n / fps - 0.6,
                                     object_diameter=DEFAULT_OBJECT_DIAMETER)
    look = RenderStyle(fps=fps, width=width, height=height, **style)
    return render_clip(scene, camera, look, Path(folder) / name, seed=seed, label="test"), camera

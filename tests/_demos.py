"""Demonstrations in memory: model paths -> camera -> Tracks, no video (fast)."""

from __future__ import annotations

import functools
import json

import numpy as np

from perception.synthetic.render import Camera
from perception.recognition.repertoire import Repertoire, SceneSpec
from perception.synthetic.recipes import StimulusParams, stimulus_paths
from perception.io.tracks import Tracks

MARKERS = ("thumb", "finger", "wrist", "object")
CAMERA = Camera(px_per_m=800.0, origin_px=(320.0, 144.0), angle_deg=0.0)


def demo_tracks(condition: str, seed: int = 0, *, fps: float = 30.0, angle_deg: float = 0.0,
                noise_px: float = 0.4, distance: float = 0.25, duration: float = 1.0,
                lost: dict | None = None) -> tuple[Tracks, dict]:
    """Tracks of one demonstration as a tracker would see it, and its truth.

    ``lost`` maps a marker to a slice of frames where it is NaN.
    """
    p = StimulusParams(condition=condition, distance=distance, duration=duration)
    t, paths = stimulus_paths(p, fps, seed=seed)
    cam = Camera(CAMERA.px_per_m, CAMERA.origin_px, angle_deg)
    world = {"thumb": paths["thumb"], "finger": paths["finger"], "wrist": paths["wrist"],
             "object": np.zeros_like(paths["wrist"])}
    rng = np.random.default_rng(seed + 1000)
    pos = np.stack([cam.world_to_pixel(world[m]) for m in MARKERS], axis=1)
    pos = pos + noise_px * rng.standard_normal(pos.shape)
    for marker, frames in (lost or {}).items():
        pos[frames, MARKERS.index(marker)] = np.nan
    ok = np.isfinite(pos).all(axis=-1)
    tracks = Tracks(
        frame=np.arange(len(t)), time=t, markers=MARKERS, position=pos,
        likelihood=ok.astype(np.float32), status=np.where(ok, 0, 2).astype(np.int8),
        attrs={"camera": json.dumps({"px_per_m": cam.px_per_m}), "object_diameter": 0.10},
    )
    truth = {"world": world, "onset_frame": int(round(p.rest_before * fps)), "params": p}
    return tracks, truth


@functools.cache
def default_repertoire(fps: float = 30.0) -> Repertoire:
    """The default repertoire for the demos' scene, built once per test process."""
    return Repertoire.build(scene=SceneSpec(distance=0.25, object_size=0.10,
                                            frame_period=1.0 / fps))

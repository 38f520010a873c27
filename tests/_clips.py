"""Rendered test clips and how to score tracks against their ground truth."""

from __future__ import annotations

import h5py
import numpy as np

from perception.synthetic.render import Camera, RenderStyle, Scene, render_clip
from perception.tracking.tracker import track_video
from perception.io.tracks import Tracks

#: The issue's hard case: noise, skin-coloured hand, lighting gradient (plus
#: blur and a camera not aligned with the approach).
HARD = dict(hand=True, noise_sd=6.0, lighting=0.45, blur_sigma=0.8)


def render(
    tmp_path,
    name="clip.mp4",
    *,
    n=60,
    fps=30.0,
    width=640,
    height=480,
    angle=20.0,
    scene=None,
    seed=0,
    **style,
):
    """Render a reach-to-grasp clip; return (RenderResult, Camera)."""
    camera = Camera.for_frame(width, height, angle_deg=angle)
    if scene is None:
        scene = Scene.reach_to_grasp(n, fps, onset=0.2, duration=n / fps - 0.6)
    style = RenderStyle(fps=fps, width=width, height=height, **style)
    return render_clip(scene, camera, style, tmp_path / name, seed=seed, label="test"), camera


def track(clip, **kwargs):
    """Track a rendered clip; return (tracks, truth, visible (T, M) bool)."""
    tracks = Tracks.load(track_video(clip.video, **kwargs))
    truth = Tracks.load(clip.truth)
    with h5py.File(clip.truth) as fh:
        visible = fh["truth/visible"][()]
    return tracks, truth, visible


def errors(tracks, truth):
    """(T, M) px distance to the truth; inf where the tracker lost a marker."""
    err = np.linalg.norm(tracks.position - truth.position, axis=-1)
    return np.where(np.isnan(err), np.inf, err)

"""Rendered test clips and how to score tracks against their ground truth."""

from __future__ import annotations

import h5py
import numpy as np

from perception.io.tracks import Tracks
from perception.synthetic.demos import HARD, render_demo_clip
from perception.tracking.video_tracks import track_video

__all__ = ["HARD", "render", "track", "errors"]

#: Render a test clip: ``render(tmp_path, name, n=..., **style) -> (RenderResult, Camera)``.
render = render_demo_clip


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

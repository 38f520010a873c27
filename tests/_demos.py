"""Demonstrations in memory (model paths -> camera -> Tracks, no video) and a cached repertoire."""

from __future__ import annotations

import functools

from perception.recognition.repertoire import Repertoire, SceneSpec
from perception.synthetic.demos import DEMO_CAMERA as CAMERA
from perception.synthetic.demos import demo_tracks
from perception.tracking.markers import MARKER_NAMES as MARKERS

__all__ = ["CAMERA", "MARKERS", "demo_tracks", "default_repertoire"]


@functools.cache
def default_repertoire(fps: float = 30.0) -> Repertoire:
    """The default repertoire for the demos' scene, built once per test process."""
    return Repertoire.build(scene=SceneSpec(distance=0.25, object_size=0.10,
                                            frame_period=1.0 / fps))

"""Demonstrations in memory (model paths -> camera -> Tracks, no video) and a cached repertoire."""

from __future__ import annotations

import functools

from perception.recognition.repertoire import Repertoire, SceneSpec
from perception.synthetic.demos import DEMO_CAMERA as CAMERA
from perception.synthetic.demos import demo_tracks
from perception.tracking.markers import MARKER_NAMES as MARKERS

__all__ = ["CAMERA", "MARKERS", "default_repertoire", "demo_tracks", "dlc_csv"]


@functools.cache
def default_repertoire(fps: float = 30.0) -> Repertoire:
    """The default repertoire for the demos' scene, built once per test process."""
    return Repertoire.build(scene=SceneSpec(distance=0.25, object_size=0.10,
                                            frame_period=1.0 / fps))


def dlc_csv(folder):
    """A DeepLabCut CSV (scorer / bodyparts / coords header rows) of a synthetic grasp in
    ``folder``: its path and the tracks it was written from."""
    import numpy as np
    import pandas as pd

    tracks = demo_tracks("normal", 0)[0]
    columns = pd.MultiIndex.from_product([["DLC_resnet50"], list(tracks.markers),
                                          ["x", "y", "likelihood"]],
                                         names=["scorer", "bodyparts", "coords"])
    xy_p = np.concatenate([tracks.position, tracks.likelihood[..., None]], axis=-1)
    path = folder / "clip.csv"
    pd.DataFrame(xy_p.reshape(len(xy_p), -1), columns=columns).to_csv(path)
    return path, tracks

"""Bad input through the Python API (``import perception as pc``) is the documented error.

A user's mistake is an :class:`~perception.errors.InputError` (a ``ValueError``)
naming the file or the field, or a ``TypeError`` saying what was expected;
never an ``AttributeError``, a bare ``FileNotFoundError`` or a library's error
from deep inside.
"""

from __future__ import annotations

import dataclasses

import pandas as pd
import pytest

import perception as pc
from perception.errors import InputError


def test_a_missing_video_is_an_input_error_naming_it(tmp_path):
    missing = tmp_path / "nope.mp4"
    for call in (lambda: pc.load_clip(missing),
                 lambda: pc.load_movements(missing)):
        with pytest.raises(InputError, match="nope.mp4: no such file"):
            call()


def test_landmarks_takes_the_object_size_in_pixels_its_error_asks_for():
    tracks, _ = pc.demo_tracks("normal", seed=0)
    bare = dataclasses.replace(tracks, tracker={})  # no apparent object size recorded
    with pytest.raises(InputError, match="object_diameter_px"):
        pc.landmarks(bare, object_diameter=0.1)
    given = pc.landmarks(bare, object_diameter=0.1, object_diameter_px=80.0)
    scaled = pc.landmarks(bare, px_per_m=800.0)
    assert given["status"].tolist() == ["complete"]
    pd.testing.assert_frame_equal(given, scaled)

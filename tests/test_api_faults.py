"""Bad input through the Python API (``import perception as pc``) is the documented error.

A user's mistake is an :class:`~perception.errors.InputError` (a ``ValueError``)
naming the file or the field, or a ``TypeError`` saying what was expected;
never an ``AttributeError``, a bare ``FileNotFoundError`` or a library's error
from deep inside.
"""

from __future__ import annotations

import pytest

import perception as pc
from perception.errors import InputError


def test_a_missing_video_is_an_input_error_naming_it(tmp_path):
    missing = tmp_path / "nope.mp4"
    for call in (lambda: pc.load_clip(missing),
                 lambda: pc.load_movements(missing)):
        with pytest.raises(InputError, match="nope.mp4: no such file"):
            call()

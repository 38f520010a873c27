"""The shipped calibration of the default models is what the code computes."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from perception.recognition.repertoire import DEFAULT_CALIBRATION, Repertoire

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
from calibrate_default import compute  # noqa: E402

pytestmark = pytest.mark.slow


def test_the_shipped_calibration_is_regenerated_by_the_tool():
    shipped = json.loads(DEFAULT_CALIBRATION.read_text())
    fresh = compute()
    assert shipped["params"] == fresh["params"] and shipped["scene"] == fresh["scene"]
    assert shipped["models"].keys() == fresh["models"].keys()
    for name, misfit in fresh["models"].items():
        np.testing.assert_allclose(shipped["models"][name], misfit, rtol=1e-9, err_msg=(
            f"{name}: the code no longer gives the shipped calibration; run "
            "tools/calibrate_default.py"))


def test_the_default_repertoire_carries_it_to_a_clips_scene():
    from perception.recognition.models import SceneSpec

    rep = Repertoire.default()
    models = rep.for_scene(SceneSpec(distance=0.3, object_size=0.08))
    shipped = json.loads(DEFAULT_CALIBRATION.read_text())["models"]
    for m in models:
        assert m.calibration is not None
        np.testing.assert_allclose(m.calibration.misfit, np.sort(shipped[m.name]))

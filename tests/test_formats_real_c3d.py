"""C3D files as real writers leave them, in the layouts of ezc3d's test files.

The files are written here with ezc3d (or stand in for what ezc3d hands
over): the layouts are those of pyomeca/ezc3d-testFiles' ``Kistler.c3d``
(force plates only: POINT:USED 0 and POINT:RATE 0) and of any C3D with more
than 255 points (POINT:LABELS holds 255 labels, LABELS2 the next ones, as
the C3D specification and ezc3d's writer split them).
"""

from __future__ import annotations

import numpy as np
import pytest

from perception.errors import InputError
from perception.io.mocap import read_mocap

ezc3d = pytest.importorskip("ezc3d", reason="the 'mocap' extra")


def _write(path, labels, frames=30, rate=100):
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [rate]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(labels)
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    points = np.ones((4, len(labels), frames))
    points[:3] = np.random.default_rng(4).uniform(100, 400, (3, len(labels), frames))
    c3d["data"]["points"] = points
    c3d.write(str(path))
    return points


def test_labels_past_255_are_read_from_labels2(tmp_path):
    path = tmp_path / "many.c3d"
    labels = [f"m{i}" for i in range(300)]
    points = _write(path, labels)
    assert "LABELS2" in ezc3d.c3d(str(path))["parameters"]["POINT"]  # as the spec splits them
    (trial,) = read_mocap(path)
    assert trial.marker_names() == tuple(labels)
    np.testing.assert_allclose(trial.markers["m299"][4], points[:3, 299, 4] / 1000, rtol=1e-6)


def test_a_file_of_forces_only_says_it_has_no_markers(tmp_path, monkeypatch):
    """What ezc3d hands over for Kistler.c3d: no points, POINT:RATE 0."""
    import sys
    import types

    content = {"parameters": {"POINT": {"LABELS": {"value": []}, "RATE": {"value": [0.0]},
                                        "USED": {"value": [0]}}},
               "data": {"points": np.zeros((4, 0, 3969)),
                        "meta_points": {"residuals": np.zeros((1, 0, 3969))}},
               "header": {"points": {"first_frame": 0, "frame_rate": 0.0}}}
    monkeypatch.setitem(sys.modules, "ezc3d", types.SimpleNamespace(c3d=lambda path: content))
    path = tmp_path / "kistler.c3d"
    path.write_bytes(b"\x02\x50")
    with pytest.raises(InputError, match="no marker points: POINT:USED is 0") as err:
        read_mocap(path)
    assert err.value.field == "POINT:USED" and "rate" not in str(err.value)

"""DeepLabCut 3-D tables (``triangulate``'s CSV) read as motion capture.

The four real Optotrak trials' first one, written as DeepLabCut writes a 3-D
table (the rows scorer, bodyparts, coords x, y, z, then one row per frame,
in mm, no time), reads back as the same markers and gets the same verdict as
the lab's own table; it was routed to the pose reader and refused before.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io.mocap import is_mocap_file, read_mocap, table_layout

DATA = Path(__file__).parent / "data" / "mocap"
NAMES = ("thumb", "index", "eyeL", "eyeR")


@pytest.fixture(scope="module")
def trial():
    return read_mocap(DATA / "optotrak-trials.tsv", rate=85.0)[0]


def _dlc3d(trial, path, individuals=None):
    """``trial``'s markers as a DeepLabCut 3-D table, mm (``individuals``: a multi-animal
    project's row of who each keypoint is)."""
    levels = [["DLC_3D"], list(NAMES), ["x", "y", "z"]]
    names = ["scorer", "bodyparts", "coords"]
    if individuals:
        columns = pd.MultiIndex.from_tuples(
            [("DLC_3D", who, part, axis) for who, part in zip(individuals, NAMES)
             for axis in "xyz"], names=["scorer", "individuals", "bodyparts", "coords"])
    else:
        columns = pd.MultiIndex.from_product(levels, names=names)
    xyz = np.concatenate([trial.markers[n] * 1000 for n in NAMES], axis=1)
    pd.DataFrame(xyz, columns=columns).to_csv(path)
    return path


def test_a_dlc_3d_table_reads_as_the_markers_it_holds(trial, tmp_path):
    path = _dlc3d(trial, tmp_path / "reachDLC_3D.csv")
    assert table_layout(path) == "dlc-3d" and is_mocap_file(path)
    (got,) = read_mocap(path, rate=85.0)
    assert got.marker_names() == NAMES and got.units == "mm" and got.rate == 85.0
    for name in NAMES:
        np.testing.assert_allclose(got.markers[name], trial.markers[name], atol=1e-9)
    assert any("DeepLabCut 3-D table" in n for n in got.notes)


def test_several_individuals_are_told_apart_by_name(trial, tmp_path):
    path = _dlc3d(trial, tmp_path / "pairDLC_3D.csv", ["left", "left", "right", "right"])
    (got,) = read_mocap(path, rate=85.0)
    assert got.marker_names() == ("left:thumb", "left:index", "right:eyeL", "right:eyeR")
    one = _dlc3d(trial, tmp_path / "oneDLC_3D.csv", ["m1"] * 4)
    assert read_mocap(one, rate=85.0)[0].marker_names() == NAMES


def test_it_is_recognised_as_the_labs_table_is(trial, tmp_path, capsys):
    path = _dlc3d(trial, tmp_path / "reachDLC_3D.csv")
    assert main(["recognize", str(path), "--rate", "85", "--markers", "thumb=thumb",
                 "finger=index", "-o", str(tmp_path / "o"), "--no-figures", "--quiet"]) == 0
    table = DATA / "optotrak-trials.tsv"
    assert main(["recognize", str(table), "--rate", "85", "--markers", "thumb=thumb",
                 "finger=index", "-o", str(tmp_path / "t"), "--no-figures", "--quiet"]) == 0
    import json

    a = json.loads((tmp_path / "o" / "reachDLC_3D.recognition.json").read_text())
    b = json.loads((tmp_path / "t" / "optotrak-trials-trial0.recognition.json").read_text())
    assert a["verdict"] == b["verdict"] == "normal"
    assert a["kinematics"]["observed"]["movement_time"] == pytest.approx(
        b["kinematics"]["observed"]["movement_time"], abs=1e-6)


@pytest.mark.parametrize("kwargs, field", [
    ({}, "rate"),
    ({"rate": 85.0, "time_column": "t"}, "time_column"),
    ({"rate": 85.0, "trial_column": "trial"}, "trial_column"),
    ({"rate": 85.0, "columns": "a,b,c,d"}, "columns"),
])
def test_what_a_dlc_3d_table_cannot_take_is_refused_in_one_line(trial, tmp_path, kwargs,
                                                                 field):
    path = _dlc3d(trial, tmp_path / "reachDLC_3D.csv")
    with pytest.raises(InputError) as err:
        read_mocap(path, **kwargs)
    assert err.value.field == field and "\n" not in str(err.value)


def test_a_2d_table_is_still_a_pose_file(trial, tmp_path):
    columns = pd.MultiIndex.from_product([["DLC_x"], ["thumb"], ["x", "y", "likelihood"]],
                                         names=["scorer", "bodyparts", "coords"])
    path = tmp_path / "clipDLC_x.csv"
    pd.DataFrame(np.ones((5, 3)), columns=columns).to_csv(path)
    assert table_layout(path) is None and not is_mocap_file(path)

"""Tables with X, Y, Z columns per marker as lab scripts export them from Vicon data.

A lab script that flattens a Nexus Trajectories block into one header row
keeps Vicon's ``Subject:Marker`` names in its columns (``Subj01:RTHUMB_X``);
the markers are named as the Nexus export's own are (docs/mocap-formats.md).
"""

from __future__ import annotations

import numpy as np

from perception.io.mocap import read_mocap


def _table(path, names):
    t = np.arange(50) / 100
    header = ["time"] + [f"{name}_{axis}" for name in names for axis in "XYZ"]
    rows = [[f"{v:.2f}"] + [f"{100 + 10 * k + v:.3f}" for k in range(3 * len(names))]
            for v in t]
    path.write_text("\n".join([",".join(header)] + [",".join(r) for r in rows]) + "\n")


def test_subject_prefixes_are_left_out_as_for_nexus_exports(tmp_path):
    _table(tmp_path / "p01.csv", ["Subj01:RTHUMB", "Subj01:RINDEX", "Subj01:RWRA"])
    (trial,) = read_mocap(tmp_path / "p01.csv")
    assert trial.marker_names() == ("RTHUMB", "RINDEX", "RWRA")
    assert "subject prefix 'Subj01:' left out of the marker names" in trial.notes
    np.testing.assert_allclose(trial.markers["RINDEX"][0], [0.13, 0.14, 0.15])


def test_two_subjects_with_one_marker_set_keep_their_names(tmp_path):
    _table(tmp_path / "pair.csv", ["P1:RTHUMB", "P2:RTHUMB", "P1:RWRA"])
    (trial,) = read_mocap(tmp_path / "pair.csv")
    assert trial.marker_names() == ("P1:RTHUMB", "P2:RTHUMB", "RWRA")

"""Real fast reaches are healthy grasps: the RTMocap pick-and-place trials (0.4-0.5 s).

They come from ``../shared/realdata`` (GPL sample data: read from there, never
copied into the repository), so the test runs where that folder is and is
skipped elsewhere. Their onsets were placed 40-70 ms early by the 1 s model's
latency until the onset fitted the movement's own start: 10 of 15 ``normal``
then, 15 now (docs/mocap.md).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from perception.io.mocap import read_mocap
from perception.reach_data import MarkerMap
from perception.reaches import trial_reaches
from perception.recordings import MocapImport, recognize_reach

FOLDER = Path(__file__).resolve().parents[2] / "shared" / "realdata" / "rtmocap-pick-and-place"
COLUMNS = ("object", "thumb", "index", "hand", "wristA", "wristB")

pytestmark = pytest.mark.skipif(not FOLDER.is_dir(), reason="../shared/realdata is not here")


def test_the_rtmocap_reaches_are_normal_grasps_ending_at_the_grasp():
    from perception.recognition.repertoire import Repertoire

    rep = Repertoire.default()
    options = MocapImport(markers=MarkerMap(thumb="thumb", finger="index",
                                            wrist=("wristA", "wristB"), object=("object",)),
                          rate=200.0)
    files = sorted(FOLDER.glob("Raw_data_*.txt"))
    verdicts, scales = [], []
    for path in files:
        (trial,) = read_mocap(path, rate=200.0, columns=COLUMNS)
        reaches, _ = trial_reaches(trial, options.markers, options.reaches)
        assert len(reaches) == 1, path.name
        rec, _ = recognize_reach(reaches[0], rep, None, options)
        verdicts.append(rec.verdict)
        scales.append(rec.normalisation.movement_time)
    assert len(files) == 15
    assert verdicts.count("normal") >= 14, verdicts
    assert max(scales) < 0.65  # fast reaches: each scored at its own speed

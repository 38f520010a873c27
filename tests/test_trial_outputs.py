"""A motion-capture trial's report made in one pass of each kind: its JSON encoded once, its
kinematic traces measured once for its figure, its JSON and the batch's summary."""

import json
import math
from pathlib import Path

import numpy as np

from perception.io.atomic import jsonable, write_json

OPTOTRAK = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"


def _encoded_twice(obj) -> str:
    """What write_json wrote: encoded, decoded, NaN made None, encoded again."""
    def clean(o):
        if isinstance(o, float) and o != o:
            return None
        if isinstance(o, dict):
            return {k: clean(v) for k, v in o.items()}
        if isinstance(o, list | tuple):
            return [clean(v) for v in o]
        return o

    return json.dumps(clean(json.loads(json.dumps(obj, default=jsonable))), indent=2) + "\n"


def test_write_json_writes_the_text_of_encoding_twice(tmp_path):
    class Float(float):
        pass

    obj = {
        "floats": [1.0, math.nan, math.inf, -math.inf, -0.0, 1e16, 1e-7, 0.1 + 0.2],
        "arrays": [np.array([[1.0, np.nan], [2.0, 3.0]]), np.array([0.5, 1.5]), np.arange(3),
                   np.zeros((0, 2)), np.array(2.5), np.array([1.5], dtype=np.float32),
                   np.array([1, None, np.nan], dtype=object)],
        "scalars": [np.float64("nan"), np.float32(0.1), np.int64(7), np.bool_(True),
                    Float(1.5), True, None, "é \u2028"],
        # keys json writes as text, a later equal one replacing the first's value
        "keys": {2: "a", "2": "b", 2.5: "c", False: "d", None: "e"},
        "other": {"set": {3, 1, 2}, "path": Path("/a/b"), "tuple": (1, (2, [np.nan]))},
        "empty": [{}, [], ()],
    }
    write_json(tmp_path / "x.json", obj)
    assert (tmp_path / "x.json").read_text() == _encoded_twice(obj)
    assert json.loads((tmp_path / "x.json").read_text())["floats"][1] is None


def test_write_json_refuses_what_json_refuses(tmp_path):
    import pytest

    for bad in ({"x": object()}, {"x": 1j}, {np.int64(1): 2}):
        with pytest.raises(TypeError):
            write_json(tmp_path / "bad.json", bad)
        assert not (tmp_path / "bad.json").exists()


def test_a_trials_kinematic_traces_are_measured_once(tmp_path, monkeypatch):
    import perception.report.kinematics as kinematics
    from perception.batch_clip import process_clip
    from perception.discovery import BatchItem
    from perception.pipeline import RecognitionSettings
    from perception.recognition.repertoire import Repertoire
    from perception.recordings import MocapImport, read_reaches

    settings = RecognitionSettings(mocap=MocapImport(rate=85.0))
    reach = read_reaches(OPTOTRAK, settings.mocap)[0]
    measured = []
    traces = kinematics.kinematic_traces

    def counted(*args, **kwargs):
        measured.append(1)
        return traces(*args, **kwargs)

    monkeypatch.setattr(kinematics, "kinematic_traces", counted)
    result = process_clip(BatchItem(reach.name, OPTOTRAK, "mocap", reach=0), tmp_path,
                          Repertoire.default(), settings, reach=reach)
    assert result.status == "ok"
    assert len(measured) == 1  # the figure's, the JSON's and the summary's: one
    report = json.loads((tmp_path / f"{reach.name}.recognition.json").read_text())
    assert report["traces"]["time"] == [None if v != v else v for v in
                                        result.summary.traces["time"].tolist()]
    assert (tmp_path / f"{reach.name}.kinematics.png").read_bytes().startswith(b"\x89PNG")

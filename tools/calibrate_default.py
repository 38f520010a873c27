"""Regenerate perception/recognition/default_calibration.json: the default repertoire's verdict.

The default repertoire (``Repertoire.default()``, what ``recognize`` and
``batch`` score against without ``--repertoire``) is planned for each clip's
scene. Calibrating the verdict of a model takes 50 of its own rendered
demonstrations (about 0.4-0.6 s a model), once per scene: longer than all
the rest of scoring a clip. A calibration transfers across scenes (models
re-planned from a built repertoire keep theirs; docs/recognition.md), so the
default models' calibrations at the default scene ship with the package and
this tool makes them. `tests/test_default_calibration.py` recomputes them
and fails, naming this tool, when the code no longer gives the shipped file.

    .venv/bin/python tools/calibrate_default.py
"""

from __future__ import annotations

import dataclasses
import json

from perception.io.atomic import write_text
from perception.recognition.models import SceneSpec
from perception.recognition.planning import default_specs
from perception.recognition.repertoire import DEFAULT_CALIBRATION, Repertoire


def compute() -> dict:
    """The default models' calibrations at the default scene, as the shipped file holds them."""
    scene = SceneSpec()
    models = Repertoire.build(default_specs(), scene).models  # planned and calibrated
    cals = [m.calibration for m in models]
    return {"scene": dataclasses.asdict(scene),
            "params": dataclasses.asdict(cals[0].params),
            "frame_period": cals[0].frame_period,
            "models": {m.name: [float(v) for v in c.misfit]
                       for m, c in zip(models, cals)}}


def main() -> None:
    write_text(DEFAULT_CALIBRATION, json.dumps(compute(), indent=1) + "\n")
    print(f"wrote {DEFAULT_CALIBRATION}")


if __name__ == "__main__":
    main()

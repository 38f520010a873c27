"""The thesis's printed model (form='thesis') reaches the grasp models and the repertoire."""

import numpy as np

from perception.recognition.models import ModelSpec
from perception.recognition.repertoire import Repertoire

THESIS_SETTINGS = {"r": 0.002, "w_v": 0.1, "w_f": 0.01, "form": "thesis"}


def test_repertoire_plans_every_model_at_the_thesis_settings():
    specs = [ModelSpec("grasp-1.0s", "grasp", {"duration": 1.0}),
             ModelSpec("reach-1.0s", "reach", {"duration": 1.0, "w_v": 0.3})]
    rep = Repertoire.build(specs, task=THESIS_SETTINGS)
    ours = Repertoire.build(specs[:1])
    for m in rep.models:
        # the printed filter: the command enters f~ at unit gain
        assert np.array_equal(m.arm.B[6:8], np.eye(2))
    assert not np.array_equal(ours.models[0].arm.B[6:8], np.eye(2))  # default unchanged
    # a model's own setting wins over the shared one; the config keeps what was planned
    tasks = [m["task"] for m in rep.config["models"]]
    assert tasks[0] == {**THESIS_SETTINGS, "duration": 1.0}
    assert tasks[1]["w_v"] == 0.3 and tasks[1]["form"] == "thesis"

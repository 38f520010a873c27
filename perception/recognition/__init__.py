"""HAMMER-MV recognition: models planned for a scene, the engine that runs them, two rules.

* :mod:`~perception.recognition.models` — what a model is (chains, specs, scenes);
* :mod:`~perception.recognition.planning` — planning models with :mod:`minvar`;
* :mod:`~perception.recognition.repertoire` — a set of models, re-planned per scene, stored;
* :mod:`~perception.recognition.engine` — every model predicts every step;
* :mod:`~perception.recognition.scoring` — the thesis and likelihood rules;
* :mod:`~perception.recognition.result` — :class:`Recognition`, the result;
* :mod:`~perception.recognition.verdict` — familiarity and the verdict;
* :mod:`~perception.recognition.calibration` — each model scores its own demonstrations;
* :mod:`~perception.recognition.rollout` — the models' own movements from their gains;
* :mod:`~perception.recognition.leaves` — every chain of every model stacked for stepping.
"""

from perception.recognition.engine import HammerParams, recognize
from perception.recognition.models import ChainModel, ModelSpec, MotorModel, SceneSpec
from perception.recognition.planning import DEFAULT_DURATIONS, build_model, default_specs
from perception.recognition.repertoire import Repertoire
from perception.recognition.result import Recognition
from perception.recognition.scoring import RULES
from perception.recognition.verdict import VERDICTS, Calibration, CalibrationParams

__all__ = [
    "Calibration",
    "CalibrationParams",
    "ChainModel",
    "DEFAULT_DURATIONS",
    "HammerParams",
    "ModelSpec",
    "MotorModel",
    "RULES",
    "Recognition",
    "Repertoire",
    "SceneSpec",
    "VERDICTS",
    "build_model",
    "default_specs",
    "recognize",
]

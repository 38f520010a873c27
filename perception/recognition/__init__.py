"""HAMMER-MV recognition: models planned for a scene, the engine that runs them, two rules.

* :mod:`~perception.recognition.models` — what a model is (chains, specs, scenes);
* :mod:`~perception.recognition.planning` — planning models with :mod:`minvar`;
* :mod:`~perception.recognition.repertoire` — a set of models, re-planned per scene, stored;
* :mod:`~perception.recognition.engine` — every model predicts every step;
* :mod:`~perception.recognition.scoring` — the thesis and likelihood rules;
* :mod:`~perception.recognition.result` — :class:`Recognition`, the result.
"""

from perception.recognition.engine import HammerParams, recognize
from perception.recognition.models import ChainModel, ModelSpec, MotorModel, SceneSpec
from perception.recognition.planning import DEFAULT_DURATIONS, build_model, default_specs
from perception.recognition.repertoire import Repertoire
from perception.recognition.result import Recognition
from perception.recognition.scoring import RULES

__all__ = [
    "ChainModel",
    "DEFAULT_DURATIONS",
    "HammerParams",
    "ModelSpec",
    "MotorModel",
    "RULES",
    "Recognition",
    "Repertoire",
    "SceneSpec",
    "build_model",
    "default_specs",
    "recognize",
]

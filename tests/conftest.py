import json
from pathlib import Path

import numpy as np
import pytest

#: Copy of shared/reference/todorov_reach.json: Todorov's kalman_lqg.m run in Octave.
REFERENCE = Path(__file__).resolve().parent / "data" / "todorov_reach.json"


@pytest.fixture(scope="session")
def todorov():
    """Inputs and outputs of Todorov's kalman_lqg.m for the thesis reach."""
    with open(REFERENCE) as fh:
        return json.load(fh)


@pytest.fixture(scope="session")
def reference_problem(todorov):
    from minvar import LQGProblem

    return LQGProblem(**{k: np.array(v, dtype=float) for k, v in todorov["inputs"].items()})

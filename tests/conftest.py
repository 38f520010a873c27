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


@pytest.fixture(params=["c", "numpy"])
def engine(request):
    """Each of the solver's engines (``solve(..., engine=engine)``); "c" only where it is built."""
    from minvar import _kernel

    if request.param == "c" and not _kernel.loaded():
        pytest.skip(f"the compiled LQG kernel is not available: {_kernel._WHY}")
    return request.param

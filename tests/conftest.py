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


@pytest.fixture(scope="module", params=["c", "numpy"])
def engine(request):
    """Each of the solver's engines in turn, as trackpy runs its tests once per engine.

    The value is for ``solve(..., engine=engine)``; while a module's tests run
    with it, ``MINVAR_KERNEL`` makes the library's own solves (``engine="auto"``:
    planning, recognition) use it too, so a module-scoped fixture that plans
    and uses ``engine`` is planned once per engine. "c" is skipped where the
    kernel is not built.
    """
    from minvar import _kernel

    if request.param == "c" and not _kernel.loaded():
        pytest.skip(f"the compiled LQG kernel is not available: {_kernel._WHY}")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("MINVAR_KERNEL", request.param)
        yield request.param


@pytest.fixture
def camera(monkeypatch):
    """Install a stand-in for ``cv2.VideoCapture`` (a test's fake camera class); returns it."""
    import cv2

    def install(cam):
        monkeypatch.setattr(cv2, "VideoCapture", cam)
        return cam

    return install

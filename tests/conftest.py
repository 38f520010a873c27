import json
import signal
from pathlib import Path

import numpy as np
import pytest

#: Copy of shared/reference/todorov_reach.json: Todorov's kalman_lqg.m run in Octave.
REFERENCE = Path(__file__).resolve().parent / "data" / "todorov_reach.json"


@pytest.fixture(scope="session", autouse=True)
def _signals_as_in_a_terminal():
    """SIGINT and SIGHUP handled as in a terminal, whoever started the suite.

    A suite started in the background by a shell without job control (``cmd &``,
    ``nohup``) inherits them ignored, and a watch leaves an ignored signal ignored
    (as under nohup, by design): its signal tests would then see no Ctrl-C, and the
    watches they run as subprocesses would inherit the ignored signals.
    """
    for number, handler in ((signal.SIGINT, signal.default_int_handler),
                            (signal.SIGHUP, signal.SIG_DFL)):
        if signal.getsignal(number) is signal.SIG_IGN:
            signal.signal(number, handler)


@pytest.fixture(autouse=True)
def _no_log_levels_from_an_earlier_main(monkeypatch):
    """Each test starts without the log levels ``hammer_mv.cli.main()`` sets for its process.

    ``main()`` sets OpenCV's and FFmpeg's log levels (``os.environ.setdefault``);
    after a test that calls it in the pytest process they would pass to every later
    subprocess of that worker, and a test that a subprocess prints no FFmpeg chatter
    would pass without the subprocess's own ``main()`` setting them.
    """
    for name in ("OPENCV_FFMPEG_LOGLEVEL", "OPENCV_LOG_LEVEL"):
        monkeypatch.delenv(name, raising=False)


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

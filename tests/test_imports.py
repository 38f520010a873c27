"""What a command or a module imports: OpenCV only for video, one import path per minvar name.

The imports are read from ``python -X importtime`` in a fresh process (its stderr lists
every module imported, indented under the one that imported it), so nothing an earlier
test imported can hide or fake a load.
"""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _demos import dlc_csv

import minvar
from minvar import lqg, moments, problem

MOCAP = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"


def _imports(stderr: str) -> list[tuple[str, int, int]]:
    """``(module, self_us, cumulative_us)`` of every line ``-X importtime`` wrote."""
    rows = []
    for line in stderr.splitlines():
        if line.startswith("import time:") and not line.rstrip().endswith("| imported package"):
            own, total, name = line.split(":", 1)[1].split("|")
            rows.append((name.strip(), int(own), int(total)))
    return rows


def _loads_opencv(rows: list[tuple[str, int, int]]) -> bool:
    """Whether OpenCV's package ran: a ``cv2.*`` module, or ``cv2`` with imports under it.

    An import that is refused (``sys.modules["cv2"] = None``, so that a library's
    optional ``import cv2`` fails) is listed too, as a bare ``cv2`` line with nothing
    under it (cumulative time = its own); OpenCV's own ``__init__`` imports its submodules.
    """
    return any(name.startswith("cv2.") or (name == "cv2" and total > own)
               for name, own, total in rows)


def _recognize(path: Path, out: Path, *extra: str) -> tuple[subprocess.CompletedProcess, list]:
    res = subprocess.run([sys.executable, "-X", "importtime", "-m", "hammer_mv", "recognize",
                          str(path), "-o", str(out), "--no-figures", "--quiet", *extra],
                         capture_output=True, text=True, timeout=300)
    rows = _imports(res.stderr)
    assert rows, "python -X importtime wrote no import list"
    return res, rows


def _said(res: subprocess.CompletedProcess) -> str:
    return "\n".join(line for line in res.stderr.splitlines()
                     if not line.startswith("import time:"))[-2000:]


def _tracks(folder: Path) -> Path:
    from perception.synthetic.demos import demo_tracks

    return demo_tracks("normal", 0)[0].save(folder / "clip.tracks.h5")


def _mp4(folder: Path) -> Path:
    """Ten black frames: enough to be read (the markers are then never found)."""
    import cv2

    path = folder / "clip.mp4"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), 30.0, (64, 48))
    assert writer.isOpened()
    for _ in range(10):
        writer.write(np.zeros((48, 64, 3), np.uint8))
    writer.release()
    return path


def test_the_import_list_tells_a_refused_import_from_a_load():
    rows = _imports("import time: self [us] | cumulative | imported package\n"
                    "import time:        7 |          7 |       cv2\n")
    assert rows == [("cv2", 7, 7)] and not _loads_opencv(rows)
    assert _loads_opencv(_imports("import time:       93 |         93 |         cv2.version\n"
                                  "import time:    18203 |      18852 |       cv2\n"))


# pose: movement.io.load_poses -> sleap_io.io.video_reading, whose top-level
# `try: import cv2` loaded OpenCV until perception/io/movement_import.py refused it
@pytest.mark.parametrize("kind", ["tracks", "pose", "mocap"])
def test_recognize_of_a_file_that_is_not_video_loads_no_opencv(tmp_path, kind):
    if kind == "tracks":
        res, rows = _recognize(_tracks(tmp_path), tmp_path / "out")
    elif kind == "pose":
        res, rows = _recognize(dlc_csv(tmp_path)[0], tmp_path / "out", "--fps", "30",
                               "--object-diameter-px", "80")
    else:
        res, rows = _recognize(MOCAP, tmp_path / "out", "--rate", "85")
    assert res.returncode == 0, _said(res)
    assert list((tmp_path / "out").glob("*.recognition.json")), _said(res)
    assert not _loads_opencv(rows), [r for r in rows if r[0].split(".")[0] == "cv2"]


QUALISYS = Path(__file__).parent / "data" / "mocap" / "qualisys-recording.tsv"


# pandas (with what it pulls in, ~0.25 s) was the whole start-up margin of these files:
# a plain DeepLabCut csv and a Qualisys export are read (and the recording's trials.csv
# written) without it (perception/io/plain_tables.py)
@pytest.mark.parametrize("kind", ["pose", "qualisys"])
def test_recognize_of_a_plain_pose_or_qualisys_file_loads_no_pandas(tmp_path, kind):
    if kind == "pose":
        res, rows = _recognize(dlc_csv(tmp_path)[0], tmp_path / "out", "--fps", "30",
                               "--object-diameter-px", "80")
    else:
        res, rows = _recognize(QUALISYS, tmp_path / "out")
    assert res.returncode == 0, _said(res)
    assert list((tmp_path / "out").glob("*.recognition.json")), _said(res)
    loaded = {name.split(".")[0] for name, _, _ in rows}
    assert not loaded & {"pandas", "xarray", "movement"}, sorted(loaded)
    if kind == "qualisys":  # the trials table written without pandas, as pandas would
        import pandas as pd

        table = next((tmp_path / "out").glob("*.trials.csv"))
        assert pd.read_csv(table)["status"].tolist() == ["ok"]


def test_recognize_of_a_video_loads_opencv(tmp_path):
    res, rows = _recognize(_mp4(tmp_path), tmp_path / "out")
    assert "Traceback" not in res.stderr and "clip.mp4" in _said(res), _said(res)
    assert _loads_opencv(rows)


def test_minvar_lqg_does_not_re_export_the_moments():
    # one import path per name: the moments of any gains are minvar.moments' (and the
    # package's, minvar.expected_cost), not also minvar.lqg's
    for name in ("expected_cost", "state_moments"):
        assert getattr(moments, name) is getattr(minvar, name)
        assert not hasattr(lqg, name), name
    assert not set(lqg.__all__) & set(moments.__all__)


def test_minvar_lqg_keeps_no_moments_name_for_an_old_importer():
    assert not hasattr(lqg, "estimation_error_covariance")


def test_lqg_problem_has_its_own_module_that_the_solver_and_moments_import():
    assert minvar.LQGProblem is problem.LQGProblem
    assert problem.LQGProblem.__module__ == "minvar.problem"
    assert "LQGProblem" not in lqg.__all__
    code = ("import sys, minvar.moments\n"
            "assert 'minvar.problem' in sys.modules and 'minvar.lqg' not in sys.modules\n"
            "assert minvar.moments.LQGProblem is sys.modules['minvar.problem'].LQGProblem\n")
    subprocess.run([sys.executable, "-c", code], check=True)

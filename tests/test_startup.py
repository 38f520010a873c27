"""What a command does at start-up that it need not (issue 45 item 4).

Nothing here is timed (start-up is measured in ``tools/bench_speed.py``): each test
checks, in a fresh process where it matters, that work a command does not need is not
done — a settings class's validator built before it is used, ``movement.io`` (pynwb,
sleap_io and what they import) loaded for a DeepLabCut table.
"""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pandas as pd
import pytest
from _demos import dlc_csv

from minvar.errors import ParameterError
from perception.errors import InputError, PlanningError


def _fresh(code: str) -> str:
    """Run ``code`` in a fresh interpreter; its stdout."""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    return res.stdout


def test_a_declared_class_is_built_when_first_made_not_when_imported():
    out = _fresh("import hammer_mv.cli.options\n"
                 "from perception.observation import ObserveParams as O\n"
                 "print(O.__pydantic_complete__, len(O.__pydantic_fields__))\n"
                 "O()\n"
                 "print(O.__pydantic_complete__)\n")
    # the option tables read the fields, which are there before the validator is
    assert out.split() == ["False", "23", "True"]


def test_a_deferred_class_refuses_a_bad_value_in_one_line_first_and_every_time():
    # pydantic's deferred build sets the class's __init__ anew: the one-line error must
    # survive it, on the first instance (which builds) and on every later one
    out = _fresh("from minvar.errors import ParameterError\n"
                 "from minvar.grasp_task import GraspTask\n"
                 "for _ in range(3):\n"
                 "    try:\n"
                 "        GraspTask(object_size=-0.001)\n"
                 "    except ParameterError as exc:\n"
                 "        print(exc)\n"
                 "print(GraspTask().object_size)\n")
    assert out.splitlines() == ["GraspTask.object_size: expected a number >= 0, got -0.001"] * 3 \
        + ["0.04"]


def test_threads_making_the_first_instances_at_once_all_get_the_one_line_error():
    # planning threads make a class's first instance at once: pydantic's build changes the
    # class in steps, and a thread that met its __init__ midway raised pydantic's error
    out = _fresh("import threading\n"
                 "from concurrent.futures import ThreadPoolExecutor\n"
                 "from minvar.errors import ParameterError\n"
                 "from minvar.grasp_task import GraspTask\n"
                 "from minvar.kinematics import TwoLinkChain\n"
                 "from minvar.plant import PointMassPlant\n"
                 "start = threading.Barrier(16)\n"
                 "def make(_):\n"
                 "    start.wait()\n"
                 "    said = []\n"
                 "    for cls, bad in ((GraspTask, {'object_size': -1.0}),\n"
                 "                     (TwoLinkChain, {'l1': 0.0}),\n"
                 "                     (PointMassPlant, {'mass': 0.0})):\n"
                 "        cls()\n"
                 "        try:\n"
                 "            cls(**bad)\n"
                 "        except ParameterError:\n"
                 "            said.append('one line')\n"
                 "        except Exception as exc:\n"
                 "            said.append(type(exc).__name__)\n"
                 "    return said\n"
                 "with ThreadPoolExecutor(16) as pool:\n"
                 "    said = {s for one in pool.map(make, range(16)) for s in one}\n"
                 "print(*sorted(said))\n")
    assert out.split() == ["one", "line"]


def test_a_deferred_class_keeps_its_signature_and_its_errors_in_process():
    import inspect

    from minvar.kinematics import TwoLinkChain
    from perception.recognition.models import SceneSpec

    assert list(inspect.signature(TwoLinkChain).parameters) == ["args", "l1", "l2", "base"]
    with pytest.raises(ParameterError, match=r"TwoLinkChain\.l1: expected a number > 0"):
        TwoLinkChain(l1=0.0)
    with pytest.raises(PlanningError, match=r"SceneSpec\.distance: expected a number > 0"):
        SceneSpec(distance=-1.0)
    assert SceneSpec(distance=0.3).distance == 0.3


def _dlc_frame(individuals: int, coords=("x", "y", "likelihood")) -> pd.DataFrame:
    rng = np.random.default_rng(4)
    parts = ["thumb", "finger", "wrist", "object"]
    names = ([f"mouse{i}" for i in range(individuals)] if individuals else [None])
    tuples = [(("DLC_x", n, b, c) if n else ("DLC_x", b, c))
              for n in names for b in parts for c in coords]
    levels = (["scorer", "individuals", "bodyparts", "coords"] if individuals
              else ["scorer", "bodyparts", "coords"])
    return pd.DataFrame(rng.uniform(0, 1, (9, len(tuples))),
                        columns=pd.MultiIndex.from_tuples(tuples, names=levels))


@pytest.mark.parametrize("individuals, coords, fps", [
    (0, ("x", "y", "likelihood"), 30.0), (0, ("x", "y", "likelihood"), None),
    (2, ("x", "y", "likelihood"), 25.0), (0, ("x", "y", "z"), 30.0),
    (0, ("x", "y", "likelihood"), -1.0)])
def test_a_dlc_table_gives_the_dataset_movement_gives(individuals, coords, fps):
    from perception.io.movement_import import dlc_inputs, movement_loaders

    _, load_poses = movement_loaders()
    df = _dlc_frame(individuals, coords)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # movement's note on a bad rate, both ways
        ours = dlc_inputs(df, fps).to_dataset()
        theirs = load_poses.from_dlc_style_df(df, fps=fps, source_software="DeepLabCut")
    assert ours.identical(theirs)


def test_a_dlc_table_refused_as_movement_refuses_it():
    from perception.io.movement_import import dlc_inputs, movement_loaders

    _, load_poses = movement_loaders()
    df = _dlc_frame(0).iloc[:, :-1]  # a column short: the values do not fill the frames
    with pytest.raises(ValueError) as theirs:
        load_poses.from_dlc_style_df(df, fps=30.0)
    with pytest.raises(ValueError) as ours:
        dlc_inputs(df, 30.0)
    assert str(ours.value) == str(theirs.value)


def _read_both_ways(monkeypatch, path, options):
    """read_pose's tracks (or error) from the table's arrays (read without pandas where the
    table is plain: perception.io.plain_tables), and from movement's dataset of pandas'
    reading (the way before: ``ValidPosesInputs.to_dataset()``)."""
    import perception.io.pose as pose

    def read():
        try:
            return pose.read_pose(path, options)
        except InputError as exc:
            return str(exc)

    class AsDataset:  # what the table was read as before: movement's dataset
        def __new__(cls, valid):
            return valid.to_dataset()

    ours = read()
    with monkeypatch.context() as m:
        m.setattr(pose, "PoseTable", AsDataset)
        m.setattr(pose, "dlc_table", lambda text, levels: None)  # through pandas and movement
        theirs = read()
    return ours, theirs


@pytest.mark.parametrize("individuals, coords, options", [
    (0, ("x", "y", "likelihood"), {"fps": 30.0, "object_diameter_px": 80.0}),
    (0, ("x", "y", "likelihood"), {"fps": 30.0, "pcutoff": 0.3, "cleaning": None}),
    (0, ("x", "y", "likelihood"), {}),  # no rate, no video beside it
    (2, ("x", "y", "likelihood"), {"fps": 25.0, "individual": "mouse1"}),
    (2, ("x", "y", "likelihood"), {"fps": 25.0}),  # which individual?
    (2, ("x", "y", "likelihood"), {"fps": 25.0, "individual": "cat"}),
    (0, ("x", "y", "z"), {"fps": 30.0}),
    (0, ("x", "y", "likelihood"), {"fps": 30.0, "keypoints": {"thumb": "nail"}}),
])
def test_a_dlc_table_reads_as_it_did_through_movement_s_dataset(tmp_path, monkeypatch,
                                                                individuals, coords, options):
    from perception.io.pose import PoseImport

    df = _dlc_frame(individuals, coords) * 600.0  # pixels; likelihoods in 0..1 below
    for i, column in enumerate(df.columns):
        if column[-1] == "likelihood":
            df.iloc[:, i] = np.linspace(0, 1, len(df))
    path = tmp_path / "grasp.csv"
    df.to_csv(path)
    ours, theirs = _read_both_ways(monkeypatch, path, PoseImport(**options))
    if isinstance(theirs, str):
        assert ours == theirs
        return
    assert not isinstance(ours, str), ours
    for name in ("frame", "time", "position", "likelihood", "status"):
        np.testing.assert_array_equal(getattr(ours, name), getattr(theirs, name), err_msg=name)
    assert ours.video == theirs.video and ours.tracker == theirs.tracker


def test_reading_a_dlc_csv_loads_no_movement_io(tmp_path):
    path, tracks = dlc_csv(tmp_path)
    out = _fresh("import sys\n"
                 "from perception.io.pose import PoseImport, read_pose\n"
                 f"t = read_pose({str(path)!r}, PoseImport(fps=30.0))\n"
                 "print(len(t.frame), t.tracker['method'])\n"
                 "print(*[m for m in ('movement.io', 'pynwb', 'sleap_io', 'dask', 'cv2')"
                 " if m in sys.modules] or ['none'])\n")
    assert out.split() == [str(len(tracks.frame)), "pose:DeepLabCut", "none"]


@pytest.mark.parametrize("kind", ["mocap", "pose"])
def test_recognize_of_a_mocap_or_dlc_file_loads_no_hdf5(tmp_path, kind):
    # h5py (~60 ms) is for tracks files, which these commands neither read nor write
    from pathlib import Path

    if kind == "mocap":
        args = [str(Path(__file__).parent / "data" / "mocap" / "qualisys-recording.tsv")]
    else:
        args = [str(dlc_csv(tmp_path)[0]), "--fps", "30", "--object-diameter-px", "80"]
    argv = ["recognize", *args, "-o", str(tmp_path / "out"), "--quiet", "--no-figures"]
    out = _fresh("import sys\n"
                 "from hammer_mv.cli import main\n"
                 f"main({argv!r})\n"
                 "print(*[m for m in ('h5py', 'movement.io', 'dask', 'cv2', 'matplotlib')"
                 " if m in sys.modules] or ['none'])\n")
    assert list((tmp_path / "out").glob("*.recognition.json")), out
    assert out.split()[-1:] == ["none"], out

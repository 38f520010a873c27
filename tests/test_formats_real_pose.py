"""Pose files in the layouts DeepLabCut and SLEAP write for multi-animal projects.

- DeepLabCut multi-animal tables (``analyze_videos`` of a project with
  ``uniquebodyparts``): the header rows scorer, individuals, bodyparts,
  coords, each animal's keypoints, then the unique body parts under the
  individual ``single`` (DeepLabCut's name for them; the object of a reach,
  often). Written here with pandas as DeepLabCut writes them (``to_hdf`` key
  ``df_with_missing``, ``to_csv``).
- SLEAP labels (``.slp``) whose project defines a track no instance is given
  (a track deleted from every frame stays in the file): written with
  sleap-io, the library SLEAP itself reads and writes ``.slp`` through.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from perception.errors import InputError
from perception.io.pose import PoseImport, read_pose

pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")

N = 40
SCORER = "DLC_resnet50_reachOct30shuffle1_200000"
PARTS = ("thumb", "index", "wrist")


def _animal(shift: float) -> dict[str, np.ndarray]:
    t = np.arange(N, dtype=float)
    return {"thumb": np.c_[100 + 3 * t + shift, 200 - t], "index": np.c_[100 + 3 * t + shift,
            220 + t], "wrist": np.c_[40 + 3 * t + shift, 210 + 0 * t]}


def _dlc_ma() -> pd.DataFrame:
    columns, data = [], []
    for who, shift in (("mouse1", 0.0), ("mouse2", 300.0)):
        for part, xy in _animal(shift).items():
            for k, coord in enumerate(("x", "y", "likelihood")):
                columns.append((SCORER, who, part, coord))
                data.append(xy[:, k] if k < 2 else np.full(N, 0.97))
    for k, coord in enumerate(("x", "y", "likelihood")):  # the unique body part: the cup
        columns.append((SCORER, "single", "cup", coord))
        data.append(np.full(N, (520.0, 215.0, 0.99)[k]))
    names = ["scorer", "individuals", "bodyparts", "coords"]
    return pd.DataFrame(np.array(data).T,
                        columns=pd.MultiIndex.from_tuples(columns, names=names))


@pytest.fixture(params=["h5", "csv"])
def dlc_ma(request, tmp_path):
    df = _dlc_ma()
    path = tmp_path / f"reach01DLC_resnet50_reachOct30shuffle1_200000_el.{request.param}"
    if request.param == "h5":
        pytest.importorskip("tables")
        df.to_hdf(path, key="df_with_missing", format="table", mode="w")
    else:
        df.to_csv(path)
    return path


def test_dlc_unique_bodyparts_are_read_with_each_animal(dlc_ma):
    with pytest.raises(InputError, match=r"2 individuals \(mouse1, mouse2\)"):
        read_pose(dlc_ma, PoseImport(fps=30))  # 'single' is no animal to choose
    for who, shift in (("mouse1", 0.0), ("mouse2", 300.0)):
        tracks = read_pose(dlc_ma, PoseImport(fps=30, individual=who, cleaning=None,
                                              keypoints={"object": "cup"}))
        assert tracks.n_frames == N  # not the table's values reshaped to other frames
        at = {m: tracks.markers.index(m) for m in ("thumb", "finger", "wrist", "object")}
        np.testing.assert_allclose(tracks.position[:, at["thumb"]], _animal(shift)["thumb"])
        np.testing.assert_allclose(tracks.position[:, at["finger"]], _animal(shift)["index"])
        np.testing.assert_allclose(tracks.position[:, at["object"]],
                                   np.tile([520.0, 215.0], (N, 1)))
        notes = tracks.tracker["reading_notes"]
        assert "keypoint 'cup' read from DeepLabCut's unique body parts" in notes


def test_sleap_track_without_instances_is_no_choice(tmp_path):
    sio = pytest.importorskip("sleap_io")
    skeleton = sio.Skeleton(["thumb", "index", "wrist", "ball"])
    video = sio.Video(filename="reach01.mp4", open_backend=False)
    used, unused = sio.Track("hand"), sio.Track("hand_old")
    frames = []
    for i in range(N):
        points = np.array([[100 + 3 * i, 200], [100 + 3 * i, 230], [40 + 3 * i, 215],
                           [400, 215]], dtype=float)
        frames.append(sio.LabeledFrame(video=video, frame_idx=i, instances=[
            sio.PredictedInstance.from_numpy(points, skeleton=skeleton, score=0.9,
                                             point_scores=np.full(4, 0.9), track=used)]))
    path = tmp_path / "reach01.slp"
    sio.save_slp(sio.Labels(labeled_frames=frames, videos=[video], skeletons=[skeleton],
                            tracks=[used, unused]), str(path))
    tracks = read_pose(path, PoseImport(fps=30, cleaning=None))
    np.testing.assert_allclose(tracks.position[:, tracks.markers.index("wrist"), 0],
                               40 + 3 * np.arange(N))
    assert "individual 'hand_old' never seen: 'hand' read" in tracks.tracker["reading_notes"]
    with pytest.raises(InputError, match="not in the file"):
        read_pose(path, PoseImport(fps=30, individual="other"))


def _collected(index) -> pd.DataFrame:
    """DeepLabCut's labelled frames as it writes them: x, y per keypoint (no likelihood),
    a row per labelled image (the layout of talmolab/sleap-io's
    tests/data/dlc/dlc_test_project/labeled-data/*/CollectedData_JohnDoe.csv)."""
    columns = [("JohnDoe", part, coord) for part in PARTS for coord in "xy"]
    values = np.random.default_rng(1).uniform(100, 900, (len(index), len(columns)))
    return pd.DataFrame(values, index=index, columns=pd.MultiIndex.from_tuples(
        columns, names=["scorer", "bodyparts", "coords"]))


@pytest.mark.parametrize("layout", ["three-column index", "path index", "h5"])
def test_dlc_labelled_frames_are_refused_saying_what_they_are(tmp_path, layout):
    images = [f"img{i:05d}.png" for i in (144, 838, 2172)]
    if layout == "three-column index":  # DeepLabCut 2.2 and later
        df = _collected(pd.MultiIndex.from_tuples([("labeled-data", "reach01", i)
                                                   for i in images]))
    else:  # DeepLabCut 2.1: one column of paths
        df = _collected([f"labeled-data/reach01/{i}" for i in images])
    path = tmp_path / f"CollectedData_JohnDoe.{'h5' if layout == 'h5' else 'csv'}"
    if layout == "h5":
        pytest.importorskip("tables")
        df.to_hdf(path, key="keypoints", mode="w")
    else:
        df.to_csv(path)
    with pytest.raises(InputError, match="DeepLabCut's labelled frames .* analyze_videos"):
        read_pose(path, PoseImport(fps=30))


def test_a_dlc_table_without_likelihoods_counts_its_points_as_seen(tmp_path):
    df = _collected(range(N))
    df[:] = np.tile(np.r_[_animal(0.0)["thumb"][0], _animal(0.0)["index"][0],
                          _animal(0.0)["wrist"][0]], (N, 1))
    df.iloc[5, 0:2] = np.nan  # the thumb lost in one frame
    path = tmp_path / "reach01.csv"
    df.to_csv(path)
    tracks = read_pose(path, PoseImport(fps=30, cleaning=None, object_diameter_px=80))
    thumb = tracks.markers.index("thumb")
    assert np.isfinite(tracks.position[:, thumb, 0]).sum() == N - 1
    assert tracks.likelihood[4, thumb] == 1.0 and tracks.likelihood[5, thumb] == 0.0


def _slp(path, instances_per_frame: int, tracks=None, user=False):
    """A SLEAP labels file of N frames, ``instances_per_frame`` predicted hands each (with
    ``tracks``, one track each), and with ``user`` a user's instance beside the first."""
    sio = pytest.importorskip("sleap_io")
    skeleton = sio.Skeleton(["thumb", "index", "wrist", "ball"])
    video = sio.Video(filename="reach01.mp4", open_backend=False)
    frames = []
    for i in range(N):
        made = []
        for k in range(instances_per_frame):
            points = np.array([[100 + 3 * i + 200 * k, 200], [100 + 3 * i + 200 * k, 230],
                               [40 + 3 * i + 200 * k, 215], [400, 215]], dtype=float)
            made.append(sio.PredictedInstance.from_numpy(
                points, skeleton=skeleton, score=0.9, point_scores=np.full(4, 0.9),
                track=None if tracks is None else tracks[k]))
        if user:
            made.append(sio.Instance.from_numpy(made[0].numpy(), skeleton=skeleton))
        frames.append(sio.LabeledFrame(video=video, frame_idx=i, instances=made))
    sio.save_slp(sio.Labels(labeled_frames=frames, videos=[video], skeletons=[skeleton],
                            tracks=list(tracks or [])), str(path))
    return path


def test_sleap_frames_of_several_untracked_instances_are_refused_not_mixed(tmp_path):
    """movement keeps one of a frame's instances when none has a track, silently: two hands
    would be read as one jumping between them. Refused, saying what to do; one untracked
    hand a frame (with a user's correction beside it) and tracked hands read as before."""
    sio = pytest.importorskip("sleap_io")
    with pytest.raises(InputError, match="up to 2 instances without a track.*`individual`"):
        read_pose(_slp(tmp_path / "two.slp", 2), PoseImport(fps=30, cleaning=None))
    one = read_pose(_slp(tmp_path / "one.slp", 1, user=True), PoseImport(fps=30, cleaning=None))
    np.testing.assert_allclose(one.position[:, one.markers.index("wrist"), 0],
                               40 + 3 * np.arange(N))
    hands = [sio.Track("left"), sio.Track("right")]
    right = read_pose(_slp(tmp_path / "tracked.slp", 2, hands),
                      PoseImport(fps=30, cleaning=None, individual="right"))
    np.testing.assert_allclose(right.position[:, right.markers.index("wrist"), 0],
                               240 + 3 * np.arange(N))


def test_sleaps_untracked_slots_are_named_as_such_when_a_choice_is_asked():
    """SLEAP's analysis export of untracked instances names their slots track_0, track_1:
    the refusal says a slot is then no one animal (a choice between them would mix hands)."""
    from perception.io.pose_arrays import pick_individual

    with pytest.raises(InputError, match=r"track_0, track_1\): choose one.*tracker did not run"):
        pick_individual(["track_0", "track_1"], None, "x.analysis.h5")
    with pytest.raises(InputError) as err:
        pick_individual(["left", "right"], None, "x.analysis.h5")
    assert "tracker" not in str(err.value)

"""Pose files in and out, checked by the tools that own the formats (movement, pandas, trackpy)."""

import numpy as np
import pandas as pd
import pytest

from perception.errors import InputError
from perception.io.exports import export_tracks
from perception.io.pose import DLC_KEY, PoseImport, is_pose_file, read_pose
from perception.io.tracks import Status
from perception.synthetic.demos import demo_tracks

movement = pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")
from movement.io import load_poses, save_poses  # noqa: E402


@pytest.fixture(scope="module")
def tracks():
    t, _ = demo_tracks("normal", 0, lost={"thumb": slice(30, 33)})
    return t


def _same(a, b):
    np.testing.assert_allclose(a, b, equal_nan=True, atol=1e-9)


@pytest.mark.parametrize("name", ["out.h5", "out.csv"])
def test_dlc_export_is_read_by_movement(tracks, tmp_path, name):
    path, _ = export_tracks(tracks, tmp_path / name, "dlc")
    ds = load_poses.from_dlc_file(path, fps=30)
    assert list(ds.keypoints.values) == list(tracks.markers)
    pos = ds.position.isel(individuals=0).transpose("time", "keypoints", "space").values
    _same(pos, tracks.position)
    conf = ds.confidence.isel(individuals=0).transpose("time", "keypoints").values
    _same(conf, tracks.likelihood)


def test_dlc_h5_is_a_pandas_hdf_table_in_dlcs_layout(tracks, tmp_path):
    path, _ = export_tracks(tracks, tmp_path / "out.h5", "dlc")
    df = pd.read_hdf(path, key=DLC_KEY)
    assert df.columns.names == ["scorer", "bodyparts", "coords"]
    assert set(df.columns.get_level_values("coords")) == {"x", "y", "likelihood"}


def test_movement_netcdf_round_trip(tracks, tmp_path):
    import xarray as xr

    (path,) = export_tracks(tracks, tmp_path / "out.nc", "movement")
    ds = xr.load_dataset(path)
    assert ds.attrs["ds_type"] == "poses" and ds.attrs["time_unit"] == "seconds"
    _same(ds.time.values, tracks.time)
    back = read_pose(path, PoseImport(object_diameter_px=80.0))
    _same(back.position, tracks.position)
    np.testing.assert_array_equal(back.status == Status.LOST, tracks.status == Status.LOST)


def test_a_dlc_file_written_by_movement_reads_back(tracks, tmp_path):
    pos = np.transpose(tracks.position, (0, 2, 1))[..., None]
    names = ["Thumb_tip", "Index_tip", "Wrist", "ball"]
    ds = load_poses.from_numpy(pos, tracks.likelihood[..., None].astype(float),
                               individual_names=["subject"], keypoint_names=names, fps=30)
    path = tmp_path / "dlc.h5"
    save_poses.to_dlc_file(ds, path, split_individuals=False)
    mapping = dict(thumb="Thumb_tip", finger="Index_tip", wrist="Wrist", object="ball")
    back = read_pose(path, PoseImport(keypoints=mapping, fps=30, object_diameter_px=80.0))
    assert back.markers == ("thumb", "finger", "wrist", "object")
    _same(back.position, tracks.position)
    _same(back.time, np.arange(tracks.n_frames) / 30)
    assert back.object_diameter_px() == 80.0
    assert back.tracker["method"] == "pose:DeepLabCut"


def test_low_likelihood_points_count_as_lost(tracks, tmp_path):
    low = tracks.likelihood.copy()
    low[10:15, 1] = 0.4  # below DeepLabCut's default cutoff
    t = tracks.replace(likelihood=low)
    path, _ = export_tracks(t, tmp_path / "low.csv", "dlc")
    back = read_pose(path, PoseImport(fps=30))
    assert np.isnan(back.position[10:15, 1]).all()
    assert (back.status[10:15, 1] == Status.LOST).all() and (back.likelihood[10:15, 1] == 0).all()
    kept = read_pose(path, PoseImport(fps=30, pcutoff=0.3))
    _same(kept.position[10:15, 1], tracks.position[10:15, 1])


def test_interpolated_points_stay_below_the_cutoff(tmp_path):
    t, _ = demo_tracks("normal", 0, lost={"finger": slice(20, 23)})
    filled = t.interpolate(5)
    path, status = export_tracks(filled, tmp_path / "f.csv", "dlc")
    back = read_pose(path, PoseImport(fps=30))
    assert np.isnan(back.position[20:23, 1]).all()  # a bridge is not a detection
    codes = pd.read_csv(status)
    assert (codes.finger[20:23] == Status.INTERPOLATED).all()


def test_trackpy_links_and_measures_our_export(tracks, tmp_path):
    trackpy = pytest.importorskip("trackpy")
    (path,) = export_tracks(tracks, tmp_path / "tp.csv", "trackpy")
    table = pd.read_csv(path)
    linked = trackpy.link(table[["frame", "x", "y"]], search_range=40, memory=5)
    assert linked["particle"].nunique() >= 4
    msd = trackpy.imsd(linked, mpp=1.0, fps=30.0)
    assert np.isfinite(msd.to_numpy()).any(axis=0).all()


@pytest.mark.parametrize("options, message", [
    (PoseImport(keypoints={"thumb": "nope"}, fps=30), "keypoint 'nope'"),
    (PoseImport(individual="ghost", fps=30), "`individual` 'ghost'"),
    (PoseImport(), "no frame rate"),
])
def test_bad_mappings_name_the_problem(tracks, tmp_path, options, message):
    path, _ = export_tracks(tracks, tmp_path / "x.csv", "dlc")
    with pytest.raises(InputError, match=message):
        read_pose(path, options)


def test_two_individuals_need_a_choice(tracks, tmp_path):
    pos = np.transpose(tracks.position, (0, 2, 1))[..., None]
    ds = load_poses.from_numpy(np.concatenate([pos, pos + 5], axis=-1),
                               np.ones((tracks.n_frames, 4, 2)),
                               individual_names=["left", "right"],
                               keypoint_names=list(tracks.markers), fps=30,
                               source_software="SLEAP")
    path = tmp_path / "two.nc"
    ds.to_netcdf(path)
    with pytest.raises(InputError, match="2 individuals"):
        read_pose(path)
    right = read_pose(path, PoseImport(individual="right"))
    _same(right.position, tracks.position + 5)


def test_files_that_are_not_pose_files(tmp_path):
    bad = tmp_path / "x.h5"
    bad.write_bytes(b"not hdf5")
    with pytest.raises(InputError, match="not an HDF5 file"):
        read_pose(bad)
    assert is_pose_file("a.csv") and is_pose_file("b.h5") and not is_pose_file("c.tracks.h5")
    with pytest.raises(InputError, match="PoseImport.keypoints: unknown marker 'elbow'"):
        PoseImport(keypoints={"elbow": "x"})
    with pytest.raises(InputError, match="PoseImport.pcutoff") as err:
        PoseImport(pcutoff=2.0)
    assert err.value.location == ("PoseImport", "pcutoff")  # the CLI names --pcutoff from it


@pytest.mark.slow
def test_recognize_a_dlc_file_like_its_tracks(tracks, tmp_path):
    """The CLI scores a DeepLabCut export as it scores the tracks it came from."""
    import json

    from hammer_mv.cli import main

    src = tracks.save(tmp_path / "clip.tracks.h5")
    pose, _ = export_tracks(tracks, tmp_path / "pose" / "clip.csv", "dlc")
    config = tmp_path / "pose.toml"
    config.write_text("fps = 30\n"
                      f"object_diameter_px = {tracks.object_diameter_px()}\n"
                      "[keypoints]\nthumb = \"thumb\"\n")
    assert main(["recognize", str(src), "-o", str(tmp_path / "a"), "--no-figures",
                 "--quiet"]) == 0
    assert main(["recognize", str(pose), "-o", str(tmp_path / "b"), "--no-figures",
                 "--quiet", "--pose-config", str(config)]) == 0
    a, b = (json.loads((tmp_path / d / "clip.recognition.json").read_text()) for d in "ab")
    assert a["winner"] == b["winner"]
    for ma, mb in zip(a["models"], b["models"]):
        assert mb["final_log_likelihood"] == pytest.approx(ma["final_log_likelihood"],
                                                           rel=1e-3, abs=0.5)


@pytest.mark.parametrize("text, message", [
    ("[keypoint]\nthumb = 'x'\n", "did you mean 'keypoints'"),
    ("[keypoints]\nthum = 'x'\n", "did you mean 'thumb'"),
    ("pcutoff = 'high'\n", "pcutoff"),
    ("keypoints = 3\n", "table"),
])
def test_a_pose_config_is_read_strictly(tmp_path, text, message):
    from perception.io.pose import load_pose_config

    path = tmp_path / "pose.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        load_pose_config(path)


def test_pose_options_override_the_config(tmp_path):
    from hammer_mv.cli import build_parser
    from hammer_mv.cli.options import pose_import

    path = tmp_path / "pose.toml"
    path.write_text("fps = 25\n[keypoints]\nthumb = 'T'\nwrist = 'W'\n")
    args = build_parser().parse_args(["recognize", "x.csv", "-o", "o", "--pose-config",
                                      str(path), "--fps", "30", "--keypoints", "wrist=Wr"])
    got = pose_import(args)
    assert got.fps == 30 and got.keypoints == {"thumb": "T", "wrist": "Wr"}


def test_landmarks_reads_a_pose_file_with_the_pose_options(tracks, tmp_path):
    """``hammer-mv landmarks`` takes recognize's pose options: a two-animal file whose
    keypoints have a lab's own names is measured for the animal and keypoints named, as the
    tracks it came from (without them it is refused, naming the choice to make)."""
    from hammer_mv.cli import main

    pos = np.transpose(tracks.position, (0, 2, 1))[..., None]
    ds = load_poses.from_numpy(np.concatenate([pos, pos + 5], axis=-1),
                               np.ones((tracks.n_frames, 4, 2)),
                               individual_names=["left", "right"],
                               keypoint_names=["T", "I", "W", "ball"], fps=30,
                               source_software="SLEAP")
    path = tmp_path / "two.nc"
    ds.to_netcdf(path)
    from perception.synthetic.demos import DEMO_CAMERA

    own = tracks.save(tmp_path / "clip.tracks.h5")
    scale = ["--px-per-m", str(DEMO_CAMERA.px_per_m)]
    assert main(["landmarks", str(own), "-o", str(tmp_path / "a.csv"), "--quiet", *scale]) == 0
    assert main(["landmarks", str(path), "-o", str(tmp_path / "no.csv"), "--quiet",
                 *scale]) == 2
    assert main(["landmarks", str(path), "-o", str(tmp_path / "b.csv"), "--quiet", *scale,
                 "--individual", "left", "--keypoints", "thumb=T", "finger=I", "wrist=W",
                 "object=ball"]) == 0
    a, b = (pd.read_csv(tmp_path / f"{x}.csv") for x in "ab")
    assert len(a) == len(b) and len(a) > 5
    np.testing.assert_allclose(b["value"], a["value"], rtol=1e-6, equal_nan=True)

import json

import h5py
import numpy as np
import pandas as pd
import pytest

from perception.errors import InputError
from perception.io.exports import export_tracks, status_path_for
from perception.io.tracks import (
    INTERPOLATED_LIKELIHOOD,
    SCHEMA,
    SCHEMA_VERSION,
    Status,
    Tracks,
    TracksWriter,
)

MARKERS = ("thumb", "finger", "wrist", "object")


def _tracks(t=50, fps=30.0, lost=()):
    """Known tracks: markers move right at 3 px/frame between frames 10 and 40."""
    time = np.arange(t) / fps
    x = np.clip(np.arange(t) - 10, 0, 30) * 3.0
    pos = np.zeros((t, 4, 2))
    for j in range(4):
        pos[:, j, 0] = 100 + 20 * j + (x if j < 3 else 0)
        pos[:, j, 1] = 50 + 10 * j
    lik = np.ones((t, 4), np.float32)
    status = np.zeros((t, 4), np.int8)
    for j, frames in lost:
        pos[frames, j] = np.nan
        lik[frames, j] = 0
        status[frames, j] = Status.LOST
    return Tracks(
        np.arange(t),
        time,
        MARKERS,
        pos,
        lik,
        status,
        video={
            "path": "clip.mp4",
            "fps_nominal": fps,
            "n_frames": t,
            "width": 640,
            "height": 480,
            "fourcc": "FMP4",
            "sha256": "ab" * 32,
        },
        tracker={"method": "test", "lost_ratio": 0.3},
    )


def test_schema_round_trip(tmp_path):
    tr = _tracks(lost=[(0, slice(5, 8))])
    path = tr.save(tmp_path / "c.tracks.h5")
    with h5py.File(path) as fh:
        assert fh.attrs["schema"] == SCHEMA
        assert fh.attrs["schema_version"] == SCHEMA_VERSION
        assert "software_version" in fh.attrs
        assert fh["tracks/position"].dtype == np.float64
        assert fh["tracks/likelihood"].dtype == np.float32
        assert fh["tracks/status"].dtype == np.int8
        assert fh["tracks/frame"].dtype == np.int64
        assert fh["tracks/position"].chunks is not None
        assert fh["tracks/position"].maxshape[0] is None
        assert [m.decode() for m in fh["tracks/markers"][()]] == list(MARKERS)
        for key in ("path", "sha256", "fps_nominal", "n_frames", "width", "height", "fourcc"):
            assert key in fh["video"].attrs
    back = Tracks.load(path)
    assert back.markers == MARKERS
    np.testing.assert_array_equal(back.position, tr.position)  # NaN in the same places
    np.testing.assert_array_equal(back.status, tr.status)
    np.testing.assert_array_equal(back.time, tr.time)
    assert back.video["fourcc"] == "FMP4" and back.tracker["lost_ratio"] == 0.3
    assert np.isnan(back.marker("thumb")[5:8]).all()
    assert not np.any(back.position == 0)


def test_streaming_writer_appends_in_chunks(tmp_path):
    path = tmp_path / "s.tracks.h5"
    with TracksWriter(path, ["a", "b"], chunk_frames=7) as w:
        for i in range(23):  # three full chunks and a partial one
            w.append(i, i / 25, [[i, -i], [np.nan, np.nan]], [1.0, 0.0], [0, 2])
        assert w.n_written == 21  # flushed chunk by chunk, not held to the end
        assert not path.exists()  # appears only when complete
        w.update(video={"n_frames": 23})
    tr = Tracks.load(path)
    assert tr.n_frames == 23 and tr.video["n_frames"] == 23
    np.testing.assert_array_equal(tr.position[:, 0, 0], np.arange(23))
    assert np.isnan(tr.marker("b")).all() and (tr.status[:, 1] == 2).all()


def test_writer_leaves_nothing_on_failure(tmp_path):
    path = tmp_path / "s.tracks.h5"
    with pytest.raises(RuntimeError), TracksWriter(path, ["a"]) as w:
        w.append(0, 0.0, [[1.0, 2.0]], [1.0], [0])
        raise RuntimeError("tracker crashed")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "schema, version, message",
    [
        ("other/format", SCHEMA_VERSION, "not a hammer-mv tracks file"),
        (SCHEMA, SCHEMA_VERSION + 1, "schema_version 2 is not supported"),
    ],
)
def test_wrong_schema_or_version_is_rejected_naming_the_file(tmp_path, schema, version, message):
    path = _tracks().save(tmp_path / "c.tracks.h5")
    with h5py.File(path, "a") as fh:
        fh.attrs["schema"] = schema
        fh.attrs["schema_version"] = version
    with pytest.raises(InputError, match=message) as err:
        Tracks.load(path)
    assert str(err.value).startswith(str(path))


def test_not_hdf5_and_missing_dataset(tmp_path):
    bad = tmp_path / "x.h5"
    bad.write_text("hello")
    with pytest.raises(InputError, match="not an HDF5 file"):
        Tracks.load(bad)
    path = _tracks().save(tmp_path / "c.tracks.h5")
    with h5py.File(path, "a") as fh:
        del fh["tracks/status"]
    with pytest.raises(InputError, match="/tracks/status: missing dataset"):
        Tracks.load(path)
    with pytest.raises(InputError, match="no such file"):
        Tracks.load(tmp_path / "none.h5")


def test_shapes_are_validated():
    tr = _tracks()
    with pytest.raises(ValueError, match="Tracks.position: expected shape"):
        tr.replace(position=tr.position[:, :2])
    with pytest.raises(ValueError, match="Tracks.markers: expected a sequence of marker names"):
        tr.replace(markers="thumb")  # was split into five markers, one per letter


def test_interpolation_fills_short_gaps_only():
    tr = _tracks(
        lost=[(0, slice(20, 23)), (1, slice(20, 30)), (2, slice(0, 3)), (2, slice(47, 50))]
    )
    filled = tr.interpolate(max_gap=5)
    truth = _tracks()
    # 3-frame gap in linear motion: filled exactly, status 3.
    np.testing.assert_allclose(filled.position[20:23, 0], truth.position[20:23, 0])
    assert (filled.status[20:23, 0] == Status.INTERPOLATED).all()
    # a bridge is less sure than its ends, and below DeepLabCut's 0.6 cutoff
    assert (filled.likelihood[20:23, 0] == INTERPOLATED_LIKELIHOOD).all()
    assert INTERPOLATED_LIKELIHOOD < 0.6
    # 10-frame gap: longer than max_gap, stays lost.
    assert np.isnan(filled.position[20:30, 1]).all()
    assert (filled.status[20:30, 1] == Status.LOST).all()
    # Leading and trailing gaps are not extrapolated.
    assert np.isnan(filled.position[:3, 2]).all() and np.isnan(filled.position[47:, 2]).all()
    # The original is untouched; max_gap=0 fills nothing.
    assert np.isnan(tr.position[20:23, 0]).all()
    assert np.isnan(tr.interpolate(0).position[20:23, 0]).all()
    with pytest.raises(ValueError, match="max_gap"):
        tr.interpolate(-1)


def test_units_are_pixels_unless_the_tracks_say_metres(tmp_path):
    """A reach's tracks in metres keep their units through a file, a pickle and a view."""
    import pickle

    tr = _tracks()
    assert tr.units == "px"
    metric = tr.replace(tracker={**tr.tracker, "units": "m"})
    back = Tracks.load(metric.save(tmp_path / "m.tracks.h5"))
    assert (back.units, pickle.loads(pickle.dumps(metric)).units, metric.rows(2, 9).units) == (
        "m", "m", "m")
    with pytest.raises(ValueError, match=r"units.*'px', 'm'|units.*px, m"):
        tr.replace(tracker={"units": "cm"})


def test_rows_are_a_view():
    tr = _tracks()
    part = tr.rows(10, 40)
    assert part.frame[0] == 10 and part.n_frames == 30
    assert np.shares_memory(part.position, tr.position)
    assert part.attrs["trimmed_rows"] == (10, 40)
    assert tr.n_frames == 50  # the full tracks are kept


def test_object_diameter_comes_from_what_the_tracker_recorded():
    tr = _tracks()
    names = tr.markers
    measured = [np.nan if m != "object" else 81.5 for m in names]
    assert tr.replace(tracker={"diameter_px": measured}).object_diameter_px() == 81.5
    # files written before diameter_px: a disc of the reference mass
    area = [np.nan if m != "object" else np.pi * 40.0**2 for m in names]
    assert tr.replace(tracker={"reference_mass_px": area}).object_diameter_px() == \
        pytest.approx(80.0)
    # a rendered clip's camera attributes are no shortcut: only the tracker's record counts
    camera = {"camera": json.dumps({"px_per_m": 800.0}), "object_diameter": 0.1}
    assert tr.replace(tracker={}, attrs=camera).object_diameter_px() is None


def test_dlc_export(tmp_path):
    tr = _tracks(lost=[(1, slice(3, 5))])
    df = tr.to_dlc()
    assert df.columns.names == ["scorer", "bodyparts", "coords"]
    assert list(df.columns.get_level_values("bodyparts").unique()) == list(MARKERS)
    assert list(df.columns.get_level_values("coords")[:3]) == ["x", "y", "likelihood"]
    assert np.isnan(df[("hammer-mv", "finger", "x")].iloc[3])
    assert df[("hammer-mv", "finger", "likelihood")].iloc[3] == 0
    assert df[("hammer-mv", "wrist", "x")].iloc[20] == pytest.approx(tr.position[20, 2, 0])
    path, status = export_tracks(tr, tmp_path / "c.csv", "dlc")
    back = pd.read_csv(path, header=[0, 1, 2], index_col=0)
    np.testing.assert_allclose(back.to_numpy(), df.to_numpy(), equal_nan=True)
    # the status codes DeepLabCut's table cannot hold, beside it
    assert status == status_path_for(path) == tmp_path / "c.status.csv"
    codes = pd.read_csv(status)
    assert list(codes.columns) == ["frame", *MARKERS]
    assert (codes.finger[3:5] == Status.LOST).all() and (codes.finger[5:] == 0).all()


def test_trackpy_and_plain_exports(tmp_path):
    tr = _tracks(lost=[(0, slice(3, 4))])
    long = tr.to_trackpy()
    assert len(long) == tr.n_frames * 4 - 1  # the lost point has no row
    assert {"frame", "time", "particle", "marker", "x", "y", "likelihood", "status"} <= set(long)
    assert long[(long.frame == 3) & (long.marker == "thumb")].empty
    assert np.isfinite(long[["x", "y"]].to_numpy()).all()
    row = long[(long.frame == 20) & (long.marker == "wrist")].iloc[0]
    assert (row.x, row.y) == pytest.approx(tuple(tr.position[20, 2]))
    (path,) = export_tracks(tr, tmp_path / "t.csv", "trackpy")
    back = pd.read_csv(path)
    assert len(back) == len(long) and back.x.isna().sum() == 0
    plain = pd.read_csv(export_tracks(tr, tmp_path / "p.csv", "csv")[0])
    assert list(plain.columns[:6]) == [
        "frame",
        "time",
        "thumb_x",
        "thumb_y",
        "thumb_likelihood",
        "thumb_status",
    ]
    assert np.isnan(plain.thumb_x[3]) and plain.wrist_x[20] == pytest.approx(tr.position[20, 2, 0])
    with pytest.raises(ValueError, match="format"):
        export_tracks(tr, tmp_path / "x.csv", "excel")
    assert not (tmp_path / "x.csv").exists()


def test_repr_is_one_line():
    text = repr(_tracks())
    assert "\n" not in text and len(text) < 120 and "50 frames" in text


def test_loaded_tracks_save_again(tmp_path):
    from _demos import demo_tracks

    from perception.io.tracks import Tracks

    t = demo_tracks("normal", 0)[0].replace(tracker={"reference_mass_px": [10.0, 12.0, 80.0, 5e3],
                                                     "method": "camshift"})
    t.save(tmp_path / "a.tracks.h5")
    back = Tracks.load(tmp_path / "a.tracks.h5")
    back.interpolate(3).save(tmp_path / "b.tracks.h5")  # load -> process -> save
    again = Tracks.load(tmp_path / "b.tracks.h5")
    assert np.array_equal(np.asarray(again.tracker["reference_mass_px"]),
                          np.asarray(t.tracker["reference_mass_px"]))
    assert np.array_equal(again.position, back.interpolate(3).position, equal_nan=True)

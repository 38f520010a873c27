"""One movement record in metres from every source (issue 42 item 1).

Known answers: tracks rendered from world paths through a turned camera give back
the world's distances and apertures in metres; the record the Python API loads is
the one recognition observed, bit for bit; a motion-capture recording's reaches and
unscored trials are counted against its trials.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from _demos import dlc_csv

from perception.errors import InputError
from perception.io.pose import PoseImport
from perception.loading import load_movements
from perception.observation import ObserveParams, movement_record, observe
from perception.pipeline import RecognitionSettings
from perception.recordings import MocapImport, read_recording
from perception.records import MARKERS, MovementRecord
from perception.synthetic.independent import draw_independent, independent_paths, tracked_paths
from perception.synthetic.scene import Camera

DATA = Path(__file__).parent / "data" / "mocap"
#: The Optotrak table's sampling rate: it has no time column.
OPTOTRAK = MocapImport(rate=1 / 0.01176471)


def _rendered(angle_deg: float = 25.0, px_per_m: float = 700.0, seed: int = 3):
    """Noise-free tracks of a grasp filmed by a turned camera, and its world paths (m)."""
    params = draw_independent("normal", np.random.default_rng(seed))
    t, paths = independent_paths(params, 30.0, seed=seed)
    world = {m: paths[m] for m in ("wrist", "finger", "thumb")}
    world["object"] = np.zeros_like(paths["wrist"])
    camera = Camera(px_per_m=px_per_m, origin_px=(320.0, 144.0), angle_deg=angle_deg)
    tracks = tracked_paths(t, world, camera, params.object_size, "independent", seed=seed,
                           noise_px=0.0)
    return tracks, world, params


@pytest.mark.parametrize("angle", [0.0, 25.0, -40.0])
def test_pixels_become_the_worlds_metres(angle):
    tracks, world, params = _rendered(angle)
    rec = movement_record(tracks, ObserveParams(object_diameter=params.object_size))
    assert rec.scale_from == "object" and rec.px_per_m == pytest.approx(700.0, rel=1e-9)
    # a turn of the camera turns the record, not its lengths: every marker's distance
    # from the object, and the aperture, are the world's
    for m in ("wrist", "finger", "thumb"):
        np.testing.assert_allclose(np.linalg.norm(getattr(rec, m), axis=1),
                                   np.linalg.norm(world[m], axis=1), atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(rec.finger - rec.thumb, axis=1),
                               np.linalg.norm(world["finger"] - world["thumb"], axis=1),
                               atol=1e-9)
    np.testing.assert_allclose(rec.object, 0.0, atol=1e-9)
    # x right, y up: the camera turns the world's axes by its angle; turned back, they are
    # the world's
    a = np.radians(angle)
    turned = rec.wrist @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]]).T
    np.testing.assert_allclose(turned, world["wrist"], atol=1e-9)


def test_a_given_scale_wins_and_the_plane_maps_back_to_pixels():
    tracks, _, params = _rendered()
    rec = movement_record(tracks, ObserveParams(px_per_m=350.0))
    assert rec.scale_from == "px_per_m" and rec.px_per_m == 350.0
    back = rec.input_transform.origin_px + rec.wrist * [350.0, -350.0]
    np.testing.assert_allclose(back, tracks.marker("wrist"), atol=1e-9)


def test_the_observation_is_the_record_turned():
    """Recognition observes the record: its raw model-frame markers are the record
    rotated, bit for bit, and the scene's origin and scale are the record's."""
    tracks, _, params = _rendered(angle_deg=10.0, seed=5)
    p = ObserveParams(object_diameter=params.object_size)
    rec = movement_record(tracks, p)
    obs = observe(tracks, p)
    assert np.array_equal(obs.scene.origin_px, rec.input_transform.origin_px)
    assert obs.scene.px_per_m == rec.input_transform.px_per_m
    raw = np.stack([obs.scene.rotated(getattr(rec, m)) for m in ("wrist", "finger", "thumb")],
                   axis=1)
    assert np.array_equal(raw, obs.clip_raw, equal_nan=True)
    # and the transform the observation keeps is the record's plane, turned
    assert np.array_equal(obs.scene.to_model(tracks.marker("thumb")), raw[:, 2], equal_nan=True)


def test_a_record_says_where_each_marker_was_seen_and_reads_as_a_table():
    tracks, _, params = _rendered()
    pos = tracks.position.copy()
    pos[40:45, tracks.markers.index("finger")] = np.nan
    rec = movement_record(tracks.replace(position=pos),
                          ObserveParams(object_diameter=params.object_size))
    assert not rec.seen["finger"][40:45].any() and rec.seen["finger"][:40].all()
    assert rec.seen["wrist"].all()
    table = rec.to_pandas()
    assert list(table.columns[:2]) == ["time", "frame"]
    assert [c for c in table.columns if c.endswith("_seen")] == [f"{m}_seen" for m in MARKERS]
    np.testing.assert_array_equal(table["wrist_x"], rec.wrist[:, 0])
    assert len(table) == tracks.n_frames


def test_the_scale_unknown_is_refused_naming_the_setting():
    tracks, _, _ = _rendered()
    bare = tracks.replace(tracker={})
    with pytest.raises(InputError, match="image scale unknown.*`px_per_m`"):
        movement_record(bare)


def test_a_start_not_at_rest_is_settled_as_recognition_settles_it(tmp_path):
    """The record load_movements gives is the one recognition observed, where the start
    had to be settled: rotated, it is the observation's raw markers, bit for bit."""
    from _demos import default_repertoire

    from perception.pipeline import recognize_tracks

    tracks, _, params = _rendered(seed=8)
    pos = tracks.position.copy()
    pos[0, tracks.markers.index("wrist")] += 40.0  # a one-frame spike at the start
    spiky = tracks.replace(position=pos)
    path = spiky.save(tmp_path / "spike.tracks.h5")
    settings = RecognitionSettings(observe=ObserveParams(object_diameter=params.object_size))
    rec = load_movements(path, settings).records[0]
    assert any("left out" in n for n in rec.notes) and len(rec.time) < spiky.n_frames
    obs = recognize_tracks(spiky, default_repertoire(), settings).observation
    raw = np.stack([obs.scene.rotated(getattr(rec, m)) for m in ("wrist", "finger", "thumb")],
                   axis=1)
    assert np.array_equal(raw, obs.clip_raw, equal_nan=True)


def test_a_tracks_file_loads_as_recognition_observes_it(tmp_path):
    tracks, _, params = _rendered(seed=7)
    path = tracks.save(tmp_path / "grasp.tracks.h5")
    settings = RecognitionSettings(observe=ObserveParams(object_diameter=params.object_size))
    loaded = load_movements(path, settings)
    assert loaded.no_reach == [] and len(loaded.records) == 1
    rec = loaded.records[0]
    assert isinstance(rec, MovementRecord) and rec.clip == "grasp" and rec.source == str(path)
    same = movement_record(tracks, settings.observe)
    for m in MARKERS:
        assert np.array_equal(getattr(rec, m), getattr(same, m), equal_nan=True)


def test_a_pose_file_loads_in_metres(tmp_path):
    path, tracks = dlc_csv(tmp_path)
    settings = RecognitionSettings(pose=PoseImport(fps=30.0, object_diameter_px=80.0))
    rec = load_movements(path, settings).records[0]
    assert rec.scale_from == "object" and rec.px_per_m == pytest.approx(80.0 / 0.10)
    rel = tracks.marker("wrist") - rec.input_transform.origin_px
    np.testing.assert_allclose(rec.wrist[:, 0], rel[:, 0] / rec.px_per_m, atol=1e-9)
    np.testing.assert_allclose(rec.wrist[:, 1], -rel[:, 1] / rec.px_per_m, atol=1e-9)


def test_a_recording_gives_one_record_per_reach_and_says_what_gave_none():
    path = DATA / "optotrak-trials.tsv"
    recording = read_recording(path, OPTOTRAK)
    loaded = load_movements(path, RecognitionSettings(mocap=OPTOTRAK))
    # nothing lost: every reach a record, every other entry a line saying why
    assert len(loaded.records) == len(recording.reaches) > 0
    assert len(loaded.no_reach) == len(recording.unscored)
    assert {r.clip for r in loaded.records} == {r.name for r in recording.reaches}
    for rec, reach in zip(loaded.records, recording.reaches):
        assert rec.scale_from == "metres" and rec.px_per_m == 1.0
        assert rec.source == str(path)
        assert any(n.startswith("wrist: the models' own") for n in rec.notes)
        # the recording's clock: the reach's onset is where the file has it
        onset = reach.time[reach.onset]
        assert np.min(np.abs(rec.time + rec.clock_offset - onset)) < 1e-9
        assert not rec.input_transform.y_down
        # a hand-span apart at rest, at most: metres, not millimetres
        assert np.linalg.norm(rec.wrist[0]) < 1.0


@pytest.mark.parametrize("name", ["vicon-nexus-trajectories.csv", "motive-export.csv"])
def test_a_recording_without_reaches_says_why_for_every_trial(name):
    """Nothing lost: a recording none of whose trials holds a reach gives no record and a
    line per trial saying why."""
    recording = read_recording(DATA / name)
    loaded = load_movements(DATA / name)
    assert loaded.records == [] and len(recording.unscored) >= 1
    assert [n for n, _ in loaded.no_reach] == [u.name for u in recording.unscored]
    assert all(why for _, why in loaded.no_reach)


def test_a_recordings_object_size_reaches_its_records():
    path = DATA / "optotrak-trials.tsv"
    small = dataclasses.replace(OPTOTRAK, reaches=dataclasses.replace(OPTOTRAK.reaches,
                                                                      object_size=0.03))
    rec = load_movements(path, RecognitionSettings(mocap=small)).records[0]
    assert rec.object_diameter == pytest.approx(0.03)


@pytest.mark.parametrize("spec, match", [("0", "a camera"), ("notes.txt", "not a video")])
def test_what_gives_no_movement_is_refused_in_one_line(tmp_path, spec, match):
    if spec.endswith(".txt"):
        spec = tmp_path / spec
        spec.write_text("hello\n")
    with pytest.raises(InputError, match=match):
        load_movements(spec)


def test_a_video_is_tracked_to_the_metres_of_its_ground_truth(tmp_path):
    """A rendered clip, tracked: its record is within tracking error of the record of its
    ground truth, and its tracks file is written where recognize writes it."""
    from _clips import render

    from perception.io.tracks import Tracks

    clip, camera = render(tmp_path, "grasp.mp4", n=45)
    rec = load_movements(clip.video).records[0]
    truth = movement_record(Tracks.load(clip.truth), ObserveParams(px_per_m=camera.px_per_m))
    assert rec.clip == "grasp" and (tmp_path / "grasp.tracks.h5").is_file()
    assert rec.scale_from == "object"
    assert rec.px_per_m == pytest.approx(camera.px_per_m, rel=0.01)
    seen = rec.seen["wrist"] & rec.seen["finger"] & rec.seen["thumb"]
    assert seen.mean() > 0.9
    for m in ("wrist", "finger", "thumb"):
        err = np.linalg.norm(getattr(rec, m)[seen] - getattr(truth, m)[seen], axis=1)
        # about a third of a pixel at 800 px/m (measured 0.4-0.5 mm, at most 1 mm)
        assert np.median(err) < 0.0015 and err.max() < 0.003, m
    # a refusal names the video the user gave, not the tracks file made from it
    with pytest.raises(InputError, match=r"grasp\.mp4: clip too short"):
        load_movements(clip.video, RecognitionSettings(observe=ObserveParams(min_frames=500)))


def test_load_movements_checks_its_settings():
    with pytest.raises(TypeError, match="load_movements"):
        load_movements(DATA / "optotrak-trials.tsv", "fast")


def test_an_error_said_of_the_users_file_keeps_its_kind_field_and_location():
    """LocatedError.at: the one way a refusal found in a file made from the user's (a
    video's tracks, a recording's reach) is said of the user's file."""
    import pickle

    from perception.errors import TrackingError

    exc = TrackingError("marker lost", "clip.tracks.h5", field="thumb", location=("a", "b"))
    moved = exc.at("clip.mp4")
    assert type(moved) is TrackingError and str(moved) == "clip.mp4: thumb: marker lost"
    assert (moved.problem, moved.field, moved.location) == ("marker lost", "thumb", ("a", "b"))
    assert str(pickle.loads(pickle.dumps(moved))) == str(moved)
    assert str(exc) == "clip.tracks.h5: thumb: marker lost"  # the original is left as it was

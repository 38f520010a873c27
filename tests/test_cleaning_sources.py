"""One cleaning for every source (issue 41, items 4 and 5).

* a pose file's single-frame jumps (DeepLabCut's spikes) are found and
  bridged by the motion-capture rules, so the file gives the landmarks of
  the same file without them; the repairs are said in the observation's notes;
* the held-sample rule spares a rounded but live marker (a 1 mm export at
  rest repeats exactly) and still finds a marker frozen while lost;
* the real Optotrak trials written as DeepLabCut files (with the
  recording's own spikes, held samples and gaps) score as the same file
  made from the cleaned recording (slow: ``tools/evaluate_real_pose.py``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from _demos import demo_tracks

from perception.cleaning import CleaningParams, clean_path, held, quantum
from perception.io.exports import write_dlc
from perception.io.pose import PoseImport, read_pose
from perception.io.tracks import Status
from perception.landmarks import LandmarkParams, observed_landmarks
from perception.observation import ObserveParams, observe
from perception.track_cleaning import TrackCleaning, clean_tracks, cleaning_notes

pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")

ROOT = Path(__file__).resolve().parents[1]
OPTOTRAK = Path("/work/shared/realdata/optotrak-grasps/trials.tsv")


# -- pose files: DeepLabCut jumps are spikes ------------------------------------------------
def _jumped(tracks, px=120.0, hold=4):
    """The tracks with single-frame jumps of ``px`` pixels in three keypoints through the
    movement, and the wrist frozen for ``hold`` frames mid-movement (as a tracker that
    keeps a lost keypoint where it was)."""
    pos = tracks.position.copy()
    n = tracks.n_frames
    for r, m, d in ((n // 3, "wrist", (1, -1)), (n // 2 + 6, "finger", (1, 0)),
                    (n // 2 + 9, "thumb", (-1, 0)), (2 * n // 3, "wrist", (0, 1))):
        pos[r, tracks.markers.index(m)] += px * np.asarray(d, dtype=float)
    w, k = tracks.markers.index("wrist"), n // 2 - 2
    pos[k:k + hold, w] = pos[k, w]
    return tracks.replace(position=pos)


@pytest.fixture(scope="module")
def demo():
    tracks = demo_tracks("normal", 1)[0]
    return tracks, tracks.object_diameter_px()


def _observed(path, diameter, clean=True):
    cleaning = TrackCleaning() if clean else None
    obs = observe(read_pose(path, PoseImport(fps=30, object_diameter_px=diameter,
                                             cleaning=cleaning)), ObserveParams())
    return obs, observed_landmarks(obs, LandmarkParams())


def _filtered_gap(a, b) -> float:
    """Largest distance between two observations' filtered digits over their common frames, m."""
    common, ia, ib = np.intersect1d(a.frame, b.frame, return_indices=True)
    return float(max(np.nanmax(np.linalg.norm(getattr(a, m)[ia] - getattr(b, m)[ib], axis=1))
                     for m in ("wrist", "finger", "thumb")))


def test_a_pose_file_with_jumps_and_a_frozen_keypoint_gives_the_clean_files_landmarks(
        demo, tmp_path):
    tracks, diameter = demo
    clean = write_dlc(tracks, tmp_path / "clean.csv")
    jumpy = write_dlc(_jumped(tracks), tmp_path / "jumpy.csv")
    a_obs, a = _observed(clean, diameter)
    b_obs, b = _observed(jumpy, diameter)
    raw_obs, raw = _observed(jumpy, diameter, clean=False)
    # uncleaned, the frozen wrist's release is the movement's peak speed (what failed) ...
    assert raw.peak_speed > 1.5 * a.peak_speed and abs(raw.movement_time - a.movement_time) > 0.05
    assert _filtered_gap(raw_obs, a_obs) > 0.02  # the jumps drag the positions scored
    # ... cleaned, the landmarks are the clean file's (within a frame where a jump hid
    # the frame they fall on)
    frame = 1 / 30
    assert b.movement_time == pytest.approx(a.movement_time, abs=frame)
    assert b.peak_speed == pytest.approx(a.peak_speed, rel=0.05)
    assert b.mga == pytest.approx(a.mga, abs=0.003)
    assert b.mga_time == pytest.approx(a.mga_time, abs=frame / a.movement_time + 1e-9)
    assert (b.aperture_peaks, b.movements) == (a.aperture_peaks, a.movements)
    assert b_obs.onset_frame == a_obs.onset_frame
    assert _filtered_gap(b_obs, a_obs) < 0.01
    # and the observation says what was repaired, marker by marker
    assert not a_obs.notes
    said = " ".join(b_obs.notes)
    assert "wrist: 2 spike(s), 3 held sample(s)" in said, b_obs.notes
    assert "finger: 1 spike(s)" in said and "thumb: 1 spike(s)" in said, b_obs.notes


def test_the_repairs_are_recorded_and_the_lost_samples_marked(demo, tmp_path):
    tracks, diameter = demo
    n = tracks.n_frames
    pos = tracks.position.copy()
    pos[n // 2, tracks.markers.index("thumb")] += 120.0
    pos[n // 3: n // 3 + 10, tracks.markers.index("wrist")] = np.nan  # a long gap stays lost
    out = clean_tracks(tracks.replace(position=pos), TrackCleaning(px_per_m=diameter / 0.1))
    record = json.loads(out.tracker["cleaning"])
    assert record["repairs"]["thumb"]["spikes"] == 1
    assert record["repairs"]["wrist"]["missing"] == 10 and record["scale"] == "given"
    j = out.markers.index("thumb")
    assert out.status[n // 2, j] in (Status.INTERPOLATED, Status.LOST)
    w = out.markers.index("wrist")
    assert (out.status[n // 3: n // 3 + 10, w] == Status.LOST).all()
    assert (out.likelihood[n // 3: n // 3 + 10, w] == 0).all()
    # untouched samples keep their pixels exactly; cleaning twice changes nothing
    keep = np.isfinite(pos).all(axis=-1) & (out.status == tracks.status)
    assert np.array_equal(out.position[keep], pos[keep])
    assert clean_tracks(out) is out
    assert cleaning_notes(out) and all("px/m" in line for line in cleaning_notes(out))


def test_the_scale_converts_the_rules_distances(demo):
    tracks, diameter = demo
    given = TrackCleaning(px_per_m=800.0).scale(tracks)
    assert given == (800.0, "given")
    assert TrackCleaning().scale(tracks) == (pytest.approx(diameter / 0.1), "the object's size")
    bare = tracks.replace(tracker={})
    assert TrackCleaning().scale(bare)[0] == TrackCleaning().default_px_per_m
    # a 15 px jump: 7.5 mm at 2000 px/m, under the 10 mm rule (kept); 30 mm at 500 px/m
    pos = tracks.position.copy()
    pos[tracks.n_frames // 2, 0] += 15.0
    jumpy = tracks.replace(position=pos)
    kept = json.loads(clean_tracks(jumpy, TrackCleaning(px_per_m=2000.0)).tracker["cleaning"])
    found = json.loads(clean_tracks(jumpy, TrackCleaning(px_per_m=500.0)).tracker["cleaning"])
    assert kept["repairs"]["thumb"]["spikes"] == 0
    assert found["repairs"]["thumb"]["spikes"] == 1


def test_a_still_scene_is_not_held(demo):
    """Rendered or rounded tracks repeat exactly wherever the whole hand is still."""
    tracks, _ = demo
    pos = tracks.position.copy()
    pos[:8] = pos[0]  # every marker exactly still over the rest
    out = clean_tracks(tracks.replace(position=pos))
    record = json.loads(out.tracker["cleaning"])
    assert all(r["held"] == 0 for r in record["repairs"].values()), record
    # one marker frozen while the others move is held
    pos = tracks.position.copy()
    j = tracks.markers.index("finger")
    n = tracks.n_frames
    pos[n // 2: n // 2 + 6, j] = pos[n // 2, j]
    record = json.loads(clean_tracks(tracks.replace(position=pos)).tracker["cleaning"])
    assert record["repairs"]["finger"]["held"] == 5


# -- the held-sample rule on a quantised signal ----------------------------------------------
def _reach_path(rate=100.0, rest=1.0, move=1.0):
    """(time, path m) of a marker at rest, then a 0.3 m minimum-jerk reach, then at rest."""
    t = np.arange(0, rest + move + rest, 1 / rate)
    s = np.clip((t - rest) / move, 0, 1)
    x = 0.3 * (10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5)
    rng = np.random.default_rng(4)
    path = np.stack([x, 0.1 * x, np.full_like(x, 0.2)], axis=1)
    return t, path + rng.normal(0, 2e-5, path.shape)  # 20 um jitter, as a real marker's


def test_a_1mm_export_at_rest_is_not_held():
    t, path = _reach_path()
    rounded = np.round(path * 1000) / 1000  # written in whole millimetres
    assert quantum(rounded) == pytest.approx(0.001)
    assert quantum(path) is None
    out, rep = clean_path(t, rounded)
    assert rep.held == 0 and rep.spikes == 0, rep
    assert np.isfinite(out).all()
    # before: every repeat run of 3 was taken for an occlusion
    assert held(rounded, 3).sum() > len(t) // 2


def test_a_truly_held_marker_is_still_found_in_a_1mm_export():
    t, path = _reach_path()
    rounded = np.round(path * 1000) / 1000
    k = int(np.searchsorted(t, 1.4))  # mid-reach, fast
    rounded[k:k + 12] = rounded[k]  # the system holds the lost marker for 12 samples
    out, rep = clean_path(t, rounded)
    assert rep.held == 11
    assert np.isnan(out[k + 1:k + 12]).all()  # 120 ms: too long to bridge
    # held to the end of the recording, while moving: still held
    late = np.round(path * 1000) / 1000
    m = int(np.searchsorted(t, 1.5))
    late[m:] = late[m]
    assert clean_path(t, late)[1].held == len(t) - m - 1
    # an unrounded recording is judged as before: every exact repeat run is held
    raw = path.copy()
    raw[k:k + 12] = raw[k]
    assert clean_path(t, raw)[1].held == 11
    # the step can be given, and 0 turns the rounding's allowance off: the rests' repeats
    # are then spared only as a marker seen again where it was held (held_distance), and
    # held with both allowances off
    rests = np.round(path * 1000) / 1000
    assert clean_path(t, rests, CleaningParams(quantum=0.0))[1].held == 0
    assert clean_path(t, rests, CleaningParams(quantum=0.0, held_distance=0.0))[1].held > 0


def test_a_held_marker_with_samples_missing_among_its_repeats_is_still_held():
    # a system that holds a lost marker may leave some of its samples empty: a repeat of
    # the last sample seen across them is held too (before: a lone repeat between two
    # missing samples was kept, the frozen thumb's one sample made a second aperture peak
    # and a real healthy grasp `abnormal (re-opening)`)
    t, path = _reach_path()
    k = int(np.searchsorted(t, 1.4))  # mid-reach, fast
    frozen = path.copy()
    frozen[k:k + 12] = frozen[k]
    frozen[k + 5:k + 7] = np.nan  # two samples missing within the hold
    frozen[k + 8] = np.nan
    assert held(frozen, 3)[[k + 7, *range(k + 9, k + 12)]].all()
    out, rep = clean_path(t, frozen)
    assert rep.held == 11 - 3 and rep.missing == 3
    assert np.isnan(out[k + 1:k + 12]).all()
    # a repeat that does not reach the run's length across the gap is no hold
    short = path.copy()
    short[k + 1] = short[k]
    short[k + 2] = np.nan
    assert not held(short, 3).any()


def test_a_quantised_marker_held_at_rest_and_released_at_rest_is_not_lost():
    t, path = _reach_path()
    rounded = np.round(path * 1000) / 1000
    k = int(np.searchsorted(t, 0.9))
    out, rep = clean_path(t[:k], rounded[:k])  # rest only
    assert rep.held == 0 and np.isfinite(out).all()


def test_a_still_marker_a_tracker_repeats_exactly_is_not_held():
    """A tracker's own output repeats a still marker to the last digit (a rendered rest, a
    blob's centroid on half pixels) while another marker jitters: seen again where it was
    held, it did not move on, and its repeats were its true place."""
    t, path = _reach_path()
    still = path.copy()
    k = int(np.searchsorted(t, 0.5))
    still[k:k + 20] = still[k]  # 0.2 s of exact repeats at rest, released at rest
    m = int(np.searchsorted(t, 0.95))
    still[m:m + 8] = still[m]  # repeats that end as the reach starts (within 5 mm)
    out, rep = clean_path(t, still)
    assert rep.held == 0 and np.isfinite(out).all()
    # a marker frozen mid-reach is seen again far from where it was held: still lost
    frozen = path.copy()
    f = int(np.searchsorted(t, 1.4))
    frozen[f:f + 12] = frozen[f]
    assert clean_path(t, frozen)[1].held == 11
    # with no allowance, every run of exact repeats is held, as before
    assert clean_path(t, still, CleaningParams(held_distance=0.0))[1].held == 19 + 7


def test_our_own_tracks_exported_as_a_pose_file_keep_their_rest(demo, tmp_path):
    """hammer-mv's tracks written as a DeepLabCut file (``tracks export --format dlc``)
    and read back: a digit the tracker repeated exactly at rest, while the object's blob
    jittered, is not lost (it was: the README's quick start gave ``digits-unseen``)."""
    tracks, diameter = demo
    pos = tracks.position.copy()
    j, o = tracks.markers.index("finger"), tracks.markers.index("object")
    pos[:10, j] = pos[0, j]  # the finger's rest, repeated to the last digit
    pos[-8:, j] = pos[-8, j]  # and at the end
    pos[:, o] += np.random.default_rng(0).normal(0, 0.3, pos[:, o].shape)  # a jittering blob
    written = write_dlc(tracks.replace(position=pos), tmp_path / "own.csv")
    obs, _ = _observed(written, diameter)
    record = json.loads(read_pose(written, PoseImport(
        fps=30, object_diameter_px=diameter)).tracker["cleaning"])
    assert record["repairs"]["finger"]["held"] == 0, record
    assert not any("finger" in note for note in obs.notes), obs.notes


# -- the real trials as DeepLabCut files ---------------------------------------------------
@pytest.mark.slow
@pytest.mark.skipif(not OPTOTRAK.is_file(), reason="the shared Optotrak table is not here")
def test_the_optotrak_trials_as_deeplabcut_files_score_as_the_clean_files(tmp_path):
    sys.path.insert(0, str(ROOT / "tools"))
    import evaluate_real_pose as ev

    from perception.reaches import MarkerMap
    from perception.recordings import MocapImport

    opts = MocapImport(markers=MarkerMap("thumb", "index"), rate=85.0)
    res = ev.evaluate(OPTOTRAK, opts, "heldout", tmp_path, mocap=False, wrist="thumb")
    assert res["reaches"] == 30
    # the recording's spikes, held samples and gaps do not change the verdict or landmarks
    assert res["same_verdict_as_clean"] == res["reaches"], res["verdicts"]
    assert res["movement_time_median_abs_diff_clean_s"] < 0.02
    assert abs(res["peak_speed_mean_excess_over_clean"]) < 0.05
    assert res["normal"] >= 26
    assert res["movement_time_median_abs_error_s"] < 0.1


def test_the_cli_cleans_pose_files_at_the_scale_it_is_given():
    # --px-per-m and --object-diameter reach the cleaning (its thresholds are in metres):
    # before, a pose file was cleaned at the assumed 1000 px/m whatever the user said
    from hammer_mv.cli import build_parser
    from hammer_mv.cli.options import recognition_settings

    parser = build_parser()
    args = parser.parse_args(["recognize", "x.csv", "-o", "out", "--px-per-m", "500"])
    assert recognition_settings(args).pose.cleaning.px_per_m == 500.0
    args = parser.parse_args(["recognize", "x.csv", "-o", "out", "--object-diameter", "0.06"])
    assert recognition_settings(args).pose.cleaning.object_diameter == 0.06
    # the defaults ask for nothing: no pose settings recorded for a video's report
    args = parser.parse_args(["recognize", "x.mp4", "-o", "out"])
    assert recognition_settings(args).pose is None

"""Real motion-capture recordings: lost samples, reaches, the field's landmarks, the verdict.

The recordings are trimmed copies of real ones (tests/data/mocap/, licences
beside them): four Optotrak grasps of a healthy adult at 85 Hz, and a
Qualisys session of reaching to a cushion at 100 Hz.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _cli import hammer_here
from _demos import default_repertoire
from scipy.signal import butter, filtfilt

from perception.cleaning import CleaningParams, clean_path
from perception.io.mocap import read_mocap
from perception.landmarks import LandmarkParams, movement_landmarks
from perception.reaches import MarkerMap, fit_plane, reach_tracks, recording_reaches
from perception.recordings import MocapImport, read_reaches, recognize_reach
from perception.synthetic.variants import late_opening, reopening

DATA = Path(__file__).parent / "data" / "mocap"
OPTOTRAK = DATA / "optotrak-trials.tsv"
QUALISYS = DATA / "qualisys-recording.tsv"
RATE = 1 / 0.01176471


@pytest.fixture(scope="module")
def optotrak_reaches():
    return read_reaches(OPTOTRAK, MocapImport(rate=RATE))


def test_a_spike_and_a_held_marker_are_lost_a_short_gap_bridged():
    t = np.arange(200) / 100.0
    path = np.stack([0.3 * t, 0.1 * np.sin(t), np.zeros_like(t)], axis=1)
    path += 1e-5 * np.random.default_rng(0).standard_normal(path.shape)
    raw = path.copy()
    raw[0] += [0.05, 0, 0]                  # a glitched first sample, 50 mm off
    raw[100:112] = raw[99]                  # held for 12 samples while occluded
    raw[150:152] = np.nan                   # a two-sample dropout
    clean, rep = clean_path(t, raw, CleaningParams())
    assert rep.spikes == 1 and rep.held == 12 and rep.missing == 2
    assert np.isnan(clean[0]).all() and np.isnan(clean[100:112]).all()
    assert np.allclose(clean[150:152], path[150:152], atol=2e-4)   # bridged: 30 ms
    assert rep.longest_gap == pytest.approx(0.13, abs=1e-9)        # the held run stays lost
    assert "held" in rep.describe("thumb")


def _independent_landmarks(time, index, thumb):
    """The field's definitions written out plainly: 10 Hz Butterworth, 5 % of peak speed."""
    b, a = butter(2, 10 / (0.5 * RATE))
    mid = filtfilt(b, a, 0.5 * (index + thumb), axis=0)
    g = filtfilt(b, a, np.linalg.norm(index - thumb, axis=1))
    v = np.linalg.norm(np.gradient(mid, time, axis=0), axis=1)
    p = int(np.argmax(v))
    on = p - int(np.argmax(v[p::-1] < 0.05 * v[p])) + 1
    end = p + int(np.argmax(v[p:] < 0.05 * v[p])) - 1
    j = on + int(np.argmax(g[on:end + 1]))
    return time[end] - time[on], (time[j] - time[on]) / (time[end] - time[on]), g[j]


def _window(trial):
    """The samples from the first clean one to just before the return starts."""
    reach = recording_reaches(trial, MarkerMap("thumb", "index"))[0]
    rows = (trial.time > trial.time[0]) & (trial.time <= reach.time[-1])
    return trial.time[rows], trial.markers["index"][rows], trial.markers["thumb"][rows]


def test_landmarks_agree_with_the_fields_definitions_computed_by_hand():
    trials = read_mocap(OPTOTRAK, rate=RATE)
    assert len(trials) == 4
    for trial in trials:
        t, index, thumb = _window(trial)
        mt, mga_share, mga = _independent_landmarks(t, index, thumb)
        lm = movement_landmarks(t, 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1))
        # the crossings are interpolated between samples: within a sample of the hand's
        assert abs(lm.movement_time - mt) < 2 / RATE
        assert abs(lm.mga_time - mga_share) < 0.05
        assert lm.mga == pytest.approx(mga, abs=1e-4)
        assert 0 <= lm.peak_speed_time <= 1 and 0 <= lm.opening_time <= 1


def test_a_recording_that_starts_in_motion_gives_the_landmarks_it_can():
    t, index, thumb = _window(read_mocap(OPTOTRAK, rate=RATE)[0])
    mid, g = 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1)
    full = movement_landmarks(t, mid, g)
    k = int(np.searchsorted(t, full.onset_time + 0.3))
    cut = movement_landmarks(t[k:], mid[k:], g[k:])
    assert math.isnan(cut.onset_time) and math.isnan(cut.movement_time)
    assert cut.end_time == pytest.approx(full.end_time, abs=2 / RATE)
    assert cut.peak_speed > 0


def test_each_trial_holds_one_reach_not_its_return(optotrak_reaches):
    assert [r.name for r in optotrak_reaches] == [f"optotrak-trials-trial{k}" for k in range(4)]
    for r in optotrak_reaches:
        g = r.aperture
        assert np.nanmax(g[r.onset:r.end + 1]) - g[r.onset] > 0.05   # the grip opens
        plane = fit_plane(r, r.transport[r.end])
        assert plane.rms < 0.02                                    # a nearly planar reach


def test_a_long_session_is_split_into_its_reaches():
    trial = read_mocap(QUALISYS)[0]
    assert trial.rate == 100
    reaches = recording_reaches(trial)
    assert len(reaches) >= 1
    r = reaches[0]
    # the object's markers mark where the hand goes: it ends much nearer the cushion
    # (the hand's markers sit on its back, well short of the cushion's centre)
    d0 = np.linalg.norm(r.transport[r.onset] - r.object)
    d1 = np.linalg.norm(r.transport[r.end] - r.object)
    assert d0 > 0.3 and d1 < 0.6 * d0


def test_a_whole_hand_grasp_is_out_of_the_verdicts_depth_and_says_so():
    reach = read_reaches(QUALISYS)[0]
    rec, info = recognize_reach(reach, default_repertoire())
    assert (rec.verdict, rec.verdict_rule) == ("unfamiliar", "not-a-precision-grip")
    assert rec.verdict_reason.startswith("not a precision grip: the digits start")
    assert math.isfinite(rec.landmarks[0].movement_time)   # its landmarks are still measured


def test_tracks_of_a_reach_hold_its_3d_aperture(optotrak_reaches):
    r = optotrak_reaches[0]
    tracks, info, _, aperture = reach_tracks(r)
    finger, thumb = tracks.marker("finger"), tracks.marker("thumb")
    assert tracks.units == "m"  # metres in the plane, not pixels
    g2d = np.linalg.norm(finger - thumb, axis=1)
    # the 2D digits stand at the 3D distance, sample for sample (rest held at the start)
    g3d = r.aperture[np.isfinite(r.aperture)]
    assert np.nanmax(g2d) == pytest.approx(np.nanmax(g3d), abs=1e-9)
    assert info["plane"]["rms_out_of_plane"] < 0.02
    assert any("where the grip closes" in n for n in info["notes"])


@pytest.mark.slow
def test_real_grasps_are_normal_and_their_variants_abnormal(optotrak_reaches):
    rep = default_repertoire()
    for r in optotrak_reaches:
        rec, _ = recognize_reach(r, rep)
        assert rec.verdict == "normal", (r.name, rec.verdict, rec.verdict_reason)
        late, _ = recognize_reach(late_opening(r), rep)
        assert (late.verdict, late.verdict_detail) == ("abnormal", "delayed-opening"), r.name
        twice, _ = recognize_reach(reopening(r), rep)
        assert (twice.verdict, twice.verdict_detail) == ("abnormal", "re-opening"), r.name
        assert late.verdict_reason and twice.verdict_reason


def test_a_shallow_reopening_is_told_from_a_real_grip_s_wobble(optotrak_reaches):
    """The aperture's second peak counts from 15 % of the opening (``peak_prominence``):
    a real healthy grip's wobble stands at most 6 % (measured on the Optotrak dev trials;
    2 % on tracked video), a closing by 30 % of the grip's opening at 60 % of it 18 %."""
    rep = default_repertoire()
    for r in optotrak_reaches:
        real, _ = recognize_reach(r, rep)
        assert real.landmarks[0].aperture_peaks == 1, r.name
        dip, _ = recognize_reach(reopening(r, depth=0.3), rep)
        assert dip.landmarks[0].aperture_peaks == 2, r.name
        assert (dip.verdict, dip.verdict_detail) == ("abnormal", "re-opening"), r.name
        assert "2 aperture peaks" in dip.verdict_reason


def test_recognize_reads_a_lab_table_and_reports_every_trial(tmp_path, capsys):
    out = tmp_path / "out"
    status, _, err = hammer_here(capsys, "recognize", OPTOTRAK, "--rate", RATE, "-o", out,
                                 "--no-figures")
    assert status == 0, err
    reports = sorted(out.glob("*.recognition.json"))
    assert len(reports) == 4
    d = json.loads(reports[0].read_text())
    assert d["verdict"] in ("normal", "abnormal", "reach", "unfamiliar")
    assert "verdict_reason" in d and isinstance(d["warnings"], list)
    assert d["mocap"]["rate"] == pytest.approx(RATE, rel=1e-3)
    assert 1.0 < d["kinematics"]["observed"]["movement_time"] < 2.5


def test_a_table_without_its_rate_is_one_line_naming_the_flag(tmp_path):
    res = subprocess.run([sys.executable, "-m", "hammer_mv", "recognize", str(OPTOTRAK),
                          "-o", str(tmp_path / "out")], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 2
    assert "--rate" in res.stderr and "Traceback" not in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_a_wrong_marker_name_is_refused(tmp_path):
    res = subprocess.run([sys.executable, "-m", "hammer_mv", "recognize", str(OPTOTRAK),
                          "--rate", "85", "--markers", "thumb=thumb", "finger=pinky",
                          "-o", str(tmp_path / "out")], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 2 and "pinky" in res.stderr and "Traceback" not in res.stderr


def test_the_landmark_definitions_are_settable():
    t, index, thumb = _window(read_mocap(OPTOTRAK, rate=RATE)[1])
    mid, g = 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1)
    five = movement_landmarks(t, mid, g)
    ten = movement_landmarks(t, mid, g, LandmarkParams(threshold=0.10))
    absolute = movement_landmarks(t, mid, g, LandmarkParams(speed=0.05, hold=0.05))
    assert ten.movement_time < five.movement_time       # a higher bound, a shorter movement
    assert absolute.movement_time > 0 and math.isfinite(absolute.onset_time)


def test_the_same_trial_as_c3d_gives_the_same_reach_and_landmarks(tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    trial = read_mocap(OPTOTRAK, rate=RATE)[0]
    names = ["index", "thumb"]
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [RATE]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = names
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    pts = np.ones((4, 2, len(trial.time)))
    for k, m in enumerate(names):
        pts[:3, k] = trial.markers[m].T * 1000
    c3d["data"]["points"] = pts
    path = tmp_path / "trial0.c3d"
    c3d.write(str(path))
    table = movement_landmarks(*_reach_arrays(read_reaches(OPTOTRAK, MocapImport(rate=RATE))[0]))
    again = movement_landmarks(*_reach_arrays(read_reaches(path)[0]))
    assert again.movement_time == pytest.approx(table.movement_time, abs=1e-3)
    assert again.mga == pytest.approx(table.mga, abs=1e-4)


def _reach_arrays(reach):
    return reach.time, reach.transport, reach.aperture


def test_landmarks_command_writes_one_row_per_trial(tmp_path, capsys):
    out = tmp_path / "lm.csv"
    status, _, err = hammer_here(capsys, "landmarks", OPTOTRAK, "--rate", RATE, "-o", out, "--wide")
    assert status == 0, err
    import pandas as pd

    table = pd.read_csv(out)
    assert list(table["trial"]) == [f"optotrak-trials-trial{k}" for k in range(4)]
    assert (table["status"] == "complete").all()
    assert table["movement_time"].between(1000, 2500).all()  # ms
    shares = table[["peak_speed_time", "mga_time", "opening_time"]]
    # within 0-100 %, or missing: trial 2's digits are unseen when its grip starts to open
    assert (shares.isna() | shares.ge(0) & shares.le(100)).all().all()
    said = table.set_index("trial")["flags"].fillna("")
    assert all("opening_time: not seen: " in said[t] for t in table["trial"][
        table["opening_time"].isna()])
    assert shares[["peak_speed_time", "mga_time"]].notna().all().all()
    # the raw MGA is the rest-subtracted opening plus the aperture at rest
    assert np.allclose(table["mga"], table["opening"] + table["rest_aperture"])


def test_landmarks_of_pose_like_tracks_need_no_wrist_and_no_object():
    from perception.io.tracks import Status, Tracks
    from perception.measure import landmarks

    reach = read_reaches(OPTOTRAK, MocapImport(rate=RATE))[1]
    tracks, *_ = reach_tracks(reach)
    keep = [tracks.markers.index(m) for m in ("thumb", "finger")]
    bare = Tracks(frame=tracks.frame, time=tracks.time, markers=("thumb", "finger"),
                  position=tracks.position[:, keep], likelihood=tracks.likelihood[:, keep],
                  status=np.full((len(tracks.time), 2), Status.TRACKED, np.int8))
    table = landmarks(bare, px_per_m=1000.0)
    assert len(table) == 1 and table.loc[0, "status"] == "complete"
    assert 1.0 < table.loc[0, "movement_time"] < 2.5
    with pytest.raises(Exception, match="px_per_m"):
        landmarks(bare)


def test_batch_scores_every_reach_of_a_recording(tmp_path, capsys):
    folder = tmp_path / "session"
    folder.mkdir()
    (folder / "trials.tsv").write_bytes(OPTOTRAK.read_bytes())
    batch = ("batch", folder, "-o", tmp_path / "report", "--rate", RATE, "--quiet")
    status, _, err = hammer_here(capsys, *batch)
    assert status == 0, err
    import pandas as pd

    summary = pd.read_csv(tmp_path / "report" / "summary.csv")
    assert sorted(summary["clip"]) == [f"trials-trial{k}" for k in range(4)]
    assert (summary["status"] == "ok").all()
    # a rerun reuses every reach's report
    assert hammer_here(capsys, *batch)[0] == 0
    assert pd.read_csv(tmp_path / "report" / "summary.csv")["reused"].all()


def test_a_reach_recorded_at_1000_hz_is_scored_like_the_same_at_85(optotrak_reaches):
    from types import SimpleNamespace

    trial = read_mocap(OPTOTRAK, rate=RATE)[1]
    t = np.arange(0, trial.time[-1], 1e-3)
    markers = {m: np.stack([np.interp(t, trial.time, p[:, k]) for k in range(3)], axis=1)
               for m, p in trial.markers.items()}
    fast = SimpleNamespace(name="fast", source="fast.tsv", time=t, markers=markers, notes=())
    reach = recording_reaches(fast, MarkerMap("thumb", "index"))[0]
    rep = default_repertoire()
    rec, info = recognize_reach(reach, rep)
    slow, _ = recognize_reach(optotrak_reaches[1], rep)
    assert info["rate"] == pytest.approx(1000, rel=1e-3)
    assert rec.verdict == slow.verdict == "normal"
    assert rec.landmarks[0].movement_time == pytest.approx(slow.landmarks[0].movement_time,
                                                           abs=0.02)


def test_landmarks_of_a_video_write_nothing_beside_it(tmp_path, capsys):
    from perception.synthetic.demos import render_demo_clip

    clips = tmp_path / "clips"
    clips.mkdir()
    video = render_demo_clip(clips, "clip.mp4", n=60)[0].video
    before = sorted(p.name for p in clips.iterdir())
    out = tmp_path / "out" / "table.csv"
    status, _, err = hammer_here(capsys, "landmarks", video, "--object-diameter", "0.1", "-o", out)
    assert status == 0, err
    assert sorted(p.name for p in clips.iterdir()) == before     # the user's folder untouched
    assert (tmp_path / "out" / "tracks" / "clip.tracks.h5").is_file()
    import pandas as pd

    table = pd.read_csv(out)
    assert (table["status"] == "complete").all()
    time = table.set_index("landmark").loc["movement_time"]
    assert time["unit"] == "ms" and 500 < time["value"] < 1500

"""One landmark table, one unit convention, a flag on every doubtful value (issue 44, items 2-3).

``batch``'s ``landmarks.csv`` and ``hammer-mv landmarks`` come from one builder
(:func:`perception.report.tables.tidy_landmarks`): the same rows, units, clocks
and factor columns, for a file, a folder or a manifest. Every value carries a
flag: ``ok``, ``inside a gap``, ``not seen`` with why, ``bound raised to N % of
peak``. The movements here are generated: minimum-jerk reaches whose movement
time, peak speed and maximum grip aperture are known in closed form.
"""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from _cli import hammer_here, main_here
from scipy.optimize import brentq

from perception.landmarks import LandmarkParams, movement_landmarks, speed_bound
from perception.report.tables import (
    LANDMARK_COLUMNS,
    LANDMARK_UNITS,
    tidy_landmarks,
    units_path,
    wide_landmarks,
)

RATE = 200.0
#: The generated reach: this far (m) in this long (s), starting here (s).
DISTANCE, DURATION, START = 0.30, 1.0, 0.6
#: Its grip: at rest, widest (m).
REST_GRIP, MAX_GRIP = 0.015, 0.085


def _minjerk(t, t0, duration):
    """Share of the way covered (0-1) by a minimum-jerk stroke."""
    s = np.clip((t - t0) / duration, 0, 1)
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def _trial(gap=None, closing=False, noise=5e-5, seed=0):
    """One trial: rest, a reach of DISTANCE in DURATION s, rest, the return, rest.

    ``gap``: (start, end) s in which the thumb is lost; ``closing``: the grip
    starts wide open and only closes; ``noise``: SD of the positions' noise, m
    (a tracker's jitter: a marker that repeats its sample exactly is taken as
    held, and lost).
    """
    t = np.arange(0, 4.5, 1 / RATE)
    # the return slower than the reach: the reach is the recording's fastest movement
    way = _minjerk(t, START, DURATION) - _minjerk(t, 2.6, 1.4)
    mid = np.c_[np.zeros_like(t), DISTANCE * way, np.zeros_like(t)]
    # the grip opens to its widest at 70 % of the reach, and closes on the object
    s = np.clip((t - START) / DURATION, 0, 1)
    opening = np.where(s < 0.7, np.sin(np.pi / 2 * s / 0.7) ** 2,
                       1 - 0.3 * np.sin(np.pi / 2 * (s - 0.7) / 0.3) ** 2)
    opening[t > 2.6] = 0.7 * (1 - _minjerk(t[t > 2.6], 2.6, 1.4))
    grip = MAX_GRIP - 0.02 * s if closing else REST_GRIP + (MAX_GRIP - REST_GRIP) * opening
    half = np.c_[0.5 * grip, np.zeros_like(t), np.zeros_like(t)]
    index, thumb = mid + half, mid - half
    rng = np.random.default_rng(seed)
    index = index + rng.normal(0, noise, index.shape)
    thumb = thumb + rng.normal(0, noise, thumb.shape)
    if gap is not None:
        thumb[(t >= gap[0]) & (t < gap[1])] = np.nan
    return t, index, thumb


def _table(trials: dict, wrist: bool = False) -> pd.DataFrame:
    """A long table (mm) of ``{(participant, condition, number): trial}``; with a ``wrist``
    marker (6 cm behind the grip, always seen) that carries the transport."""
    parts = []
    for (who, cond, number), (t, index, thumb) in trials.items():
        cols = {"participant": who, "condition": cond, "trial": number, "time": t}
        markers = [("index", index), ("thumb", thumb)]
        if wrist:
            seen = np.where(np.isfinite(thumb), thumb, index)
            markers.append(("wrist", 0.5 * (index + seen) - [0.0, 0.06, 0.0]))
        for name, xyz in markers:
            for k, ax in enumerate("XYZ"):
                cols[f"{name}{ax}"] = xyz[:, k] * 1000
        parts.append(pd.DataFrame(cols))
    return pd.concat(parts, ignore_index=True)


def _known():
    """Movement time (s), peak speed (m/s) and its time (share) of the generated reach by the
    5 % rule, in closed form."""
    def speed(s):  # of the minimum-jerk stroke, m/s
        return 30 * s**2 * (1 - s) ** 2 * DISTANCE / DURATION

    peak = speed(0.5)
    s_on = brentq(lambda s: speed(s) - 0.05 * peak, 1e-6, 0.5)
    return (1 - 2 * s_on) * DURATION, peak, 0.5


def hammer(*args, timeout=300):
    """``hammer-mv *args`` as a subprocess: for what the process shows (exit status 2 in one
    line); the lines and files of a command are tested in-process (:func:`hammer_here`)."""
    return subprocess.run([sys.executable, "-m", "hammer_mv", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


def _read(path) -> pd.DataFrame:
    """A long landmark table as pandas reads it, text cells as written (empty is "")."""
    return pd.read_csv(path, keep_default_na=False, na_values={"value": [""]},
                       dtype={"trial_number": str, "reach_number": str})


# -- the long table, read by pandas, against known values --------------------------------------
def test_the_long_table_holds_known_values_in_lab_units(tmp_path, capsys):
    table = tmp_path / "reach.tsv"
    _table({("p1", "small", 1): _trial()}).to_csv(table, sep="\t", index=False)
    out = tmp_path / "lm.csv"
    res = hammer_here(capsys, "landmarks", table, "-o", out)
    assert res.returncode == 0, res.stderr
    lm = _read(out)
    assert list(lm.columns) == ["clip", "trial", "condition", "participant", "trial_number",
                                "reach_number", "landmark", "value", "unit", "clock", "flag",
                                "status", "reason"]
    assert list(lm["landmark"]) == list(LANDMARK_COLUMNS)
    row = lm.set_index("landmark")
    assert row["unit"].to_dict() == LANDMARK_UNITS
    assert set(row["unit"]) == {"ms", "mm", "mm/s", "%", "count"}
    assert row.loc["onset_time", "clock"] == "recording"
    assert row.loc["time_to_peak_speed", "clock"] == "onset"
    assert row.loc["movement_time", "clock"] == ""
    assert (row["flag"] == "ok").all(), row["flag"]
    assert set(row["condition"]) == {"small"} and set(row["participant"]) == {"p1"}
    mt, peak, peak_share = _known()
    value = row["value"]
    step_ms = 1000 / RATE
    assert value["movement_time"] == pytest.approx(mt * 1000, abs=2 * step_ms)
    assert value["peak_speed"] == pytest.approx(peak * 1000, rel=0.01)
    assert value["peak_speed_time"] == pytest.approx(peak_share * 100, abs=1.0)
    assert value["mga"] == pytest.approx(MAX_GRIP * 1000, abs=0.5)
    # the aperture at the rule's onset: the grip opens from the reach's start
    s_on = (DURATION - mt) / 2 / DURATION
    rest = REST_GRIP + (MAX_GRIP - REST_GRIP) * np.sin(np.pi / 2 * s_on / 0.7) ** 2
    assert value["rest_aperture"] == pytest.approx(rest * 1000, abs=0.5)
    assert value["opening"] == pytest.approx(value["mga"] - value["rest_aperture"])
    # the onset on the recording's clock: the reach starts at START s, the rule's onset after it
    onset = START + (DURATION - mt) / 2
    assert value["onset_time"] == pytest.approx(onset * 1000, abs=2 * step_ms)
    assert value["time_to_peak_speed"] == pytest.approx(
        value["peak_speed_time"] / 100 * value["movement_time"])
    assert value["aperture_peaks"] == 1 and value["movements"] == 1


# -- flags ---------------------------------------------------------------------------------------
def test_a_peak_speed_inside_a_gap_is_flagged_and_a_clean_one_is_not():
    t, index, thumb = _trial()
    clean = movement_landmarks(t, 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1))
    assert clean.flag("peak_speed") == "ok"
    # the thumb lost for 0.2 s around the peak (at START + DURATION / 2)
    mid_time = START + DURATION / 2
    t, index, thumb = _trial(gap=(mid_time - 0.12, mid_time + 0.08))
    lm = movement_landmarks(t, 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1))
    assert math.isfinite(lm.peak_speed)  # a value is given, and flagged
    for name in ("peak_speed", "peak_speed_time", "peak_speed_seconds"):
        assert lm.flag(name).startswith("inside a gap: the transport point was lost for 20"), \
            lm.flag(name)
    assert lm.flag("mga") == "ok"  # the MGA, at 70 %, is seen


def test_an_opening_time_not_seen_has_a_flag_and_why(tmp_path, capsys):
    # the thumb lost for 0.3 s from just after the onset: the grip opens unseen
    gap_trial = _trial(gap=(START + 0.1, START + 0.4))
    t, index, thumb = gap_trial
    lm = movement_landmarks(t, 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1))
    assert math.isnan(lm.opening_time)
    assert lm.flag("opening_time").startswith("not seen: the grip opened while a digit was lost")
    # a grip that never opens: never past the opening level
    t, index, thumb = _trial(closing=True, noise=0.0)
    flat = movement_landmarks(t, 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1))
    assert flat.flag("opening_time") == "not seen: the grip never crossed the opening level"
    # in the table: an empty cell always has its flag, and the console does not call it
    # complete (a wrist carries the transport: the movement's onset is seen)
    table = tmp_path / "gap.tsv"
    _table({("p1", "small", 1): _trial(), ("p1", "small", 2): gap_trial}, wrist=True).to_csv(
        table, sep="\t", index=False)
    out = tmp_path / "lm.csv"
    res = hammer_here(capsys, "landmarks", table, "-o", out)
    assert res.returncode == 0, res.stderr
    assert "2 movement(s), 1 complete, 1 with a flagged landmark" in res.stdout
    lm = _read(out)
    empty = lm[lm["value"].isna()]
    assert len(empty) and (empty["flag"] != "ok").all() and (empty["flag"] != "").all()
    cell = lm[(lm["trial_number"] == "2") & (lm["landmark"] == "opening_time")].iloc[0]
    assert math.isnan(cell["value"]) and cell["flag"].startswith("not seen: ")


def test_a_raised_bound_is_flagged_with_its_share():
    # noisy positions: the still hand's speed floor, doubled, is above 5 % of the peak
    t, index, thumb = _trial(noise=0.0015, seed=3)
    mid, grip = 0.5 * (index + thumb), np.linalg.norm(index - thumb, axis=1)
    params = LandmarkParams(cutoff=None)
    lm = movement_landmarks(t, mid, grip, params)
    speed = params.speed_of(t, mid)
    peak = int(np.nanargmax(speed))
    share = speed_bound(speed, peak, params) / speed[peak]
    assert share > 0.06
    said = f"bound raised to {share * 100:.0f} % of peak"
    assert lm.flag("onset_time") == said and lm.flag("end_time") == said
    assert lm.flag("movement_time") == said
    # without the noise floor's raise the bound is the asked one: no flag
    asked = movement_landmarks(t, mid, grip, LandmarkParams(cutoff=None, noise_factor=0))
    assert asked.flag("onset_time") == "ok"


def test_a_trial_that_gives_no_reach_keeps_its_rows():
    from perception.landmarks import Landmarks
    from perception.report.tables import MovementLandmarks

    moves = [MovementLandmarks("a", "a", Landmarks(movement_time=1.2), "complete"),
             MovementLandmarks("b", "b", None, "no reach", "no reach: the hand never moved",
                               factors={"participant": "p1"}, trial_number="7")]
    long = tidy_landmarks(moves)
    b = long[long["clip"] == "b"]
    assert len(b) == len(LANDMARK_COLUMNS) and b["value"].isna().all()
    assert (b["flag"] == "not scored").all() and (b["status"] == "no reach").all()
    assert (b["reason"] == "no reach: the hand never moved").all()
    a = long[long["clip"] == "a"].set_index("landmark")
    assert a.loc["movement_time", "value"] == 1200.0 and a.loc["movement_time", "flag"] == "ok"
    assert a.loc["mga", "flag"] == "not seen"  # missing, never "ok"
    wide = wide_landmarks(moves).set_index("clip")
    assert wide.loc["a", "movement_time"] == 1200.0 and wide.loc["b", "trial_number"] == "7"


# -- one builder: batch, and landmarks on a file, a folder and a manifest ------------------------
@pytest.fixture(scope="module")
def design(tmp_path_factory):
    """A folder of one long table: 2 participants x 2 conditions and a still trial, and a
    manifest naming the table with a session."""
    src = tmp_path_factory.mktemp("design")
    trials = {("p1", "small", 1): _trial(), ("p1", "large", 2): _trial(noise=2e-4, seed=1),
              ("p2", "small", 3): _trial(gap=(1.0, 1.2)), ("p2", "large", 4): _trial()}
    frame = _table(trials)
    still = frame[frame["trial"] == 1].copy()
    still["trial"] = 5
    for c in still.columns:
        if c.endswith(("X", "Y", "Z")):  # the hand never moves; the tracker's jitter
            still[c] = still[c].iloc[0] + np.random.default_rng(5).normal(0, 0.05, len(still))
    pd.concat([frame, still], ignore_index=True).to_csv(src / "table.tsv", sep="\t",
                                                        index=False)
    pd.DataFrame({"clip": ["table"], "video": ["table.tsv"], "session": ["s1"]}).to_csv(
        src / "manifest.csv", index=False)
    return src


@pytest.fixture(scope="module")
def batch_table(design, tmp_path_factory):
    from _demos import default_repertoire

    from perception.batch import discover, run_batch

    out = tmp_path_factory.mktemp("report")
    run_batch(discover(design), out, default_repertoire(), quiet=True)
    return _read(out / "landmarks.csv")


def _same(ours: pd.DataFrame, batch: pd.DataFrame) -> None:
    """The two tables agree: rows, columns, units, clocks, flags and values."""
    assert list(ours.columns) == list(batch.columns)
    assert list(ours["clip"]) == list(batch["clip"])
    assert list(ours["landmark"]) == list(batch["landmark"])
    for column in ("trial", "condition", "participant", "trial_number", "reach_number", "unit",
                   "clock", "flag", "status", "reason"):
        assert list(ours[column]) == list(batch[column]), column
    # every value, onset_time and end_time on the recording's clock included (the report's
    # observation clock put on it by the report's time_origin)
    assert "observation" not in set(batch["clock"])
    np.testing.assert_allclose(ours["value"], batch["value"], rtol=1e-9, atol=1e-9)


def test_landmarks_on_a_folder_and_a_manifest_give_batchs_table(design, batch_table, tmp_path,
                                                                 capsys):
    out = tmp_path / "folder.csv"
    res = hammer_here(capsys, "landmarks", design, "-o", out)
    assert res.returncode == 1, res.stderr  # the still trial is not scored
    assert "5 trials, 4 reaches scored, 1 not scored" in res.stdout
    folder = _read(out)
    assert "session" in folder.columns and set(folder["session"]) == {"s1"}
    _same(folder, batch_table)
    assert set(folder["participant"]) == {"p1", "p2"}
    assert set(folder["condition"]) == {"small", "large"}
    assert (folder[folder["trial_number"] == "5"]["flag"] == "not scored").all()
    res = hammer_here(capsys, "landmarks", design / "manifest.csv", "-o",
                      tmp_path / "manifest.csv")
    assert res.returncode == 1, res.stderr
    pd.testing.assert_frame_equal(_read(tmp_path / "manifest.csv"), folder)


def test_the_wide_table_has_the_same_values_and_a_units_sidecar(design, tmp_path, capsys):
    long_out, wide_out = tmp_path / "long.csv", tmp_path / "wide.csv"
    assert hammer_here(capsys, "landmarks", design, "-o", long_out).returncode == 1
    assert hammer_here(capsys, "landmarks", design, "-o", wide_out, "--wide").returncode == 1
    long, wide = _read(long_out), pd.read_csv(wide_out, dtype={"trial_number": str})
    assert len(wide) == long["clip"].nunique()
    pivot = long.pivot(index="clip", columns="landmark", values="value")
    w = wide.set_index("clip")
    for name in LANDMARK_COLUMNS:
        np.testing.assert_allclose(w[name].astype(float), pivot.loc[w.index, name], rtol=1e-12)
    units = json.loads(units_path(wide_out).read_text())
    assert units_path(wide_out).name == "wide.units.json"
    assert units == {name: {"unit": unit, "clock": clock}
                     for name, (unit, clock) in LANDMARK_COLUMNS.items()}
    assert set(units) <= set(wide.columns)
    # the gap's flag is said beside the movement
    gap = w[w["trial_number"] == "3"].iloc[0]
    assert "inside a gap" in gap["flags"]


# -- pose files: the flag the suggestion names exists ---------------------------------------------
def test_landmarks_takes_object_diameter_px_and_suggests_only_its_own_flags():
    import re

    from hammer_mv.cli import build_parser
    from hammer_mv.cli.flags import as_flags
    from perception.errors import InputError
    from perception.io.tracks import Status, Tracks
    from perception.measure import measure

    t, index, thumb = _trial()
    px = 1000.0  # one pixel a millimetre
    position = np.stack([thumb[:, :2], index[:, :2]], axis=1) * px
    tracks = Tracks(frame=np.arange(len(t)), time=t, markers=("thumb", "finger"),
                    position=position, likelihood=np.ones(position.shape[:2], np.float32),
                    status=np.full(position.shape[:2], Status.TRACKED, np.int8))
    with pytest.raises(InputError) as err:
        measure(tracks)
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices["landmarks"]
    flags = {s for a in sub._actions for s in a.option_strings}
    # the library names fields; the command line says them as its flags
    assert "--" not in str(err.value)
    shown = str(as_flags(err.value))
    said = set(re.findall(r"--[a-z][a-z-]+", shown))
    assert said and said <= flags and "`" not in shown, (said - flags, shown)
    assert "--object-diameter-px" in flags
    # 60 mm across in the image, 0.06 m across in the world: the same scale
    found = measure(tracks, object_diameter=0.06, object_diameter_px=60.0).movements[0]
    direct = measure(tracks, px_per_m=px).movements[0]
    assert found.landmarks.movement_time == pytest.approx(direct.landmarks.movement_time)


def test_object_diameter_px_scales_only_tracks_that_do_not_measure_the_object():
    # batch's landmarks.csv reads a tracked video at its tracker's measured object size,
    # whatever --object-diameter-px says (a pose file's flag); landmarks took the flag over
    # the measurement, so one command line gave a video other values in the two tables
    from perception.measure import measure
    from perception.synthetic.demos import demo_tracks

    tracks, _ = demo_tracks("normal", 0)
    assert tracks.object_diameter_px() == pytest.approx(80.0)  # as its tracker measured
    own = measure(tracks, object_diameter=0.1).movements[0].landmarks
    given = measure(tracks, object_diameter=0.1, object_diameter_px=60.0).movements[0].landmarks
    assert given.mga == own.mga and given.peak_speed == own.peak_speed


def test_landmarks_on_a_deeplabcut_file_takes_the_flag_it_suggests(tmp_path, capsys):
    from perception.io.exports import write_dlc
    from perception.synthetic.demos import demo_tracks

    tracks, _ = demo_tracks("normal", 0, fps=25.0)
    pose = tmp_path / "t1DLC_resnet50_xShuffle1_1000.csv"
    write_dlc(tracks, pose, scorer="DLC_resnet50_xShuffle1_1000")
    out = tmp_path / "lm.csv"
    res = hammer_here(capsys, "landmarks", pose, "--fps", 25, "-o", out)
    assert res.returncode == 2 and "--object-diameter-px" in res.stderr, res.stderr
    with pytest.raises(SystemExit):  # argparse ends --help
        main_here("landmarks", "--help")
    help_text = capsys.readouterr().out
    for flag in {f for f in res.stderr.split() if f.startswith("--")}:
        assert flag.strip("(),.:") in help_text, flag  # every flag it names, it has
    res = hammer_here(capsys, "landmarks", pose, "--fps", 25, "-o", out, "--object-diameter-px",
                      80, "--object-diameter", 0.06)
    assert res.returncode == 0, res.stderr
    by_px = _read(out).set_index("landmark")["value"]
    res = hammer_here(capsys, "landmarks", pose, "--fps", 25, "-o", out, "--px-per-m", 80 / 0.06)
    assert res.returncode == 0, res.stderr
    pd.testing.assert_series_equal(_read(out).set_index("landmark")["value"], by_px)
    assert 500 < by_px["movement_time"] < 1500


def test_a_table_in_si_units_is_put_in_lab_units_with_its_sidecar(tmp_path):
    from perception.report.tables import in_lab_units, write_units

    si = pd.DataFrame({"clip": ["a"], "movement_time": [1.25], "peak_speed_time": [0.4],
                       "mga": [0.081], "aperture_peaks": pd.array([1], dtype="Int64"),
                       "verdict": ["normal"]})
    lab = in_lab_units(si)
    assert lab.loc[0, "movement_time"] == 1250.0 and lab.loc[0, "peak_speed_time"] == 40.0
    assert lab.loc[0, "mga"] == pytest.approx(81.0) and lab.loc[0, "aperture_peaks"] == 1
    assert lab.loc[0, "verdict"] == "normal" and si.loc[0, "movement_time"] == 1.25
    path = write_units(tmp_path / "summary.csv", lab.columns)
    assert path == tmp_path / "summary.units.json"
    assert json.loads(path.read_text()) == {
        "movement_time": {"unit": "ms", "clock": ""}, "peak_speed_time": {"unit": "%", "clock": ""},
        "mga": {"unit": "mm", "clock": ""}, "aperture_peaks": {"unit": "count", "clock": ""}}


def test_times_go_on_the_recordings_clock_or_say_whose_they_are():
    from perception.landmarks import Landmarks
    from perception.report.tables import MovementLandmarks

    lm = Landmarks(onset_time=0.1, end_time=1.3, movement_time=1.2)
    known = tidy_landmarks([MovementLandmarks("a", "a", lm, "complete", clock_offset=2.0)])
    unknown = tidy_landmarks([MovementLandmarks("a", "a", lm, "complete", clock_offset=None)])
    k, u = known.set_index("landmark"), unknown.set_index("landmark")
    assert k.loc["onset_time", "value"] == pytest.approx(2100.0)
    assert k.loc["onset_time", "clock"] == "recording"
    assert u.loc["onset_time", "value"] == pytest.approx(100.0)
    assert u.loc["onset_time", "clock"] == "observation"  # a report without its time origin
    assert k.loc["movement_time", "value"] == u.loc["movement_time", "value"] == 1200.0


# -- a transport point never seen: `marker lost`, as a recording's trial says it -----------------
def _lost(tracks, *markers):
    """``tracks`` with ``markers`` lost in every row."""
    position = tracks.position.copy()
    position[:, [tracks.markers.index(m) for m in markers]] = np.nan
    return dataclasses.replace(tracks, position=position)


def test_tracks_whose_transport_point_is_lost_throughout_say_marker_lost_and_which():
    from perception.measure import measure
    from perception.synthetic.demos import demo_tracks

    tracks, _ = demo_tracks("normal", 1)
    for lost, why in ((("thumb", "finger", "wrist", "object"), "wrist, thumb, finger"),
                      (("wrist", "thumb"), "wrist, thumb")):
        found = measure(_lost(tracks, *lost), px_per_m=700)
        row = found.table.iloc[0]
        # not "in motion throughout" with no reason: nothing tells whether the hand moved
        assert row["status"] == "marker lost", lost
        assert row["reason"] == f"marker lost throughout: {why}"
        assert found.measured == 0 and found.movements[0].landmarks is None
        assert found.movements[0].status == "marker lost"
    # the digits seen, never at once, and no wrist: the midpoint is what is lost
    alternate = tracks.position.copy()
    alternate[::2, 0] = alternate[1::2, 1] = np.nan
    row = measure(_lost(dataclasses.replace(tracks, position=alternate), "wrist"),
                  px_per_m=700).table.iloc[0]
    assert row["reason"] == "marker lost throughout: wrist, thumb and finger together"
    # the wrist seen in one row carries the transport, and gives no speed
    once = _lost(tracks, "thumb", "finger", "wrist").position
    once[10, 2] = tracks.position[10, 2]
    row = measure(dataclasses.replace(tracks, position=once), px_per_m=700).table.iloc[0]
    assert row["status"] == "marker lost" and "wrist is never seen long enough" in row["reason"]
    # a thumb lost while the wrist is seen: the movement is measured whole, the aperture's
    # landmarks flagged as not seen
    thumbless = measure(_lost(tracks, "thumb"), px_per_m=700).movements[0]
    assert thumbless.status == "complete" and thumbless.landmarks.peak_speed > 0
    assert thumbless.landmarks.flag("mga").startswith("not seen")
    # the value itself says so, wherever it is read
    t = np.arange(50) / 30.0
    lm = movement_landmarks(t, np.full((50, 2), np.nan), np.full(50, 0.02))
    assert lm.status == "marker lost"


def test_landmarks_and_recognize_of_a_tracks_file_whose_markers_are_lost(tmp_path, capsys):
    from perception.synthetic.demos import demo_tracks

    path = tmp_path / "gone.tracks.h5"
    _lost(demo_tracks("normal", 1)[0], "thumb", "finger", "wrist").save(path)
    out = tmp_path / "lm.csv"
    res = hammer_here(capsys, "landmarks", path, "--px-per-m", 700, "-o", out)
    assert res.returncode == 1, res.stderr  # a trial not measured, as a recording's
    assert "gone: not scored: marker lost throughout: wrist, thumb, finger" in res.stderr
    table = _read(out)
    assert set(table["status"]) == {"marker lost"} and set(table["flag"]) == {"not scored"}
    res = hammer("recognize", path, "--px-per-m", 700, "-o", tmp_path / "rec", "--no-figures")
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1, res.stderr
    assert "never seen" in res.stderr


def test_tracks_of_too_few_rows_for_a_speed_say_too_short_as_a_recording_does():
    from perception.measure import measure
    from perception.synthetic.demos import demo_tracks

    tracks, _ = demo_tracks("normal", 1)
    for n in (1, 2):
        found = measure(tracks.rows(0, n), px_per_m=700)
        row = found.table.iloc[0]
        # "in motion throughout" with no reason before: two rows show no motion at all
        assert (row["status"], row["reason"]) == ("too short", f"too short: {n} samples")
        assert found.measured == 0 and found.movements[0].landmarks is None
    # three rows give a speed: a movement that the rows cut, as before
    assert measure(tracks.rows(0, 3), px_per_m=700).table.iloc[0]["status"] == "starts in motion"

"""Motion-capture files as labs write them: Vicon Nexus and OptiTrack Motive CSV exports,
headerless tables (RTMocap's layout), the time column, and the reader's fault cases.

The three layout files in tests/data/mocap were written for these tests
(synthetic reach-like numbers) in the layouts the vendors' exports have:
``vicon-nexus-trajectories.csv`` (a Devices block, the Trajectories block, a
Model Outputs block; 100 Hz, mm, subject ``Subject01``), ``motive-export.csv``
(Motive format 1.23: a rigid body ``Cup`` with one rigid-body marker, three
markers of ``Hand``; 120 Hz, metres) and ``headerless-rtmocap-layout.txt``
(no header, tab-separated, object/thumb/index/hand/wristA/wristB x X Y Z in mm).
"""

from __future__ import annotations

import codecs
from pathlib import Path

import numpy as np
import pytest

from perception.errors import InputError
from perception.io.mocap import (
    LAYOUTS,
    LAYOUTS_READ,
    is_mocap_file,
    read_mocap,
    table_layout,
    unknown_layout,
)

DATA = Path(__file__).resolve().parent / "data" / "mocap"
VICON = DATA / "vicon-nexus-trajectories.csv"
MOTIVE = DATA / "motive-export.csv"
HEADERLESS = DATA / "headerless-rtmocap-layout.txt"
RTMOCAP = ("object", "thumb", "index", "hand", "wristA", "wristB")


def _refused(path, **kw) -> InputError:
    """The InputError reading ``path`` raises; it names the file."""
    with pytest.raises(InputError) as err:
        read_mocap(path, **kw)
    assert str(path) in str(err.value)
    return err.value


def _write(tmp_path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# -- layouts ---------------------------------------------------------------------------
def test_each_layout_is_named(tmp_path):
    assert table_layout(VICON) == "vicon-nexus" and table_layout(MOTIVE) == "motive"
    assert table_layout(HEADERLESS) == "headerless"
    assert table_layout(DATA / "qualisys-recording.tsv") == "qtm"
    assert table_layout(DATA / "optotrak-trials.tsv") == "xyz-table"
    assert table_layout(tmp_path / "any.c3d") == "c3d"
    dlc = _write(tmp_path, "dlc.csv", "scorer,DLC,DLC,DLC\nbodyparts,thumb,thumb,thumb\n"
                                      "coords,x,y,likelihood\n0,1,2,0.9\n")
    assert table_layout(dlc) is None and not is_mocap_file(dlc)
    for path in (VICON, MOTIVE, HEADERLESS):
        assert is_mocap_file(path)
    assert set(LAYOUTS) == {"qtm", "vicon-nexus", "motive", "xyz-table", "headerless", "c3d",
                            "trc", "dlc-3d"}


def test_unknown_layout_is_one_line_naming_what_was_expected(tmp_path):
    path = _write(tmp_path, "notes.csv", "subject,age,hand\nP01,34,right\n")
    assert table_layout(path) is None
    err = unknown_layout(path)
    assert str(path) in str(err) and "'subject,age,hand'" in err.problem
    for layout in ("Qualisys", "Vicon Nexus", "Motive", "X, Y and Z", "`columns`"):
        assert layout in err.problem and layout in LAYOUTS_READ
    assert "pose" not in str(err) and "\n" not in str(err)
    wide = _write(tmp_path, "wide.csv", ",".join(["1.5"] * 20) + "\n")
    assert table_layout(wide) is None and "20 columns" in unknown_layout(wide).problem


# -- Vicon Nexus -----------------------------------------------------------------------
@pytest.fixture(scope="module")
def vicon():
    (trial,) = read_mocap(VICON)
    return trial


def test_vicon_trajectories_block_is_read(vicon):
    assert vicon.name == "vicon-nexus-trajectories" and vicon.marker_names() == (
        "thumb", "index", "wrist")
    assert vicon.rate == 100.0 and vicon.units == "mm"
    np.testing.assert_allclose(vicon.time, np.arange(40) / 100)  # frame 1 is t = 0
    # row "21,0,317.208,15.537,279.935,..." (mm)
    np.testing.assert_allclose(vicon.markers["thumb"][20], [0.317208, 0.015537, 0.279935])
    np.testing.assert_allclose(vicon.markers["wrist"][0], [0.1, 0.05, 0.2])
    assert np.flatnonzero(np.isnan(vicon.markers["index"][:, 0])).tolist() == [12, 13]
    assert "Devices, Model Outputs blocks skipped: only the Trajectories are read" in vicon.notes
    assert any("'Subject01:' left out" in n for n in vicon.notes)
    assert not any("inferred" in n for n in vicon.notes)  # the units row says mm


def _vicon_lines() -> list[str]:
    return VICON.read_text().splitlines()


def test_vicon_without_devices_block_and_leading_blank_lines(tmp_path, vicon):
    lines = _vicon_lines()
    start = lines.index("Trajectories")
    path = _write(tmp_path, "trial.csv", "\n\n" + "\n".join(lines[start:start + 45]) + "\n")
    (trial,) = read_mocap(path)
    assert table_layout(path) == "vicon-nexus"
    np.testing.assert_array_equal(trial.markers["wrist"], vicon.markers["wrist"])
    assert not any("skipped" in n for n in trial.notes)


def test_vicon_two_subjects_keep_their_names(tmp_path):
    text = VICON.read_text().replace("Subject01:index", "Subject02:thumb")
    (trial,) = read_mocap(_write(tmp_path, "two.csv", text))
    assert trial.marker_names() == ("Subject01:thumb", "Subject02:thumb", "wrist")


def test_vicon_sub_frames_other_than_0_are_left_out(tmp_path, vicon):
    lines = _vicon_lines()
    at = lines.index("Trajectories") + 5
    extra = lines[at].replace("1,0,", "1,1,", 1)
    path = _write(tmp_path, "sub.csv", "\n".join(lines[:at + 1] + [extra] + lines[at + 1:]))
    (trial,) = read_mocap(path)
    assert len(trial.time) == 40
    assert any("1 rows of sub frames other than 0 left out" in n for n in trial.notes)


def test_vicon_semicolons_and_decimal_commas(tmp_path, vicon):
    text = VICON.read_text()
    text = "\n".join(line.replace(",", ";") for line in text.splitlines())
    text = "\n".join(";".join(c.replace(".", ",") for c in line.split(";"))
                     for line in text.splitlines())
    (trial,) = read_mocap(_write(tmp_path, "locale.csv", text))
    np.testing.assert_allclose(trial.markers["thumb"], vicon.markers["thumb"])


def test_vicon_units_row_and_given_rate(tmp_path):
    (trial,) = read_mocap(_write(tmp_path, "m.csv", VICON.read_text().replace(",mm", ",m")))
    assert trial.units == "m" and trial.markers["wrist"][0][0] == pytest.approx(100.0)
    (trial,) = read_mocap(VICON, rate=50)
    assert trial.rate == 50.0 and trial.time[10] == pytest.approx(0.2)  # timed by the rate
    assert any("rate 50 samples/s given" in n and "says 100" in n for n in trial.notes)


def test_vicon_refusals(tmp_path):
    lines = _vicon_lines()
    devices = _write(tmp_path, "devices.csv", "\n".join(lines[:lines.index("Trajectories")]))
    assert table_layout(devices) == "vicon-nexus"
    err = _refused(devices)
    assert err.field == "Trajectories" and "without a Trajectories block" in err.problem
    assert "Devices" in err.problem
    err = _refused(VICON, time_column="Frame")
    assert err.field == "time_column" and "no time column" in err.problem
    assert _refused(VICON, trial_column="trial").field == "trial_column"
    text = VICON.read_text().replace(",,mm,mm,mm,mm", ",,mm,cm,mm,mm")
    mixed = _write(tmp_path, "mixed.csv", text)
    err = _refused(mixed)
    assert err.field == "Trajectories units" and "cm, mm" in err.problem


# -- OptiTrack Motive ------------------------------------------------------------------
@pytest.fixture(scope="module")
def motive():
    (trial,) = read_mocap(MOTIVE)
    return trial


def test_motive_markers_rigid_bodies_rate_and_units(motive):
    assert motive.marker_names() == ("Cup", "Marker1", "thumb", "index", "wrist")
    assert motive.rate == 120.0 and motive.units == "m"  # Export Frame Rate, Length Units
    np.testing.assert_allclose(motive.time[:3], [0.0, 0.008333, 0.016667])
    np.testing.assert_array_equal(motive.markers["Cup"][5], [0.42, 0.05, 0.2])  # the pivot
    np.testing.assert_array_equal(motive.markers["Marker1"][5], [0.42, 0.05, 0.23])
    np.testing.assert_array_equal(motive.markers["wrist"][0], [0.1, 0.05, 0.2])
    assert np.flatnonzero(np.isnan(motive.markers["thumb"][:, 0])).tolist() == [20]
    assert any("'Cup:', 'Hand:' left out" in n for n in motive.notes)


def test_motive_length_units(tmp_path, motive):
    lines = MOTIVE.read_text().splitlines()
    lines[0] = lines[0].replace("Meters", "Millimeters")
    (mm,) = read_mocap(_write(tmp_path, "mm.csv", "\n".join(lines)))
    assert mm.units == "mm"
    np.testing.assert_allclose(mm.markers["wrist"] * 1000, motive.markers["wrist"])
    lines[0] = lines[0].replace("Millimeters", "Inches")
    err = _refused(_write(tmp_path, "in.csv", "\n".join(lines)))
    assert err.field == "Length Units" and "'Inches'" in err.problem


def test_motive_rate_given_must_agree_with_its_clock(motive):
    err = _refused(MOTIVE, rate=60)
    assert err.field == "rate" and "'Time (Seconds)'" in err.problem
    assert "120 samples/s" in err.problem and "`time_column` none" in err.problem
    (trial,) = read_mocap(MOTIVE, rate=60, time_column="none")
    np.testing.assert_allclose(trial.time, np.arange(36) / 60)
    assert any("'Time (Seconds)' ignored" in n for n in trial.notes)
    (same,) = read_mocap(MOTIVE, rate=120.5)  # within 1 %
    assert same.rate == 120.5
    np.testing.assert_array_equal(same.time, motive.time)
    assert _refused(MOTIVE, time_column="Frame").field == "time_column"


# -- headerless tables (RTMocap's layout) ---------------------------------------------
def test_headerless_table_with_columns():
    (trial,) = read_mocap(HEADERLESS, rate=200, columns=RTMOCAP)
    assert trial.marker_names() == RTMOCAP and trial.rate == 200.0 and trial.units == "mm"
    np.testing.assert_allclose(trial.time, np.arange(40) / 200)
    # line 2: "430 50 180 160.05 39.777 206.44 ..."
    np.testing.assert_allclose(trial.markers["object"][1], [0.43, 0.05, 0.18])
    np.testing.assert_allclose(trial.markers["thumb"][1], [0.16005, 0.039777, 0.20644])
    (again,) = read_mocap(HEADERLESS, rate=200, columns=",".join(RTMOCAP))
    np.testing.assert_array_equal(again.markers["wristB"], trial.markers["wristB"])


def test_headerless_refusals(tmp_path):
    err = _refused(HEADERLESS, rate=200)
    assert err.field == "columns" and "18 columns" in err.problem and "6 markers" in err.problem
    err = _refused(HEADERLESS, rate=200, columns=("object", "thumb", "index"))
    assert err.field == "columns" and "9 columns" in err.problem and "18 columns" in err.problem
    err = _refused(HEADERLESS, columns=RTMOCAP)
    assert err.field == "rate"
    err = _refused(HEADERLESS, rate=200, columns=("a", "a", "b", "c", "d", "e"))
    assert err.field == "columns" and "'a' named twice" in err.problem
    err = _refused(DATA / "optotrak-trials.tsv", rate=85, columns=RTMOCAP)
    assert err.field == "columns" and "header" in err.problem
    wide = _write(tmp_path, "wide.txt", "\n".join(["\t".join(["1.5"] * 20)] * 3))
    err = _refused(wide, rate=100)
    assert err.field == "columns" and "20 columns" in err.problem
    assert "not a multiple of 3" in err.problem


def test_headerless_last_marker_lost_throughout(tmp_path):
    rows = ["\t".join(["1", "2", "3", "4", "5", "6"]) + "\t\t\t" for _ in range(4)]
    (trial,) = read_mocap(_write(tmp_path, "lost.txt", "\n".join(rows)), rate=100,
                          columns="a,b,c", units="mm")
    assert trial.lost_markers() == ("c",)
    assert any("'c' never seen" in n for n in trial.notes)


# -- the time column -------------------------------------------------------------------
def _intervals_table(tmp_path) -> Path:
    """An Optotrak-like table whose ``time`` holds frame intervals (ms) and whose clock is
    ``globalTime`` (ms), two trials."""
    rng = np.random.default_rng(1)
    lines = ["trial\ttime\tglobalTime\tindexX\tindexY\tindexZ"]
    clock = 5000.0
    for trial in (1, 2):
        for i in range(30):
            step = 11.765 + rng.normal(0, 0.3)
            clock += step
            lines.append(f"{trial}\t{step:.3f}\t{clock:.3f}\t{100 + 5 * i}\t{-300 + 2 * i}\t10")
    return _write(tmp_path, "optotrak.txt", "\n".join(lines) + "\n")


def test_time_column_of_steps_names_the_clock(tmp_path):
    path = _intervals_table(tmp_path)
    err = _refused(path)
    assert err.field == "time" and "steps between samples" in err.problem
    assert "not a clock" in err.problem and "'globalTime'" in err.problem
    assert "`time_column`" in err.problem
    trials = read_mocap(path, time_column="globalTime")
    assert [t.name for t in trials] == ["optotrak-trial1", "optotrak-trial2"]
    assert trials[0].rate == pytest.approx(85, rel=0.02)
    assert any("'globalTime' in ms" in n for n in trials[0].notes)
    assert trials[1].time[0] > trials[0].time[-1]  # the clock runs on
    plain = read_mocap(path, time_column="none", rate=85)
    np.testing.assert_allclose(plain[1].time, np.arange(30) / 85)
    assert any("'time' ignored" in n for n in plain[0].notes)
    assert _refused(path, time_column="none").field == "rate"


def test_frame_counter_is_not_ms(tmp_path):
    rows = "\n".join(f"{i},{100 + i},{20},{30}" for i in range(10))
    path = _write(tmp_path, "frames.csv", "time,a_x,a_y,a_z\n" + rows + "\n")
    err = _refused(path)
    assert err.field == "rate" and "counts frames" in err.problem
    assert "`time_column`" in err.problem
    (trial,) = read_mocap(path, rate=100)
    np.testing.assert_allclose(trial.time, np.arange(10) / 100)
    assert trial.rate == 100.0 and any("counts frames" in n for n in trial.notes)
    ms = _write(tmp_path, "ms.csv", "time_ms,a_x,a_y,a_z\n" + rows + "\n")
    (trial,) = read_mocap(ms)  # a name saying ms is believed: 1000 Hz
    assert trial.rate == 1000.0


def test_rate_given_and_time_column_are_reconciled(tmp_path):
    rows = "\n".join(f"{i / 100:.2f},{100 + i},{20},{30}" for i in range(10))
    path = _write(tmp_path, "t.csv", "t,a_x,a_y,a_z\n" + rows + "\n")
    err = _refused(path, rate=50)
    assert err.field == "rate" and "disagrees with the time column 't'" in err.problem
    (trial,) = read_mocap(path, rate=100.5)
    assert trial.rate == 100.5 and trial.time[5] == pytest.approx(0.05)
    (trial,) = read_mocap(path, rate=50, time_column="none")
    assert trial.time[5] == pytest.approx(0.1)


def test_qtm_rate_given_against_its_time_column(tmp_path):
    qtm = DATA / "qualisys-recording.tsv"
    err = _refused(qtm, rate=50)
    assert err.field == "rate" and "'Time'" in err.problem and "FREQUENCY" in err.problem
    (trial,) = read_mocap(qtm, rate=50, time_column="none")
    assert trial.rate == 50.0 and trial.time[200] == pytest.approx(4.0)
    assert any("FREQUENCY says 100" in n for n in trial.notes)


# -- issue 46: faults that live in the reader ----------------------------------------
def test_decimal_commas_found_past_the_first_row(tmp_path):
    path = _write(tmp_path, "lab.csv", "time_s;wrist X;wrist Y;wrist Z\n0;100;20;3\n"
                                       "0,01;101,5;20,25;3\n0,02;102,5;20,5;3\n")
    (trial,) = read_mocap(path, units="mm")
    np.testing.assert_allclose(trial.markers["wrist"][1], [0.1015, 0.02025, 0.003])
    assert trial.rate == pytest.approx(100.0)


def test_utf16_excel_unicode_text(tmp_path):
    text = "time\tthumb X\tthumb Y\tthumb Z\r\n0\t100,5\t20\t3\r\n0,01\t101,5\t20\t3\r\n"
    path = tmp_path / "excel.txt"
    path.write_bytes(codecs.BOM_UTF16_LE + text.encode("utf-16-le"))
    assert is_mocap_file(path) and table_layout(path) == "xyz-table"
    (trial,) = read_mocap(path, units="mm")
    np.testing.assert_allclose(trial.markers["thumb"][1], [0.1015, 0.02, 0.003])
    assert "read as UTF-16 text" in trial.notes
    broken = tmp_path / "broken.txt"
    broken.write_bytes(codecs.BOM_UTF16_LE + text.encode("utf-16-le") + b"\x00\xd8")
    err = _refused(broken)
    assert "UTF-16" in err.problem and "UTF-8" in err.problem


def test_comment_lines_above_the_header(tmp_path):
    path = _write(tmp_path, "c.csv", "# exported by lab script v2\n# subject P01\n"
                                     "t,a_x,a_y,a_z\n0,1,2,3\n0.01,1,2,4\n")
    assert is_mocap_file(path)
    (trial,) = read_mocap(path)
    assert len(trial.time) == 2 and "2 comment lines (#) above the table skipped" in trial.notes


@pytest.mark.parametrize("header, name", [("t,a_x,a_y,a_z,a_x", "a_x"),
                                          ("t,a_x,a_y,a_z,A_X", "A_X")])
def test_duplicated_column_is_one_clear_error(tmp_path, header, name):
    err = _refused(_write(tmp_path, "dup.csv", header + "\n0,1,2,3,4\n"))
    assert err.field == name and "columns 2 and 5" in err.problem


def test_repeated_trial_id_is_not_merged(tmp_path):
    rows = [f"{trial},{i / 100},{i},{2},{3}" for trial in (1, 2, 1) for i in range(5)]
    path = _write(tmp_path, "rep.csv", "trial,t,a_x,a_y,a_z\n" + "\n".join(rows) + "\n")
    err = _refused(path)
    assert err.field == "trial" and "trial 1 appears in 2 separate blocks" in err.problem
    assert "data rows 1-5, 11-15" in err.problem


def test_a_phase_column_is_not_a_trial_column():
    err = _refused(DATA / "optotrak-trials.tsv", rate=85, trial_column="graspPhase")
    assert err.field == "graspPhase" and "does not number the trials" in err.problem
    assert "`trial_column`" in err.problem


def test_truncated_c3d_is_said_to_be_short(tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("thumb", "thumb")
    points = np.ones((4, 2, 200))
    points[:3] = np.random.default_rng(2).uniform(100, 400, (3, 2, 200))
    c3d["data"]["points"] = points
    whole = tmp_path / "whole.c3d"
    c3d.write(str(whole))
    (trial,) = read_mocap(whole)
    assert len(trial.time) == 200 and not any("cut short" in n for n in trial.notes)
    assert trial.marker_names() == ("thumb", "thumb_2")
    assert any("labels written more than once ('thumb')" in n for n in trial.notes)
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(whole.read_bytes()[:2000])
    (short,) = read_mocap(cut)
    assert len(short.time) == 14
    assert "the file is cut short: its header states 200 frames, it holds 14: those 14 are " \
           "read" in short.notes
    np.testing.assert_allclose(short.markers["thumb"], trial.markers["thumb"][:14])


def test_units_from_the_markers_spread_not_one_glitch(tmp_path):
    t = np.arange(100) / 100
    lines = ["t,thumb_x,thumb_y,thumb_z,index_x,index_y,index_z,wrist_x,wrist_y,wrist_z,"
             "spare_x,spare_y,spare_z"]
    for i, ti in enumerate(t):
        spare = "5000,5000,5000" if i == 40 else "0.1,0.1,0.1"  # one glitch in a spare marker
        lines.append(f"{ti:.2f},{0.3 + 0.2 * ti:.4f},0.1,0.05,{0.3 + 0.2 * ti:.4f},0.16,0.05,"
                     f"{0.2 + 0.2 * ti:.4f},0.13,0.1,{spare}")
    (trial,) = read_mocap(_write(tmp_path, "glitch.csv", "\n".join(lines) + "\n"))
    assert trial.units == "m"
    note = next(n for n in trial.notes if n.startswith("units inferred: m ("))
    assert "median over 4 markers" in note


def test_markers_never_seen_are_named(tmp_path):
    rows = [f"{i / 100},{100 + i},20,30,0,0,0,,," for i in range(5)]
    path = _write(tmp_path, "lost.csv", "t,thumb_x,thumb_y,thumb_z,wrist_x,wrist_y,wrist_z,"
                                        "index_x,index_y,index_z\n" + "\n".join(rows) + "\n")
    (trial,) = read_mocap(path)
    assert trial.lost_markers() == ("wrist", "index")
    assert any("markers 'wrist', 'index' never seen" in n for n in trial.notes)


def test_qtm_marker_columns_not_listed_are_noted(tmp_path):
    lines = (DATA / "qualisys-recording.tsv").read_text().splitlines()
    names = next(i for i, line in enumerate(lines) if line.startswith("MARKER_NAMES"))
    lines[names] = lines[names].replace("\tpillow_right", "")
    (trial,) = read_mocap(_write(tmp_path, "q.tsv", "\n".join(lines) + "\n"))
    assert "pillow_right" not in trial.markers
    assert any("MARKER_NAMES does not list, not read: 'pillow_right'" in n for n in trial.notes)

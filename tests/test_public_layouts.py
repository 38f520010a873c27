"""Other labs' files as they really are: layouts met in public example files.

Each file here is written by the test, in the layout of a public file that
hammer-mv misread or refused in words that did not fit (session 62's survey;
docs/mocap-formats.md, "Where the layouts came from"), with numbers of its own:

- pyomeca's ``tests/data/markers.trc``: an OpenSim TRC file opened in a
  spreadsheet and saved as CSV (every line parted by commas and padded with
  empty cells to the widest, a row of empty cells under the X1 Y1 Z1 row);
- the C3D samples of c3d.org (as BTKData keeps them): ``Eb015vi.c3d``, a DEC
  (VAX) file whose header floats are DEC floats, and Peak Performance's
  ``FP1.C3D``, whose POINT:UNITS is ``'mete'`` (metres cut to 4 characters) and
  whose markers (PT00 ... PT07, a gait trial) move for 8 s on end: no hand's
  markers, said as such, not as a wrong rate;
  SGI (MIPS) files and files ezc3d finds not standard, refused in ezc3d's words
  meant for its own users;
- Rofunc's OptiTrack Motive take (``Take 2023-03-29 06.23.40 PM.csv``): rigid
  bodies, their Rigid Body Markers, and the same markers again as Markers
  (measured), under the same names;
- a Qualisys QTM export of analysis data (``DATA_INCLUDED Angle``), as beside
  the 3D exports of reiv27/biomechanics;
- DeepLabCut's example ``..._skeleton.csv`` (``analyzeskeleton``: bone lengths);
- pyomeca's ``markers_without_header.csv``: a Vicon Nexus Trajectories block
  without its header lines (frame, sub frame, then X, Y, Z per marker), and
  lab tables of numbers that start with a frame counter and a time;
- Anipose tables of a hand whose digits are numbered, as hand labs name them
  (``left_wrist_x, ..., left_d1_knuckle_x, ..., right_d2_tip``: digit 1 the
  thumb, digit 2 the index; a reach-to-grasp project's MATLAB scripts);
- SLEAP's analysis CSV (its test file
  ``minimal_instance.000_centered_pair_low_quality.analysis.csv``: ``track,
  frame_idx, instance.score, NODE.x, NODE.y, NODE.score``), which movement does
  not read; SLEAP's ``predictions.analysis.h5`` written out in that layout
  read the same as the HDF5 file;
- a pose file without an object keypoint given ``--object-diameter-px`` to
  ``landmarks``, which takes no default real diameter.
"""

from __future__ import annotations

import struct

import numpy as np
import pytest
from _cli import hammer_here

from perception.errors import InputError
from perception.io.mocap import read_mocap, table_layout
from perception.io.mocap_tables import leading_columns
from perception.io.mocap_text import table_text

KEYS = "DataRate,CameraRate,NumFrames,NumMarkers,Units,OrigDataRate,OrigDataStartFrame," \
       "OrigNumFrames"


def _rows(n=8, markers=3):
    """Frame i: marker k at (100 k + i, 200 + i, 300 - i) mm, at 100 Hz."""
    return [[i + 1, f"{i / 100:.2f}", *[v for k in range(markers)
                                       for v in (100 * k + i, 200.5 + i, 300 - i)]]
            for i in range(n)]


def _spreadsheet_trc(path, sep=",", decimal="."):
    """A TRC file as a spreadsheet saves it as CSV: pyomeca's ``markers.trc`` layout."""
    names = ("thumb", "index", "wrist")
    width = 2 + 3 * len(names) + 4  # every line padded to the widest (a longer first line)

    def line(cells):
        cells = [str(c).replace(".", decimal) for c in cells]
        return sep.join(cells + [""] * (width - len(cells)))

    n = 8
    lines = [line(["PathFileType", 4, "(X/Y/Z)", "/home/lab/dapo/0_markers/DapOF6H1_1.trc"]),
             line(KEYS.split(",")), line([100, 100, n, len(names), "mm", 100, 0, n]),
             line(["Frame#", "Time", *[c for m in names for c in (m, "", "")]]),
             line(["", "", *[f"{a}{k}" for k in range(1, 4) for a in "XYZ"]]), line([]),
             *[line(r) for r in _rows(n)]]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("sep, decimal", [(",", "."), (";", ",")])
def test_a_trc_file_saved_as_csv_by_a_spreadsheet_is_read(tmp_path, sep, decimal):
    (trial,) = read_mocap(_spreadsheet_trc(tmp_path / "DapOF6H1_1.trc", sep, decimal))
    assert trial.marker_names() == ("thumb", "index", "wrist") and trial.rate == 100.0
    np.testing.assert_allclose(trial.time, np.arange(8) / 100)
    np.testing.assert_allclose(trial.markers["index"][3], [0.103, 0.2035, 0.297])
    assert any("saved as CSV" in note for note in trial.notes)


def test_a_trc_file_saved_as_csv_is_told_by_its_first_line(tmp_path):
    path = _spreadsheet_trc(tmp_path / "DapOF6H1_1.csv")
    assert table_layout(path) == "trc"
    (trial,) = read_mocap(path)
    np.testing.assert_allclose(trial.markers["wrist"][0], [0.2, 0.2005, 0.3])


def _counted(path, lead, n=6):
    """Numbers only: ``lead`` (frame; frame, sub frame; frame, time) then two markers'
    X, Y, Z in mm."""
    rows = []
    for i in range(n):
        first = {"frame": [i + 1], "sub": [i + 1, 0], "time": [i + 1, f"{i / 100:.3f}"]}[lead]
        rows.append(",".join(map(str, first + [10.5 + i, 20, 30, 110, 120 + i, 130])) + ",")
    path.write_text("\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("lead, kinds", [("frame", ("frame",)), ("sub", ("frame", "sub frame")),
                                         ("time", ("frame", "time"))])
def test_a_table_of_numbers_led_by_a_frame_counter_is_read(tmp_path, lead, kinds):
    path = _counted(tmp_path / "markers_without_header.csv", lead)
    assert table_layout(path) == "headerless"
    assert leading_columns(table_text(path), len(kinds)) == kinds
    with pytest.raises(InputError, match=rf"{len(kinds) + 6} columns \(a frame counter") as err:
        read_mocap(path, rate=100)
    assert err.value.field == "columns" and "X, Y, Z for each of 2 markers" in str(err.value)
    (trial,) = read_mocap(path, columns="a,b", rate=None if lead == "time" else 100)
    np.testing.assert_allclose(trial.markers["b"][2], [0.11, 0.122, 0.13])
    np.testing.assert_allclose(trial.time, np.arange(6) / 100, atol=1e-12)
    assert any(f"read as the {' and '.join(kinds)}" in note for note in trial.notes)


def test_a_table_of_numbers_whose_first_column_does_not_count_is_refused(tmp_path):
    path = tmp_path / "odd.csv"
    path.write_text("\n".join(f"{v},10,20,30" for v in (3.5, 1.25, 7.0)) + "\n")
    assert table_layout(path) is None


def test_a_motive_rigid_body_marker_and_the_marker_it_solves_are_told_apart(tmp_path):
    types = ["Rigid Body"] * 7 + ["Rigid Body Marker"] * 3 + ["Marker"] * 3
    names = ["Box"] * 7 + ["Box:Marker1"] * 6
    parts = ["Rotation"] * 4 + ["Position"] * 9
    axes = list("XYZW") + list("XYZ") * 3
    lines = ["Format Version,1.23,Take Name,Take 2023-03-29 06.23.40 PM,Capture Frame Rate,"
             "120.000000,Export Frame Rate,120.000000,Rotation Type,Quaternion,Length Units,"
             "Millimeters,Coordinate Space,Global", "",
             ",Type," + ",".join(types), ",Name," + ",".join(names),
             ",ID," + ",".join(["7264DAA5"] * 10 + ['"C5B98015"'] * 3),
             ",," + ",".join(parts), "Frame,Time (Seconds)," + ",".join(axes)]
    lines += [f"{i},{i / 120:.6f},0,0,0,1,100,200,300,110,210,310,111,211,311" for i in range(4)]
    path = tmp_path / "Take 2023-03-29 06.23.40 PM.csv"
    path.write_text("\n".join(lines) + "\n")
    (trial,) = read_mocap(path)
    assert trial.marker_names() == ("Box", "Marker1 (rigid body)", "Marker1")
    np.testing.assert_allclose(trial.markers["Marker1"][0], [0.111, 0.211, 0.311])
    np.testing.assert_allclose(trial.markers["Marker1 (rigid body)"][0], [0.11, 0.21, 0.31])
    assert any("the Marker keeps the name" in note for note in trial.notes)


def test_digits_named_by_their_number_are_guessed_on_the_hand_that_moves(tmp_path):
    from perception.reach_data import MarkerMap

    parts = [f"{side}_{p}" for side in ("left", "right")
             for p in ("wrist", "d1_knuckle", "d1_tip", "d2_tip", "d5_tip")]
    header = [f"{p}_{a}" for p in parts for a in ("x", "y", "z", "error", "ncams", "score")]
    rows = []
    for i in range(100):  # the right hand reaches 300 mm in 0.6 s between rests; the left stays
        u = min(max((i - 20) / 60, 0), 1)
        x = 300 * (10 * u**3 - 15 * u**4 + 6 * u**5)
        opening = 40 * np.sin(np.pi * u)  # the digits open and close on the way
        rows.append([v for p in parts for v in (
            (x if p.startswith("right") else 0) + 5 * parts.index(p),
            100 + (opening if p.endswith("d2_tip") else 0), 50, 0.5, 3, 0.9)])
    path = tmp_path / "reach01.csv"
    path.write_text("\n".join([",".join(header + ["fnum"])]
                              + [",".join(map(str, r + [i])) for i, r in enumerate(rows)]) + "\n")
    (trial,) = read_mocap(path, rate=100, units="mm")
    guess = MarkerMap.guess(trial.markers)
    assert (guess.thumb, guess.finger, guess.wrist) == ("right_d1_tip", "right_d2_tip",
                                                        ("right_wrist",))
    from perception.reaches import trial_reaches

    (reach,), _ = trial_reaches(trial)  # the right hand's 300 mm
    assert "marker 'right_d1_tip' taken as the thumb (digit 1)" in reach.notes


def test_a_recording_of_no_hand_says_so_before_judging_its_pace(tmp_path, capsys):
    """Peak Performance's FP1.C3D: 8 markers walking for 8 s without a pause."""
    t = np.arange(480) / 60
    header = ["time"] + [f"PT0{k}_{a}" for k in range(8) for a in "XYZ"]
    rows = [[f"{s:.4f}"] + [f"{v:.4f}" for k in range(8)
                            for v in (1.2 * s + 0.1 * k, 0.4 + 0.05 * np.sin(6 * s), 0.8)]
            for s in t]
    path = tmp_path / "FP1.csv"
    path.write_text("\n".join([",".join(header)] + [",".join(r) for r in rows]) + "\n")
    ran = hammer_here(capsys, "landmarks", path, "--units", "m", "-o", tmp_path / "lm.csv")
    assert ran.returncode == 2
    assert "--markers: no marker 'thumb' for the thumb (the recording has PT00" in ran.stderr
    assert "--rate" not in ran.stderr


ezc3d = pytest.importorskip("ezc3d", reason="the 'mocap' extra")


def _fake_ezc3d(monkeypatch, frames, error=None):
    """ezc3d as it reads the DEC file (all its frames), or raising ``error``."""
    import sys
    import types

    def c3d(path):
        if error is not None:
            raise OSError(error)
        points = np.ones((4, 2, frames))
        points[:3] = np.arange(frames) + 100.0
        return {"parameters": {"POINT": {"LABELS": {"value": ["thumb", "index"]},
                                         "RATE": {"value": [50.0]}, "UNITS": {"value": ["mm"]}}},
                "data": {"points": points,
                         "meta_points": {"residuals": np.zeros((1, 2, frames))}},
                "header": {"points": {"first_frame": 0, "frame_rate": 50.0}}}

    monkeypatch.setitem(sys.modules, "ezc3d", types.SimpleNamespace(c3d=c3d))


def _dec(value: float) -> bytes:
    """``value`` as a DEC (VAX F) float: the IEEE bytes of 4 × value, words swapped."""
    ieee = struct.pack("<f", 4 * value)
    return ieee[2:] + ieee[:2]


def test_a_dec_c3d_is_read_whole_not_said_to_be_cut_short(tmp_path, monkeypatch):
    """c3d.org's ``Eb015vi.c3d``: DEC processor (85), integer data (scale +0.0833 as a DEC
    float, which read as an IEEE float is negative: floats, twice the bytes per frame)."""
    frames, points = 450, 2
    head = bytearray(512)
    head[0], head[1] = 2, 0x50
    head[2:10] = struct.pack("<HHHH", points, 0, 1, frames)
    head[12:16] = _dec(0.08333334)
    head[16:18] = struct.pack("<H", 4)  # the data from block 4
    head[20:24] = _dec(50.0)
    assert struct.unpack("<f", bytes(head[12:16]))[0] < 0  # what misled the count
    params = bytearray(1024)
    params[3] = 85  # DEC
    data = bytes(frames * points * 4 * 2)  # 4 integers of 2 bytes per point and frame
    path = tmp_path / "Eb015vi.c3d"
    path.write_bytes(bytes(head) + bytes(params) + data)
    _fake_ezc3d(monkeypatch, frames)
    (trial,) = read_mocap(path)
    assert len(trial.time) == frames and not any("cut short" in n for n in trial.notes)


def test_a_c3d_whose_unit_is_cut_to_four_letters_is_read(tmp_path):
    """Peak Performance's ``FP1.C3D`` writes POINT:UNITS 'mete'."""
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [60]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("PT00", "PT01")
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mete"]
    points = np.ones((4, 2, 10))
    points[:3] = 0.5
    c3d["data"]["points"] = points
    c3d.write(str(tmp_path / "FP1.c3d"))
    (trial,) = read_mocap(tmp_path / "FP1.c3d")
    assert trial.units == "m" and "POINT:UNITS 'mete' read as m" in trial.notes
    np.testing.assert_allclose(trial.markers["PT01"][0], [0.5, 0.5, 0.5])


@pytest.mark.parametrize("said, meant", [
    ("MIPS processor type not supported yet, please open a GitHub issue to report that you "
     "want this feature!", "MIPS (SGI) processor, which ezc3d, the C3D reader, does not read"),
    ("The format is not standard. If you want to ignore this error, set ignoreBadFormatting "
     "to true: iostream error", "ezc3d: The format is not standard: iostream error")])
def test_a_c3d_ezc3d_cannot_read_is_refused_in_words_for_our_user(tmp_path, monkeypatch, said,
                                                                   meant):
    """c3d.org's SGI samples (``sgi_int.c3d``) and BKIN Technologies' ``sample22``."""
    _fake_ezc3d(monkeypatch, 1, error=said)
    path = tmp_path / "sgi_int.c3d"
    path.write_bytes(b"\x02\x50" + bytes(510))
    with pytest.raises(InputError, match="not a readable C3D file") as err:
        read_mocap(path)
    assert meant in str(err.value)
    assert "GitHub" not in str(err.value) and "ignoreBadFormatting" not in str(err.value)


def test_a_qtm_export_of_angles_says_it_holds_no_markers(tmp_path):
    path = tmp_path / "Measurement1_left_q1.tsv"
    rows = [f"{i + 1}\t{i / 100:.5f}\t{79.3 + i / 10:.3f}" for i in range(5)]
    path.write_text("\r\n".join(["NO_OF_FRAMES\t5", "NO_OF_DATA_TYPES\t1", "FREQUENCY\t100",
                                 "TIME_STAMP\t2026-01-20, 10:25:12", "DATA_INCLUDED\tAngle",
                                 "DATA_TYPES\tleft_q1_XY", "", "Frame\tTime\tleft_q1_XY\t",
                                 *rows]) + "\r\n")
    with pytest.raises(InputError, match="a QTM export of 'Angle' data \\(left_q1_XY\\), not "
                                         "markers' positions: export the 3D data") as err:
        read_mocap(path)
    assert err.value.field == "DATA_INCLUDED"


def _dlc_csv(path, parts=("thumb", "index", "wrist"), n=30):
    """A DeepLabCut table (``analyze_videos``' CSV) of the hand alone: the digits open and
    close while the hand moves 200 px to the right."""
    t = np.linspace(0, 1, n)
    move = 200 * (10 * t**3 - 15 * t**4 + 6 * t**5)
    at = {"wrist": (100 + move, 300 + 0 * t), "thumb": (180 + move, 290 - 30 * np.sin(np.pi * t)),
          "index": (180 + move, 310 + 30 * np.sin(np.pi * t))}
    scorer = "DLC_resnet50_reachJan1shuffle1_100000"
    lines = [",".join(["scorer"] + [scorer] * 3 * len(parts)),
             ",".join(["bodyparts"] + [p for p in parts for _ in range(3)]),
             ",".join(["coords"] + ["x", "y", "likelihood"] * len(parts))]
    lines += [",".join([str(i)] + [f"{v:.3f}" for p in parts
                                   for v in (at[p][0][i], at[p][1][i], 0.99)])
              for i in range(n)]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_deeplabcut_skeleton_table_is_named_as_bone_lengths(tmp_path, capsys):
    pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")
    path = tmp_path / "reachingvideo1shortDLC_resnet50_TESTNov4shuffle1_10_skeleton.csv"
    path.write_text(",thumb_index,thumb_index,thumb_index\n,length,orientation,likelihood\n"
                    "0,462.8,181.1,0.59\n1,460.1,180.2,0.61\n")
    ran = hammer_here(capsys, "landmarks", path, "--fps", "30", "-o", tmp_path / "lm.csv")
    assert ran.returncode == 2
    assert "DeepLabCut's bone lengths (analyzeskeleton), not poses" in ran.stderr
    assert "LightningPose" not in ran.stderr and len(ran.stderr.strip().splitlines()) == 1


def test_landmarks_asks_for_the_real_diameter_when_the_apparent_one_is_given(tmp_path, capsys):
    pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")
    path = _dlc_csv(tmp_path / "reach01DLC_resnet50_reachJan1shuffle1_100000.csv")
    out = tmp_path / "lm.csv"
    ran = hammer_here(capsys, "landmarks", path, "--fps", "30", "--object-diameter-px", "80",
                      "-o", out)
    assert ran.returncode == 2
    (line,) = [x for x in ran.stderr.splitlines() if "error" in x]
    assert ("--object-diameter: the scale is unknown: the object is 80 px across, but its real "
            "diameter is not given") in line
    ran = hammer_here(capsys, "landmarks", path, "--fps", "30", "--object-diameter-px", "80",
                      "--object-diameter", "0.08", "-o", out)
    assert ran.returncode in (0, 1) and out.exists()  # measured, at 1000 px/m


def _sleap_csv(path, rows):
    """SLEAP's analysis CSV (``write_tracking_h5``'s ``csv=True``): a row per instance."""
    head = "track,frame_idx,instance.score," + ",".join(
        f"{n}.x,{n}.y,{n}.score" for n in ("thumb", "index", "wrist"))
    path.write_text("\n".join([head, *rows]) + "\n")
    return path


def _sleap_row(track, frame, score=0.9):
    at = [(200 + frame, 100), (200 + frame, 140 + frame), (150 + frame, 120)]
    return f"{track},{frame},0.95," + ",".join(f"{x},{y},{score}" for x, y in at)


def test_a_sleap_analysis_csv_is_read_as_its_hdf5_would_be(tmp_path):
    pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")
    from perception.io.pose import PoseImport, read_pose

    rows = [_sleap_row(t, f) for f in (0, 1, 3) for t in ("mouse1", "mouse2")]
    rows.append(_sleap_row("mouse1", 4, score=0.2))  # below --pcutoff: lost
    path = _sleap_csv(tmp_path / "labels.v001.000_trial01.analysis.csv", rows)
    options = PoseImport(fps=30, individual="mouse2", object_diameter_px=80.0, cleaning=None)
    with pytest.raises(InputError, match="the file holds 2 individuals \\(mouse1, mouse2\\)"):
        read_pose(path, PoseImport(fps=30, object_diameter_px=80.0))
    tracks = read_pose(path, options)
    assert tracks.n_frames == 5 and tracks.tracker["method"] == "pose:SLEAP"
    position = np.asarray(tracks.position)
    np.testing.assert_allclose(position[3, :3], [[203, 100], [203, 143], [153, 120]])
    assert np.isnan(position[2, :3]).all()  # frame 2: no instance in the file
    mouse1 = read_pose(path, PoseImport(fps=30, individual="mouse1", object_diameter_px=80.0,
                                        cleaning=None))
    assert np.isnan(np.asarray(mouse1.position)[4, :3]).all()  # scored 0.2


def test_a_sleap_analysis_csv_of_untracked_instances_is_refused(tmp_path, capsys):
    pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")
    path = _sleap_csv(tmp_path / "untracked.analysis.csv",
                      [_sleap_row("", 0), _sleap_row("", 0), _sleap_row("", 1)])
    ran = hammer_here(capsys, "landmarks", path, "--fps", "30", "-o", tmp_path / "lm.csv")
    assert ran.returncode == 2
    assert "frame 0 holds two instances without a track" in ran.stderr
    assert "not a table of a layout read" not in ran.stderr

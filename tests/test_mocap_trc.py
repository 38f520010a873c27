"""OpenSim TRC marker files: the layout, the variants real writers produce, the refusals, and
the commands end to end.

Every file here is written by the test in the layout of a writer whose
output was read while building the reader (docs/mocap-formats.md, "OpenSim
TRC files"): OpenSim's ``TRCFileAdapter`` and its example files (an extra tab
before the first name, ``Times``, ``NaN``/``Nan``/``NAN``, blanks for lost
markers, a NumFrames above the rows held, CRLF), Motion Analysis Cortex
(values padded with spaces, ``PathFileType  4``), Pose2Sim (seven values for
eight keys, no blank line, empty cells), OpenCap (a first line parted by
spaces, ``nan``). The numbers are synthetic, or (the end-to-end test) the
rows of ``qualisys-recording.tsv`` written out as a TRC file.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io.mocap import (
    LAYOUTS,
    LAYOUTS_READ,
    MOCAP_SUFFIXES,
    is_mocap_file,
    read_mocap,
    table_layout,
)
from perception.sources import check_command, clip_name, input_kind

DATA = Path(__file__).resolve().parent / "data" / "mocap"
QTM = DATA / "qualisys-recording.tsv"
KEYS = ("DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
        "\tOrigNumFrames")


def _trc(tmp_path, rows, names=("thumb", "index", "wrist"), *, rate="100.00", units="mm",
         frames=None, name="trial.trc", newline="\n", values=None) -> Path:
    """A TRC file as OpenSim writes it: ``rows`` are the data lines (tab-joined lists or
    text)."""
    rows = ["\t".join(map(str, r)) if not isinstance(r, str) else r for r in rows]
    n = len(rows) if frames is None else frames
    values = values or f"{rate}\t{rate}\t{n}\t{len(names)}\t{units}\t{rate}\t1\t{n}"
    lines = ["PathFileType\t4\t(X/Y/Z)\t" + name, KEYS, values,
             "Frame#\tTime\t" + "\t\t\t".join(names) + "\t\t\t",
             "\t\t" + "\t".join(f"X{k}\tY{k}\tZ{k}" for k in range(1, len(names) + 1)) + "\t",
             "", *rows]
    path = tmp_path / name
    path.write_bytes((newline.join(lines) + newline).encode())
    return path


def _reach_rows(n=6, rate=100.0, markers=3):
    """Rows of ``n`` frames: marker k at (100 k + i, 200 + i, 300 - i) mm at frame i."""
    return [[i + 1, f"{i / rate:.4f}", *[v for k in range(markers)
                                        for v in (100 * k + i, 200 + i, 300 - i)]]
            for i in range(n)]


def _refused(path, **kw) -> InputError:
    """The one-line InputError reading ``path`` raises; it names the file."""
    with pytest.raises(InputError) as err:
        read_mocap(path, **kw)
    assert str(path) in str(err.value) and "\n" not in str(err.value)
    return err.value


# -- the layout and where it is registered ------------------------------------------------
def test_a_trc_file_is_motion_capture_for_every_command(tmp_path):
    path = _trc(tmp_path, _reach_rows())
    assert table_layout(path) == "trc" and is_mocap_file(path)
    assert "trc" in LAYOUTS and "OpenSim TRC" in LAYOUTS_READ and ".trc" in MOCAP_SUFFIXES
    assert input_kind(path).name == "mocap" and clip_name(path) == ("trial", "mocap")
    for command in ("recognize", "batch", "landmarks", "watch"):
        assert check_command(path, command).name == "mocap"
    # a TRC under another ending is told by its first line
    txt = tmp_path / "trial.txt"
    txt.write_bytes(path.read_bytes())
    assert table_layout(txt) == "trc" and read_mocap(txt)[0].marker_names() == (
        "thumb", "index", "wrist")


def test_values_in_metres_times_and_rate_from_the_file(tmp_path):
    trial, = read_mocap(_trc(tmp_path, _reach_rows()))
    assert trial.name == "trial" and trial.rate == 100.0 and trial.units == "mm"
    np.testing.assert_allclose(trial.time, np.arange(6) / 100)
    np.testing.assert_allclose(trial.markers["index"][2], [0.102, 0.202, 0.298])
    np.testing.assert_allclose(trial.markers["wrist"][5], [0.205, 0.205, 0.295])
    assert trial.notes == () and trial.extra == {}


@pytest.mark.parametrize(("units", "scale"), [("m", 1.0), ("cm", 0.01), ("mm", 0.001)])
def test_units_from_the_units_key(tmp_path, units, scale):
    trial, = read_mocap(_trc(tmp_path, _reach_rows(), units=units))
    assert trial.units == units
    np.testing.assert_allclose(trial.markers["thumb"][1], np.array([1, 201, 299]) * scale)


def test_units_given_win_over_the_file(tmp_path):
    trial, = read_mocap(_trc(tmp_path, _reach_rows(), units="mm"), units="m")
    assert trial.units == "m"
    np.testing.assert_allclose(trial.markers["thumb"][1], [1, 201, 299])
    # a Units value that is no length is refused, unless --units says the unit
    odd = _trc(tmp_path, _reach_rows(), units="px", name="odd.trc")
    assert "unknown length unit 'px'" in str(_refused(odd))
    assert read_mocap(odd, units="mm")[0].units == "mm"


def test_units_written_as_words(tmp_path):
    assert read_mocap(_trc(tmp_path, _reach_rows(), units="Millimeters"))[0].units == "mm"


# -- lost samples -------------------------------------------------------------------------
def test_lost_samples_empty_cells_nans_of_any_case_and_missing_trailing_cells(tmp_path):
    rows = _reach_rows(6)
    rows[0][2:5] = ["", "", ""]                 # thumb lost: empty cells
    rows[1][5:8] = ["NaN", "nan", "NAN"]        # index lost: OpenSim's spellings
    rows[2][5:8] = ["Nan", "-nan", "nAn"]
    rows[3] = rows[3][:5]                       # the row ends after thumb: index, wrist lost
    rows[4][2:5] = [0, 0, 0]                    # thumb at the origin: lost
    trial, = read_mocap(_trc(tmp_path, rows))
    lost = {m: np.flatnonzero(np.isnan(xyz).all(axis=1)).tolist()
            for m, xyz in trial.markers.items()}
    assert lost == {"thumb": [0, 4], "index": [1, 2, 3], "wrist": [3]}
    assert not np.isnan(trial.markers["thumb"][3]).any()
    assert "1 samples at exactly (0, 0, 0) read as lost" in trial.notes


def test_a_marker_never_seen_is_named(tmp_path):
    rows = [r[:5] for r in _reach_rows(6, markers=3)]    # index and wrist never written
    trial, = read_mocap(_trc(tmp_path, rows))
    assert trial.lost_markers() == ("index", "wrist")
    assert any("'index', 'wrist' never seen" in n for n in trial.notes)


# -- variants seen in the wild ------------------------------------------------------------
def test_opensim_example_layout_names_off_their_columns_times_crlf(tmp_path):
    """OpenSim's own subject01 files: 'Times', an extra tab before the first name and
    before X1, no trailing tab; CRLF line ends (OpenSim's CRLF test file)."""
    lines = ["PathFileType\t4\t(X/Y/Z)\tsubject01.trc", KEYS, "60.000000\t60.000000\t3\t2\tm"
             "\t60.000000\t1\t3", "Frame#\tTimes\t\tthumb\t\tindex",
             "\t\t\tX1\tY1\tZ1\tX2\tY2\tZ2", "",
             "1\t0.4\t0.1\t0.2\t0.3\t0.4\t0.5\t0.6", "2\t0.417\t0.11\t0.2\t0.3\t0.4\t0.5\t0.6",
             "3\t0.433\t0.12\t0.2\t0.3\t0.4\t0.5\t0.6"]
    path = tmp_path / "subject01.trc"
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    trial, = read_mocap(path)
    assert trial.marker_names() == ("thumb", "index") and trial.rate == 60.0
    np.testing.assert_allclose(trial.time, [0.4, 0.417, 0.433])
    np.testing.assert_allclose(trial.markers["thumb"][:, 0], [0.1, 0.11, 0.12])
    np.testing.assert_allclose(trial.markers["index"][2], [0.4, 0.5, 0.6])


def test_cortex_padded_values_and_a_first_line_parted_by_spaces(tmp_path):
    """Motion Analysis Cortex: 'PathFileType  4', values padded with spaces, a cropped
    recording whose first frame is 185 at 3.067 s, times rounded to the ms."""
    rows = [f"{185 + i}\t{3.067 + i / 60:.3f}\t" + "\t".join(f"  {v:9.3f} " for v in
                                                         (100 + i, 200, 300, 400, 500, 600))
            + "\t" for i in range(7)]
    path = _trc(tmp_path, rows, ("R.Thumb", "R.Index"),
                values="  60.0 \t  60.0 \t    7 \t     2 \tmm \t  60.0 \t    185 \t    7")
    text = path.read_text().replace("PathFileType\t4", "PathFileType  4", 1)
    path.write_text(text)
    trial, = read_mocap(path)
    assert trial.rate == 60.0 and trial.notes == ()   # rounded times keep DataRate true
    assert trial.time[0] == pytest.approx(3.067)
    np.testing.assert_allclose(trial.markers["R.Thumb"][6], [0.106, 0.2, 0.3])


def test_pose2sim_seven_values_no_blank_line_empty_cells(tmp_path):
    """Pose2Sim's trc_write: 7 values for the 8 keys, names ending in two tabs, the rows
    straight under the X/Y/Z line, lost points as empty cells (pandas' to_csv)."""
    lines = ["PathFileType\t4\t(X/Y/Z)\tdemo.trc", KEYS, "30\t30\t3\t2\tm\t30\t3",
             "Frame#\tTime\tRWrist\t\t\tRThumb\t\t", "\t\tX1\tY1\tZ1\tX2\tY2\tZ2",
             "1\t0.0\t0.1\t0.2\t0.3\t\t\t", "2\t0.0333333\t0.1\t0.2\t0.3\t0.4\t0.5\t0.6",
             "3\t0.0666667\t0.1\t0.2\t0.3\t0.4\t0.5\t0.6"]
    path = tmp_path / "demo.trc"
    path.write_text("\n".join(lines) + "\n")
    trial, = read_mocap(path)
    assert trial.rate == 30.0 and trial.units == "m" and len(trial.time) == 3
    assert np.isnan(trial.markers["RThumb"][0]).all()
    assert "line 3 holds 7 values for the 8 keys of line 2: read in order" in trial.notes


def test_opencap_spaces_in_the_first_line_and_nan(tmp_path):
    """OpenCap's utilsDataman: 'PathFileType  4<TAB>(X/Y/Z) <folder with spaces>', %.1f
    rates, 'nan' for a lost point, no trailing tab."""
    lines = ["PathFileType  4\t(X/Y/Z) /data/Session 1/MarkerData", KEYS,
             "60.0\t60.0\t3\t2\tm\t60.0\t1\t3", "Frame#\tTime\tr_thumb\t\t\tr_index\t\t\t",
             "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\t", "",
             "1\t0.0000000\t0.1\t0.2\t0.3\tnan\tnan\tnan",
             "2\t0.0166667\t0.1\t0.2\t0.3\t0.4\t0.5\t0.6",
             "3\t0.0333333\t0.1\t0.2\t0.3\t0.4\t0.5\t0.6"]
    path = tmp_path / "opencap.trc"
    path.write_text("\n".join(lines) + "\n")
    trial, = read_mocap(path)
    assert trial.marker_names() == ("r_thumb", "r_index") and trial.rate == 60.0
    assert np.isnan(trial.markers["r_index"][0]).all()


def test_a_file_parted_by_spaces_throughout(tmp_path):
    lines = ["PathFileType 4 (X/Y/Z) spaced.trc", KEYS.replace("\t", " "),
             "100 100 3 2 mm 100 1 3", "Frame# Time thumb index", "X1 Y1 Z1 X2 Y2 Z2",
             "1 0.00 100 200 300 400 500 600", "2 0.01 101 200 300 400 500 600",
             "3 0.02 102 200 300 400 500 600"]
    path = tmp_path / "spaced.trc"
    path.write_text("\n".join(lines) + "\n")
    trial, = read_mocap(path)
    assert trial.marker_names() == ("thumb", "index")
    np.testing.assert_allclose(trial.markers["thumb"][2], [0.102, 0.2, 0.3])


def test_names_with_spaces_and_a_subject_prefix(tmp_path):
    trial, = read_mocap(_trc(tmp_path, _reach_rows(markers=3),
                             ("Subject1:R thumb tip", "Subject1:R index", "Subject1:wrist")))
    assert trial.marker_names() == ("R thumb tip", "R index", "wrist")
    assert any("'Subject1:' left out" in n for n in trial.notes)


def test_num_markers_that_disagree_with_the_names_is_a_note(tmp_path):
    path = _trc(tmp_path, _reach_rows(), values="100\t100\t6\t5\tmm\t100\t1\t6")
    trial, = read_mocap(path)
    assert len(trial.markers) == 3
    assert "NumMarkers says 5; line 4 names 3 markers: those are read" in trial.notes


# -- a cut file ---------------------------------------------------------------------------
def test_a_cut_file_is_read_as_far_as_it_goes(tmp_path):
    rows = _reach_rows(6)
    rows[5] = "6\t0.0500\t105\t205"           # cut inside the last row's first marker
    trial, = read_mocap(_trc(tmp_path, rows, frames=200))
    assert len(trial.time) == 6
    assert ("the file is cut short: its header states 200 frames (NumFrames), it holds 6: "
            "those 6 are read") in trial.notes
    assert np.isnan(trial.markers["thumb"][5, 2]) and np.isnan(trial.markers["wrist"][5]).all()
    # cut before its time: that row is left out
    rows[5] = "6\t"
    trial, = read_mocap(_trc(tmp_path, rows, frames=200, name="cut.trc"))
    assert len(trial.time) == 5 and "the last row is cut short (no time): left out" in trial.notes


def test_num_frames_below_the_rows_held_is_a_note(tmp_path):
    trial, = read_mocap(_trc(tmp_path, _reach_rows(6), frames=4))
    assert len(trial.time) == 6
    assert "NumFrames says 4; the file holds 6 frames: all 6 are read" in trial.notes


# -- the rate and the clock ---------------------------------------------------------------
def test_the_time_column_is_the_clock_a_rate_given_must_agree(tmp_path):
    path = _trc(tmp_path, _reach_rows())
    assert read_mocap(path, rate=100.5)[0].rate == 100.5     # within 1 %
    err = _refused(path, rate=50)
    assert err.field == "rate" and "DataRate" in err.problem and "`time_column` none" in \
        err.problem
    trial, = read_mocap(path, rate=50, time_column="none")
    np.testing.assert_allclose(trial.time, np.arange(6) / 50)
    assert any("the times are built from the rate given" in n for n in trial.notes)


def test_a_data_rate_the_times_do_not_keep_gives_way_to_the_clock(tmp_path):
    """OpenSim's std_walking2_markers.trc: DataRate 250, times 0.04 s apart."""
    rows = _reach_rows(6, rate=25.0)
    trial, = read_mocap(_trc(tmp_path, rows, rate="250.000000"))
    assert trial.rate == 25.0
    np.testing.assert_allclose(trial.time, np.arange(6) * 0.04)
    assert ("DataRate says 250; the time column 'Time' steps at 25 samples/s: the time column "
            "is the clock") in trial.notes


def test_a_data_rate_that_is_no_rate_leaves_the_rate_to_the_clock(tmp_path):
    path = _trc(tmp_path, _reach_rows(6), rate="0")
    trial, = read_mocap(path)
    assert trial.rate == 100.0 and "DataRate '0' is not a rate: the rate is the Time " \
        "column's" in trial.notes
    assert _refused(path, time_column="none", rate=None).field == "DataRate"


def test_a_time_column_of_frame_numbers_is_not_a_clock(tmp_path):
    rows = [[i + 1, i + 1, *r[2:]] for i, r in enumerate(_reach_rows(6))]
    err = _refused(_trc(tmp_path, rows))
    assert "counts frames" in err.problem


# -- refusals -----------------------------------------------------------------------------
def _lines(path: Path) -> list[str]:
    return path.read_text().split("\n")


def test_a_header_naming_more_markers_than_the_columns_hold_is_refused(tmp_path):
    path = _trc(tmp_path, _reach_rows(markers=2), ("thumb", "index"))
    lines = _lines(path)
    lines[3] = "Frame#\tTime\tthumb\t\t\tindex\t\t\twrist\t\t\t"
    path.write_text("\n".join(lines))
    err = _refused(path)
    assert err.problem.startswith("line 4 names 3 markers ('thumb', 'index', 'wrist'); line 5 "
                                  "labels 6 coordinate columns (X, Y, Z of 2 markers)")


def test_a_header_naming_fewer_markers_than_the_columns_hold_is_refused(tmp_path):
    path = _trc(tmp_path, _reach_rows(markers=3))
    lines = _lines(path)
    lines[3] = "Frame#\tTime\tthumb\t\t\tindex\t\t\t"
    path.write_text("\n".join(lines))
    assert "line 4 names 2 markers" in _refused(path).problem
    # with no X/Y/Z line to say so, the rows' width tells
    del lines[4]
    path.write_text("\n".join(lines))
    err = _refused(path)
    assert err.problem.startswith("data row 1 holds 11 columns (X, Y, Z of 3 markers after "
                                  "Frame# and Time); line 4 names 2 markers (8 columns)")


def test_names_with_spaces_in_a_file_parted_by_spaces_are_refused(tmp_path):
    lines = ["PathFileType 4 (X/Y/Z) spaced.trc", KEYS.replace("\t", " "),
             "100 100 2 2 mm 100 1 2", "Frame# Time R thumb R index", "X1 Y1 Z1 X2 Y2 Z2",
             "1 0.00 100 200 300 400 500 600", "2 0.01 101 200 300 400 500 600"]
    path = tmp_path / "spaced.trc"
    path.write_text("\n".join(lines) + "\n")
    assert "a marker's name cannot hold a space" in _refused(path).problem


@pytest.mark.parametrize(("damage", "said"), [
    (lambda ls: ls.__setitem__(0, "Trajectories\t100"), "not an OpenSim TRC file"),
    (lambda ls: ls.__setitem__(1, "Rate\tUnits"), "expected the header keys"),
    (lambda ls: ls.__setitem__(3, "thumb\t\t\tindex"), "expected 'Frame#, Time'"),
    (lambda ls: ls.__setitem__(3, "Frame#\tTime\t\t"), "names no marker"),
    (lambda ls: ls.__setitem__(4, "\t\tX1\tY1\tZ1\tY2\tX2\tZ2"), "not X, Y, Z per marker"),
    (lambda ls: ls.__delitem__(slice(5, None)), "no data rows"),
    (lambda ls: ls.__delitem__(slice(3, None)), "ends before its marker names"),
    (lambda ls: ls.__setitem__(6, "1\t0.0\t1\t2\tabc\t4\t5\t6"), "not a number: 'abc'"),
])
def test_damaged_files_are_refused_in_one_line(tmp_path, damage, said):
    path = _trc(tmp_path, _reach_rows(markers=2), ("thumb", "index"))
    lines = _lines(path)
    damage(lines)
    path.write_text("\n".join(lines))
    assert said in _refused(path).problem


def test_options_a_trc_file_has_no_use_for_are_refused(tmp_path):
    path = _trc(tmp_path, _reach_rows())
    assert _refused(path, trial_column="trial").field == "trial_column"
    assert _refused(path, time_column="Time").field == "time_column"
    assert _refused(path, columns="a,b,c").field == "columns"
    assert "factors" in _refused(path, factors="participant").problem


def test_the_command_line_refuses_in_one_line_with_exit_2(tmp_path, capsys):
    path = _trc(tmp_path, _reach_rows(markers=2), ("thumb", "index"))
    lines = _lines(path)
    lines[4] = "\t\tX1\tY1\tZ1"
    path.write_text("\n".join(lines))
    assert main(["recognize", str(path), "-o", str(tmp_path / "out"), "--no-figures"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(path) in err and "line 4 names 2 markers" in err
    assert main(["landmarks", str(path), "-o", str(tmp_path / "lm.csv")]) == 2
    assert str(path) in capsys.readouterr().err


# -- Anipose / DeepLabCut-3D triangulated tables (the X/Y/Z table reader) -----------------
def test_an_anipose_table_gives_its_body_parts_and_keeps_the_rest_as_extras(tmp_path):
    """Anipose's triangulate: bp_x, bp_y, bp_z, bp_error, bp_ncams, bp_score per body part,
    then M_00..M_22, center_0..2 and fnum."""
    import pandas as pd

    n, parts = 40, ("thumb_tip", "index_tip", "wrist", "box", "pinky_mcp")
    columns = {}
    for k, bp in enumerate(parts):
        for a, axis in enumerate("xyz"):
            columns[f"{bp}_{axis}"] = 100.0 * k + 3.0 * np.arange(n) * (a + 1)
        columns.update({f"{bp}_error": np.full(n, 1.5), f"{bp}_ncams": np.full(n, 3.0),
                        f"{bp}_score": np.full(n, 0.9)})
    columns["thumb_tip_x"][3] = columns["thumb_tip_y"][3] = columns["thumb_tip_z"][3] = np.nan
    columns.update({f"M_{i}{j}": np.full(n, float(i == j)) for i in range(3) for j in range(3)})
    columns.update({f"center_{i}": np.zeros(n) for i in range(3)})
    columns["fnum"] = np.arange(n)
    path = tmp_path / "pose-3d.csv"
    pd.DataFrame(columns).to_csv(path, index=False)
    assert table_layout(path) == "xyz-table"
    trial, = read_mocap(path, rate=100)
    assert trial.marker_names() == parts
    assert set(trial.extra) == {f"{bp}_{what}" for bp in parts
                                for what in ("error", "ncams", "score")} | {
        f"M_{i}{j}" for i in range(3) for j in range(3)} | {"center_0", "center_1",
                                                            "center_2", "fnum"}
    assert trial.units == "mm" and np.isnan(trial.markers["thumb_tip"][3]).all()
    np.testing.assert_allclose(trial.markers["index_tip"][2], [0.106, 0.112, 0.118])


# -- the commands, end to end -------------------------------------------------------------
def _as_trc(tsv: Path, trc: Path) -> int:
    """The Qualisys recording's rows written out as a TRC file, number for number."""
    lines = tsv.read_text().splitlines()
    names = next(line for line in lines if line.startswith("MARKER_NAMES")).split("\t")[1:]
    rows = lines[next(i for i, line in enumerate(lines) if line.startswith("Frame\t")) + 1:]
    header = [f"PathFileType\t4\t(X/Y/Z)\t{trc.name}", KEYS,
              f"100.00\t100.00\t{len(rows)}\t{len(names)}\tmm\t100.00\t1\t{len(rows)}",
              "Frame#\tTime\t" + "\t\t\t".join(names) + "\t\t",
              "\t\t" + "\t".join(f"X{k}\tY{k}\tZ{k}" for k in range(1, len(names) + 1)), ""]
    trc.write_text("\n".join(header + rows) + "\n")
    return len(rows)


def _report(folder: Path, clip: str) -> dict:
    report = json.loads((folder / f"{clip}.recognition.json").read_text())
    for key in ("input", "fingerprint"):   # the file's name, and a digest of it
        report.pop(key)
    report["mocap"].pop("source")
    return report


def test_recognize_a_trc_file_as_its_qualisys_original(tmp_path):
    trc = tmp_path / "qualisys-recording.trc"
    assert _as_trc(QTM, trc) == 350
    original, = read_mocap(QTM)
    trial, = read_mocap(trc)
    assert trial.marker_names() == original.marker_names() and trial.rate == original.rate
    np.testing.assert_array_equal(trial.time, original.time)
    for name in original.markers:
        np.testing.assert_array_equal(trial.markers[name], original.markers[name])
    assert main(["recognize", str(trc), "-o", str(tmp_path / "trc"), "--no-figures"]) == 0
    assert main(["recognize", str(QTM), "-o", str(tmp_path / "tsv"), "--no-figures"]) == 0
    got, want = _report(tmp_path / "trc", trc.stem), _report(tmp_path / "tsv", QTM.stem)
    assert got["verdict"] == want["verdict"] and got["kinematics"] == want["kinematics"]
    assert got == want
    rows = (tmp_path / "trc" / f"{trc.stem}.trials.csv").read_text().splitlines()
    assert len(rows) == 2       # one recording in, one trial with one reach out


def test_batch_landmarks_and_watch_take_trc_files(tmp_path):
    folder = tmp_path / "session"
    folder.mkdir()
    _as_trc(QTM, folder / "P01.trc")
    _as_trc(QTM, folder / "P02.trc")
    (folder / "notes.txt").write_text("participants 1 and 2\n")
    assert main(["batch", str(folder), "-o", str(tmp_path / "report")]) == 0
    batch = json.loads((tmp_path / "report" / "batch.json").read_text())
    assert (batch["clips"], batch["ok"], len(batch["skipped"])) == (2, 2, 1)  # 2 in, 2 out
    summary = (tmp_path / "report" / "summary.csv").read_text().splitlines()[1:]
    assert sorted(row.split(",")[0] for row in summary) == ["P01", "P02"]
    assert main(["landmarks", str(folder / "P01.trc"), "--markers", "thumb=thumb_tip",
                 "finger=index_tip", "-o", str(tmp_path / "lm.csv")]) == 0
    measured = (tmp_path / "lm.csv").read_text().splitlines()
    assert measured[1].startswith("P01,P01,,1,1,movement_time,")
    assert main(["watch", str(folder / "P02.trc"), "--markers", "thumb=thumb_tip",
                 "finger=index_tip", "-o", str(tmp_path / "watch"), "--no-figures",
                 "--as-fast-as-possible"]) == 0
    assert (tmp_path / "watch" / "P02.recognition.json").is_file()

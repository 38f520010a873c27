"""Issue 46's motion-capture and ``landmarks`` fault cases: each wrong input gets a clear word.

Duplicated marker names, a marker in two roles, tabs and spaces mixed in a
table, lost markers, the ``landmarks`` command's output and inputs, and the
object size a reach's note gives. The tables are written here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_reach_finding import _simple_reach

from hammer_mv.cli import main
from perception.errors import InputError
from perception.reaches import MarkerMap, ReachParams, reach_tracks, recording_reaches
from perception.report.tables import LANDMARK_UNITS


def _table(trial, **lost) -> pd.DataFrame:
    """``trial`` as an X/Y/Z table in mm, with each ``lost`` marker (name=True) at (0, 0, 0)."""
    cols = {"time": trial.time}
    markers = dict(trial.markers)
    for name in lost:
        markers[name] = np.zeros((len(trial.time), 3))
    for m, xyz in markers.items():
        for k, ax in enumerate("xyz"):
            cols[f"{m}_{ax}"] = xyz[:, k] * 1000
    return pd.DataFrame(cols)


def _reach():
    return _simple_reach([(0.75, 1.05, 1.4, 0.05, 0.035)])


# -- a marker in two roles ---------------------------------------------------------------------
@pytest.mark.parametrize("kwargs, field", [
    (dict(thumb="thumb", finger="thumb"), "finger"),
    (dict(thumb="t", finger="i", wrist=("w", "t")), "wrist"),
    (dict(thumb="t", finger="i", object="i"), "object"),
    (dict(thumb="t", finger="i", wrist="w", object="w"), "object"),
])
def test_one_marker_in_two_roles_is_refused_naming_the_field(kwargs, field):
    with pytest.raises(InputError) as err:
        MarkerMap(**kwargs)
    assert err.value.field == field


def test_markers_on_the_command_line_in_two_roles_exit_2(tmp_path, capsys):
    path = tmp_path / "reach.tsv"
    _table(_reach()).to_csv(path, sep="\t", index=False)
    code = main(["landmarks", str(path), "-o", str(tmp_path / "out.csv"),
                 "--markers", "thumb=thumb", "finger=thumb"])
    assert code == 2
    assert "same marker" in capsys.readouterr().err
    assert not (tmp_path / "out.csv").exists()


def test_a_mapped_name_matching_two_markers_but_for_case_is_refused():
    trial = _reach()
    trial = type(trial)(trial.name, trial.source, trial.time,
                        {**trial.markers, "Wrist": trial.markers["thumb"] + 0.05,
                         "WRIST": trial.markers["thumb"] + 0.06}, trial.rate, "m")
    with pytest.raises(InputError, match="'WRIST', 'Wrist'") as err:
        recording_reaches(trial, MarkerMap("thumb", "index", wrist="wrist"))
    assert err.value.field == "markers"


# -- landmarks: its output and its inputs -------------------------------------------------------
def test_landmarks_refuses_an_output_that_is_not_csv(tmp_path, capsys):
    path = tmp_path / "reach.tsv"
    _table(_reach()).to_csv(path, sep="\t", index=False)
    code = main(["landmarks", str(path), "-o", str(tmp_path / "x.png")])
    assert code == 2
    err = capsys.readouterr().err
    assert ".csv" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.png").exists()


def test_landmarks_of_the_same_table_twice_measures_it_once(tmp_path, capsys):
    path = tmp_path / "reach.tsv"
    _table(_reach()).to_csv(path, sep="\t", index=False)
    out = tmp_path / "out.csv"
    main(["landmarks", str(path), str(path), "-o", str(out)])
    table = pd.read_csv(out)  # one movement: a row per landmark of it, once
    assert table["trial"].nunique() == 1 and len(table) == len(LANDMARK_UNITS)
    assert "more than once" in capsys.readouterr().err


def test_landmarks_of_a_missing_table_says_not_found(tmp_path):
    from perception.measure import landmarks

    with pytest.raises(InputError, match="not found"):
        landmarks(tmp_path / "nosuch.tsv")


# -- a reach's note gives the object size used -------------------------------------------------
def test_the_object_size_note_gives_the_size_used():
    # the grip closes 5 mm below its rest: no size; the least, 5 mm, is used
    trial = _simple_reach([(0.75, 1.05, 1.4, 0.05, -0.005)])
    reach = recording_reaches(trial, MarkerMap("thumb", "index"))[0]
    info = reach_tracks(reach).info
    said = [n for n in info["notes"] if n.startswith("object size")]
    assert info["object_size"] == pytest.approx(0.005)
    assert said and "object size: 5 mm" in said[0], said


# -- tabs and spaces mixed in a table -----------------------------------------------------------
def _mixed(tmp_path, header: str, row) -> Path:
    path = tmp_path / "mixed.tsv"
    path.write_text(header + "".join(row(i) for i in range(50)))
    return path


def test_a_table_parting_some_fields_by_spaces_loses_no_column(tmp_path):
    from perception.io.mocap import read_mocap

    path = _mixed(tmp_path, "time\tthumb_x thumb_y\tthumb_z\tindex_x\tindex_y\tindex_z\n",
                  lambda i: f"{i / 100}\t{i} {2 * i}\t{3 * i + 100}\t{i + 300}\t2\t{i * 5}\n")
    trial = read_mocap(path)[0]
    assert sorted(trial.markers) == ["index", "thumb"]
    assert np.allclose(trial.markers["thumb"][3], [0.003, 0.006, 0.109])
    assert any("tabs and spaces" in n for n in trial.notes)


def test_a_table_whose_mixed_separators_leave_rows_uneven_is_refused_naming_the_line(tmp_path):
    from perception.io.mocap import read_mocap

    path = _mixed(tmp_path, "time\tthumb x\tthumb_y\tthumb_z\tindex_x\tindex_y\tindex_z\n",
                  lambda i: f"{i / 100}\t{i} {2 * i}\t{3 * i + 100}\t{i + 300}\t2\t{i * 5}\n")
    with pytest.raises(InputError, match="line 2 parts its fields by tabs and spaces"):
        read_mocap(path)


# -- duplicated and unlisted marker names are said ----------------------------------------------
def _qtm(tmp_path, names, columns, *, markers=None):
    """A Qualisys export of 30 frames whose MARKER_NAMES line lists ``names``."""
    text = (f"NO_OF_FRAMES\t30\nNO_OF_CAMERAS\t7\nNO_OF_MARKERS\t{markers or len(names)}\n"
            "FREQUENCY\t100\nDATA_INCLUDED\t3D\nMARKER_NAMES\t" + "\t".join(names) + "\n"
            "Frame\tTime\t" + "\t".join(f"{c} {a}" for c in columns for a in "XYZ") + "\n")
    for i in range(30):
        text += f"{i + 1}\t{i / 100:.5f}\t" + "\t".join(
            f"{100 + i + 10 * k + j:.3f}" for k in range(len(columns)) for j in range(3)) + "\n"
    path = tmp_path / "qtm.tsv"
    path.write_text(text)
    return path


@pytest.mark.parametrize("names, columns, markers, said", [
    (["thumb", "", "index"], ["thumb", "index"], None, "MARKER_NAMES leaves name 2 empty"),
    (["thumb", "index"], ["thumb", "index"], 3, "NO_OF_MARKERS says 3; MARKER_NAMES lists 2"),
    (["thumb", "Thumb", "index"], ["thumb", "Thumb", "index"], None,
     "marker names apart only in case ('thumb', 'Thumb')"),
])
def test_a_qualisys_marker_list_that_disagrees_is_noted(tmp_path, names, columns, markers, said):
    from perception.io.mocap import read_mocap

    (trial,) = read_mocap(_qtm(tmp_path, names, columns, markers=markers))
    assert any(said in n for n in trial.notes), trial.notes


def test_a_qualisys_name_listed_twice_is_refused_naming_it(tmp_path):
    from perception.io.mocap import read_mocap

    with pytest.raises(InputError, match="'thumb' named more than once"):
        read_mocap(_qtm(tmp_path, ["thumb", "thumb", "index"], ["thumb", "thumb", "index"]))


def test_c3d_labels_written_thrice_say_what_each_is_read_as(tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    from perception.io.mocap import read_mocap

    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("index", "index", "index")
    points = np.ones((4, 3, 50))
    points[:3] = np.random.default_rng(2).uniform(100, 400, (3, 3, 50))
    c3d["data"]["points"] = points
    path = tmp_path / "thrice.c3d"
    c3d.write(str(path))
    (trial,) = read_mocap(path)
    assert trial.marker_names() == ("index", "index_2", "index_3")
    assert any("'index' as 'index', 'index_2', 'index_3'" in n for n in trial.notes), trial.notes


def test_repeated_subject_marker_names_say_what_each_is_read_as():
    from perception.io.mocap_trial import strip_subject

    names, notes = strip_subject(["thumb", "thumb", "index"])
    assert names == ["thumb", "thumb_2", "index"]
    assert any("'thumb' as 'thumb', 'thumb_2'" in n for n in notes), notes


# -- the numbers that shape a reach are declared ----------------------------------------------
def test_a_synthesised_wrist_is_placed_wrist_behind_the_grip():
    trial = _simple_reach([(0.75, 1.05, 1.4, 0.05, 0.04)])
    reach = recording_reaches(trial, MarkerMap("thumb", "index"))[0]
    for behind in (0.06, 0.09):
        tracks = reach_tracks(reach, ReachParams(wrist_behind=behind)).tracks
        pos = {m: tracks.position[:, i] for i, m in enumerate(tracks.markers)}
        mid = 0.5 * (pos["thumb"] + pos["finger"])
        assert tracks.units == "m"
        gap = np.linalg.norm(mid - pos["wrist"], axis=1)
        assert np.nanmedian(gap) == pytest.approx(behind, abs=1e-9)


def test_min_rest_is_the_rest_a_reach_is_given():
    trial = _simple_reach([(0.75, 1.05, 1.4, 0.05, 0.04)])
    reach = recording_reaches(trial, MarkerMap("thumb", "index"))[0]
    rest = {}
    for need in (0.3, 1.5):
        info = reach_tracks(reach, ReachParams(min_rest=need)).info
        rest[need] = [n for n in info["notes"] if "of rest before the movement" in n]
    assert not rest[0.3] and rest[1.5], rest  # 0.75 s of rest: enough for 0.3 s, not 1.5 s

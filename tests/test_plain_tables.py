"""Plain tables read without pandas read as pandas reads them (perception.io.plain_tables).

A DeepLabCut csv, a Qualisys TSV export and a recording's ``trials.csv`` are read or
written without pandas where they are plain (issue 45 item 4: pandas' import was the
whole start-up margin of a pose or motion-capture file); each is compared here with
pandas' own reading or writing, value for value, on the plain case and on tables that
must be left to pandas (which then read exactly as before).
"""

from __future__ import annotations

import io
import random

import numpy as np
import pandas as pd
import pytest

from perception.io import mocap_qtm, pose
from perception.io.mocap import read_mocap
from perception.io.mocap_text import _read_options, header_width
from perception.io.plain_tables import dlc_table, numeric_table
from perception.io.pose import PoseImport

# ---------------------------------------------------------------- values


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bit for bit (NaN where NaN, -0.0 where -0.0)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and bool(np.all(a.view(np.int64) == b.view(np.int64)))


# ---------------------------------------------------------------- DeepLabCut csv

MARKERS4 = ("thumb", "finger", "wrist", "object")

_HEADER = ("scorer" + ",DLC" * 12 + "\n"
           "bodyparts,thumb,thumb,thumb,finger,finger,finger,wrist,wrist,wrist,"
           "object,object,object\n" + "coords" + ",x,y,likelihood" * 4 + "\n")
#: The wrist's and the object's cells, after the thumb's and the finger's of each row.
_REST = ",5,6,1,7,8,1"


def _rows(text: str) -> str:
    """Data lines of the thumb and finger cells, completed with :data:`_REST`."""
    return "".join(line + _REST + end for line, end in
                   zip(text.split("\n"), ["\n"] * text.count("\n") + [""]) if line or end)


def _pandas_dlc(path, levels):
    df = pd.read_csv(path, header=list(range(levels)))
    df = df.set_index(df.columns[0])
    return [c for c in df.columns], df.index.to_numpy(), df.to_numpy()


#: Tables read without pandas, each as pandas reads it.
PLAIN = {
    "repr floats": _HEADER + _rows("0,314.6714679176009,295.8,1.0,1e-3,.5,0.25\n"
                                   "1,3.,-2.5E+2,0,12,-7,1\n"),
    "CRLF, no last newline": (_HEADER + _rows("0,1.5,2.5,0.9,3,4,1\n1,1.25,2.75,0.8,3,4,1")
                              ).replace("\n", "\r\n"),
    "blank cells and NaN": _HEADER + _rows("0,,NaN,0.0,nan,4,\n1,1,2,,3,4,1\n"),
    "integers only": _HEADER + _rows("0,1,2,1,3,4,1\n1,5,6,0,7,8,1\n"),
    "quoted header": (_HEADER.replace(",x,y,likelihood", ',"x","y","like,lihood"')
                      .replace("object\n", '"object"\n') + _rows("0,1.5,2.5,0.9,3,4,1\n")),
    "quoted names": (_HEADER.replace(",x,y,likelihood", ',"x","y","likelihood"')
                     + _rows("0,1.5,2.5,0.9,3,4,1\n")),
    "long digits": _HEADER + _rows("0,0.1000000000000000055511151231257827,"
                                   "1.7976931348623157e308,4.9e-324,2.2250738585072014e-308,"
                                   "123456789012345,0.3\n"),
}

#: Tables left to pandas (plain_tables answers None).
LEFT = {
    "a blank line": _HEADER + _rows("0,1,2,1,3,4,1\n") + "\n" + _rows("1,1,2,1,3,4,1\n"),
    "a lone CR": (_HEADER + _rows("0,1,2,1,3,4,1\n")).replace("\n", "\r"),
    "quotes in the data": _HEADER + _rows('0,"1",2,1,3,4,1\n'),
    "minus zero integer": _HEADER + _rows("0,-0,2,1,3,4,1\n"),
    "a 16-digit integer": _HEADER + _rows("0,1234567890123456,2,1,3,4,1\n"),
    "inf": _HEADER + _rows("0,inf,2,1,3,4,1\n"),
    "NA": _HEADER + _rows("0,NA,2,1,3,4,1\n"),
    "spaces": _HEADER + _rows("0, 1,2,1,3,4,1\n"),
    "a short row": _HEADER + _rows("0,1,2,1,3,4\n"),
    "an empty header cell": (_HEADER.replace("finger,finger", "finger,", 1)
                             + _rows("0,1,2,1,3,4,1\n")),
    "image paths for frames": _HEADER + _rows("labeled-data/img001.png,1,2,1,3,4,1\n"),
    "float frame numbers": _HEADER + _rows("0.0,1,2,1,3,4,1\n"),
    "a unicode line break": _HEADER + _rows("0,1,2,1,3,4,1\u2028\n"),
    "no data": _HEADER,
    "a text cell": _HEADER + _rows("0,one,2,1,3,4,1\n"),
}


@pytest.mark.parametrize("name", PLAIN)
def test_a_plain_dlc_csv_reads_as_pandas_reads_it(tmp_path, name):
    path = tmp_path / "grasp.csv"
    path.write_bytes(PLAIN[name].encode())
    read = dlc_table(path.read_bytes().decode(), 3)
    assert read is not None, name
    columns, frames, values = read
    theirs = _pandas_dlc(path, 3)
    assert columns == theirs[0]
    assert frames.dtype == np.int64 and np.array_equal(frames, theirs[1])
    assert _same(values, theirs[2])


@pytest.mark.parametrize("name", LEFT)
def test_a_dlc_csv_that_is_not_plain_is_left_to_pandas(name):
    assert dlc_table(LEFT[name], 3) is None


def _tracks_both_ways(monkeypatch, path, options):
    """read_pose's tracks (or its error) as read now, and through pandas and movement."""
    def read():
        try:
            return pose.read_pose(path, options)
        except Exception as exc:  # noqa: BLE001 - the same error both ways, whatever it is
            return f"{type(exc).__name__}: {exc}"

    ours = read()
    with monkeypatch.context() as m:
        m.setattr(pose, "dlc_table", lambda text, levels: None)
        theirs = read()
    return ours, theirs


@pytest.mark.parametrize("name", [*PLAIN, *LEFT])
def test_read_pose_gives_what_pandas_and_movement_give(tmp_path, monkeypatch, name):
    text = {**PLAIN, **LEFT}[name]
    path = tmp_path / "grasp.csv"
    path.write_bytes(text.encode())
    options = PoseImport(fps=30.0, cleaning=None, pcutoff=0.0)
    ours, theirs = _tracks_both_ways(monkeypatch, path, options)
    if isinstance(theirs, str):
        assert ours == theirs
        return
    assert not isinstance(ours, str), ours
    for field in ("frame", "time", "position", "likelihood", "status"):
        assert _same(getattr(ours, field), getattr(theirs, field)), field
    assert ours.video == theirs.video and ours.tracker == theirs.tracker


def test_a_multi_animal_dlc_csv_reads_as_through_pandas(tmp_path, monkeypatch):
    rng = np.random.default_rng(7)
    tuples = [("DLC", who, part, c) for who in ("m1", "m2") for part in MARKERS4
              for c in ("x", "y", "likelihood")]
    df = pd.DataFrame(rng.uniform(1, 600, (12, len(tuples))),
                      columns=pd.MultiIndex.from_tuples(
                          tuples, names=["scorer", "individuals", "bodyparts", "coords"]))
    df.iloc[3, 4] = np.nan
    path = tmp_path / "grasp.csv"
    df.to_csv(path)
    assert dlc_table(path.read_text(), 4) is not None
    ours, theirs = _tracks_both_ways(monkeypatch, path, PoseImport(fps=25.0, individual="m2"))
    assert not isinstance(ours, str), ours
    for field in ("frame", "time", "position", "likelihood", "status"):
        assert _same(getattr(ours, field), getattr(theirs, field)), field
    assert ours.tracker == theirs.tracker


def test_a_dlc_csv_whose_columns_are_out_of_order_is_left_to_pandas(tmp_path, monkeypatch):
    # y before x: movement's reshape reads the columns in their order; so must we
    header = _HEADER.replace("coords,x,y", "coords,y,x")
    assert dlc_table(header + _rows("0,1,2,1,3,4,1\n"), 3) is not None  # the caller checks
    path = tmp_path / "grasp.csv"
    path.write_text(header + _rows("0,1,2,1,3,4,1\n1,1,2,1,3,4,1\n"))
    assert pose._plain_dlc(path, 30.0) is None
    ours, theirs = _tracks_both_ways(monkeypatch, path, PoseImport(fps=30.0))
    assert ours == theirs if isinstance(theirs, str) else _same(ours.position, theirs.position)


def test_reading_a_dlc_csv_loads_neither_pandas_nor_movement(tmp_path):
    import subprocess
    import sys

    from _demos import dlc_csv

    path, tracks = dlc_csv(tmp_path)
    code = ("import sys\n"
            "from perception.io.pose import PoseImport, read_pose\n"
            f"t = read_pose({str(path)!r}, PoseImport(fps=30.0))\n"
            "print(len(t.frame))\n"
            "print(*[m for m in ('pandas', 'movement', 'xarray') if m in sys.modules]"
            " or ['none'])\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=300).stdout
    assert out.split() == [str(len(tracks.frame)), "none"]


# ---------------------------------------------------------------- Qualisys TSV


def _qtm(rows: str, header: str = "Frame\tTime\tm1 X\tm1 Y\tm1 Z\tm2 X\tm2 Y\tm2 Z\t\n") -> str:
    return ("NO_OF_FRAMES\t3\nNO_OF_MARKERS\t2\nFREQUENCY\t100\nDATA_INCLUDED\t3D\n"
            "MARKER_NAMES\tm1\tm2\n" + header + rows)


_ROWS = ("1\t0.00000\t110.406\t135.075\t460.584\t62.382\t161.390\t450.921\n"
         "2\t0.01000\t110.763\tnan\t460.458\t62.756\t161.680\t450.796\n"
         "3\t0.02000\t111.120\t135.659\t\t63.103\t-0.000\t1e2\n")

QTM_PLAIN = {
    "QTM's header ending in a tab": _qtm(_ROWS),
    "CRLF": _qtm(_ROWS).replace("\n", "\r\n"),
    "rows as wide as the header": _qtm(_ROWS.replace("\n", "\t\n")),
    "no tab after the header": _qtm(_ROWS, "Frame\tTime\tm1 X\tm1 Y\tm1 Z\tm2 X\tm2 Y\tm2 Z\n"),
    "spaces around names": _qtm(_ROWS, "Frame\t Time \tm1 X\tm1 Y\tm1 Z\tm2 X\tm2 Y\tm2 Z\t\n"),
}

QTM_LEFT = {
    "a blank line": _qtm(_ROWS.replace("\n", "\n\n", 1)),
    "a quoted name": _qtm(_ROWS, 'Frame\t"Time"\tm1 X\tm1 Y\tm1 Z\tm2 X\tm2 Y\tm2 Z\t\n'),
    "a name twice": _qtm(_ROWS, "Frame\tTime\tm1 X\tm1 X\tm1 Z\tm2 X\tm2 Y\tm2 Z\t\n"),
    "a short row": _qtm(_ROWS + "4\t0.03\t1\t2\t3\n"),
    "a text cell": _qtm(_ROWS + "4\t0.03\t1\t2\t3\t4\tfive\t6\n"),
    "a decimal comma": _qtm(_ROWS.replace("110.406", "110,406")),
    "a space before a number": _qtm(_ROWS.replace("\t110.406", "\t 110.406")),
    "an empty name inside": _qtm(_ROWS, "Frame\t\tm1 X\tm1 Y\tm1 Z\tm2 X\tm2 Y\tm2 Z\t\n"),
}


def _pandas_qtm(raw: bytes, skip: int):
    df = pd.read_csv(io.BytesIO(raw), **_read_options("\t", skip, 0, "."), low_memory=False)
    header_width(df)
    return list(df.columns), df.to_numpy(dtype=float)


@pytest.mark.parametrize("name", QTM_PLAIN)
def test_a_plain_qtm_table_reads_as_pandas_reads_it(name):
    raw = QTM_PLAIN[name].encode()
    table = numeric_table(raw, "\t", 5, 1000)
    assert table is not None
    columns, values = _pandas_qtm(raw, 5)
    assert table.columns == columns
    assert _same(table.values, values)
    assert len(table) == 3 and table.shape == values.shape


@pytest.mark.parametrize("name", QTM_LEFT)
def test_a_qtm_table_that_is_not_plain_is_left_to_pandas(name):
    assert numeric_table(QTM_LEFT[name].encode(), "\t", 5, 1000) is None


def test_more_rows_than_allowed_are_left_to_pandas():
    assert numeric_table(QTM_PLAIN["CRLF"].encode(), "\t", 5, 2) is None


@pytest.mark.parametrize("name", [*QTM_PLAIN, *QTM_LEFT])
def test_read_mocap_of_a_qtm_file_gives_what_pandas_gives(tmp_path, monkeypatch, name):
    path = tmp_path / "rec.tsv"
    path.write_bytes({**QTM_PLAIN, **QTM_LEFT}[name].encode())

    def read():
        try:
            return read_mocap(path, rate=None)
        except Exception as exc:  # noqa: BLE001 - the same error both ways
            return f"{type(exc).__name__}: {exc}"

    ours = read()
    with monkeypatch.context() as m:
        m.setattr(mocap_qtm, "numeric_table", lambda *args: None)
        theirs = read()
    if isinstance(theirs, str):
        assert ours == theirs
        return
    assert not isinstance(ours, str), ours
    assert len(ours) == len(theirs)
    for a, b in zip(ours, theirs):
        assert a.notes == b.notes and a.rate == b.rate and a.units == b.units
        assert list(a.markers) == list(b.markers)
        assert _same(a.time, b.time)
        for m in a.markers:
            assert _same(a.markers[m], b.markers[m]), m


def test_the_shipped_qualisys_file_is_read_without_pandas():
    import subprocess
    import sys
    from pathlib import Path

    path = Path(__file__).parent / "data" / "mocap" / "qualisys-recording.tsv"
    code = ("import sys\n"
            "from perception.io.mocap import read_mocap\n"
            f"print(len(read_mocap({str(path)!r})))\n"
            "print('pandas' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=300).stdout
    assert out.split() == ["1", "False"]


# ---------------------------------------------------------------- trials.csv


def test_a_trials_table_is_written_as_pandas_writes_it(tmp_path):
    from hammer_mv.cli.recording import _trials_table_cells
    from perception.io.atomic import write_csv

    pool = [None, float("nan"), 1, 2, 0, -3, 1.5, 0.1, 1e-7, 123456.789, 1e16, -0.0, 2.0,
            "a", "b c", 'x,"y"', "", "1", True, np.float64(0.3), np.int64(4)]
    columns = ["trial", "participant", "trial_number", "reach_number", "onset_time"]
    rng = random.Random(3)
    compared = 0
    for _ in range(600):
        kinds = {c: rng.sample(pool, rng.randint(1, 4)) for c in columns}
        rows = [{c: rng.choice(kinds[c]) for c in columns if rng.random() < 0.9}
                for _ in range(rng.randint(0, 5))]
        try:
            df = pd.DataFrame(rows, columns=columns).astype({"reach_number": "Int64"})
        except (TypeError, ValueError):
            continue  # pandas refuses such a reach_number: not a recording's
        cells = _trials_table_cells(rows, columns)
        write_csv(tmp_path / "pandas.csv", df)
        write_csv(tmp_path / "ours.csv", cells)
        assert (tmp_path / "ours.csv").read_bytes() == (tmp_path / "pandas.csv").read_bytes(), \
            rows
        compared += isinstance(cells, dict)
    assert compared > 100  # most written without pandas


def test_a_dlc_csv_with_text_among_its_values_is_refused_in_one_line(tmp_path):
    # pandas reads the column as text; its values reached numpy as objects, and
    # float('one') was a bug's traceback (ValueError) rather than the user's error
    from perception.errors import InputError

    path = tmp_path / "grasp.csv"
    path.write_bytes(LEFT["a text cell"].encode())
    with pytest.raises(InputError, match=r"a value of keypoint 'thumb' is not a number"):
        pose.read_pose(path, PoseImport(fps=30.0))

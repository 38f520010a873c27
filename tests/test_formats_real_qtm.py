"""Qualisys Track Manager TSV exports in the variants QTM and spreadsheets write.

Written here in the layout of QTM's "Motion data (.tsv)" export
(docs.qualisys.com, QTM manual; the header lines as in the QTM 2022 exports
quoted in pberck/mocap, MoCapReader's docstring): the header keys, then
``Frame  Time  [SMPTE]  name X  name Y  name Z  [name Type] ...``. The
optional columns: a SMPTE timecode, and a ``Type`` column per marker when
"Include type information per frame" is set. A European spreadsheet that
opens and saves the file again writes decimal commas.
"""

from __future__ import annotations

import numpy as np
import pytest

from perception.errors import InputError
from perception.io.mocap import read_mocap

NAMES = ("thumb_tip", "index_tip", "wrist")


def _qtm(path, *, decimal=".", smpte=False, types=False, rows=40):
    head = [f"NO_OF_FRAMES\t{rows}", "NO_OF_CAMERAS\t20", "NO_OF_MARKERS\t3",
            "FREQUENCY\t200", "NO_OF_ANALOG\t0", "ANALOG_FREQUENCY\t0", "DESCRIPTION\t--",
            "TIME_STAMP\t2022-06-02, 15:49:44.620\t25975.44751328", "DATA_INCLUDED\t3D",
            "MARKER_NAMES\t" + "\t".join(NAMES),
            "TRAJECTORY_TYPES\t" + "\t".join(["Measured"] * 3)]
    columns = ["Frame", "Time"] + (["SMPTE"] if smpte else [])
    for name in NAMES:
        columns += [f"{name} {a}" for a in "XYZ"] + ([f"{name} Type"] if types else [])
    lines = head + ["\t".join(columns)]
    values = 100.0 + np.arange(rows * 9).reshape(rows, 9) * 0.125
    for i in range(rows):
        cells = [str(i + 1), f"{i / 200:.5f}"] + ([f"15:49:44:{i % 25:02d}"] if smpte else [])
        for k in range(3):
            cells += [f"{v:.3f}" for v in values[i, 3 * k:3 * k + 3]]
            cells += ["Gap-filled" if i == 3 else "Measured"] if types else []
        lines.append("\t".join(c.replace(".", decimal) if c[:1].isdigit() and ":" not in c
                               else c for c in cells))
    path.write_text("\n".join(lines) + "\n")
    return values


def test_decimal_commas_are_read(tmp_path):
    values = _qtm(tmp_path / "komma.tsv", decimal=",")
    (trial,) = read_mocap(tmp_path / "komma.tsv")
    np.testing.assert_allclose(trial.markers["index_tip"], values[:, 3:6] / 1000)
    np.testing.assert_allclose(trial.time[:3], [0, 0.005, 0.01])
    assert trial.rate == 200


def test_type_and_timecode_columns_are_named_not_read(tmp_path):
    values = _qtm(tmp_path / "typed.tsv", smpte=True, types=True)
    (trial,) = read_mocap(tmp_path / "typed.tsv")
    assert trial.marker_names() == NAMES
    np.testing.assert_allclose(trial.markers["wrist"], values[:, 6:9] / 1000)
    assert "the markers' 'Type' columns not read (3 columns)" in trial.notes
    assert "column 'SMPTE' not read (not a marker's X, Y, Z)" in trial.notes
    assert not any("does not list" in n for n in trial.notes)  # they are all listed


def test_a_comma_in_a_dotted_table_is_still_refused(tmp_path):
    _qtm(tmp_path / "mixed.tsv")
    lines = (tmp_path / "mixed.tsv").read_text().splitlines()
    cells = lines[14].split("\t")
    cells[2] = cells[2].replace(".", ",")  # one cell in 120 with a comma: no decimal commas
    lines[14] = "\t".join(cells)
    (tmp_path / "mixed.tsv").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="thumb_tip X: not a number: '102,250'"):
        read_mocap(tmp_path / "mixed.tsv")

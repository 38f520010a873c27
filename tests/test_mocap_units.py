"""A table that says its unit in its column names is read in that unit.

``Thumb X (cm)``, ``thumb.x [m]``, ``THUMB_X_mm``: the unit a lab's export
writes beside each coordinate wins over the one the positions' spread would
suggest (a reach of 70 cm read as 70 mm before), and columns that disagree
are refused unless ``units`` says.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from perception.errors import InputError
from perception.io.mocap import read_mocap

DATA = Path(__file__).parent / "data" / "mocap"


@pytest.fixture(scope="module")
def trial():
    return read_mocap(DATA / "optotrak-trials.tsv", rate=85.0)[0]


def _table(trial, path, column, scale):
    """``trial``'s thumb and index as a table with a time column, ``column(marker, axis)``
    naming each coordinate, in metres times ``scale``."""
    table = {"time": trial.time - trial.time[0]}
    for marker in ("thumb", "index"):
        for k, axis in enumerate("XYZ"):
            table[column(marker, axis)] = trial.markers[marker][:, k] * scale
    pd.DataFrame(table).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("column, scale, unit", [
    (lambda m, a: f"{m.capitalize()} {a} (cm)", 100.0, "cm"),
    (lambda m, a: f"{m}.{a.lower()} [m]", 1.0, "m"),
    (lambda m, a: f"{m.upper()}_{a}_mm", 1000.0, "mm"),
    (lambda m, a: f"{m.capitalize()} ({a})", 1000.0, "mm"),  # none said: inferred
])
def test_the_unit_the_columns_state_is_the_tables(trial, tmp_path, column, scale, unit):
    (got,) = read_mocap(_table(trial, tmp_path / "take.csv", column, scale))
    assert got.units == unit
    names = {m.lower(): m for m in got.markers}
    assert set(names) == {"thumb", "index"}  # "Thumb (X)": no bracket left in the name
    for marker in ("thumb", "index"):
        np.testing.assert_allclose(got.markers[names[marker]], trial.markers[marker],
                                   atol=1e-9)


def test_columns_that_state_different_units_are_refused_unless_units_says(trial, tmp_path):
    path = _table(trial, tmp_path / "take.csv",
                  lambda m, a: f"{m}_{a} ({'cm' if m == 'thumb' else 'mm'})", 100.0)
    with pytest.raises(InputError, match="state different units") as err:
        read_mocap(path)
    assert err.value.field == "units"
    assert read_mocap(path, units="cm")[0].units == "cm"


def test_a_large_table_read_trial_by_trial_states_its_unit_alike(trial, tmp_path, monkeypatch):
    from perception.io import mocap_stream

    path = tmp_path / "session.csv"
    table = {"trial": np.repeat([1, 2], len(trial.time)),
             "time": np.tile(trial.time - trial.time[0], 2)}
    for marker in ("thumb", "index"):
        for k, axis in enumerate("XYZ"):
            table[f"{marker} {axis} (cm)"] = np.tile(trial.markers[marker][:, k] * 100, 2)
    pd.DataFrame(table).to_csv(path, index=False)
    monkeypatch.setattr(mocap_stream, "STREAM_BYTES", 0)  # streamed, as a large file is
    trials = read_mocap(path)
    assert type(trials).__name__ == "TrialStream" and len(trials) == 2
    for got in trials:
        assert got.units == "cm"
        np.testing.assert_allclose(got.markers["thumb"], trial.markers["thumb"], atol=1e-9)


def _two_row(trial, path, units_row=None, scale=1000.0):
    """``trial``'s thumb and index under a header of two rows (the markers' names above
    their x, y, z), with a row of units below it if given."""
    rows = ["time,thumb,,,index,,", ",x,y,z,x,y,z"] + ([units_row] if units_row else [])
    for i, t in enumerate(trial.time - trial.time[0]):
        values = [v * scale for m in ("thumb", "index") for v in trial.markers[m][i]]
        rows.append(",".join([f"{t:.6f}", *(f"{v:.6f}" for v in values)]))
    path.write_text("\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("units_row, scale, unit", [
    (None, 1000.0, "mm"),            # inferred
    ("s,cm,cm,cm,cm,cm,cm", 100.0, "cm"),  # said by the units row
])
def test_a_header_of_two_rows_names_each_markers_x_y_z(trial, tmp_path, units_row, scale,
                                                       unit):
    from perception.io.mocap import table_layout

    path = _two_row(trial, tmp_path / "take.csv", units_row, scale)
    assert table_layout(path) == "xyz-table"
    (got,) = read_mocap(path)
    assert got.marker_names() == ("thumb", "index") and got.units == unit
    assert got.rate == pytest.approx(85.0, rel=1e-3)
    for marker in ("thumb", "index"):
        np.testing.assert_allclose(got.markers[marker], trial.markers[marker], atol=1e-6)
    assert any("two rows" in n for n in got.notes)


def test_an_axis_without_its_markers_name_is_no_two_row_header(trial, tmp_path):
    from perception.io.mocap import table_layout

    path = _two_row(trial, tmp_path / "take.csv")
    lines = path.read_text().splitlines()
    lines[0] = "time,,,,index,,"  # the thumb's name left out
    path.write_text("\n".join(lines) + "\n")
    assert table_layout(path) is None

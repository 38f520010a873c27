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

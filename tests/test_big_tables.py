"""Large long tables read trial by trial (issue 46, "Size"): the same trials and landmarks as
read whole, in memory that does not grow with the number of trials, with progress said.

A table above :data:`perception.io.mocap_stream.STREAM_BYTES` is read in
chunks of :data:`~perception.io.mocap_stream.CHUNK_ROWS` rows; here both are
forced small, so that tables of a few kB take that path and a trial spans
several chunks.
"""

import io
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io import mocap_stream, mocap_text
from perception.io.mocap import read_mocap
from perception.io.mocap_trial import TrialStream, reading_progress
from perception.measure import measure
from perception.recordings import MocapImport

REAL = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"


@pytest.fixture
def streamed(monkeypatch):
    """Every table with a trial column read trial by trial, 100 rows a chunk."""
    monkeypatch.setattr(mocap_stream, "STREAM_BYTES", 0)
    monkeypatch.setattr(mocap_stream, "CHUNK_ROWS", 100)


def _whole(path, **kw):
    old = mocap_stream.STREAM_BYTES
    mocap_stream.STREAM_BYTES = 1 << 62
    try:
        return read_mocap(path, **kw)
    finally:
        mocap_stream.STREAM_BYTES = old


def write_table(path: Path, trials: int = 6, rows: int = 150, *, sep: str = "\t",
                time: str | None = None, decimal: str = ".", seed: int = 0) -> Path:
    """A long table: trial ids, a participant, thumb/index/wrist in mm, a text column, a
    count, an empty column; an optional time column (``"s"``, ``"ms"``); lost samples."""
    rng = np.random.default_rng(seed)
    head = ["trial", *(["time"] if time else []), "participant", *(
        f"{m}_{a}" for m in ("thumb", "index", "wrist") for a in "xyz"), "note", "count",
        "spare"]
    lines = [sep.join(head)]
    for k in range(trials):
        xyz = 300 + np.cumsum(rng.normal(0, 2, (rows, 9)), axis=0)
        xyz[rng.integers(0, rows, 3), 0:3] = 0  # the thumb lost: at the origin
        for i in range(rows):
            cells = [str(100 + k)]
            if time:
                cells.append(f"{i / 100:.2f}" if time == "s" else f"{10 * i}")
            cells += [f"P{k // 3}", *(f"{v:.3f}" for v in xyz[i]), f"n{k}", str(i % 7), ""]
            line = sep.join(cells)
            lines.append(line.replace(".", ",") if decimal == "," else line)
    path.write_text("\n".join(lines) + "\n")
    return path


def _same_trials(a, b) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert (x.name, x.trial_number, x.rate, x.units) == (y.name, y.trial_number, y.rate,
                                                             y.units)
        assert x.notes == y.notes and dict(x.factors) == dict(y.factors)
        np.testing.assert_array_equal(x.time, y.time)
        assert list(x.markers) == list(y.markers) and list(x.extra) == list(y.extra)
        for m in x.markers:
            np.testing.assert_array_equal(x.markers[m], y.markers[m])
        for c in x.extra:
            np.testing.assert_array_equal(x.extra[c], y.extra[c])


@pytest.mark.usefixtures("streamed")
@pytest.mark.parametrize("layout", [dict(), dict(time="s"), dict(time="ms"), dict(sep=","),
                                    dict(sep=";", decimal=",")])
def test_a_table_read_in_chunks_gives_the_trials_read_whole(tmp_path, layout):
    path = write_table(tmp_path / "t.tsv", **layout)
    kw = {} if layout.get("time") else {"rate": 100}
    trials = read_mocap(path, **kw)
    assert isinstance(trials, TrialStream)  # the path under test, not the whole read
    whole = _whole(path, **kw)
    assert isinstance(whole, list)
    _same_trials(list(trials), whole)
    assert trials.names == tuple(t.name for t in whole)
    _same_trials([trials[2], trials[-1]], [whole[2], whole[-1]])
    _same_trials(list(trials), whole)  # a second pass reads them again
    assert any("units inferred: mm" in n for n in whole[0].notes)
    assert any("'note' is not numeric" in n for n in whole[0].notes)
    assert any("read as lost" in n for n in whole[0].notes)


@pytest.mark.usefixtures("streamed")
def test_the_real_trials_give_the_same_landmarks_read_in_chunks(tmp_path):
    lines = REAL.read_text().splitlines()
    path = tmp_path / "real.tsv"  # 4 real reaches twice, renumbered: 4,000 rows, 40 chunks
    path.write_text("\n".join([lines[0], *lines[1:], *(
        "\t".join([str(10 + int(r.split("\t")[0])), *r.split("\t")[1:]]) for r in lines[1:])])
        + "\n")
    options = MocapImport(rate=85)
    assert isinstance(read_mocap(path, rate=85), TrialStream)
    chunked = measure(path, mocap=options)
    mocap_stream.STREAM_BYTES = 1 << 62
    whole = measure(path, mocap=options)
    assert chunked.trials == whole.trials == 8
    assert chunked.measured == whole.measured >= 6
    assert chunked.table.equals(whole.table)


@pytest.mark.usefixtures("streamed")
@pytest.mark.parametrize("fault, said", [
    (lambda lines: lines + lines[1:40], "appears in 2 separate blocks"),
    (lambda lines: lines[:300] + ["101\tx"] + lines[300:], "line 301 has 2 fields"),
    (lambda lines: lines[:500] + [lines[500].replace("\t3", "\tabc", 1)] + lines[501:],
     "not a number: 'abc"),
])
def test_a_fault_anywhere_in_a_streamed_table_is_said_as_read_whole(tmp_path, fault, said):
    path = write_table(tmp_path / "t.tsv")
    path.write_text("\n".join(fault(path.read_text().splitlines())) + "\n")
    with pytest.raises(InputError) as whole:
        _whole(path, rate=100)
    with pytest.raises(InputError) as chunked:
        read_mocap(path, rate=100)  # refused when opened, not halfway through the trials
    assert str(chunked.value) == str(whole.value)
    assert said in str(whole.value)


def _peak(path: Path) -> int:
    """tracemalloc's peak, bytes, of reading ``path``'s trials one by one, keeping none."""
    tracemalloc.start()
    try:
        for trial in read_mocap(path, rate=100):
            assert len(trial.time)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.usefixtures("streamed")
def test_memory_does_not_grow_with_the_number_of_trials(tmp_path, monkeypatch):
    import pandas  # noqa: F401 - imported before the count, not counted in it

    # the buffers of a fixed size (the head decoded, the blocks whose fields are counted,
    # the rows of a chunk) made small, so that 2 MB is a large table
    monkeypatch.setattr(mocap_stream, "HEAD_BYTES", 1 << 16)
    monkeypatch.setattr(mocap_text, "_FIELDS_CHUNK", 1 << 19)
    monkeypatch.setattr(mocap_stream, "CHUNK_ROWS", 500)
    few = write_table(tmp_path / "few.tsv", trials=20, rows=100)
    many = write_table(tmp_path / "many.tsv", trials=200, rows=100)
    streamed_few, streamed_many = _peak(few), _peak(many)
    monkeypatch.setattr(mocap_stream, "STREAM_BYTES", 1 << 62)
    whole_few, whole_many = _peak(few), _peak(many)
    assert whole_many > 3 * whole_few  # read whole, ten times the rows take several times more
    assert streamed_many < 2 * streamed_few  # trial by trial, the rows are never all held
    assert streamed_many < whole_many / 3


@pytest.mark.usefixtures("streamed")
def test_progress_is_said_through_a_callback(tmp_path):
    path = write_table(tmp_path / "t.tsv", trials=5)
    said = []
    with reading_progress(lambda done, total, what: said.append((done, total, what))):
        trials = read_mocap(path, rate=100)
        list(trials)
    checked = [s for s in said if s[2] == "checking t.tsv"]
    read = [s for s in said if s[2] == "reading t.tsv"]
    assert checked[-1][:2] == (750, 750) and len(checked) == 8  # 100 rows a chunk
    assert read == [(k, 5, "reading t.tsv") for k in range(1, 6)]
    said.clear()
    list(trials)  # outside: nothing said
    assert said == []


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.usefixtures("streamed")
def test_landmarks_draws_a_progress_bar_on_a_terminal_only(tmp_path, monkeypatch):
    path = write_table(tmp_path / "t.tsv", trials=4)
    monkeypatch.delenv("CI", raising=False)
    for env, quiet, terminal, drawn in [(None, False, True, True), ("true", False, True, False),
                                        (None, True, True, False), (None, False, False, False)]:
        if env:
            monkeypatch.setenv("CI", env)
        err = _Terminal() if terminal else io.StringIO()
        monkeypatch.setattr(sys, "stderr", err)
        main(["landmarks", str(path), "--rate", "100", "-o", str(tmp_path / "out.csv"),
              *(["--quiet"] if quiet else [])])
        monkeypatch.delenv("CI", raising=False)
        said = err.getvalue()
        assert ("reading t.tsv" in said and "measuring t.tsv" in said) is drawn, said
        assert ("checking t.tsv" in said) is drawn


@pytest.mark.usefixtures("streamed")
def test_a_table_cut_short_after_it_was_opened_is_refused_not_read_short(tmp_path):
    path = write_table(tmp_path / "t.tsv", trials=4)
    trials = read_mocap(path, rate=100)
    path.write_text("\n".join(path.read_text().splitlines()[:301]) + "\n")  # 2 trials left
    with pytest.raises(InputError, match="changed while it was read .2 of its 4 trials gone"):
        list(trials)

"""A batch reads each recording once, in its own process, and says where its time went
(issue 45 item 1: every one of 16 workers read the whole 600-trial table, 4 s each).
"""

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import perception.recordings as recordings
from perception.batch import _Job, _Work, discover, run_batch
from perception.discovery import expand_recordings, recording_items
from perception.pipeline import RecognitionSettings
from perception.recognition.repertoire import Repertoire
from perception.recordings import MocapImport

TABLE = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"
SETTINGS = RecognitionSettings(mocap=MocapImport(rate=85.0))


@pytest.fixture
def session(tmp_path):
    folder = tmp_path / "session"
    folder.mkdir()
    shutil.copy(TABLE, folder / "trials.tsv")
    return folder


def test_a_reach_goes_to_its_worker_with_its_samples(session, tmp_path, monkeypatch):
    pairs = recording_items(discover(session), SETTINGS)
    assert [i for i, _ in pairs] == expand_recordings(discover(session), SETTINGS)
    work = [_Work(*pair) for pair in pairs]
    reaches = [w for w in work if w.item.reach is not None]
    assert len(reaches) == 4 and all(w.reach is not None for w in reaches)
    reference = _Job(tmp_path / "read", SETTINGS, "rep").run(reaches[0].__class__(
        reaches[0].item), Repertoire.default())  # read from the file, as before

    def no_reading(*args, **kwargs):
        raise AssertionError("the worker read the recording")

    recordings._cached.cache_clear()
    monkeypatch.setattr(recordings, "cached_reaches", no_reading)
    monkeypatch.setattr(recordings, "cached_recording", no_reading)
    shipped = _Job(tmp_path / "shipped", SETTINGS, "rep").run(reaches[0], Repertoire.default())
    assert shipped.status == reference.status == "ok"
    assert shipped.summary.verdict == reference.summary.verdict
    np.testing.assert_array_equal(shipped.summary.confidence, reference.summary.confidence)
    assert shipped.timing.cpu > 0 and shipped.timing.end > shipped.timing.start


def test_the_batch_says_where_its_time_went(session, tmp_path):
    summary = run_batch(discover(session), tmp_path / "out", Repertoire.default(), SETTINGS,
                        quiet=True)
    timing = summary.attrs["timing"]
    assert {"read", "clips", "report"} <= set(timing) and min(
        timing[k] for k in ("read", "clips", "report")) > 0
    runs = timing["runs"]
    assert runs.shape == (len(summary), 4)  # a row per summary row, every one run here
    assert not np.isnan(runs).any() and (runs[:, 2] >= runs[:, 1]).all()
    assert (runs[:, 2] - runs[:, 1]).sum() <= timing["clips"] + 1e-6  # one process: in turn


def _same(a, b):
    pd.testing.assert_frame_equal(a.reset_index(drop=True), b.reset_index(drop=True))


def test_a_recording_read_while_its_reaches_are_scored(session, tmp_path):
    """--jobs 2 hands out a recording's reaches as it reads them: the same rows as one
    process that reads it whole first, every trial counted, the timing of each."""
    shutil.copy(TABLE, session / "more.tsv")
    one = run_batch(discover(session), tmp_path / "one", Repertoire.default(), SETTINGS,
                    quiet=True)
    two = run_batch(discover(session), tmp_path / "two", Repertoire.default(), SETTINGS,
                    quiet=True, jobs=2)
    assert len(one) == 8 and one.attrs["trials"] == two.attrs["trials"] == 8
    _same(one, two)
    runs = two.attrs["timing"]["runs"]
    assert len(np.unique(runs[:, 0])) == 2  # two workers ran them
    for out in ("one", "two"):
        assert len(list((tmp_path / out).glob("*.recognition.json"))) == 8


def test_a_recording_that_fails_at_its_end_is_taken_back(session, tmp_path, monkeypatch):
    """A recording found at its end to give nothing (a marker never seen) has had its
    trials handed out: they are taken back, outputs and rows, and the recording is
    one failed row, as when it is read whole first."""
    from perception.errors import InputError

    real = recordings.iter_recording

    def fails_at_the_end(path, options=None):
        yield from real(path, options)
        raise InputError("marker 'thumb' is never seen in any of its 4 trials", path)

    monkeypatch.setattr(recordings, "iter_recording", fails_at_the_end)
    recordings._cached.cache_clear()
    shutil.copy(TABLE, session / "other.tsv")  # a recording read to its end, for contrast
    out = {}
    for jobs in (1, 2):
        out[jobs] = run_batch(discover(session), tmp_path / f"j{jobs}", Repertoire.default(),
                              SETTINGS, quiet=True, jobs=jobs)
        recordings._cached.cache_clear()
    _same(out[1], out[2])
    failed = out[2][out[2]["status"] == "failed"]
    assert list(failed["clip"]) == ["other", "trials"]  # both fail: the patch holds for each
    assert failed["error"].str.contains("never seen").all()
    assert not list((tmp_path / "j2").glob("*.recognition.json"))  # the trials' taken back

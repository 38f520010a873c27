"""tools/bench_recognition.py's scaling harness: the process counts it times, the
clips it makes, and its measure of what the machine itself allows."""

import dataclasses
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from _demos import default_repertoire

from perception.batch import discover
from perception.synthetic.recipes import load_recipe, synthesize

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import bench_recognition  # noqa: E402


@pytest.mark.parametrize("cores, expected", [(1, [1]), (2, [1, 2]), (6, [1, 2, 4, 6]),
                                             (16, [1, 2, 4, 8, 16])])
def test_process_counts_double_up_to_every_core(cores, expected):
    assert bench_recognition._worker_counts(cores) == expected


@pytest.mark.parametrize("cores", [1, 2, 5, 16])
def test_clip_counts_give_every_process_several_clips(cores):
    counts = bench_recognition._counts(cores)
    total = sum(counts.values())
    assert total == max(40, bench_recognition.CLIPS_PER_CORE * cores)
    assert max(counts.values()) - min(counts.values()) <= 1
    assert set(counts) == {"normal", "delayed", "open-close-open"}


@pytest.mark.slow
def test_side_by_side_batches_share_every_clip_once(tmp_path):
    recipe = dataclasses.replace(load_recipe(ROOT / "datasets" / "smoke.toml"),
                                 counts={"normal": 2, "delayed": 1})
    synthesize(recipe, tmp_path / "clips", seed=0)
    items = discover(tmp_path / "clips")
    start = time.perf_counter()
    wall = bench_recognition._side_by_side(items, tmp_path / "out", default_repertoire(), 2)
    # the run's own wall time: within the call's, however long a busy machine takes
    assert 0 < wall <= time.perf_counter() - start
    done = [list(pd.read_csv(f)["clip"])
            for f in sorted((tmp_path / "out").glob("alone*/summary.csv"))]
    ranked = [i.clip for i in sorted(items, key=lambda i: i.path.stat().st_size, reverse=True)]
    # largest first, dealt in turn: the first and third largest to one, the second to the other
    assert sorted(done[0]) == sorted(ranked[0::2]) and done[1] == ranked[1:2]


@pytest.mark.slow
def test_side_by_side_reports_a_failed_batch_instead_of_waiting(tmp_path):
    recipe = dataclasses.replace(load_recipe(ROOT / "datasets" / "smoke.toml"),
                                 counts={"normal": 2})
    synthesize(recipe, tmp_path / "clips", seed=0)
    items = discover(tmp_path / "clips")
    items[1] = dataclasses.replace(items[1], path=tmp_path / "gone.mp4")  # fails its batch
    with pytest.raises(RuntimeError, match="failed"):
        bench_recognition._side_by_side(items, tmp_path / "out", default_repertoire(), 2)


def test_the_study_names_the_lines_that_hold_more_a_trial_largest_first():
    import study_memory

    small = {"/v/site-packages/pandas/frame.py:3": 1_000, f"{ROOT}/perception/batch.py:9": 500,
             "/v/lib/python3.11/dataclasses.py:1501": 900}
    large = {"/v/site-packages/pandas/frame.py:3": 301_000,  # 3 kB a trial more
             f"{ROOT}/perception/batch.py:9": 100,  # shrank: not named
             "/v/lib/python3.11/dataclasses.py:1501": 900,  # the same: not named
             "/v/lib/python3.11/json/decoder.py:7": 50_000}  # new among the largest
    rows = study_memory._grown_lines(small, large, 100)
    assert [(what, size) for what, size, *_ in rows] == [
        ("    held a trial, pandas/frame.py:3", "3000 B"),
        ("    held a trial, json/decoder.py:7", "500 B")]


def test_make_bench_finds_every_section():
    # tools/bench.py runs main() of each tools/bench_<name>.py: a helper module named so
    # (the study part once was) broke `make bench` before any section ran
    import bench

    sections = bench._discover()
    assert {"solver", "execution", "recognition"} <= set(sections)
    assert all(callable(run) for run in sections.values())

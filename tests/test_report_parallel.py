"""The batch report's statistics fitted in worker processes: the same rows, in order.

A study's mixed models (one a measure) were the report's serial tail: 15 of
its 22 s at 1,200 trials. With ``jobs`` above 1 they are fitted side by side
in worker processes, which must give the table fitted here, bit for bit.
"""

import numpy as np
import pandas as pd

from perception.report import statistics
from perception.report.statistics import landmark_statistics


def _measures() -> pd.DataFrame:
    """Four measures of 8 participants x 12 trials, two conditions, each participant
    with an offset of their own (a mixed model's case) and one measure constant."""
    rng = np.random.default_rng(11)
    rows = []
    for measure, unit, effect in (("peak_speed", "mm/s", 40.0), ("mga", "mm", 4.0),
                                  ("movement_time", "ms", 0.0), ("aperture_peaks", "count",
                                                                  None)):
        for p in range(8):
            offset = rng.normal(0.0, 3.0)
            for k in range(12):
                cond = ("normal", "delayed")[k % 2]
                value = (1.0 if effect is None else
                         100.0 + offset + effect * (cond == "delayed") + rng.normal(0.0, 2.0))
                rows.append({"clip": f"P{p}-trial{k}", "trial": str(k), "condition": cond,
                             "participant": f"P{p}", "measure": measure, "value": value,
                             "unit": unit, "clock": "", "flag": "ok"})
    return pd.DataFrame(rows)


def test_statistics_fitted_in_workers_are_those_fitted_here(monkeypatch):
    data = _measures()
    here = landmark_statistics(data)
    assert set(here["method"]) >= {"mixedlm", "cell_means"}  # both paths taken
    monkeypatch.setattr(statistics, "PARALLEL_TRIALS", 10)  # these 96 trials a measure
    used = []
    import perception.workers as workers

    real = workers.run_pool

    def counted(items, job, jobs, **kwargs):
        used.append(jobs)
        return real(items, job, jobs, **kwargs)

    monkeypatch.setattr(workers, "run_pool", counted)
    there = landmark_statistics(data, jobs=2)
    assert used == [2]  # the workers fitted them
    pd.testing.assert_frame_equal(here, there, check_exact=True)
    assert list(there["measure"].drop_duplicates()) == list(data["measure"].drop_duplicates())


def test_a_measure_whose_worker_died_is_fitted_here(monkeypatch):
    """A worker killed under a measure (out of memory) costs its time, not the report: the
    pool's ``lost`` fits that measure here, with the same rows."""
    from concurrent.futures.process import BrokenProcessPool

    import perception.workers as workers

    data = _measures()
    here = landmark_statistics(data)
    monkeypatch.setattr(statistics, "PARALLEL_TRIALS", 10)
    real = workers.run_pool

    def first_dies(items, job, jobs, **kwargs):
        items = list(items)
        dead = workers._lost(job, items[0], BrokenProcessPool("killed"))
        return [dead, *real(items[1:], job, jobs, **kwargs)]

    monkeypatch.setattr(workers, "run_pool", first_dies)
    pd.testing.assert_frame_equal(landmark_statistics(data, jobs=2), here, check_exact=True)


def test_small_batches_fit_here(monkeypatch):
    import perception.workers as workers

    def refused(*args, **kwargs):
        raise AssertionError("a worker started for 96 trials a measure")

    monkeypatch.setattr(workers, "run_pool", refused)
    table = landmark_statistics(_measures(), jobs=4)  # under PARALLEL_TRIALS: here
    assert len(table) and table["measure"].nunique() == 4


def test_a_report_whose_statistics_ran_in_workers_is_the_same(tmp_path, monkeypatch):
    from test_batch_rows import _results

    from perception.batch import summary_table
    from perception.report import write_batch_report

    results = _results(4)
    summary, recs = summary_table(results), {r.clip: r.summary for r in results}
    write_batch_report(summary, recs, tmp_path / "one", figure_format="svg")
    monkeypatch.setattr(statistics, "PARALLEL_TRIALS", 2)
    assert statistics.fitted_in_workers(
        statistics.measure_table(pd.read_csv(tmp_path / "one" / "landmarks.csv"), summary), 2)
    write_batch_report(summary, recs, tmp_path / "two", figure_format="svg", jobs=2)
    names = sorted(p.name for p in (tmp_path / "one").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "two").iterdir())
    assert "landmark_statistics.csv" in names
    for name in names:
        assert (tmp_path / "one" / name).read_bytes() == (tmp_path / "two" / name).read_bytes(), \
            name

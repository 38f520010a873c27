"""What a batch keeps of a clip while it runs: one value a model, the curves on disk.

A batch's own process held every model's curves of every clip (about 50 kB a
trial), though its report reads one model's: :class:`perception.batch_clip.ModelRows`
keeps them on disk and gives back the reference model's, and the report
written from them is the report written from the results in memory.
"""

import dataclasses
import pickle

import numpy as np

from perception.batch import ClipResult, summary_table
from perception.batch_clip import ModelRows
from perception.report import ClipSummary, write_batch_report
from perception.report.conditions import reference_model


def _results(models: int) -> list[ClipResult]:
    """Six scored clips of two conditions against ``models`` models (half of them grasp
    models), each with its kinematic traces and landmarks."""
    rng = np.random.default_rng(7)
    names = [f"{'grasp' if m % 2 == 0 else 'reach'}-{m}" for m in range(models)]
    kinds = [n.split("-")[0] for n in names]
    out = []
    for k, cond in enumerate(["normal", "delayed"] * 3):
        time = np.linspace(0.0, 0.8 + 0.05 * k, 40)
        confidence = np.cumsum(rng.uniform(0.0, 0.01, (models, time.size)), axis=1)
        traces = {"time": np.linspace(-0.2, 1.0, 90),
                  "wrist_speed": np.round(np.abs(np.sin(np.linspace(0, 3, 90))) + k / 10, 6),
                  "aperture": np.round(0.05 + 0.03 * np.sin(np.linspace(0, 3.1, 90)), 6)}
        observed = {"onset_time": 0.0, "end_time": 0.8, "movement_time": 0.8,
                    "peak_speed": 1.0 + k / 10, "peak_speed_time": 0.4, "mga": 0.08,
                    "mga_time": 0.6, "aperture_peaks": 1}
        summary = ClipSummary(
            f"P{k % 3}-trial{k}", time, names, kinds, confidence,
            rng.normal(100.0, 10.0, models), names[0], "likelihood", verdict="normal",
            familiarity=0.5, margin=1.0, familiarities=rng.uniform(0, 1, models),
            transport=confidence * rng.uniform(0.2, 0.8, (models, 1)),
            aperture=0.05 + 0.01 * rng.standard_normal(time.size),
            extras={"condition": cond, "mocap": {"trial": str(k)}},
            kinematics={"observed": observed}, traces=traces, time_origin=1.5)
        out.append(ClipResult(summary.clip, cond, "ok", summary=summary,
                              factors=(("participant", f"P{k % 3}"),)))
    return out


def _arrays(summary: ClipSummary) -> int:
    """Bytes of a summary's arrays, its traces' among them."""
    fields = [getattr(summary, f.name) for f in dataclasses.fields(summary)]
    fields += list((summary.traces or {}).values())
    return sum(v.nbytes for v in fields if isinstance(v, np.ndarray))


def test_a_kept_clip_holds_one_value_a_model_however_many_models(tmp_path):
    kept = {}
    for models in (2, 32):
        with ModelRows(tmp_path) as rows:
            full = _results(models)[0]
            kept[models] = rows.keep(full).summary
            assert kept[models].confidence.shape == (models, 1)
            assert kept[models].transport.size == 0
            # the final values summary.csv reads are those of the results
            assert np.array_equal(kept[models].confidence[:, 0], full.summary.confidence[:, -1])
    # a final confidence and likelihood a model, and nothing else: no curve, no trace
    assert _arrays(kept[32]) == 32 * 2 * 8 and _arrays(kept[2]) == 2 * 2 * 8
    assert len(pickle.dumps(kept[32])) - len(pickle.dumps(kept[2])) < 30 * 40 * 8


def test_the_reference_models_curves_come_back_bit_for_bit(tmp_path):
    results = _results(8)
    with ModelRows(tmp_path) as rows:
        kept = [rows.keep(r).summary for r in results]
        for full, short in zip(results, kept):
            s = full.summary
            one = rows.restored(short, "grasp-4")
            assert one.names == ["grasp-4"] and one.kinds == ["grasp"]
            assert one.confidence.tobytes() == s.confidence[4:5].tobytes()
            assert one.transport.tobytes() == s.transport[4:5].tobytes()
            assert one.final_log_likelihood.tobytes() == s.final_log_likelihood[4:5].tobytes()
            every = rows.restored(short, None)  # no reference: every model's curves
            assert every.names == s.names
            assert every.confidence.tobytes() == s.confidence.tobytes()
            assert every.transport.tobytes() == s.transport.tobytes()
    assert not list(tmp_path.iterdir())  # the file is gone with the context


def test_a_report_from_kept_rows_is_the_report_from_the_results(tmp_path,
                                                                figure_format="svg"):
    results = _results(6)
    memory, kept_out = tmp_path / "memory", tmp_path / "kept"
    write_batch_report(summary_table(results),
                       {r.clip: r.summary for r in results}, memory,
                       figure_format=figure_format)
    with ModelRows(tmp_path) as rows:
        kept = [rows.keep(r) for r in results]
        scored = [r.summary for r in kept]
        reference = reference_model(scored, [r.condition for r in kept])
        # each clip read back from disk as the report reads it, as run_batch gives them
        write_batch_report(summary_table(kept, reference), rows.summaries(scored, reference),
                           kept_out, figure_format=figure_format)
    files = sorted(p.name for p in memory.iterdir())
    assert files == sorted(p.name for p in kept_out.iterdir())
    assert f"confidence_all.{figure_format}" in files and "summary.csv" in files
    for name in files:  # tables, page and figures, byte for byte (figures carry no date)
        assert (memory / name).read_bytes() == (kept_out / name).read_bytes(), name


def test_a_kept_clip_holds_no_curve_and_no_sentence_however_long_the_clip(tmp_path):
    long = _results(4)[0]
    s = long.summary
    n = 20_000  # a long clip: every curve and trace 20,000 samples
    long = dataclasses.replace(long, summary=dataclasses.replace(
        s, time=np.linspace(0, 1, n), confidence=np.ones((4, n)), transport=np.ones((4, n)),
        aperture=np.ones(n), traces={k: np.ones(n) for k in s.traces},
        verdict_reason="x" * 10_000, extras={**s.extras, "notes": ["y" * 10_000]}))
    with ModelRows(tmp_path) as rows:
        short = rows.keep(_results(4)[0]).summary
        kept = rows.keep(long).summary
        assert len(pickle.dumps(kept)) == len(pickle.dumps(short)) < 2_500
        back = rows.restored(kept, None)  # and all of it comes back
        assert back.traces["time"].size == n and back.verdict_reason == "x" * 10_000
        assert back.extras["notes"] == ["y" * 10_000] and back.confidence.shape == (4, n)
        assert back.landmark("mga") == kept.landmark("mga") == 0.08


def test_the_report_reads_the_kept_clips_one_at_a_time(tmp_path):
    """write_batch_report given a mapping that reads each clip back holds a few at once,
    not every one (a study's are 21 kB a trial)."""
    import gc
    import weakref
    from collections.abc import Mapping

    results = [dataclasses.replace(r, clip=f"{r.clip}-{k}", summary=dataclasses.replace(
        r.summary, clip=f"{r.clip}-{k}")) for k in range(3) for r in _results(4)]
    alive: weakref.WeakSet = weakref.WeakSet()
    most = []

    class Counted(Mapping):  # each look-up a new summary, as one read back from disk
        def __init__(self, kept):
            self.kept = kept

        def __getitem__(self, clip):
            if len(alive) > 4:  # what a full collection frees does not count (one is slow)
                gc.collect()
            most.append(len(alive))
            one = pickle.loads(pickle.dumps(self.kept[clip]))
            alive.add(one)
            return one

        def __iter__(self):
            return iter(self.kept)

        def __len__(self):
            return len(self.kept)

    write_batch_report(summary_table(results), Counted({r.clip: r.summary for r in results}),
                       tmp_path, figure_format="svg")
    assert len(results) == 18 and len(most) >= 4 * 18  # every clip read, several times
    # the clip being read, the previous one, and the two typical clips of Fig. 5.8(a)
    assert max(most) <= 4
    page = (tmp_path / "report.html").read_text()
    assert all(f">{r.clip}</h3>" in page for r in results)


def test_a_batch_gives_its_clips_warnings_without_reading_its_reports_back(tmp_path):
    import copy
    import json
    import shutil
    from pathlib import Path

    from hammer_mv.cli import batch as cli
    from perception.batch import discover, run_batch
    from perception.pipeline import RecognitionSettings
    from perception.recognition.repertoire import Repertoire
    from perception.recordings import MocapImport
    from perception.report.clip import clip_outputs

    (tmp_path / "in").mkdir()
    shutil.copy(Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv",
                tmp_path / "in" / "P1.tsv")
    out = tmp_path / "out"
    summary = run_batch(discover(tmp_path / "in"), out, Repertoire.default(),
                        RecognitionSettings(mocap=MocapImport(rate=85.0)), quiet=True)
    scored = summary.loc[summary["status"] == "ok", "clip"].tolist()
    assert scored
    read_back = [(c, json.loads(clip_outputs(out, c)["json"].read_text())["warning_values"])
                 for c in scored]
    kept = summary.attrs["warnings"]
    assert copy.deepcopy(summary.attrs)["warnings"] is kept  # shared, not copied
    assert cli._warnings(summary) == read_back


def test_the_landmark_table_built_a_column_at_a_time_is_the_one_built_a_row_at_a_time():
    import math

    import pandas as pd

    from perception.landmarks import Landmarks
    from perception.report import tables
    from perception.report.tables import MovementLandmarks, tidy_landmarks

    observed = _results(2)[0].summary.kinematics["observed"]
    movements = [
        MovementLandmarks("a", "a", Landmarks.from_dict(observed), "complete",
                          condition="normal", factors={"participant": "P1", "block": "2"},
                          trial_number="1", reach_number="1"),
        MovementLandmarks("b", "b", None, "no reach", reason="the hand never moved",
                          factors={"participant": "P2"}),  # no block, no condition
    ]
    factors = ["participant", "block", "session"]  # session: no movement has one
    rows = []  # the table as it was built: a dict a row
    for m in movements:
        cells = tables._cells(m, factors)
        for name, value, unit, clock, flag in m.values():
            rows.append({**cells, "landmark": name, "value": value, "unit": unit,
                         "clock": clock, "flag": flag, "status": m.status, "reason": m.reason})
    names = [*tables._HEAD, *factors, *tables._NUMBERS, *tables._LONG]
    expected = pd.DataFrame(rows, columns=names).astype({"trial_number": str,
                                                         "reach_number": str})
    table = tidy_landmarks(movements, factors)
    pd.testing.assert_frame_equal(table, expected, check_exact=True)
    assert table["session"].isna().all() and not math.isnan(table["value"].iloc[0])


def _with_unscored(results: list[ClipResult]) -> list[ClipResult]:
    """``results`` and two rows without a result: a failed clip with a factor of its own
    (``block``) and a trial that gives no reach."""
    return [ClipResult("a-failed", "normal", "failed", "boom", reason="boom",
                       factors=(("participant", "P9"), ("block", "2"))),
            *results,
            ClipResult("z-none", None, "no reach", reason="the hand never moved",
                       factors=(("participant", "P0"),))]


def test_landmarks_csv_written_a_chunk_at_a_time_is_the_whole_tables(tmp_path):
    import pandas as pd

    from perception.report.tables import landmark_table, write_landmark_table

    results = _with_unscored(_results(3))
    summary = summary_table(results)
    recognitions = {r.clip: r.summary for r in results if r.summary is not None}
    whole = landmark_table(summary, recognitions)
    whole.to_csv(tmp_path / "whole.csv", index=False)
    for chunk in (1, 2, 3, 100):  # the first chunk without a block, the last one too
        columns, kept = write_landmark_table(summary, recognitions, tmp_path / "chunks.csv",
                                             keep=("clip", "value", "block", "nothing"),
                                             chunk=chunk)
        assert (tmp_path / "chunks.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()
        assert columns == list(whole.columns) and set(kept) == {"clip", "value", "block"}
        assert kept["clip"] == whole["clip"].tolist()
        assert np.array_equal(np.frombuffer(kept["value"]), whole["value"].to_numpy(),
                              equal_nan=True)
        pd.testing.assert_series_equal(pd.Series(kept["block"], name="block"),
                                       whole["block"])


def test_the_statistics_read_the_measure_tables_columns_bit_for_bit(tmp_path):
    import pandas as pd

    from perception.report import batch as report
    from perception.report.statistics import measure_table
    from perception.report.tables import landmark_table, write_landmark_table

    results = _with_unscored(_results(4))
    summary = summary_table(results)
    recognitions = {r.clip: r.summary for r in results if r.summary is not None}
    columns, kept = write_landmark_table(summary, recognitions, tmp_path / "l.csv",
                                         keep=("clip", "condition", "participant", "landmark",
                                               "value", "unit"))
    expected = measure_table(landmark_table(summary, recognitions), summary)[
        ["measure", "unit", "participant", "condition", "value"]]
    pd.testing.assert_frame_equal(report._measures(columns, kept, summary), expected,
                                  check_exact=True)
    assert expected["measure"].iloc[-1] == "reference_confidence"
    assert np.isnan(expected["value"].iloc[-1])  # the trial without a result


def test_profiles_of_curves_one_at_a_time_are_those_of_every_curve_at_once():
    import pandas as pd

    from perception.report.conditions import PROFILE_POINTS, _phase, condition_profiles

    results = _results(4)
    recs = [r.summary for r in results]
    conds = [r.condition for r in results]
    table = condition_profiles(recs, conds, "grasp-2")
    phase = np.linspace(0, 1, PROFILE_POINTS)
    for cond, rows in table.groupby("condition", sort=False):
        mine = [r for r, c in zip(recs, conds) if c == cond]
        total = np.array([np.interp(phase, _phase(r), r.confidence[2]) for r in mine])
        transport = np.array([np.interp(phase, _phase(r), r.transport[2]) for r in mine])
        for column, curves in (("", total), ("transport_", transport),
                               ("grip_", total - transport)):
            assert rows[f"{column}mean"].to_numpy().tobytes() == np.nanmean(
                curves, axis=0).tobytes()
            assert rows[f"{column}sd"].to_numpy().tobytes() == np.nanstd(
                curves, axis=0, ddof=1).tobytes()
        assert (rows["n"] == len(mine)).all()
    assert list(pd.unique(table["condition"])) == ["normal", "delayed"]


def test_a_clips_curves_come_back_without_the_rest_bit_for_bit(tmp_path):
    """What the profiles and confidence figures read of a clip (its time, aperture and the
    reference model's curves) is read back without unpickling the rest of its summary."""
    from perception.batch_clip import ClipCurves

    results = _results(8)
    with ModelRows(tmp_path) as rows:
        scored = [rows.keep(r).summary for r in results]
        kept = rows.summaries(scored, "grasp-4")
        curves = kept.curves("grasp-4")
        assert list(curves) == list(kept) and len(curves) == len(kept)
        for full in results:
            s, one = full.summary, curves[full.clip]
            assert isinstance(one, ClipCurves) and one.names == ["grasp-4"]
            assert one.clip == s.clip and one.index("grasp-4") == 0
            for name, values in (("time", s.time), ("aperture", s.aperture),
                                 ("confidence", s.confidence[4:5]),
                                 ("transport", s.transport[4:5])):
                assert getattr(one, name).tobytes() == values.tobytes(), name
                assert getattr(one, name).shape == values.shape, name
            # the whole summary read as before, its time and aperture among its arrays
            whole = kept[full.clip]
            assert isinstance(whole, ClipSummary)
            assert whole.time.tobytes() == s.time.tobytes()
            assert whole.aperture.tobytes() == s.aperture.tobytes()
            assert whole.traces["time"].tobytes() == s.traces["time"].tobytes()
        # curves of another model than the one kept for: the whole summary, as before
        assert isinstance(kept.curves("grasp-2")[results[0].clip], ClipSummary)


def test_the_report_reads_its_profiles_and_confidence_figures_from_the_curves(tmp_path):
    """Six of the report's twelve passes over the clips read their curves alone."""
    results = _results(6)
    with ModelRows(tmp_path) as rows:
        kept = [rows.keep(r) for r in results]
        scored = [r.summary for r in kept]
        reference = reference_model(scored, [r.condition for r in kept])
        calls = {"whole": 0, "curves": 0}
        restored, curves = rows._restored, rows._curves

        def counted(kind, read):
            def read_counted(*args):
                calls[kind] += 1
                return read(*args)
            return read_counted

        rows._restored, rows._curves = counted("whole", restored), counted("curves", curves)
        write_batch_report(summary_table(kept, reference), rows.summaries(scored, reference),
                           tmp_path / "out", figure_format="svg")
    n = len(results)
    # aperture profiles, typical clips, every clip's confidence, three condition profiles
    assert calls["curves"] >= 6 * n
    assert calls["whole"] <= 6 * n


def test_summary_csv_written_a_chunk_at_a_time_is_the_whole_tables(tmp_path):
    from perception.report.batch import _printable_table, write_summary_csv
    from perception.report.tables import in_lab_units

    # a failed clip, a trial without a reach and a name that is not UTF-8 (escaped in
    # the file): the chunks' columns differ in what they hold, not in what they write
    results = [*_with_unscored(_results(3)),
               ClipResult("bad-\udcff-name", "normal", "failed", "no file", reason="no file")]
    summary = summary_table(results)
    _printable_table(in_lab_units(summary)).to_csv(tmp_path / "whole.csv", index=False,
                                                   errors="backslashreplace")
    whole = (tmp_path / "whole.csv").read_bytes()
    assert b"bad-\\xff-name" in whole and b"movement_time" in whole
    for chunk in (1, 2, 3, 100):
        write_summary_csv(tmp_path / "chunks.csv", summary, chunk=chunk)
        assert (tmp_path / "chunks.csv").read_bytes() == whole
    write_summary_csv(tmp_path / "empty.csv", summary.iloc[:0])
    assert (tmp_path / "empty.csv").read_bytes() == whole.split(b"\n")[0] + b"\n"

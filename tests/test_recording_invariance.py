"""The same real movements written in another lab's conventions keep their verdicts.

The four real Optotrak grasps shipped in tests/data/mocap/ are rewritten as
``tools/evaluate_invariance.py`` rewrites them — the lab's frame turned, its
origin elsewhere, a left hand, y up, a clock that starts late, thirty more
markers, two-sample dropouts, 60, 100 and 200 samples/s, 0.3 and 1 mm of
noise — and scored again. Nothing a lab chooses may change a verdict; the
landmarks stay where the definitions put them: exactly under a rigid change
of frame, within a sample's worth under another rate.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import evaluate_invariance as inv  # noqa: E402

#: Transforms that move no sample relative to the others: the landmarks are the same.
RIGID = ("rotated frame", "origin 2 m away", "left hand (mirrored)", "y up (y and z swapped)",
         "clock from 1234.5 s", "30 more markers")


@pytest.fixture(scope="module")
def rep():
    from perception.recognition.repertoire import Repertoire

    return Repertoire.default()


@pytest.fixture(scope="module")
def scored(rep):
    trials = inv.trials_of("shipped")
    return trials, [inv.score(t, rep) for t in trials]


def test_the_shipped_trials_are_four_normal_grasps(scored):
    _, base = scored
    assert [[r["verdict"] for r in rows] for rows in base] == [["normal"]] * 4


@pytest.mark.parametrize("name", list(inv.TRANSFORMS))
def test_a_labs_conventions_change_no_verdict(rep, scored, name):
    trials, base = scored
    for trial, rows in zip(trials, base):
        got = inv.score(inv.TRANSFORMS[name](trial), rep)
        assert [r["verdict"] for r in got] == [r["verdict"] for r in rows], (trial.name, got)
        (b,), (g,) = rows, got
        if name in RIGID:
            assert g["movement_time"] == pytest.approx(b["movement_time"], abs=1e-6)
            assert g["mga"] == pytest.approx(b["mga"], abs=1e-6)
        elif "samples/s" in name or name == "2-sample dropouts":
            # the onset and end interpolated between samples; the MGA of a 10 Hz low-pass
            assert g["movement_time"] == pytest.approx(b["movement_time"], abs=0.005)
            assert g["mga"] == pytest.approx(b["mga"], abs=1e-4)
        else:  # noise moves where a slow end crosses 5 % of the peak speed
            assert g["movement_time"] == pytest.approx(b["movement_time"], abs=0.1)
            assert g["mga"] == pytest.approx(b["mga"], abs=1e-3)


def test_the_samples_made_at_another_rate_leave_out_what_the_system_did_not_measure():
    trial = inv.trials_of("shipped")[0]
    frozen = trial.markers["thumb"].copy()
    k = len(frozen) // 2
    frozen[k:k + 8] = frozen[k]  # held while occluded, as the Optotrak does
    held = inv.MocapTrial(trial.name, trial.source, trial.time,
                          {**trial.markers, "thumb": frozen}, trial.rate, trial.units)
    thumb = inv.measured(held).markers["thumb"]
    assert np.isnan(thumb[k + 1:k + 8]).all() and np.isfinite(thumb[k]).all()
    at200 = inv.resampled(200.0)(held)
    inside = (at200.time > trial.time[k + 1]) & (at200.time < trial.time[k + 7])
    assert np.isnan(at200.markers["thumb"][inside]).all()  # no ramp out of a frozen marker

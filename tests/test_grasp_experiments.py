"""Chapter 4 experiments: the trends the thesis reports (issue 3, "done when")."""

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from minvar.grasp_experiments import (
    EXPERIMENTS,
    movement_time_experiment,
    object_size_experiment,
    run_experiment,
    run_sweep,
    variability_distance_experiment,
    variability_size_experiment,
    viapoint_distance_experiment,
    viapoint_height_experiment,
)


@pytest.fixture(scope="module")
def sizes():
    return object_size_experiment(trials=100, seed=1)


def test_mga_grows_with_object_size_with_slope_near_one(sizes):
    s = sizes.summary
    assert len(s) == 9 and list(s.object_size) == pytest.approx(np.arange(9) * 0.01)
    assert np.all(np.diff(s.mga_mean) > 0)
    assert 0.7 <= sizes.stats["mga_slope"] <= 1.0
    assert sizes.stats["mga_r"] > 0.99
    # the MGA exceeds the object by about the two via-point offsets
    assert np.all((s.mga_mean > s.object_size + 0.015) & (s.mga_mean < s.object_size + 0.03))


def test_mga_time_within_human_range_and_later_for_larger_objects(sizes):
    t = sizes.summary.mga_time_mean.to_numpy()
    assert np.all((t >= 0.6) & (t <= 0.8))  # thesis line 905, with 100 repetitions
    assert np.all(np.diff(t) >= 0) and t[-1] - t[0] >= 0.05
    # the repetitions' mean times are the exact mean aperture's, to within a step
    np.testing.assert_allclose(t, sizes.summary.mga_time_exact, atol=0.011)


def test_larger_viapoint_offset_gives_larger_earlier_mga():
    e = viapoint_distance_experiment((0.0, 0.005, 0.01, 0.02), trials=100, seed=2)
    s = e.summary
    assert np.all(np.diff(s.mga_mean) > 0.003)
    assert np.all(np.diff(s.mga_time_mean) <= 0) and s.mga_time_mean.iloc[-1] < \
        s.mga_time_mean.iloc[0] - 0.05


def test_endpoint_sd_lowest_with_level_viapoints():
    e = viapoint_height_experiment((-0.02, -0.01, 0.0, 0.01, 0.02), trials=200, seed=3)
    s = e.summary
    for digit in ("finger", "thumb"):
        exact = np.hypot(s[f"{digit}_sd_x_exact"], s[f"{digit}_sd_y_exact"]).to_numpy()
        assert np.argmin(exact) == 2  # level with the targets
        # the repetitions show it against the far settings (20 % apart; SD error 5 %)
        mc = s[f"{digit}_sd"].to_numpy()
        assert mc[2] < min(mc[0], mc[4])
    # distance from target: larger below and above than level, exactly and in the mean
    for col in ("finger_distance_exact", "finger_distance_mean"):
        d = s[col].to_numpy()
        assert d[2] < d[1] < d[0] and d[2] < d[3] < d[4]
    np.testing.assert_allclose(s.finger_distance_mean, s.finger_distance_exact, rtol=0.05)


@pytest.mark.slow
def test_wrist_and_aperture_sd_fall_as_movement_time_grows():
    e = movement_time_experiment((0.6, 0.9, 1.2), trials=200, seed=4)
    s = e.summary
    for comp in ("wrist", "aperture"):
        assert np.all(np.diff(s[f"{comp}_sd_peak_exact"]) < 0)
        assert s[f"{comp}_sd_peak"].iloc[-1] < s[f"{comp}_sd_peak"].iloc[0]
        # the fall is resolved by 200 repetitions: its bootstrap interval is below 0
        lo, hi = e.stats[f"{comp}_sd_peak_change_ci"]
        assert lo < e.stats[f"{comp}_sd_peak_change"] < hi < 0
    # over normalised time the slower movement is less variable overall, and at
    # every step from 30 % on (before that, in the rise, the fixed muscle delay
    # is a larger part of the short movement and the slow one rises earlier)
    c = e.curves
    for comp in ("wrist", "aperture"):
        fast = c[c.setting == 0].set_index("relative_time")[f"{comp}_sd_exact"]
        slow = c[c.setting == 2].set_index("relative_time")[f"{comp}_sd_exact"]
        assert slow.mean() < 0.85 * fast.mean()
        common = fast.index.intersection(slow.index)
        later = common[common >= 0.3]
        assert len(later) > 10 and np.all(slow[later] < fast[later])


def test_variability_with_size_and_distance():
    size = variability_size_experiment((0.0, 0.04, 0.08), trials=100, seed=5)
    dist = variability_distance_experiment((0.08, 0.16, 0.24), trials=100, seed=6)
    # the wrist does not see the object's size; the grip does not see the distance
    assert size.stats["wrist_sd_peak_exact_range"] == 0.0
    assert dist.stats["aperture_sd_peak_exact_range"] == 0.0
    # ... and 100 repetitions see no difference either
    for e, comp in ((size, "wrist"), (dist, "aperture")):
        lo, hi = e.stats[f"{comp}_sd_peak_change_ci"]
        assert lo < 0 < hi
    # aperture SD grows with size; wrist SD grows with distance (signal-dependent noise)
    assert np.all(np.diff(size.summary.aperture_sd_peak_exact) > 0)
    assert size.stats["aperture_sd_peak_change_ci"][0] > 0
    assert np.all(np.diff(dist.summary.wrist_sd_peak_exact) > 0)
    assert dist.stats["wrist_sd_peak_change_ci"][0] > 0


def test_distance_sweep_is_in_wrist_travel():
    e = variability_distance_experiment((0.08, 0.24), trials=10, seed=0)
    s = e.summary
    # the thesis's "distance to be moved" (line 953): the wrist travels it, and the object
    # centre is the 6 cm wrist stand-off further on
    assert list(s.transport_distance) == pytest.approx([0.08, 0.24])
    assert list(s.distance) == pytest.approx([0.14, 0.30])
    c = e.curves[e.curves.setting == 1]
    travel = np.hypot(c.wrist_x.iloc[-1] - c.wrist_x.iloc[0],
                      c.wrist_y.iloc[-1] - c.wrist_y.iloc[0])
    assert travel == pytest.approx(0.24, abs=2e-3)
    assert e.shown == "transport_distance" and set(e.trials.transport_distance) == {0.08, 0.24}


def test_peak_intervals_cover_the_exact_values():
    e = variability_size_experiment((0.02, 0.06), trials=200, seed=8)
    s, b = e.summary, e.bootstrap
    assert len(b) == 2 * 400 and set(b.setting) == {0, 1}
    hits = 0
    for col in ("wrist_sd_peak", "aperture_sd_peak"):
        assert np.all(s[f"{col}_ci_low"] <= s[col]) and np.all(s[col] <= s[f"{col}_ci_high"])
        hits += int(np.sum((s[f"{col}_ci_low"] <= s[f"{col}_exact"])
                           & (s[f"{col}_exact"] <= s[f"{col}_ci_high"])))
    assert hits >= 3  # 95 % intervals: all four cover the exact peak but by rare chance
    # the MGA intervals come from the repetitions' spread
    se = s.mga_sd / np.sqrt(s.trials)
    np.testing.assert_allclose(s.mga_ci_high - s.mga_mean, 1.96 * se, rtol=1e-3)


def test_sweep_seeding_is_per_setting():
    a = run_sweep("object_size", (0.02, 0.04), trials=20, seed=9)
    b = run_sweep("object_size", (0.04,), trials=20, seed=9)
    c = run_sweep("object_size", (0.02, 0.04), trials=20, seed=np.random.SeedSequence(9))
    ta, tb, tc = a.trials, b.trials, c.trials
    pd.testing.assert_frame_equal(ta, tc)
    # setting 0 draws the same whatever follows it
    first = ta[ta.setting == 0].drop(columns=["object_size"]).reset_index(drop=True)
    alone = tb.drop(columns=["object_size"]).reset_index(drop=True)
    np.testing.assert_array_equal(first.wrist_peak_dev, alone.wrist_peak_dev)
    # settings use different children
    assert not np.array_equal(ta[ta.setting == 0].wrist_peak_dev.to_numpy(),
                              ta[ta.setting == 1].wrist_peak_dev.to_numpy())
    # the bootstrap draws are seeded too
    d1 = run_sweep("object_size", (0.04,), trials=20, seed=9, bootstrap=5).bootstrap
    d2 = run_sweep("object_size", (0.04,), trials=20, seed=9, bootstrap=5).bootstrap
    pd.testing.assert_frame_equal(d1, d2)


def test_sweep_tables_are_tidy():
    sweep = run_sweep("duration", (0.6, 1.0), trials=10, seed=0)
    s, tr, cur = sweep.summary, sweep.trials, sweep.curves
    assert list(s.duration) == [0.6, 1.0] and len(tr) == 20
    assert cur.groupby("setting").size().tolist() == [61, 101]
    assert {"mga", "finger_distance", "wrist_peak_dev"} <= set(tr.columns)
    assert {"wrist_sd", "aperture_sd_exact", "finger_speed"} <= set(cur.columns)
    assert sweep.bootstrap.empty and len(sweep.moments) == 2
    # the exact moments are those the summary's exact columns came from
    np.testing.assert_allclose(sweep.moments[1].wrist_sd.max(), s.wrist_sd_peak_exact.iloc[1])


def test_bad_experiment_inputs():
    with pytest.raises(ValueError, match="experiment"):
        run_experiment("nonsense")
    with pytest.raises(ValueError, match="trials"):
        run_experiment("object-size", trials=1)
    with pytest.raises(ValueError, match="object_size"):
        run_sweep("object_size", (0.04, 0.5), trials=5)
    with pytest.raises(ValueError, match="parameter"):
        run_sweep("colour", (1,), trials=5)



@pytest.mark.parametrize("values", [(0.04,), (0.01, 0.01)])
def test_an_mga_regression_over_one_setting_is_refused_before_simulating(values, monkeypatch):
    # it was scipy's "Cannot calculate a linear regression" after every
    # setting had been simulated (minutes at the thesis's 500 repetitions)
    import minvar.grasp_experiments as ge

    monkeypatch.setattr(ge, "run_sweep", lambda *a, **k: pytest.fail("simulated first"))
    with pytest.raises(ValueError, match=r"values: .*at least 2 different settings"):
        viapoint_distance_experiment(values, trials=5)
    with pytest.raises(ValueError, match=r"values: .*at least 2 different settings"):
        object_size_experiment(values[:1], trials=5)
    monkeypatch.undo()
    # a sweep without a regression runs one setting
    assert len(viapoint_height_experiment((0.0,), trials=5).summary) == 1

def test_figures_are_built_and_named_after_the_thesis():
    e = variability_size_experiment((0.02, 0.06), trials=10, seed=0)
    figures = e.plot()
    assert set(figures) == {"fig4_13_variability_size_sd", "fig4_14_variability_size_peaks"}
    assert all(isinstance(f, Figure) for f in figures.values())
    assert len(figures["fig4_14_variability_size_peaks"].axes) == 4
    assert set(EXPERIMENTS) == {"viapoint-height", "viapoint-time", "viapoint-distance",
                                "object-size", "movement-time", "variability-size",
                                "variability-distance"}

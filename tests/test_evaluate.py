"""The healthy-adult population of the independent generator and tools/evaluate_verdict.py:
the sampler's ranges, disjoint dev and held-out seeds, the metrics on tables with a known
answer, clips at the extremes of scale and reach staying in the frame, a quick end-to-end
run."""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from perception.io.tracks import Tracks
from perception.synthetic.independent import CONDITIONS, RANGES, independent_paths
from perception.synthetic.population import (
    POPULATION_FPS,
    POPULATION_RANGES,
    POPULATION_STYLE,
    draw_population,
    population_camera,
    render_population_set,
)

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import evaluate_verdict as ev  # noqa: E402

# -- (a) the sampler ---------------------------------------------------------------

#: The literature's ranges the population must stay within (docs/recognition.md §10).
STATED = {"duration": (0.65, 1.4), "peak_velocity_time": (0.36, 0.50),
          "mga_excess": (0.015, 0.035), "mga_time": (0.60, 0.80), "curvature": (-0.01, 0.03),
          "distance": (0.22, 0.40), "approach_angle_deg": (-20.0, 20.0)}


def test_population_draws_stay_within_the_stated_ranges():
    for key, (lo, hi) in STATED.items():
        assert POPULATION_RANGES[key] == pytest.approx((lo, hi))
    assert POPULATION_RANGES["px_per_m"] == (550.0, 900.0)
    assert set(POPULATION_FPS) == {25.0, 30.0, 60.0}
    fps_seen = set()
    for seed in range(400):
        for cond in CONDITIONS:
            d = draw_population(cond, np.random.default_rng(seed))
            p = d.params
            assert p.condition == cond
            for key, (lo, hi) in STATED.items():
                assert lo <= getattr(p, key) <= hi, (key, getattr(p, key))
            for key in ("delayed_onset", "delayed_mga_time", "oco_first_time", "oco_close_time",
                        "oco_reopen_time", "oco_depth"):  # the condition timings: as today's
                assert RANGES[key][0] <= getattr(p, key) <= RANGES[key][1]
            assert 550 <= d.px_per_m <= 900 and d.fps in POPULATION_FPS
            assert p.rest_before >= 0.3 and p.rest_after >= 0.3
            row = d.row()
            assert row["movement_time"] == p.duration and row["px_per_m"] == d.px_per_m
            fps_seen.add(d.fps)
    assert fps_seen == set(POPULATION_FPS)


def test_the_old_ranges_are_unchanged():
    assert RANGES["duration"] == (0.85, 1.15) and RANGES["distance"] == (0.242, 0.258)


def test_population_clips_start_and_end_at_rest():
    d = draw_population("normal", np.random.default_rng(3), wobble=0.0)
    t, paths = independent_paths(d.params, d.fps, seed=0)
    still = (t <= d.params.rest_before) | (t >= d.params.rest_before + d.params.duration)
    for m in ("wrist", "finger", "thumb"):
        xy = paths[m][still]
        first = xy[t[still] <= d.params.rest_before]
        last = xy[t[still] > d.params.rest_before]
        assert np.ptp(first, axis=0).max() < 1e-9 and np.ptp(last, axis=0).max() < 1e-9


def test_dev_and_heldout_seeds_never_overlap():
    seeds = {name: set(ev.set_seeds(name, ev.MAX_CLIPS)) for name in ev.SETS}
    for a in seeds:
        for b in seeds:
            assert a == b or not seeds[a] & seeds[b], (a, b)
    with pytest.raises(ValueError):
        ev.set_seeds("dev", ev.MAX_CLIPS + 1)
    assert ev.parse_counts("normal=30,delayed=10,open-close-open=10,reach=10") == \
        ev.DEFAULT_COUNTS
    assert sum(ev.DEFAULT_COUNTS.values()) >= 60 and ev.DEFAULT_COUNTS["normal"] >= 30


# -- (b) the metrics ---------------------------------------------------------------

def _tables(rows):
    """(summary, manifest) of rows (clip, condition, verdict, familiarity, mt, fps)."""
    man = pd.DataFrame([{"clip": c, "condition": k, "video": f"{c}.mp4", "movement_time": mt,
                         "fps": fps} for c, k, _, _, mt, fps in rows])
    summ = pd.DataFrame([{"clip": c, "condition": k, "verdict": v, "familiarity": f,
                          "status": "failed" if v is None else "ok"}
                         for c, k, v, f, _, _ in rows])
    return summ, man


def test_auc_of_separated_and_reversed_sets():
    assert ev.auc([0.5, 0.6, 0.9], [0.0, 0.01, 0.2]) == 1.0
    assert ev.auc([0.0, 0.01, 0.2], [0.5, 0.6, 0.9]) == 0.0
    assert ev.auc([0.5, np.nan], [0.0, 0.2]) == pytest.approx(2.5 / 4)  # NaN is 0: a tie
    assert math.isnan(ev.auc([], [0.1]))


def test_metrics_on_a_table_with_a_known_answer():
    rows = [("n1", "normal", "normal", 0.4, 0.7, 25.0),
            ("n2", "normal", "abnormal", 0.005, 0.9, 30.0),    # confidently wrong
            ("n3", "normal", "abnormal", 0.03, 1.3, 60.0),     # wrong, not confidently
            ("n4", "normal", None, np.nan, 1.0, 30.0),         # failed
            ("d1", "delayed", "abnormal", 0.001, 0.9, 30.0),
            ("d2", "delayed", "normal", 0.7, 1.0, 30.0),       # confidently wrong
            ("o1", "open-close-open", "reach", 0.3, 1.25, 60.0),  # wrong, not confidently
            ("o2", "open-close-open", "unfamiliar", 0.02, 0.75, 25.0),
            ("r1", "reach", "reach", 0.6, 0.9, 30.0),
            ("r2", "reach", "abnormal", 0.001, 1.3, 60.0)]     # confidently wrong
    table, groups = ev.evaluate(*_tables(rows))
    m = groups["all"]
    assert m["n"] == 10
    assert m["confusion"]["normal"] == {"normal": 1, "abnormal": 2, "reach": 0, "unfamiliar": 0,
                                        ev.FAILED: 1}
    assert m["confusion"]["open-close-open"]["unfamiliar"] == 1
    assert m["confusion"]["open-close-open"]["reach"] == 1
    assert m["right"]["normal"] == {"right": 1, "n": 4, "share": 0.25}
    assert m["right"]["delayed"]["right"] == 1 and m["right"]["open-close-open"]["right"] == 0
    assert m["right"]["reach"]["right"] == 1 and m["right_all"]["right"] == 3
    assert m["confidently_wrong"]["count"] == 3
    assert sorted(m["confidently_wrong"]["clips"]) == ["d2", "n2", "r2"]
    # normal familiarities 0.4, 0.005, 0.03, 0 (failed) vs 0.001, 0.7, 0.3, 0.02
    pos, neg = [0.4, 0.005, 0.03, 0.0], [0.001, 0.7, 0.3, 0.02]
    pairs = sum((a > b) + 0.5 * (a == b) for a in pos for b in neg)
    assert m["auc"] == pytest.approx(pairs / 16)
    # the groups: movement-time bands and frame rates
    assert groups["MT < 0.8 s"]["n"] == 2 and groups["MT 0.8–1.2 s"]["n"] == 5
    assert groups["MT > 1.2 s"]["n"] == 3
    assert groups["25 fps"]["n"] == 2 and groups["60 fps"]["n"] == 3
    assert groups["60 fps"]["confidently_wrong"]["count"] == 1
    assert table.set_index("clip").loc["n4", "verdict"] == ev.FAILED
    md = ev.markdown({"set": "dev", "seeds": [1000, 1009], "groups": groups, "jobs": 1},
                     table, list_clips=True)
    assert "| normal | 1 | 2 | 0 | 0 | 1 |" in md
    assert "| all | 10 | 1 / 4 | 1 / 2 | 0 / 2 | 1 / 2 | 3 / 10 (30 %) | 3 |" in md


def test_a_new_verdict_gets_its_own_column():
    rows = [("n1", "normal", "normal", 0.4, 1.0, 30.0),
            ("d1", "delayed", "odd", 0.1, 1.0, 30.0)]
    _, groups = ev.evaluate(*_tables(rows))
    assert groups["all"]["confusion"]["delayed"]["odd"] == 1


# -- (c) the extremes stay in the frame ----------------------------------------------

EXTREMES = {
    "far-coarse": {"distance": (0.40, 0.40), "px_per_m": (550.0, 550.0)},
    "near-fine": {"distance": (0.22, 0.22), "px_per_m": (900.0, 900.0)},
    # the largest image of the reach: far, fine, turned as far as the ranges go
    "far-fine": {"distance": (0.40, 0.40), "px_per_m": (900.0, 900.0),
                 "approach_angle_deg": (20.0, 20.0), "camera_angle_deg": (10.0, 10.0),
                 "curvature": (0.03, 0.03), "mga_excess": (0.035, 0.035)},
}
FPS = {"far-coarse": 60.0, "near-fine": 25.0, "far-fine": 30.0}


@pytest.mark.parametrize("extreme", list(EXTREMES))
def test_clips_at_the_extremes_stay_in_the_frame(tmp_path, extreme):
    ranges = {**EXTREMES[extreme], "duration": (0.65, 0.65)}
    man = render_population_set(tmp_path, dict.fromkeys(CONDITIONS, 1), seed=5, ranges=ranges,
                                fps_choices=(FPS[extreme],))
    assert list(man["condition"]) == list(CONDITIONS)
    for col in ("clip", "condition", "video", "movement_time", "distance", "px_per_m", "fps",
                "approach_deg", "mga_excess", "mga_time", "peak_velocity_time", "curvature"):
        assert col in man.columns
    on_disk = pd.read_csv(tmp_path / "manifest.csv")
    pd.testing.assert_frame_equal(on_disk[["clip", "fps", "px_per_m"]],
                                  man[["clip", "fps", "px_per_m"]])
    w, h = POPULATION_STYLE.width, POPULATION_STYLE.height
    for _, row in man.iterrows():
        assert row["distance"] == pytest.approx(ranges["distance"][0])
        assert row["px_per_m"] == pytest.approx(ranges["px_per_m"][0])
        assert row["fps"] == FPS[extreme] and row["movement_time"] == 0.65
        params = json.loads(row["parameters"])
        assert params["fps"] == FPS[extreme] and params["distance"] == row["distance"]
        truth = Tracks.load(tmp_path / row["truth"])
        assert truth.time[1] == pytest.approx(1 / FPS[extreme])
        radius = {"thumb": 0.006, "finger": 0.006, "wrist": 0.035, "object": 0.05}
        for j, name in enumerate(truth.markers):
            xy = truth.position[:, j]
            r = radius[name] * row["px_per_m"]
            assert (xy - r >= 0).all() and (xy[:, 0] + r <= w).all() and \
                (xy[:, 1] + r <= h).all(), (row["clip"], name)
        # at rest in the first and last 0.3 s
        wrist = truth.position[:, list(truth.markers).index("wrist")]
        k = int(0.3 * FPS[extreme])
        assert np.ptp(wrist[:k], axis=0).max() < 1.0 and np.ptp(wrist[-k:], axis=0).max() < 1.0


def test_every_drawn_population_clip_fits_its_frame():
    from perception.synthetic.population import _check_in_frame

    for seed in range(300):
        for cond in CONDITIONS:
            d = draw_population(cond, np.random.default_rng(seed))
            _, paths = independent_paths(d.params, d.fps, seed=seed)
            _check_in_frame(paths, population_camera(d), POPULATION_STYLE, f"{cond}-{seed}")


# -- (d) end to end ----------------------------------------------------------------

@pytest.mark.slow
def test_quick_evaluation_end_to_end(tmp_path):
    assert ev.main(["--set", "dev", "--quick", "-o", str(tmp_path), "--jobs", "2",
                    "--quiet"]) == 0
    result = json.loads((tmp_path / "evaluation.json").read_text())
    # quick by its size, whatever the machine's speed (no wall-time bound): 2 seeds, 4 clips
    assert result["seeds"] == [1000, 1003] and result["groups"]["all"]["n"] == 4
    assert len(result["clips"]) == 4
    assert {c["condition"] for c in result["clips"]} == set(CONDITIONS)
    assert all(c["verdict"] != ev.FAILED for c in result["clips"])
    md = (tmp_path / "evaluation.md").read_text()
    assert "| condition |" in md and "| all | 4 |" in md
    assert (tmp_path / "report" / "summary.csv").is_file()

"""Chapter 3's letters, measured: the 's' (Figs. 3.6-3.7) and the 'a' (Figs. 3.8-3.9)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from minvar.analysis import THESIS_DURATIONS, closest_approach, count_speed_peaks, speed_accuracy
from minvar.lqg import solve
from minvar.moments import state_moments
from minvar.plant import POSITION
from minvar.plotting.reach import reach_figure, speed_accuracy_figure
from minvar.plotting.viapoints import letter_durations_figure, letter_figure
from minvar.reach import simulate_reach
from minvar.similarity import path_distance
from minvar.task import reach_problem
from minvar.viapoints import expected_path, letter_a
from tools.thesis.ch3_reach import sd_falls
from tools.thesis.ch3_tasks import LETTER_DURATIONS, LETTER_SWEEP, S_TASK, _ms, _reversal, _stops
from tools.thesis.claims import Measured
from tools.thesis.common import rng_for, save
from tools.thesis.records import CONDITIONAL


def fig3_6_3_7(out: Path | None, got: dict, trials: int, seed: int, w: dict) -> None:
    """Figs. 3.6-3.7: the 's' through its via-points, and its speed-accuracy sweep."""
    s_task = replace(S_TASK, **w)
    r = simulate_reach(s_task, trials, seed=rng_for(seed, "fig3_6"))
    save(out, "fig3_6_s_movement", reach_figure(r, shown=50))
    _, expected = expected_path(s_task)
    miss = [closest_approach(expected, v.position) for v in s_task.via_points]
    miss_mc = [closest_approach(r.mean_position, v.position) for v in s_task.via_points]
    end = np.linalg.norm(expected[-1] - s_task.goal)
    # the repetitions' scatter where each via-point is due: what 'passes' is judged against
    due = [int(round(v.fraction * (r.time.size - 1))) for v in s_task.via_points]
    scatter = [float(np.sqrt(r.position[:, k].var(axis=0, ddof=1).sum())) for k in due + [-1]]
    peaks = count_speed_peaks(r.mean_speed)
    got["s-via-points"] = Measured(
              "expected path " + ", ".join(f"{m * 1000:.1f}" for m in miss)
              + f" mm from the via-points, {end * 1000:.1f} mm from the goal",
              {"every_miss_within_2sd": all(m < 2 * sd for m, sd in zip([*miss, end], scatter))},
              note="positional SD at the via-points' times " + ", ".join(
                  f"{sd * 1000:.1f}" for sd in scatter[:-1]) + f" mm, at the end "
              f"{scatter[-1] * 1000:.1f} mm; the mean of our {r.trials} repetitions passes "
              + ", ".join(f"{m * 1000:.1f}" for m in miss_mc) + " mm away. The via-point "
              "cost is soft, so the path cuts the corners; our own former rules (5 mm, "
              "docs/model.md; the end within 1 cm) are not the thesis's and judge nothing.")
    got["s-bells"] = Measured(f"{peaks} speed peaks", {"speed_peaks": peaks})
    sweep = speed_accuracy(s_task, THESIS_DURATIONS, trials, seed=seed + 1)
    save(out, "fig3_7_s_speed_accuracy", speed_accuracy_figure(sweep), sweep.summary)
    got["sd-falls-s"] = sd_falls(sweep.summary, trials)


def fig3_8_3_9(out: Path | None, got: dict, trials: int, seed: int, w: dict) -> None:
    """Figs. 3.8-3.9: the letter 'a', its reversal, and its shape at other movement times."""
    rng = rng_for(seed, "fig3_8")
    results = [simulate_reach(letter_a(duration=d).to_task(**w), trials, seed=rng)
               for d in LETTER_DURATIONS]
    main = results[1]
    save(out, "fig3_8_letter_a", letter_figure(main))
    d = main.task.duration
    t_exp, p_exp = expected_path(main.task)
    speed_exp = np.linalg.norm(np.gradient(p_exp, t_exp, axis=0), axis=1)
    when, slow = _reversal(t_exp, speed_exp, d)
    single = np.array([_reversal(main.time, s, d) for s in main.speed])
    rel_single = np.median(single[:, 1] / main.speed.max(axis=1))
    stops = [t for t in LETTER_SWEEP if _stops(letter_a(duration=t).to_task(**w))]
    flips = 0 < len(stops) < len(LETTER_SWEEP)
    got["a-stops"] = Measured(
              f"{slow * 1000:.0f} mm/s ({slow / speed_exp.max():.0%} of peak) on the "
              f"expected path at {d:g} s; single movements: median {rel_single:.0%} of peak; "
              f"below 10 % at {', '.join(f'{t:g}' for t in stops) or 'none'} of "
              f"{LETTER_SWEEP[0]:g}-{LETTER_SWEEP[-1]:g} s",
              {"slowest_speed": slow, "peak_speed": speed_exp.max()},
              verdict=CONDITIONAL if flips else None,
              note="the speed there is the model's: a direction reversal through a via-point "
              "need not stop the hand, the cost only asks it to pass the point"
              + (f"; conditional on the movement time: holds from {min(stops):g} s"
                 if flips else ""))
    got["a-reversal-70"] = Measured(
              f"at {when:.0%} on the expected path; single movements: median "
              f"{np.median(single[:, 0]):.0%}",
              note="our via-points (the thesis does not give its own) put the top of the stem "
              "at 70 % of the movement, so the reversal is there because we placed it there")

    rows = []
    for r in results:
        task = r.task
        miss = [closest_approach(r.mean_position, v.position) for v in task.via_points]
        spread = np.sqrt(r.position.var(axis=0, ddof=1).sum(axis=1)).mean()
        rows.append({"duration": task.duration, "max_via_miss_m": max(miss),
                     "mean_path_sd_m": spread,
                     "shape_distance_to_slowest_m": path_distance(
                         r.mean_position, results[-1].mean_position)})
    table = pd.DataFrame(rows)
    save(out, "fig3_9_letter_a_durations", letter_durations_figure(results), table)
    apart = table["shape_distance_to_slowest_m"]
    slow = results[-1]
    scatter = float(np.median([path_distance(p, slow.mean_position) for p in slow.position]))
    times = table["duration"] * 1000
    sweep = _letter_sweep(w, scatter)
    save(out, "fig3_9_letter_a_duration_sweep", table=sweep)
    keeps = sweep["shape_distance_m"] < scatter
    fastest = sweep["duration"][keeps].min()
    flips = not keeps.all() and keeps.iloc[:-1].any()
    got["a-keeps-shape"] = Measured(
              f"mean paths at {times.iloc[0]:.0f} and {times.iloc[1]:.0f} ms at most "
              f"{apart.iloc[0] * 1000:.1f} and {apart.iloc[1] * 1000:.1f} mm from the "
              f"{times.iloc[-1]:.0f} ms one (letter 10 cm high); swept over "
              f"{_ms(sweep['duration'])} ms, the expected path stays within the noise of the "
              f"{times.iloc[-1]:.0f} ms one down to {fastest * 1000:.0f} ms",
              {"keeps_at_every_time": bool(keeps.all()), "scatter_mm": scatter * 1000,
               "slowest_ms": times.iloc[-1]},
              verdict=CONDITIONAL if flips else None,
              note="the thesis gives neither the 'a's via-points nor its three movement "
              f"times, and the verdict turns on them: the shape keeps within the noise for "
              f"movement times from {fastest * 1000:.0f} ms up, not below (table "
              "fig3_9_letter_a_duration_sweep.csv). Our former 20 mm rule was our own "
              "number.")
    got["a-fastest-crudest"] = Measured(
              "largest via-point miss " + ", ".join(
                  f"{m * 1000:.1f}" for m in table["max_via_miss_m"])
              + " mm; mean positional SD " + ", ".join(
                  f"{s * 1000:.1f}" for s in table["mean_path_sd_m"])
              + " mm at " + ", ".join(f"{d:.0f}" for d in times) + " ms",
              {"fastest_largest_both": bool(table["max_via_miss_m"].idxmax() == 0
                                            and table["mean_path_sd_m"].idxmax() == 0),
               "trials": trials},
              note=_fastest_note(sweep))



def _letter_sweep(w: dict, scatter: float) -> pd.DataFrame:
    """The 'a' at each of :data:`LETTER_SWEEP`, exact: its expected path's Hausdorff
    distance from the slowest's, its largest via-point miss and its mean positional SD
    (exact moments), against the repetition noise ``scatter`` (m)."""
    rows, paths = [], {}
    for d in LETTER_SWEEP:
        task = letter_a(duration=d).to_task(**w)
        problem = reach_problem(task)
        sol = solve(problem)
        _, cov = state_moments(problem, sol.K, sol.L)
        paths[d] = p = sol.mean_states[:, POSITION]
        rows.append({"duration": d,
                     "max_via_miss_m": max(closest_approach(p, v.position)
                                           for v in task.via_points),
                     "mean_path_sd_m": float(np.sqrt(cov[:, 0, 0] + cov[:, 1, 1]).mean())})
    table = pd.DataFrame(rows)
    table["shape_distance_m"] = [path_distance(paths[d], paths[LETTER_SWEEP[-1]])
                                 for d in LETTER_SWEEP]
    table["noise_m"] = scatter
    return table


def _fastest_note(sweep: pd.DataFrame) -> str:
    """Whether the fastest of any set of the swept times is the crudest and noisiest."""
    miss, sd = sweep["max_via_miss_m"].to_numpy(), sweep["mean_path_sd_m"].to_numpy()
    fails = [f"{d * 1000:.0f} ms (miss {miss[i] * 1000:.1f} mm, slower ones up to "
             f"{miss[i + 1:].max() * 1000:.1f} mm)" for i, d in enumerate(sweep["duration"][:-1])
             if not (miss[i] > miss[i + 1:].max() and sd[i] > sd[i + 1:].max())]
    return (f"over the sweep of movement times ({_ms(sweep['duration'])} ms, exact moments) "
            "the fastest of any set is the crudest and noisiest" + (
                "" if not fails else ", except with its fastest at " + "; ".join(fails)
                + ": millimetre misses, within the repetition noise"))


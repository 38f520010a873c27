"""Thesis appendix A: via-point selection and generalisation, Figs. A.1-A.3.

``reproduce(out, *, trials, seed)`` writes the figures and returns the claims
(see ``reproduce_common``).

The thesis compares its three via-point criteria on "several repeated
trials" of one curved movement it does not specify. Ours: single noisy
repetitions (the observed movements) of four minimum variance movements — a
plain reach, a reach bowed by one via-point, the 's' of Fig. 3.6 and the
letter 'a' — ``REPEATS`` of each.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from reproduce_common import Progress, borderline, claim, no_progress, rng_for, save

from minvar.plotting.viapoints import criteria_figure, curvature_figure, generalisation_figure
from minvar.reach import simulate_reach
from minvar.similarity import path_distance
from minvar.task import ReachTask, ViaPoint
from minvar.viapoints import CRITERIA, compare_criteria, letter_a, replay

#: The observed movements of Fig. A.1 (m, s); all within a 0.30 + 0.30 m arm's reach.
TEST_TASKS = {
    "reach": ReachTask((0.2, 0.2), (0.1, 0.5), 0.8),
    "bowed reach": ReachTask(
        (-0.15, 0.30), (0.15, 0.30), 1.0, (ViaPoint((0.0, 0.42), fraction=0.4),)
    ),
    "s": ReachTask(
        (-0.2, 0.5), (-0.4, 0.2), 1.0,
        (ViaPoint((-0.4, 0.4), fraction=0.25), ViaPoint((-0.2, 0.3), fraction=0.75)),
    ),
    "letter a": letter_a(duration=1.5).to_task(),
}
REPEATS = 3
#: Fig. A.3: the 'a' at its original time, re-timed faster, and scaled by 1/2.
A3_SLOW, A3_FAST, A3_SCALE = 2.0, 1.0, 0.5


def _observed(seed: int, repeats: int):
    names, trajs = [], []
    for name, task in TEST_TASKS.items():
        r = simulate_reach(task, repeats, seed=rng_for(seed, f"figA_1 {name}"))
        for k in range(repeats):
            names.append(name)
            trajs.append((r.time, r.position[k]))
    return names, trajs


def _coincident(table: pd.DataFrame, a: str, b: str, steps: int) -> tuple[int, int]:
    """How many of criterion ``a``'s via-points lie within ``steps`` samples of one of ``b``'s."""
    near = total = 0
    for _, rows in table.groupby("trajectory"):
        ia = np.asarray(rows.loc[rows["criterion"] == a, "indices"].iloc[0])
        ib = np.asarray(rows.loc[rows["criterion"] == b, "indices"].iloc[0])
        total += len(ia)
        if len(ib):
            near += int(np.sum(np.min(np.abs(ia[:, None] - ib[None]), axis=1) <= steps))
    return near, total


def _fig_a1(out: Path, claims: list, seed: int, repeats: int):
    names, trajs = _observed(seed, repeats)
    comparison = compare_criteria(trajs)
    table = comparison.table.assign(movement=[names[k] for k in comparison.table["trajectory"]])
    save(out, "figA_1_viapoint_criteria", criteria_figure(comparison), table)
    save(out, "figA_1_viapoint_criteria_summary", table=comparison.summary)
    s = comparison.summary.set_index("criterion")
    scores = ", ".join(f"{c} {s.loc[c, 'score'] * 1e4:.2f}" for c in CRITERIA)
    wins = ", ".join(f"{c} {s.loc[c, 'wins']}" for c in CRITERIA)
    msds = ", ".join(f"{c} {s.loc[c, 'msd_per_sample'] * 1e4:.2f}" for c in CRITERIA)
    points = ", ".join(f"{c} {s.loc[c, 'n_points']:.1f}" for c in CRITERIA)
    how = (f"{len(trajs)} observed movements ({repeats} noisy repetitions each of: "
           + ", ".join(TEST_TASKS) + "); replayed by the model's expected path; eq. A.2 "
           "in the joint space of a 0.30 + 0.30 m arm, per sample. Extrema below 5 % of a "
           "signal's range ignored.")
    claims.append(claim(
        "A.1, Fig. A.1(a)", "Acceleration extrema capture the original movement well",
        "captures well",
        f"MSD per sample (1e-4 rad²): {msds}; points stored: {points}",
        s.loc["acceleration", "msd_per_sample"] <= s.loc["speed", "msd_per_sample"],
        "Judged by acceleration's MSD being no worse than speed's. The criteria follow the text "
        "(extrema of speed, acceleration, curvature); Fig. A.1's caption says 'zero-crossings of "
        "the derivatives of position, velocity and curvature'. " + how,
    ))
    best = comparison.best
    near, total = _coincident(comparison.table, "curvature", "acceleration", steps=3)
    note = ("Eq. A.1 in SI units: with speeds well under 1 m/s the '+1' dominates the "
            "denominator and |a|^2 the numerator, so curvature extrema sit close to "
            f"acceleration extrema ({near} of {total} curvature via-points within 30 ms of an "
            "acceleration one). ")
    if best != "curvature":
        note += f"Ours disagrees: {best} scores best on this set."
    claims.append(claim(
        "A.1, Fig. A.1(b)", "Curvature extrema give the best MSD × number of via-points",
        "curvature best",
        f"best: {best}; mean MSD/sample × points (1e-4 rad²): {scores}; "
        f"lowest on each movement: {wins}",
        best == "curvature", note + " " + how,
    ))
    return names, trajs, comparison


def _fig_a2(out: Path, names: list, trajs: list, comparison) -> None:
    k = names.index("bowed reach")
    t, p = trajs[k]
    rows = comparison.table
    idx = rows.loc[(rows["trajectory"] == k) & (rows["criterion"] == "curvature"), "indices"]
    idx = idx.iloc[0]
    save(out, "figA_2_curvature_viapoints", curvature_figure(t, p, idx))


def _fig_a3(out: Path, claims: list, n: int, seed: int) -> None:
    rng = rng_for(seed, "figA_3")
    movement = letter_a(duration=A3_SLOW)
    faster = movement.retime(A3_FAST)
    smaller = movement.transform(scale=A3_SCALE)
    results = [simulate_reach(m.to_task(), n, seed=rng) for m in (movement, faster, smaller)]
    save(out, "figA_3_generalisation", generalisation_figure(*results))
    _, p_slow = replay(movement)
    _, p_fast = replay(faster)
    _, p_small = replay(smaller)
    s0 = np.asarray(movement.start)
    expected_small = A3_SCALE * (p_slow - s0) + s0
    shape = path_distance(p_slow, p_fast)
    scaled_err = float(np.linalg.norm(p_small - expected_small, axis=1).max())
    table = pd.DataFrame(
        {"movement": ["original", "re-timed", "scaled"],
         "duration_s": [m.duration for m in (movement, faster, smaller)],
         "scale": [1.0, 1.0, A3_SCALE],
         "path_distance_to_original_shape_m": [0.0, shape, scaled_err]}
    )
    save(out, "figA_3_generalisation", table=table)
    claims += [
        claim("A.2, Fig. A.3(a)", "Re-timed (eq. A.3) the 'a' keeps its basic shape",
              "shape retained, cruder when faster",
              f"{A3_SLOW * 1000:.0f} ms -> {A3_FAST * 1000:.0f} ms: expected paths at most "
              f"{shape * 1000:.1f} mm apart (letter 10 cm high)", shape < 0.02,
              "Judged within 20 % of the letter's height (Hausdorff distance); the faster "
              "movement cuts the bowl's corners." + borderline(shape, 0.02)),
        claim("A.2, Fig. A.3(b)",
              "Scaled by 1/2 (eqs. A.4-A.5) the 'a' is the same letter, half size",
              "same shape, half size",
              f"expected path within {scaled_err * 1000:.2f} mm of the original scaled by 1/2",
              scaled_err < 0.05 * A3_SCALE * 0.10,
              "Judged within 5 % of the scaled letter's height. Not exact: signal-dependent "
              "noise scales with the movement but the sensory noise does not."),
    ]


def reproduce(
    out: Path,
    *,
    trials: int | None = None,
    seed: int = 0,
    repeats: int = REPEATS,
    progress: Progress = no_progress,
) -> list[dict]:
    """Figs. A.1-A.3 into ``out``; the appendix's claims.

    Parameters
    ----------
    out : Path
        Output folder.
    trials : int, optional
        Repetitions drawn for Fig. A.3 (default 50).
    seed : int
        Base seed; each figure draws from its own stream.
    repeats : int
        Observed repetitions of each test movement in Fig. A.1.
    progress : callable
        Called with the name of each figure as it starts.
    """
    out = Path(out)
    n = 50 if trials is None else int(trials)
    claims = []

    progress("figA_1")
    names, trajs, comparison = _fig_a1(out, claims, seed, repeats)
    progress("figA_2")
    _fig_a2(out, names, trajs, comparison)
    progress("figA_3")
    _fig_a3(out, claims, n, seed)
    return claims

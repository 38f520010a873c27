"""Thesis chapter 2 (section 2.2): the minimum jerk family, Figs. 2.5-2.8, measured.

``reproduce(out, *, trials, seed)`` writes the figures and returns the claims of
:data:`tools.thesis.ch2_claims.CLAIMS`, evaluated. The models are noiseless, so
``trials`` is unused; ``seed`` places the ten movements of Figs. 2.5 and 2.7.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from minvar.analysis import count_speed_peaks, path_deviation, peak_to_mean_speed
from minvar.baselines import (
    minimum_angle_jerk,
    minimum_derivative,
    minimum_jerk,
    peak_to_mean_ratio,
)
from minvar.plotting.baselines import (
    angle_jerk_hand_figure,
    angle_jerk_joint_figure,
    derivative_order_figure,
    minimum_jerk_figure,
)
from tools.thesis.ch2_claims import CLAIMS
from tools.thesis.claims import Measured, evaluate
from tools.thesis.common import Progress, no_progress, rng_for, save

#: The movement of Figs. 2.5, 2.7, 2.8 (m, s): a lateral reach in front of the
#: shoulder of a two-link arm with 0.30 m links (the thesis gives no coordinates).
START, GOAL, DURATION = np.array([-0.15, 0.30]), np.array([0.15, 0.40]), 1.0
#: "Similar points in one area of the workspace": start and goal jittered by up to this, m.
JITTER = 0.02
ORDERS = (2, 3, 4, 5, 6)
#: The human peak/mean velocity ratio the thesis quotes (line 276).
HUMAN_R = 1.875


def _movements(seed: int, count: int = 10) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = rng_for(seed, "fig2_5")
    jitter = rng.uniform(-JITTER, JITTER, size=(count, 2, 2))
    return [(START + j[0], GOAL + j[1]) for j in jitter]


def _fig2_5(out: Path, got: dict, pairs: list) -> None:
    jerk = [minimum_jerk(s, g, DURATION, dt=0.001) for s, g in pairs]
    rows = [
        {
            "movement": k,
            "start_x": s[0], "start_y": s[1], "goal_x": g[0], "goal_y": g[1],
            "max_deviation_m": np.abs(path_deviation(m.position, s, g)).max(),
            "peak_to_mean": peak_to_mean_speed(m.speed, m.time),
            "speed_peaks": count_speed_peaks(m.speed),
        }
        for k, ((s, g), m) in enumerate(zip(pairs, jerk))
    ]
    table = pd.DataFrame(rows)
    save(out, "fig2_5_minimum_jerk", minimum_jerk_figure(jerk), table)
    dev = table["max_deviation_m"].max()
    got["jerk-straight"] = Measured(
        f"max deviation {dev * 1000:.1e} mm over {len(jerk)} movements",
        {"max_deviation_m": dev})
    bells = int((table["speed_peaks"] == 1).sum())
    got["jerk-bells"] = Measured(f"{bells}/{len(jerk)} profiles with one peak",
                                 {"one_peak_each": bells == len(jerk)})


def _fig2_6(out: Path, got: dict) -> None:
    ratios = {n: peak_to_mean_ratio(n) for n in ORDERS}
    # 20 cm in 1 s, sampled at 1 ms: the thesis's Fig. 2.6
    movements = {n: minimum_derivative(n, (0.0, 0.0), (0.20, 0.0), 1.0, dt=0.001)
                 for n in ORDERS}
    sampled = {n: peak_to_mean_speed(m.speed, m.time) for n, m in movements.items()}
    table = pd.DataFrame(
        {"order": list(ORDERS), "ratio_closed_form": [ratios[n] for n in ORDERS],
         "ratio_sampled_1ms": [sampled[n] for n in ORDERS]}
    )
    save(out, "fig2_6_derivative_order", derivative_order_figure(movements), table)
    values = [ratios[n] for n in ORDERS]
    got["ratio-rises"] = Measured("n = 2..6: " + ", ".join(f"{r:.3f}" for r in values),
                                  {"rises_every_order": bool(np.all(np.diff(values) > 0))})
    nearest = min(ORDERS, key=lambda n: abs(ratios[n] - HUMAN_R))
    got["human-nearest"] = Measured(
        f"n = {nearest}: minimum jerk's r = 15/8 = {ratios[3]:.4f} exactly ({sampled[3]:.4f} "
        f"sampled at 1 ms); n = 2: {ratios[2]:.3f}, n = 4: {ratios[4]:.3f}",
        {"nearest_order": nearest},
        note="1.875 is the thesis's value for humans, not for minimum jerk: that minimum "
        "jerk's own ratio is exactly 15/8 = 1.875 is our closed form, which is why the human "
        "value sits on it")


def _fig2_7(out: Path, got: dict, pairs: list) -> list:
    arm = [minimum_angle_jerk(s, g, DURATION, dt=0.005) for s, g in pairs]
    save(out, "fig2_7_angle_jerk_joints", angle_jerk_joint_figure(arm))
    joint_dev = max(
        np.abs(path_deviation(m.joints.position, m.joints.position[0], m.joints.position[-1])).max()
        for m in arm
    )
    got["angle-jerk-joints"] = Measured(
        f"max deviation {joint_dev:.1e} rad over {len(arm)} movements",
        {"max_deviation_rad": joint_dev})
    return arm


def _fig2_8(out: Path, got: dict, pairs: list, arm: list) -> None:
    hand_dev = np.array([
        np.abs(path_deviation(m.hand.position, s, g)).max() for (s, g), m in zip(pairs, arm)
    ])
    lengths = np.array([np.linalg.norm(g - s) for s, g in pairs])
    rel = hand_dev / lengths
    main = minimum_angle_jerk(START, GOAL, DURATION, dt=0.005)
    straight = minimum_jerk(START, GOAL, DURATION, dt=0.005)
    table = pd.DataFrame({
        "movement": np.arange(len(arm)), "length_m": lengths, "hand_max_deviation_m": hand_dev,
        "hand_speed_peaks": [count_speed_peaks(m.hand.speed) for m in arm],
        "hand_peak_to_mean": [peak_to_mean_speed(m.hand.speed, m.time) for m in arm],
    })
    save(out, "fig2_8_angle_jerk_hand", angle_jerk_hand_figure(main, straight), table)
    got["angle-jerk-hand-path"] = Measured(
        f"max deviation {hand_dev.min() * 1000:.0f}-{hand_dev.max() * 1000:.0f} mm "
        f"({rel.min():.0%}-{rel.max():.0%} of the movement length)",
        {"min_relative_deviation": rel.min(), "max_relative_deviation": rel.max()},
        note="arm: two 0.30 m links, shoulder at the origin, elbow angle positive; movements "
        "of about 32 cm across the front (the thesis gives no coordinates)")
    peaks = table["hand_speed_peaks"]
    got["angle-jerk-hand-speed"] = Measured(
        f"{int((peaks == 1).sum())}/{len(arm)} with one peak; peak/mean "
        f"{table['hand_peak_to_mean'].min():.2f}-{table['hand_peak_to_mean'].max():.2f}",
        {"one_peak_each": bool((peaks == 1).all())})


def reproduce(
    out: Path, *, trials: int | None = None, seed: int = 0, quick: bool = False,
    progress: Progress = no_progress,
) -> list[dict]:
    """Figs. 2.5-2.8 into ``out``; the chapter's claims.

    Parameters
    ----------
    out : Path
        Output folder.
    trials : int, optional
        Unused (the models are noiseless); accepted for a uniform interface.
    quick : bool
        Unused (a smoke run is as long).
    seed : int
        Places the ten jittered movements.
    progress : callable
        Called with the name of each figure as it starts.
    """
    out = Path(out)
    got: dict[str, Measured] = {}
    pairs = _movements(seed)

    progress("fig2_5")
    _fig2_5(out, got, pairs)
    progress("fig2_6")
    _fig2_6(out, got)
    progress("fig2_7")
    arm = _fig2_7(out, got, pairs)
    progress("fig2_8")
    _fig2_8(out, got, pairs, arm)
    claims = evaluate(CLAIMS, got)
    for c in claims:  # no cost weights enter chapter 2's models
        c["at_thesis"] = f"{c['verdict']}: same (no cost weights in these models)"
    return claims

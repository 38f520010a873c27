"""Thesis chapter 2 (section 2.2): the minimum jerk family, Figs. 2.5-2.8.

``reproduce(out, *, trials, seed)`` writes the figures and returns the claims
(see ``reproduce_common``). The models are noiseless, so ``trials`` is unused;
``seed`` places the ten movements of Figs. 2.5 and 2.7.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from reproduce_common import Progress, cite, claim, no_progress, rng_for, save

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


def _fig2_5(out: Path, claims: list, pairs: list) -> None:
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
    claims.append(claim(
        "2.2.2", "Minimum jerk hand paths are straight", "straight",
        f"max deviation {dev * 1000:.1e} mm over {len(jerk)} movements", dev < 1e-9,
        location="Fig. 2.5(a); line 260",
        measure="largest distance of each path from its start-goal line; agree below 1e-9 m "
        "(straight to rounding)",
    ))
    bells = int((table["speed_peaks"] == 1).sum())
    claims.append(claim(
        "2.2.2", "Minimum jerk speed profiles are smooth single bells",
        "bell-shaped", f"{bells}/{len(jerk)} profiles with one peak", bells == len(jerk),
        location="Fig. 2.5(b); line 260",
        measure="speed peaks (prominence 5 % of the maximum); agree if one in every profile",
    ))


def _fig2_6(out: Path, claims: list) -> None:
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
    claims.append(claim(
        "2.2.3", "r, the peak/mean velocity ratio, increases with the derivative order n",
        "increases with n",
        "n = 2..6: " + ", ".join(f"{r:.3f}" for r in values),
        bool(np.all(np.diff(values) > 0)), location="Fig. 2.6(c); line 276",
        measure="r of the rest-to-rest minimum-derivative profile, closed form "
        "1 / (4^(n-1) B(n, n)) (checked against profiles sampled at 1 ms); agree if it rises "
        "at every order",
    ))
    nearest = min(ORDERS, key=lambda n: abs(ratios[n] - HUMAN_R))
    claims.append(claim(
        "2.2.3", "Humans (r ≈ 1.875) are closest to minimum jerk",
        "human r = 1.875 (the dashed line); nearest order n = 3",
        f"n = {nearest}: minimum jerk's r = 15/8 = {ratios[3]:.4f} exactly ({sampled[3]:.4f} "
        f"sampled at 1 ms); n = 2: {ratios[2]:.3f}, n = 4: {ratios[4]:.3f}",
        nearest == 3, location="Fig. 2.6(c); lines 274, 276",
        measure="the order whose r is nearest the human 1.875",
        note="1.875 is the thesis's value for humans, not for minimum jerk: that minimum "
        "jerk's own ratio is exactly 15/8 = 1.875 is our closed form, which is why the human "
        "value sits on it",
    ))


def _fig2_7(out: Path, claims: list, pairs: list) -> list:
    arm = [minimum_angle_jerk(s, g, DURATION, dt=0.005) for s, g in pairs]
    save(out, "fig2_7_angle_jerk_joints", angle_jerk_joint_figure(arm))
    joint_dev = max(
        np.abs(path_deviation(m.joints.position, m.joints.position[0], m.joints.position[-1])).max()
        for m in arm
    )
    claims.append(claim(
        "2.2.4", "Minimum angle jerk: joint paths are straight in joint space",
        "straight joint paths", f"max deviation {joint_dev:.1e} rad over {len(arm)} movements",
        joint_dev < 1e-9, location="Fig. 2.7; line 287",
        measure="largest distance of each joint-space path from its start-goal line; agree "
        "below 1e-9 rad",
    ))
    return arm


def _fig2_8(out: Path, claims: list, pairs: list, arm: list) -> None:
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
    claims.append(claim(
        "2.2.4", "Minimum angle jerk: hand path roughly straight, slightly curved",
        "slight curvature",
        f"max deviation {hand_dev.min() * 1000:.0f}-{hand_dev.max() * 1000:.0f} mm "
        f"({rel.min():.0%}-{rel.max():.0%} of the movement length)",
        bool(np.all((rel > 0.01) & (rel < 0.15))), location="Fig. 2.8(a); lines 285, 294",
        measure="largest distance of each hand path from its start-goal line; 'slight' "
        "taken as 1-15 % of the movement length",
        note="arm: two 0.30 m links, shoulder at the origin, elbow angle positive; movements "
        "of about 32 cm across the front (the thesis gives no coordinates)",
    ))
    peaks = table["hand_speed_peaks"]
    claims.append(claim(
        "2.2.4", "Minimum angle jerk hand speed is bell-shaped", "bell-shaped",
        f"{int((peaks == 1).sum())}/{len(arm)} with one peak; peak/mean "
        f"{table['hand_peak_to_mean'].min():.2f}-{table['hand_peak_to_mean'].max():.2f}",
        bool((peaks == 1).all()), location="Fig. 2.8(b); line 294",
        measure="speed peaks (prominence 5 % of the maximum); agree if one in every profile",
    ))


def reproduce(
    out: Path, *, trials: int | None = None, seed: int = 0, progress: Progress = no_progress
) -> list[dict]:
    """Figs. 2.5-2.8 into ``out``; the chapter's claims.

    Parameters
    ----------
    out : Path
        Output folder.
    trials : int, optional
        Unused (the models are noiseless); accepted for a uniform interface.
    seed : int
        Places the ten jittered movements.
    progress : callable
        Called with the name of each figure as it starts.
    """
    out = Path(out)
    claims = []
    pairs = _movements(seed)

    progress("fig2_5")
    _fig2_5(out, claims, pairs)
    progress("fig2_6")
    _fig2_6(out, claims)
    progress("fig2_7")
    arm = _fig2_7(out, claims, pairs)
    progress("fig2_8")
    _fig2_8(out, claims, pairs, arm)
    cite(claims, CITES)
    for c in claims:  # no cost weights enter chapter 2's models
        c["at_thesis"] = f"{c['verdict']}: same (no cost weights in these models)"
    return claims


_IDENTITY = {"verdict": "by construction", "why": "+By construction: a closed-form property of "
             "the minimum-derivative model (nothing fitted), so it checks our implementation, "
             "not a finding."}
#: Claim prefix -> (thesis line, the thesis's words on it[, changes]).
CITES = {
    "Minimum jerk hand paths are straight": (
        260, "fit the criterion for straight hand trajectories", _IDENTITY),
    "Minimum jerk speed profiles": (260, "characteristic bell-shaped velocity profiles",
                                    _IDENTITY),
    "r, the peak/mean": (276, "the value of r increases with n", _IDENTITY),
    "Humans (r": (276, "closest to minimum jerk trajectories", _IDENTITY),
    "Minimum angle jerk: joint paths": (287, "leads to straight paths in joint space",
                                        _IDENTITY),
    "Minimum angle jerk: hand path": (294, "smooth and roughly straight, with a slight degree "
                                      "of curvature"),
    "Minimum angle jerk hand speed": (294, "the required bell-shape"),
}

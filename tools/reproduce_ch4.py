"""Reproduce thesis chapter 4 (grasping): every figure, table and quantitative claim.

``reproduce(out, trials=500, seed=0)`` runs the seven experiments of
:mod:`minvar.grasp_experiments` (each from its own child of ``seed``), saves
their figures (PNG, named after the thesis's, e.g. ``fig4_10_object_size_mga.png``)
and tables (CSV) into ``out``, and returns the chapter's claims
(:func:`reproduce_common.claim`) and two sensitivity tables
(:func:`reproduce_common.sensitivity`): the verdicts that depend on where the
closed digits start (``tip_start``) and on how far the wrist travels, across
their plausible ranges. ``tools/reproduce_thesis.py`` calls it; run alone,
this script also writes ``claims.csv`` and prints the claims::

    python tools/reproduce_ch4.py -o out/ch4 [--trials 500] [--seed 0]

Measures: trends in standard deviations and distances are judged on exact
(first-order) moments (``*_exact``), so no verdict hinges on sampling error;
what 500 repetitions per setting could resolve is given as 95 % intervals
(bootstrap for peak SDs, normal for means). Line numbers refer to the thesis
text (``minimum-variance-thesis.txt``). The geometry follows the text and its
figures (docs/model.md); nothing was tuned to these numbers.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT, ROOT / "tools"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

import reproduce_ch4_hand as hand  # noqa: E402
from reproduce_ch4_sensitivity import (  # noqa: E402
    SD_ERROR_500,
    UM,
    cm,
    level_is_best,
    mark_conditional,
    pct,
    tip_start_table,
    travel_table,
    u_minimum,
)
from reproduce_common import (  # noqa: E402
    THESIS_SETTINGS,
    at_settings,
    cite,
    claim,
)

from hammer_mv.cli.grasp import write_experiment  # noqa: E402
from minvar.analysis import path_deviation  # noqa: E402
from minvar.grasp import GraspTask, plan_grasp, simulate_grasp  # noqa: E402
from minvar.grasp_experiments import EXPERIMENTS, GraspExperiment  # noqa: E402
from minvar.plotting.grasp import grasp_figure, setup_figure  # noqa: E402
from perception.io.atomic import save_figure, write_csv  # noqa: E402

log = logging.getLogger("reproduce_ch4")

#: The thesis's MGA slope (line 903) and the human one (lines 696, 742).
SLOPE_THESIS, SLOPE_HUMAN = 0.92, 0.8


def _ci(pair, scale: float, fmt: str = ".1f") -> str:
    lo, hi = pair
    return f"95 % CI {lo * scale:{fmt}} to {hi * scale:{fmt}}"


def _monotonic(y, increasing: bool) -> bool:
    d = np.diff(np.asarray(y, dtype=float))
    return bool(np.all(d > 0) if increasing else np.all(d < 0))


def _excludes_zero(pair) -> bool:
    return pair[0] > 0 or pair[1] < 0


def _total_sd(s: pd.DataFrame, digit: str = "finger") -> np.ndarray:
    return np.hypot(s[f"{digit}_sd_x_exact"], s[f"{digit}_sd_y_exact"]).to_numpy()


# --- 4.2.1: via-point position ------------------------------------------------------
def _viapoint_height(e: GraspExperiment) -> list[dict]:
    s = e.summary
    h = s.viapoint_height.to_numpy()
    d = s.finger_distance_exact.to_numpy()
    d_thumb = s.thumb_distance_exact.to_numpy()
    lvl = int(np.argmin(np.abs(h)))
    mc, half = s.finger_distance_mean.iloc[lvl], 1.96 * s.finger_distance_sd.iloc[lvl] / np.sqrt(
        s.trials.iloc[lvl])
    out = [claim(
        "4.2.1.1", "Digit end-point distance from the target falls as the via-points come "
        "level with the targets and rises again above them",
        "decreases toward level, increases above", ", ".join(
            f"{cm(x)}: {y * UM:.0f}" for x, y in zip(h, d)) + " µm (finger); " + ", ".join(
            f"{cm(x)}: {y * UM:.0f}" for x, y in zip(h, d_thumb)) + f" µm (thumb); finger at "
        f"level, {s.trials.iloc[lvl]} repetitions: {mc * UM:.0f} ± {half * UM:.0f} µm",
        level_is_best(h, d) and level_is_best(h, d_thumb), location="Fig. 4.3(a,b); line 788",
        measure="exact mean end-point distance (expected distance of the exact end-point "
        "distribution) of each digit per via-point height, -2 to +2 cm; agree if each "
        "digit's is lowest at level and monotone on both sides",
        note=f"the distance is mostly the plan's systematic end-point error, not scatter; "
        f"the thumb's is larger ({d_thumb[lvl] * UM:.1f} against {d[lvl] * UM:.1f} µm at "
        "level): the digits' SDs mirror each other, their systematic errors do not. Depends "
        "on where the closed tips start (see the tip_start sensitivity table)")]
    sd = _total_sd(s)
    near = sd[[max(lvl - 1, 0), min(lvl + 1, len(h) - 1)]] / sd[lvl] - 1
    axes = {a: s[f"finger_sd_{a}_exact"].to_numpy() for a in ("x", "y")}
    lowest = {a: h[int(np.argmin(v))] for a, v in axes.items()}
    out.append(claim(
        "4.2.1.1", "Digit end-point SD is lowest with the via-points level with the targets",
        "lowest at 0 cm (level), per digit and axis as Fig. 4.3(c,d) plots it",
        "lowest x SD at " + cm(lowest["x"]) + ", lowest y SD at " + cm(lowest["y"])
        + f"; total SD lowest at {cm(h[int(np.argmin(sd))])} ({sd[lvl] * UM:.2f} µm level, "
        f"neighbours {100 * near.min():.1f}-{100 * near.max():.1f} % higher)",
        all(level_is_best(h, v) for v in axes.values()), location="Fig. 4.3(c,d); line 790",
        measure="exact finger end-point SD per axis (x, y; the figure's panels) per height; "
        "agree if each axis is lowest at level and monotone on both sides",
        note=f"the total SD is lowest at level, but by less than twice the "
        f"{100 * SD_ERROR_500:.1f} % standard error of an SD from the thesis's 500 repetitions, "
        "so a Monte Carlo figure could not show it; per axis the minimum is off level. "
        "Thumb mirrors the finger."))
    out.append(hand.level_claim(e))
    return out


def _viapoint_time(e: GraspExperiment) -> list[dict]:
    s, c = e.summary, e.curves
    f = s.viapoint_time.to_numpy()
    sd = _total_sd(s)
    i_max = int(np.argmax(sd))
    out = [claim(
        "4.2.1.2", "End-point SD peaks for a via-point late in the movement, falling after",
        "peak at about 87 %",
        f"peak at {pct(f[i_max])} ({sd[i_max] * UM:.1f} µm), {sd[-1] * UM:.1f} µm at "
        f"{pct(f[-1])}", abs(f[i_max] - 0.87) <= 0.05 and sd[-1] < sd[i_max],
        location="Fig. 4.5(c,d); line 818",
        measure="exact total finger end-point SD over via-point times 50-95 % (2.5 % "
        "steps); agree if the peak is within 5 % of the movement of 87 % and the SD falls "
        "after it")]
    t_min, _ = u_minimum(f, sd)
    flat = f[(sd <= sd.min() * (1 + SD_ERROR_500)) & (f <= 0.85)]
    i70 = int(np.argmin(np.abs(f - 0.7)))
    wrist = float(c[c.setting == i70].wrist_sd_exact.iloc[-1])
    below = (f >= 0.5 - 1e-9) & (f < 0.7 - 1e-9)
    rise = sd[below] / sd[i70] - 1
    resolved = 2 * SD_ERROR_500
    agrees = bool(np.all(rise > 0) and rise.max() > resolved)
    out.append(claim(
        "4.2.1.2", "End-point SD is lowest for a via-point near 70 % and rises below it",
        "below approximately 70 %: an increase in SD",
        f"SD at 50-67.5 % is {100 * rise.min():+.1f} to {100 * rise.max():+.1f} % of the SD at "
        f"70 % ({sd[i70] * UM:.2f} µm); lowest at {pct(t_min)}",
        agrees, location="Fig. 4.5(c,d); lines 834, 838",
        measure="exact total finger end-point SD for via-point times 50-67.5 % against 70 %; "
        "an increase counts only beyond 2 standard errors of an SD from the thesis's 500 "
        f"repetitions ({100 * resolved:.1f} %); agree if the SD is higher at every earlier time "
        "and resolvably so somewhere",
        note=f"ours falls below 70 % (flat bottom {pct(flat.min())}-{pct(flat.max())}); "
        f"the wrist, which the via-point does not move, supplies {wrist * UM:.1f} of the "
        f"{sd[i70] * UM:.1f} µm (the hand-frame row removes it). Our former rule (an "
        "interior minimum within 50-80 %) was our own and passed any flat curve."))
    out.append(hand.timing_claim(e))
    d = s.finger_distance_exact.to_numpy()

    def at(x):
        return d[np.argmin(np.abs(f - x))]

    out.append(claim(
        "4.2.1.2", "End-point distance hardly changes below about 80 % and climbs sharply "
        "beyond 85 %", "flat below 80 %, sharp rise beyond 85 %",
        f"{at(0.5) * UM:.0f} µm at 50 %, {at(0.8) * UM:.0f} µm at 80 %, "
        f"{at(0.9) * UM:.0f} µm at 90 %, {at(0.95) * UM:.0f} µm at 95 %",
        at(0.95) - at(0.8) > 5 * (at(0.8) - at(0.5)), location="Fig. 4.5(a,b); line 836",
        measure="exact mean end-point distance; agree if the rise from 80 to 95 % is more "
        "than 5 times the rise from 50 to 80 %"))
    out.append(_curvature_claim(e))
    return out


#: The via-point times whose mean paths Fig. 4.4(a) draws.
FIG44_TIMES = (0.5, 0.6, 0.7, 0.8, 0.9)


def _path_shape(cur: pd.DataFrame) -> tuple[float, float]:
    """A mean finger path's largest distance from its chord (world frame, m) and its peak
    curvature in the hand frame (1/m, where it moves at over 10 % of its top speed)."""
    world = cur[["finger_x", "finger_y"]].to_numpy()
    hand = world - cur[["wrist_x", "wrist_y"]].to_numpy()
    v = np.gradient(hand, axis=0)
    a = np.gradient(v, axis=0)
    speed = np.hypot(*v.T)
    k = np.abs(v[:, 0] * a[:, 1] - v[:, 1] * a[:, 0]) / np.maximum(speed, 1e-12) ** 3
    return (float(np.abs(path_deviation(world, world[0], world[-1])).max()),
            float(k[speed > 0.1 * speed.max()].max()))


def _curvature_claim(e: GraspExperiment) -> dict:
    """Fig. 4.4(a): later via-points, more curved paths; earlier, a more abrupt turn."""
    shape = [_path_shape(e.curves[e.curves.setting == i]) for i in range(len(e.values))]
    drawn = [int(np.argmin(np.abs(e.values - x))) for x in FIG44_TIMES]
    bulge, turn = ([shape[i][j] for i in drawn] for j in (0, 1))
    top = e.values[int(np.argmax([b for b, _ in shape]))]
    times = ", ".join(f"{100 * x:.0f}" for x in FIG44_TIMES)
    return claim(
        "4.2.1.2", "A later via-point gives more curved digit paths; an earlier one a more "
        "abrupt change of direction", "later: more curved; earlier: more abrupt",
        "largest distance from the chord " + ", ".join(f"{b * 100:.2f}" for b in bulge)
        + " cm; peak curvature (hand frame) " + ", ".join(f"{k / 100:.0f}" for k in turn)
        + f" 1/cm at via-point times {times} %",
        _monotonic(bulge, True) and _monotonic(turn, False),
        location="Fig. 4.4(a); line 814",
        measure=f"mean finger paths drawn in Fig. 4.4(a) (via-point at {times} %): their "
        "largest distance from the start-end chord (world frame, as drawn) must grow with "
        "the via-point time, and their peak curvature in the hand frame (the turn onto the "
        "target line) must fall",
        note="" if top >= e.values.max() - 1e-9 else
        f"over the whole sweep the chord distance peaks at {pct(top)} and falls again for "
        "later via-points, beyond the figure's range (a via-point that close to the end "
        "pulls the path out for less time)")


# --- 4.2.2: grasping predictions ------------------------------------------------------
def _viapoint_distance(e: GraspExperiment) -> list[dict]:
    s = e.summary
    o = s.viapoint_offset.to_numpy()
    m, t = s.mga_mean.to_numpy(), s.mga_time_mean.to_numpy()
    lo, hi = e.stats["mga_slope_ci"]
    return [
        claim("4.2.2.1", "A via-point further from the object gives a larger MGA",
              "MGA increases with via-point distance",
              f"MGA {m[0] * 100:.2f} -> {m[-1] * 100:.2f} cm for {cm(o[0])} -> {cm(o[-1])}; "
              f"slope {e.stats['mga_slope']:.2f} (95 % CI {lo:.2f} to {hi:.2f})",
              _monotonic(m, True) and lo > 0, location="Fig. 4.8(a); lines 875, 877",
              measure="mean MGA of 500 repetitions per distance; agree if it rises at every "
              "step and the regression slope's 95 % CI is above 0",
              note="slope about 2: both digits move out by the offset"),
        claim("4.2.2.1", "A via-point further from the object gives an earlier MGA",
              "MGA occurs earlier with via-point distance",
              f"MGA at {pct(t[0])} -> {pct(t[-1])} for {cm(o[0])} -> {cm(o[-1])}",
              bool(np.all(np.diff(t) <= 0) and t[-1] < t[0]),
              location="Fig. 4.8(b); lines 875, 877",
              measure="mean relative time of the MGA (1 % steps); agree if never later and "
              "earlier overall"),
    ]


def _object_size(e: GraspExperiment) -> list[dict]:
    s, st = e.summary, e.stats
    sz = s.object_size.to_numpy()
    t = s.mga_time_exact.to_numpy()
    slope, (lo, hi) = st["mga_slope"], st["mga_slope_ci"]
    ours = f"{slope:.3f} (95 % CI {lo:.3f} to {hi:.3f}; r = {st['mga_r']:.4f})"
    tol = (SLOPE_THESIS - SLOPE_HUMAN) / 2
    inside = bool(np.all((t >= 0.6 - 1e-9) & (t <= 0.8 + 1e-9)))
    edge = " Borderline: the smallest object peaks at exactly 60 %." if abs(
        t.min() - 0.6) < 0.005 else ""
    return [
        claim("4.2.2.2", "MGA grows linearly with object size; regression slope", "0.92",
              ours, abs(slope - SLOPE_THESIS) <= tol,
              location="Fig. 4.10(a); line 903",
              measure=f"slope of MGA on object size, 9 sizes 0-8 cm x 500 repetitions, CI "
              f"from the repetitions; agree within {tol:.2f} of 0.92 (half the gap to the "
              "human 0.8: nearer the thesis's model than to people)"),
        claim("4.2.2.2", "The model's MGA slope is approximately 0.8",
              "0.92 (line 903) and approximately 0.8 (line 971)", ours, False,
              verdict="thesis inconsistent",
              location="line 903 (Fig. 4.10(a)) vs line 971 (summary); humans about 0.8, "
              "lines 696, 742",
              measure="the same regression; compared with both of the thesis's values",
              note=f"the thesis reports 0.92 for its model in 4.2.2.2 and 'approximately 0.8' "
              f"in the summary; ours is {abs(slope - SLOPE_THESIS):.2f} from 0.92 and "
              f"{abs(slope - SLOPE_HUMAN):.2f} from 0.8"),
        claim("4.2.2.2", "MGA occurs at 60-80 % of the movement for every object size",
              "60-80 % for sizes 0-8 cm",
              f"{pct(t.min())}-{pct(t.max())} (" + ", ".join(pct(x) for x in t)
              + " for " + ", ".join(f"{100 * x:g}" for x in sz) + " cm)", inside,
              location="Fig. 4.10(b); line 905 (also 973)",
              measure="time of the exact mean aperture's maximum (1 % steps; the "
              "repetitions' mean times are within 1 %); agree if every size is within "
              "60-80 %", note="depends on where the closed tips start: the smallest "
              "object's MGA comes earlier as the tips start nearer the target line (tip_start "
              "tables)." + edge),
        claim("4.2.2.2", "MGA occurs later for larger objects", "later for larger objects",
              f"{pct(t[0])} at {cm(sz[0])} -> {pct(t[-1])} at {cm(sz[-1])}",
              bool(np.all(np.diff(t) >= 0) and t[-1] > t[0]),
              location="Fig. 4.10(b); line 903",
              measure="time of the exact mean aperture's maximum; agree if never earlier and "
              "later overall"),
    ]


# --- 4.2.3: variability ---------------------------------------------------------------
def _trend(e: GraspExperiment, col: str, scale: float, unit: str, fmt: str = ".1f") -> str:
    y = e.summary[f"{col}_exact"].to_numpy()
    return (f"{y[0] * scale:{fmt}} -> {y[-1] * scale:{fmt}} {unit} "
            f"(change {_ci(e.stats[f'{col}_change_ci'], scale, fmt)} {unit})")


_UNRESOLVED = "{n} repetitions per setting do not resolve the change (its CI includes 0)"
_EFFECT = ("exact peak over the movement per setting; 95 % CI of the change from the first "
           "to the last setting from 400 bootstrap resamples of the 500 repetitions each "
           "(the thesis used one-way ANOVA, which over 500 repetitions flags any nonzero "
           "effect)")


def _movement_time(e: GraspExperiment) -> list[dict]:
    out = []
    for comp, label in (("wrist", "Wrist"), ("aperture", "Grip aperture")):
        col = f"{comp}_sd_peak"
        y = e.summary[f"{col}_exact"].to_numpy()
        resolved = e.stats[f"{col}_change_ci"][1] < 0
        out.append(claim(
            "4.2.3.1", f"{label} peak SD falls as movement time grows (600-1200 ms)",
            "decreases", _trend(e, col, UM, "µm"), _monotonic(y, False) and resolved,
            location=f"Fig. 4.12({'a' if comp == 'wrist' else 'c'}); line 927",
            measure=_EFFECT + "; agree if the exact peaks fall at every step and the CI is "
            "below 0",
            note="" if resolved else _UNRESOLVED.format(n=e.summary.trials.iloc[0])))
    tw = e.summary.wrist_sd_peak_time_exact.to_numpy()
    ta = e.summary.aperture_sd_peak_time_exact.to_numpy()
    out.append(claim(
        "4.2.3.1", "Peak variability occurs earlier in longer movements",
        "generally earlier with longer movement time",
        f"wrist {_trend(e, 'wrist_sd_peak_time', 100, '%', '.0f')}; aperture "
        f"{_trend(e, 'aperture_sd_peak_time', 100, '%', '.0f')}",
        tw[-1] < tw[0] and ta[-1] < ta[0], location="Fig. 4.12(b,d); line 927",
        measure="exact time of the peak SD (fraction of the movement), 600 vs 1200 ms, with "
        "the bootstrap CI of the change; agree if earlier for both"))
    return out


def _slope_change(experiments: list[GraspExperiment], via: float = 0.7, w: float = 0.1):
    """Slope of the exact aperture SD over the 10 % after the via-point minus over the 10 %
    before it, per setting of each experiment (SD per unit of relative time, m)."""
    rows = []
    for e in experiments:
        for i in range(len(e.summary)):
            cur = e.curves[e.curves.setting == i]
            rt, sd = cur.relative_time.to_numpy(), cur.aperture_sd_exact.to_numpy()

            def at(x, rt=rt, sd=sd):
                return sd[int(np.argmin(np.abs(rt - x)))]

            before, after = (at(via) - at(via - w)) / w, (at(via + w) - at(via)) / w
            rows.append((e.name, i, before, after))
    return rows


def _slope_claim(experiments: list[GraspExperiment]) -> dict:
    rows = _slope_change(experiments)
    change = np.array([a - b for *_, b, a in rows])
    falling = int(sum(b < 0 for *_, b, _ in rows))
    return claim(
        "4.2.3.1", "Grip aperture SD changes slope just after the 70 % via-point",
        "change of slope just after the via-point (Figs. 4.11(b), 4.13(b), 4.15(b))",
        f"slope after minus before: {change.min() * UM:.0f} to {change.max() * UM:.0f} µm per "
        f"movement time, positive in {int(np.sum(change > 0))} of {len(change)} settings",
        bool(np.all(change > 0)), location="Fig. 4.11(b); lines 923, 925",
        measure="exact aperture SD: mean slope over 70-80 % minus over 60-70 % of the "
        "movement, every setting of the movement-time, object-size and distance sweeps; "
        "agree if positive in all",
        note=f"the SD falls over the 10 % before the via-point in {falling} of {len(rows)} "
        "settings; after it, with only the target left to reach, the digits speed up and "
        "the SD falls less or rises, as the thesis explains")


def _variability_size(e: GraspExperiment) -> list[dict]:
    st, s = e.stats, e.summary
    sz = s.object_size.to_numpy()
    w = s.wrist_sd_peak_exact.to_numpy()
    a = s.aperture_sd_peak_exact.to_numpy()
    tw = s.wrist_sd_peak_time_exact.to_numpy()
    ta = s.aperture_sd_peak_time_exact.to_numpy()
    r = np.corrcoef(sz, a)[0, 1]
    construction = ("the arm's plan does not depend on the object (the wrist target is 6 cm "
                    "short of its centre whatever its size), so its variability cannot")
    ci_t = st["aperture_sd_peak_time_max_diff_ci"]
    return [
        claim("4.2.3.2", "Wrist peak SD is unaffected by object size", "no significant effect",
              f"{w[1] * UM:.1f} µm at every size (relative range "
              f"{st['wrist_sd_peak_exact_range']:.0e})", False, verdict="by construction",
              location="Figs. 4.13(a), 4.14(a); line 943", measure="exact wrist peak SD",
              note=construction + " change"),
        claim("4.2.3.2", "With no object (size 0) the wrist peak SD is much higher",
              "much higher at 0 cm", f"{w[0] * UM:.1f} µm at 0 cm, {w[1:].mean() * UM:.1f} "
              "µm for 2-8 cm", w[0] > 1.2 * w[1:].mean(), verdict="thesis inconsistent",
              location="Fig. 4.14(a); line 943 vs lines 949, 1205",
              measure="exact wrist peak SD, 0 cm vs 2-8 cm",
              note=construction + " single out size 0 (ours is the same at every size). The "
              "thesis says both: line 943 finds its model's wrist SD much higher at 0 cm, line "
              "1205 that its model shows object size has no effect 'on the wrist movement', as "
              "'the planning of the reaching component takes no account of the object "
              "properties' (and line 949: 'no effect on the wrist movement')"),
        claim("4.2.3.2", "Wrist peak SD occurs slightly later for larger objects",
              "slightly later", f"{pct(tw[0])} at every size", tw[-1] > tw[0],
              verdict="thesis inconsistent", location="Fig. 4.14(b); line 943 vs line 1205",
              measure="exact time of the wrist peak SD",
              note=construction + " move in time either. Line 943 reports a later wrist peak "
              "for larger objects; line 1205 says its model's object size has no effect on "
              "the wrist movement, the reach being planned without the object's properties"),
        claim("4.2.3.2", "Aperture peak SD grows (linearly) with object size",
              "strong linear increase",
              f"{_trend(e, 'aperture_sd_peak', UM, 'µm')}; r = {r:.3f}",
              _monotonic(a, True) and r > 0.95 and _excludes_zero(
                  st["aperture_sd_peak_change_ci"]),
              location="Figs. 4.13(b), 4.14(c); line 945",
              measure=_EFFECT + "; agree if the exact peaks rise at every step, r > 0.95 and "
              "the CI excludes 0",
              note="wider grips need larger digit commands, hence more signal-dependent noise"),
        claim("4.2.3.2", "Timing of the aperture peak SD does not vary significantly with "
              "object size", "no significant change",
              f"{pct(ta.min())}-{pct(ta.max())}; largest difference "
              f"{st['aperture_sd_peak_time_max_diff'] * 100:+.0f} % ({_ci(ci_t, 100, '+.0f')} %)",
              not _excludes_zero(ci_t), location="Fig. 4.14(d); line 947",
              measure="exact time of the aperture peak SD; 95 % bootstrap CI of the largest "
              "difference between sizes; agree if the CI includes 0 (500 repetitions cannot "
              "resolve it)",
              note="" if not _excludes_zero(ci_t) else
              f"the repetitions resolve a shift of the aperture SD's peak between sizes "
              f"(the exact shift is {st['aperture_sd_peak_time_max_diff'] * 100:+.0f} %)"),
    ]


def _variability_distance(e: GraspExperiment) -> list[dict]:
    st, s = e.stats, e.summary
    travel = s.transport_distance.to_numpy()
    w = s.wrist_sd_peak_exact.to_numpy()
    rising = _monotonic(w, True) and st["wrist_sd_peak_change_ci"][0] > 0
    tw = s.wrist_sd_peak_time_exact.to_numpy()
    return [
        claim("4.2.3.3", "Grip aperture SD is unaffected by transport distance",
              "no effect", f"exact peak {s.aperture_sd_peak_exact.iloc[0] * UM:.1f} µm at "
              f"every distance (relative range {st['aperture_sd_peak_exact_range']:.0e})",
              False, verdict="by construction",
              location="Figs. 4.15(b), 4.16(c); lines 963, 1209",
              measure="exact aperture peak SD per transport distance",
              note="the grip is planned from the wrist target and the aperture does not "
              "depend on the wrist, so distance cannot act on it. Kudoh et al. found an "
              "effect in people, which the thesis also does not reproduce (line 965)"),
        claim("4.2.3.3", "Wrist SD changes with transport distance",
              "decreases (line 963); increases (lines 1207, 1209)",
              f"{_trend(e, 'wrist_sd_peak', UM, 'µm')} for wrist travel {cm(travel[0])} -> "
              f"{cm(travel[-1])}", False, verdict="thesis inconsistent",
              location="Figs. 4.15(a), 4.16(a); line 963 vs lines 1207-1209 (965 cites "
              "Kudoh et al.'s significant effect)",
              measure=_EFFECT + "; distance = how far the wrist moves (line 953)",
              note=("ours increases, as lines 1207-1209 say (a longer transport in the same "
                    "time needs larger commands, so more signal-dependent noise) and against "
                    "line 963" if rising else "ours does not rise monotonically")),
        claim("4.2.3.3", "Time of the wrist peak SD against transport distance",
              "not stated: Fig. 4.16(b) is not discussed; by the speed argument of lines "
              "929, 1209 a faster movement peaks later (Fig. 4.12(b))",
              f"{_trend(e, 'wrist_sd_peak_time', 100, '%', '.0f')}",
              tw[-1] > tw[0], location="Fig. 4.16(b); lines 929, 961-965",
              measure="exact time of the wrist peak SD, 8 vs 24 cm, with the bootstrap CI of "
              "the change; agree if later for the longer (faster) transport",
              note="a longer transport in the same time is a faster one; the thesis found "
              "faster (shorter) movements peak later"),
        claim("4.2.3.3", "Time of the aperture peak SD against transport distance",
              "not stated (Fig. 4.16(d))",
              f"{pct(s.aperture_sd_peak_time_exact.iloc[0])} at every distance", False,
              verdict="by construction", location="Fig. 4.16(d); lines 961-965",
              measure="exact time of the aperture peak SD",
              note="the grip's plan does not depend on distance"),
    ]


_CLAIMS = {
    "viapoint-height": _viapoint_height,
    "viapoint-time": _viapoint_time,
    "viapoint-distance": _viapoint_distance,
    "object-size": _object_size,
    "movement-time": _movement_time,
    "variability-size": _variability_size,
    "variability-distance": _variability_distance,
}


def _claims(base: GraspTask, trials: int, seed: int, out: Path | None):
    """Every experiment's claims on ``base`` (figures and tables into ``out`` unless None)."""
    children = np.random.SeedSequence(seed).spawn(len(EXPERIMENTS) + 1)
    claims: list[dict] = []
    done = {}
    for (name, run), child in zip(EXPERIMENTS.items(), children):
        t0 = time.perf_counter()
        done[name] = exp = run(trials=trials, seed=child, base=base)
        if out is not None:
            write_experiment(exp, out)
        claims += _CLAIMS[name](exp)
        log.info("%s: %.1f s", name, time.perf_counter() - t0)
    for c in claims:  # a verdict that fails its rule says so, even where no cause is known
        if c["verdict"] == "differs" and not c["why"]:
            c["why"] = (f"the numbers fail the rule in the measure column ({trials} "
                        "repetitions per setting)")
    at = next(i for i, c in enumerate(claims) if c["section"] == "4.2.3.2")
    claims.insert(at, _slope_claim([done[k] for k in ("movement-time", "variability-size",
                                                      "variability-distance")]))
    return claims, done, children


def _inconsistencies() -> list[dict]:
    """Places where the thesis says two different things (no model enters)."""
    return [
        claim("4.1.2", "Object size and the transport component: Kudoh et al. as the thesis "
              "reports them", "object size 'had a significant impact on the variability of "
              "both the transport and the grasp components' (line 751) vs 'no effect on the "
              "wrist movement' (line 949)", "— (a reading of the thesis)", False,
              verdict="thesis inconsistent", location="line 751 vs line 949",
              line=751, quote="object size had a significant impact on the variability of "
              "both the transport and the grasp components",
              measure="the two sentences compared", at_thesis="thesis inconsistent: no model",
              note="line 949 says Kudoh et al. showed 'no effect on the wrist movement'; the "
              "same study cannot show both"),
        claim("4.2.2.1", "The via-point distances of Figs. 4.7-4.8", "0.0-2.0 cm in 0.5 cm "
              "steps (line 854) vs 0.0-1.0 cm in 0.25 cm steps (line 858, Fig. 4.7's caption)",
              "we sweep 0-2.25 cm in 0.25 cm steps, which holds both", False,
              verdict="thesis inconsistent", location="line 854 vs line 858", line=854,
              quote="Via-point distances from the object were set at 0.0cm, 0.5cm, 1.0cm, "
              "1.5cm and 2.0cm", measure="the text against the caption",
              at_thesis="thesis inconsistent: no model",
              note="Fig. 4.7's caption (line 858) gives 0.0, 0.25, 0.5, 0.75 and 1.0 cm"),
    ]


#: Claims whose verdict depends on tip_start, and the tip_start table column that judges them.
TIP_DEPENDENT = {"Digit end-point distance from the target": 1,
                 "End-point SD is lowest for a via-point near 70 %": 2,
                 "MGA occurs at 60-80 %": 3}

_BY_CONSTRUCTION_MGA = {"verdict": "by construction", "why": "+By construction: the digit "
                        "via-points sit the offset outside the object on each side, so the MGA "
                        "is about object size + 2 x offset; its rise follows from where we "
                        "put them."}
#: Claim prefix -> (thesis line, the thesis's words on it[, changes]); line None: our own.
CITES = {
    "Digit end-point distance from the target": (788, "decreases as the via-point position "
                                                 "comes level with the target positions"),
    "Hand frame: digit end-point SD is lowest": (
        790, "the lowest end-point standard deviation for each digit is found when the "
        "via-points are located at the same level"),
    "Hand frame: end-point SD is lowest for a via-point near 70 %": (
        834, "below approximately 70% of the movement time show an increase in standard "
        "deviation"),
    "Digit end-point SD is lowest": (790, "the lowest end-point standard deviation for each "
                                     "digit is found when the via-points are located at the "
                                     "same level"),
    "End-point SD peaks for a via-point late": (818, "a peak in the end-point standard "
                                                "deviation at approximately 87%"),
    "End-point SD is lowest for a via-point near 70 %": (
        834, "below approximately 70% of the movement time show an increase in standard "
        "deviation"),
    "End-point distance hardly changes": (836, "This climbs sharply beyond 85%"),
    "A later via-point gives more curved": (814, "Trajectories with a via-point later in the "
                                            "movement are more curved"),
    "A via-point further from the object gives a larger MGA": (
        875, "the grip size *increases* and occurs *earlier*", _BY_CONSTRUCTION_MGA),
    "A via-point further from the object gives an earlier MGA": (
        877, "grip size increases and occurs *earlier*"),
    "MGA grows linearly with object size": (903, "This line has a slope of 0.92",
                                            _BY_CONSTRUCTION_MGA),
    "The model's MGA slope is approximately 0.8": (971, "with a slope of approximately 0.8"),
    "MGA occurs at 60-80 %": (905, "values between 60-80% of the movement time"),
    "MGA occurs later for larger objects": (903, "occurs *later* for increasing object sizes"),
    "Wrist peak SD falls": (927, "peak standard deviation decreases as movement time "
                            "increases"),
    "Grip aperture peak SD falls": (927, "peak standard deviation decreases as movement time "
                                    "increases"),
    "Peak variability occurs earlier": (927, "the peak variability occurring earlier in the "
                                        "movement"),
    "Grip aperture SD changes slope": (923, "a change in the slope of the variability just "
                                       "after the via-point"),
    "Wrist peak SD is unaffected by object size": (943, "object size has no significant effect "
                                                   "on the peak standard deviation"),
    "With no object (size 0)": (943, "the peak standard deviation was much higher"),
    "Wrist peak SD occurs slightly later": (943, "occurs slightly later in the movement for "
                                            "larger object sizes"),
    "Aperture peak SD grows": (945, "a strong linear correlation between peak standard "
                               "deviation and grip aperture"),
    "Timing of the aperture peak SD": (947, "does not vary significantly with object size"),
    "Grip aperture SD is unaffected by transport": (963, "has no effect on the standard "
                                                    "deviation of the grip aperture"),
    "Wrist SD changes with transport distance": (963, "increasing the movement distance "
                                                 "decreases the overall standard deviation of "
                                                 "the wrist"),
    "Time of the wrist peak SD against transport": (None, ""),
    "Time of the aperture peak SD against transport": (None, ""),
}


def reproduce(out: Path, *, trials: int = 500, seed: int = 0) -> list[dict]:
    """Run every chapter-4 experiment, save figures and tables, return the claims.

    Every claim is also computed at the thesis's cost weights
    (:data:`reproduce_common.THESIS_SETTINGS`; its ``at_thesis``), and those
    that depend on ``tip_start`` say over which of its values they hold.

    Parameters
    ----------
    out : pathlib.Path
        Folder for the PNG figures (``fig4_*.png``) and CSV tables (created).
    trials : int
        Repetitions per setting (thesis: 500).
    seed : int
        Root seed; each experiment uses its own child.

    Returns
    -------
    list of dict
        One claim per quantitative statement (:func:`reproduce_common.claim`),
        then the sensitivity tables (:func:`reproduce_common.sensitivity`).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    base = GraspTask()
    plan = plan_grasp(base)
    save_figure(out / "fig4_1_setup.png", setup_figure(plan=plan))
    claims, done, children = _claims(base, trials, seed, out)
    typical = simulate_grasp(base, trials, seed=children[-1], plan=plan)
    save_figure(out / "fig4_6_typical_grasp.png", grasp_figure(typical))
    theirs, done_t, _ = _claims(replace(base, **THESIS_SETTINGS), trials, seed, None)
    cite(theirs, CITES)  # a by-construction row is one in both columns
    at_settings(claims, theirs, "r = 0.002, w_v = 0.1: ")
    t0 = time.perf_counter()
    tip, used = tip_start_table(base, done)
    tip_t, _ = tip_start_table(replace(base, **THESIS_SETTINGS), done_t,
                               " at the thesis's settings (its model and weights)")
    tables = [tip, tip_t, travel_table(base, used)]
    log.info("sensitivity: %.1f s", time.perf_counter() - t0)
    mark_conditional(claims, TIP_DEPENDENT, tip, tip_t)
    cite(claims, CITES)
    return claims + _inconsistencies() + tables


def markdown(records: list[dict]) -> str:
    """The claims as a markdown table (sensitivity tables are left out).

    Parameters
    ----------
    records : list of dict
        From :func:`reproduce`.
    """
    keys = ("location", "claim", "measure", "thesis", "ours", "verdict", "why")
    rows = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for c in records:
        if c.get("kind") != "sensitivity":
            rows.append("| " + " | ".join(str(c[k]).replace("|", "/") for k in keys) + " |")
    return "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command line: ``reproduce_ch4.py -o DIR [--trials N] [--seed N]``.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default: ``sys.argv[1:]``).
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "out" / "thesis" / "ch4")
    parser.add_argument("--trials", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    t0 = time.perf_counter()
    records = reproduce(args.output, trials=args.trials, seed=args.seed)
    claims = [c for c in records if c.get("kind") != "sensitivity"]
    write_csv(args.output / "claims.csv", pd.DataFrame(claims))
    print(markdown(records))
    agree = sum(c["verdict"] == "agree" for c in claims)
    print(f"{agree} of {len(claims)} claims agree; {time.perf_counter() - t0:.0f} s; "
          f"figures and tables in {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

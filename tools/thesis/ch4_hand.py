"""Chapter 4's digit end-point claims in the hand frame, beside the world-frame rows.

Line 790 speaks of "the lowest end-point standard deviation for each digit" with
the via-points level with the targets "in the wrist target frame of reference".
A digit's world-frame end-point SD is mostly the wrist's (the arm and the digits
are planned and executed as independent chains, so the world covariance of a
tip is the wrist's plus the tip's own about the wrist); the hand frame removes
the wrist and leaves what the digit's via-point acts on. These rows give the
same claims (lines 790 and 834) measured there, from the exact moments of the
experiments :mod:`tools.thesis.ch4` runs.
"""

from __future__ import annotations

import numpy as np

from minvar.grasp_experiments import GraspExperiment
from tools.thesis.ch4_rules import SD_ERROR_500, UM, cm, level_is_best, pct
from tools.thesis.claims import Measured

DIGITS = ("finger", "thumb")


def hand_cov(moments, digit: str) -> np.ndarray:
    """(2, 2) covariance of a digit's final position about the wrist (hand frame), m^2."""
    return getattr(moments, f"{digit}_cov")[-1] - moments.wrist_cov[-1]


def _sds(e: GraspExperiment, digit: str) -> dict[str, np.ndarray]:
    cov = np.array([hand_cov(m, digit) for m in e.moments])
    x, y = np.sqrt(cov[:, 0, 0]), np.sqrt(cov[:, 1, 1])
    return {"x": x, "y": y, "total": np.hypot(x, y)}


def level(e: GraspExperiment) -> tuple[str, Measured]:
    """Line 790 in the hand frame: each digit's SD lowest with the via-points level."""
    h = e.values
    lvl = int(np.argmin(np.abs(h)))
    sds = {d: _sds(e, d) for d in DIGITS}
    lowest = {(d, a): h[int(np.argmin(v))] for d, s in sds.items() for a, v in s.items()}
    per_axis = all(level_is_best(h, s[a]) for s in sds.values() for a in ("x", "y"))
    total = sds["finger"]["total"]
    near = total[[max(lvl - 1, 0), min(lvl + 1, len(h) - 1)]] / total[lvl] - 1
    shape = "monotone" if level_is_best(h, total) else "not monotone"
    return "hand-sd-level", Measured(
        "; ".join(f"{d}: lowest x SD at {cm(lowest[(d, 'x')])}, y at {cm(lowest[(d, 'y')])}, "
                  f"total at {cm(lowest[(d, 'total')])}" for d in DIGITS)
        + f"; finger total {total[lvl] * UM:.2f} µm at level, neighbours "
        f"{100 * near[0]:+.1f} % and {100 * near[1]:+.1f} %",
        {"each_axis_level_is_best": per_axis},
        note=f"the total hand-frame SD is lowest at level ({shape} on both sides), its "
        f"nearer neighbour {100 * near.min():.1f} % higher against "
        f"{200 * SD_ERROR_500:.1f} %, two standard errors of an SD from 500 repetitions; per "
        "axis the minima lie off level, in this frame as in the world's. The thumb mirrors "
        "the finger in the hand frame, so its SDs are the finger's.")


def timing(e: GraspExperiment) -> tuple[str, Measured]:
    """Line 834 in the hand frame: SD lowest near 70 %, higher for earlier via-points."""
    f = e.values
    sd = _sds(e, "finger")["total"]
    i70 = int(np.argmin(np.abs(f - 0.7)))
    below = (f >= 0.5 - 1e-9) & (f < 0.7 - 1e-9)
    rise = sd[below] / sd[i70] - 1
    upto = f <= 0.85 + 1e-9
    t_min = f[int(np.argmin(np.where(upto, sd, np.inf)))]
    return "hand-sd-70", Measured(
        f"SD about the wrist at 50-67.5 % is {100 * rise.min():+.1f} to {100 * rise.max():+.1f} "
        f"% of the SD at 70 % ({sd[i70] * UM:.2f} µm); lowest at {pct(t_min)}",
        {"smallest_rise": rise.min(), "largest_rise": rise.max()},
        note="without the wrist's share the fall below 70 % is larger, not smaller: the "
        "digits' own scatter is lowest for a via-point near 60 %")

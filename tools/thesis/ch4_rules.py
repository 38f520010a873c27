"""Chapter 4's verdict rules and units, shared by its claims and its sensitivity tables."""

from __future__ import annotations

import numpy as np
import pandas as pd

UM = 1e6
#: Sampling error of an SD from the thesis's 500 repetitions, 1/sqrt(2 (n - 1)): a rise
#: in the SD counts beyond twice this (the rule of chapter 4's line-834 row).
SD_ERROR_500 = 1 / np.sqrt(2 * 499)


def pct(x: float) -> str:
    """A fraction as a whole percentage, ``"70 %"``."""
    return f"{100 * x:.0f} %"


def cm(x: float) -> str:
    """Metres as centimetres, ``"2 cm"``."""
    return f"{100 * x:g} cm"


def level_is_best(heights, values) -> bool:
    """Lowest at the level setting, falling toward it from below and rising above."""
    h, v = np.asarray(heights), np.asarray(values)
    i = int(np.argmin(v))
    return bool(abs(h[i]) < 1e-9 and np.all(np.diff(v[: i + 1]) < 0)
                and np.all(np.diff(v[i:]) > 0))


def u_minimum(times, sd, upto: float = 0.85) -> tuple[float, bool]:
    """Where the SD is lowest among via-point times <= ``upto``, and whether that is
    an interior minimum (the SD rises on both sides). Where, only: an interior minimum
    is not the thesis's claim (line 834 asks for a rise below 70 %), so no verdict
    rests on it."""
    t, y = np.asarray(times), np.asarray(sd)
    keep = t <= upto + 1e-9
    i = int(np.argmin(np.where(keep, y, np.inf)))
    return float(t[i]), bool(0 < i < int(keep.sum()) - 1)


#: A rise in the SD counts beyond this share (two standard errors of an SD from the
#: thesis's 500 repetitions).
RESOLVED = 2 * SD_ERROR_500
#: The thesis's MGA slope (line 903) and the human one (lines 696, 742).
SLOPE_THESIS, SLOPE_HUMAN = 0.92, 0.8


def ci_words(pair, scale: float, fmt: str = ".1f") -> str:
    """``"95 % CI lo to hi"``, scaled."""
    lo, hi = pair
    return f"95 % CI {lo * scale:{fmt}} to {hi * scale:{fmt}}"


def monotonic(y, increasing: bool) -> bool:
    """Whether ``y`` rises (or falls) at every step."""
    d = np.diff(np.asarray(y, dtype=float))
    return bool(np.all(d > 0) if increasing else np.all(d < 0))


def excludes_zero(pair) -> bool:
    """Whether an interval lies wholly above or below 0."""
    return pair[0] > 0 or pair[1] < 0


def total_sd(s: pd.DataFrame, digit: str = "finger") -> np.ndarray:
    """A digit's total exact end-point SD per setting of a sweep's summary, m."""
    return np.hypot(s[f"{digit}_sd_x_exact"], s[f"{digit}_sd_y_exact"]).to_numpy()

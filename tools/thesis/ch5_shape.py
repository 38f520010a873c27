"""Chapter 5's claims on the confidence profiles' shape (Fig. 5.8(a-c)), measured on one
batch scored under one reading: the open-close-open fall and recovery, normal's peak,
and where the profiles vary between clips."""

from __future__ import annotations

import numpy as np

from tools.thesis.ch5_batch import Batch, series
from tools.thesis.ch5_fixed import ABNORMAL
from tools.thesis.ch5_readings import oco_landmarks
from tools.thesis.claims import Measured


def _closing(s: dict) -> tuple[int, int] | None:
    """Indices of the first aperture peak and the unexpected closing's deepest point: the
    clip's own landmarks (:func:`reproduce_ch5_readings.oco_landmarks`)."""
    found = oco_landmarks(s["phase"], s["g"])
    if found is None:
        return None
    return tuple(int(np.searchsorted(s["phase"], p)) for p in found[:2])


def _fall(c: np.ndarray, phase: np.ndarray, low: int) -> tuple[float, bool]:
    """Fall of ``c`` from its peak before index ``low`` to its lowest until a quarter of the
    movement after it, as a fraction of the peak; and whether it rises again by the end."""
    top = int(np.argmax(c[: low + 1]))
    window = (phase >= phase[top]) & (phase <= phase[low] + 0.25)
    bottom = float(c[window].min())
    return (float((c[top] - bottom) / c[top]) if c[top] > 0 else 0.0), bool(c[-1] > bottom)


def oco(b: Batch) -> list[tuple[str, Measured]]:
    """The open-close-open profile falls after the unexpected closing, then recovers.

    The thesis gives no size for "a notable descending trend", so a fall counts
    where it exceeds what normal clips show over the same window (their mean
    profile's fall; for single clips, the largest single normal clip's): the
    threshold is the data's noise, not a number of ours.
    """
    grid = np.linspace(0, 1, 101)
    falls, recovered, curves, lows = [], [], [], []
    for d in b.by_condition("open-close-open"):
        s = series(d, b.reference)
        found = _closing(s)
        if found is None:
            continue
        fall, up = _fall(s["C"], s["phase"], found[1])
        falls.append(fall)
        recovered.append(up)
        curves.append(np.interp(grid, s["phase"], s["C"]))
        lows.append(s["phase"][found[1]])
    falls, curves = np.array(falls), np.array(curves)
    low = int(round(100 * np.median(lows)))
    normal = np.array([np.interp(grid, series(d, b.reference)["phase"],
                                 series(d, b.reference)["C"]) for d in b.by_condition("normal")])
    floor_mean = _fall(normal.mean(axis=0), grid, low)[0]
    floor = max(_fall(c, grid, low)[0] for c in normal)
    mean_fall, mean_up = _fall(curves.mean(axis=0), grid, low)
    rng = np.random.default_rng(0)
    boot = [_fall(curves[rng.integers(len(curves), size=len(curves))].mean(axis=0), grid, low)[0]
            for _ in range(1000)]
    lo, hi = np.percentile(boot, [2.5, 97.5])
    share = float(np.mean(falls > floor)) if len(falls) else float("nan")
    upto = float(np.percentile(falls, 5)) if len(falls) else float("nan")
    how = ("fall: from the confidence's peak before each clip's own closing (the aperture's "
           "deepest unexpected minimum) to its lowest until a quarter of the movement after "
           f"it, as a share of the peak; the closings' median is at {low} % of the movement. "
           "The thesis gives no size for 'notable': the threshold is the fall normal clips "
           "show over the same window (noise), not a number of ours.")
    return [
        ("oco-mean", Measured(
            f"falls {100 * mean_fall:.1f} % (bootstrap 95 % CI over clips {100 * lo:.1f}-"
              f"{100 * hi:.1f} %; normal's mean profile {100 * floor_mean:.1f} %); recovers: "
              f"{'yes' if mean_up else 'no'}",
        {"ci_low": lo, "normal_fall": floor_mean, "recovers": mean_up},
        note=how + " Agreement: the fall's confidence interval lies above normal's.")),
        ("oco-each", Measured(
            f"falls beyond {100 * floor:.1f} % (the largest normal clip's fall) in "
              f"{100 * share:.0f} % of {len(falls)} clips (median {100 * np.median(falls):.1f} "
              f"%, range {100 * falls.min():.1f}-{100 * falls.max():.1f} %; 95 % of clips "
              f"fall by more than {100 * upto:.1f} %); recovers in "
              f"{100 * np.mean(recovered):.0f} %",
        {"share_beyond": share, "share_recovered": np.mean(recovered)},
        note=how + " Agreement: >= 95 % of clips. A clip whose closing coincides with the "
              "reference model's own closing (a slow demonstration read on a faster model) "
              "earns confidence for it instead: the model predicts that closing too.")),
    ]


def _peak_and_fall(c: np.ndarray, phase: np.ndarray) -> tuple[float, float]:
    top = int(np.argmax(c))
    return float(phase[top]), float((c[top] - c[top:].min()) / c[top]) if c[top] > 0 else 0.0


def normal_peak(b: Batch) -> tuple[str, Measured]:
    """Normal: maximum at maximum aperture, a slight fall after it."""
    ours, mga = [], []
    for d in b.by_condition("normal"):
        s = series(d, b.reference)
        ours.append(_peak_and_fall(s["C"], s["phase"]))
        mga.append(float(s["phase"][np.nanargmax(s["g"])]))
    ours = np.array(ours)
    return ("peak", Measured(
        f"peak at {100 * np.median(ours[:, 0]):.0f} % of the movement (maximum "
        f"aperture at {100 * np.median(mga):.0f} %), fall after it "
        f"{100 * np.median(ours[:, 1]):.1f} %",
        {"peak_from_mga": abs(np.median(ours[:, 0]) - np.median(mga)),
         "fall": np.median(ours[:, 1])},
        note="agreement: the median peak within 15 % of the movement of the maximum aperture, "
        "and a fall after it of at least 1 % of the peak. With the magnitude of the "
        "predicted change (the text) an agreeing closing raises confidence, so the "
        "confidence rises to the end; the printed sign makes every observed closing lower "
        "it, agreeing or not."))


def _rise_sd(b: Batch, cond: str, window) -> float:
    """SD across clips of C's rise over ``window(series) -> (lo, hi)`` phases (None: skip)."""
    rises = []
    for d in b.by_condition(cond):
        s = series(d, b.reference)
        span = window(s)
        if span is not None:
            rises.append(np.interp(span[1], s["phase"], s["C"])
                         - np.interp(span[0], s["phase"], s["C"]))
    return float(np.std(rises, ddof=1)) if len(rises) > 1 else float("nan")


def _oco_window(first: int, last: int):
    """The window between two of a clip's own open-close-open landmarks (0: the start,
    1: the first peak, 2: the closing's deepest point, 3: the end)."""
    def window(s):
        found = oco_landmarks(s["phase"], s["g"])
        return None if found is None else ((0.0, *found[:2], 1.0)[first],
                                           (0.0, *found[:2], 1.0)[last])
    return window


def spread(b: Batch) -> tuple[str, Measured]:
    """Fig. 5.8(c)'s SD pattern: small for normal; where each stimulus varies most."""
    windows = {"first half": lambda s: (0.0, 0.5), "second half": lambda s: (0.5, 1.0),
               "before the closing": _oco_window(0, 1), "closing": _oco_window(1, 2),
               "after it": _oco_window(2, 3)}
    sd = {c: {w: _rise_sd(b, c, f) for w, f in windows.items()} for c in ("normal", *ABNORMAL)}
    halves, oco = ("first half", "second half"), ("before the closing", "closing", "after it")
    normal_least = all(sd["normal"][w] <= min(sd[c][w] for c in ABNORMAL) for w in halves)
    delayed_first = sd["delayed"]["first half"] > sd["delayed"]["second half"]
    oco_closing = max(oco, key=lambda w: sd["open-close-open"][w]) == "closing"

    def cm(c, ws):
        return ", ".join(f"{w} {100 * sd[c][w]:.2f}" for w in ws)

    return ("sd", Measured(f"SD (cm) of the rise within each window: normal {cm('normal', halves)}"
        f"; delayed {cm('delayed', halves)}; open-close-open {cm('open-close-open', oco)}",
        {"normal_least": normal_least, "delayed_most_in_first_half": delayed_first,
         "oco_most_at_closing": oco_closing},
        note="SD across clips of how much the reference model's confidence rises within each "
        "window of normalised movement time; an open-close-open clip's windows come from its "
        "own aperture (before the closing: to its first peak; closing: from there to the "
        "closing's deepest point; after it: to the end). Agreement: normal's least in "
        "both halves, delayed's larger in the first half, open-close-open's largest at the "
        "closing."))




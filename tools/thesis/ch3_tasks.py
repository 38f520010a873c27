"""Chapter 3's movements: the reaches, the 's' and the letter 'a' the figures draw."""

from __future__ import annotations

import numpy as np

from minvar.baselines import peak_to_mean_ratio
from minvar.task import ReachTask, ViaPoint
from minvar.viapoints import expected_path

#: Fig. 3.4 (thesis coordinates, shoulder at the origin).
REACH = ReachTask((0.2, 0.2), (0.4, 0.5), 0.5)
#: Fig. 3.6, the 's'.
S_TASK = ReachTask(
    (-0.2, 0.5), (-0.4, 0.2), 1.0,
    (ViaPoint((-0.4, 0.4), fraction=0.25), ViaPoint((-0.2, 0.3), fraction=0.75)),
)
#: Fig. 3.2: a 30 cm reach bowed through one via-point (the thesis gives no coordinates).
BOW_START, BOW_GOAL, BOW_VIA = (-0.15, 0.30), (0.15, 0.30), (0.0, 0.40)
#: Fig. 3.3: A -> B and B -> C, 0.5 s each, merged into A -> C through B in 1 s.
A, B, C = (-0.15, 0.30), (0.0, 0.45), (0.15, 0.30)
#: Peak/mean speed ratios nearer the human 1.875 than minimum acceleration's (n = 2)
#: or minimum snap's (n = 4): midway to each (Fig. 2.6(c)).
HUMAN_LIKE = tuple((peak_to_mean_ratio(3) + peak_to_mean_ratio(n)) / 2 for n in (2, 4))
#: Fig. 3.9: movement times of the letter 'a', s.
LETTER_DURATIONS = (1.0, 1.5, 2.0)


def _bow(fraction: float | None, w: dict) -> ReachTask:
    vias = () if fraction is None else (ViaPoint(BOW_VIA, fraction=fraction),)
    return ReachTask(BOW_START, BOW_GOAL, 1.0, vias, **w)


def _reversal(time: np.ndarray, speed: np.ndarray, duration: float) -> tuple[float, float]:
    """Time (fraction) and speed of the slowest moment between 55 and 85 % of a movement."""
    window = np.flatnonzero((time > 0.55 * duration) & (time < 0.85 * duration))
    i = window[np.argmin(speed[window])]
    return time[i] / duration, speed[i]


def _stops(task: ReachTask) -> bool:
    """Whether the expected path slows below 10 % of its peak speed at the 'a''s reversal."""
    t, p = expected_path(task)
    speed = np.linalg.norm(np.gradient(p, t, axis=0), axis=1)
    return _reversal(t, speed, task.duration)[1] < 0.1 * speed.max()


#: Movement times of the 'a' swept, s: to where its shape parts from the slowest's.
LETTER_SWEEP = (0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.5, 1.75, 2.0)


def _ms(durations) -> str:
    return f"{min(durations) * 1000:.0f}-{max(durations) * 1000:.0f}"


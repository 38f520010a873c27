"""How far the transport slowed, resumed row after row (issue 45, item 6): after every
row of a stream it is :func:`perception.recognition.rules.slowed` of the rows so far,
bit for bit, whatever was measured before."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from perception.recognition import evidence
from perception.recognition.rules import slowed


def _obs(time, wrist, onset, end):
    """An observation's fields that the arrival reads: the scored rows ``onset:end``."""
    return SimpleNamespace(clip_time=time, clip_wrist=wrist, time=time[onset:end],
                           wrist=wrist[onset:end])


def test_the_arrival_of_every_prefix_is_slowed_of_its_rows():
    rng = np.random.default_rng(2)
    n, fps = 240, 30.0
    t = np.arange(n) / fps
    s = np.clip((t - 0.5) / 1.5, 0, 1)
    x = 0.3 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    wrist = np.c_[x, 0.1 * x] + rng.normal(0, 2e-4, (n, 2))
    wrist[[70, 71, 150, 200]] = np.nan
    onset = 14
    evidence._ARRIVAL.local.__dict__.clear()
    resumed = 0
    for m in range(onset + 3, n + 1):
        end = min(m, 80)  # the movement grows, then stays while the hand rests
        obs = _obs(t[:m], wrist[:m], onset, end)
        kept = evidence._ARRIVAL.longest(end - onset, (t[onset:m], wrist[onset:m]))
        resumed += kept is not None
        want = slowed(t[onset:m], wrist[onset:m], movement=end - onset)
        got = evidence._arrival(obs)
        assert np.float64(got).tobytes() == np.float64(want).tobytes(), m
    assert resumed >= n - 80 - 1  # every row at rest resumed the one before


def test_rows_that_differ_are_measured_again():
    t = np.arange(100) / 30.0
    wrist = np.c_[np.linspace(0, 0.3, 100) ** 2, np.zeros(100)]
    evidence._ARRIVAL.local.__dict__.clear()
    first = evidence._arrival(_obs(t[:90], wrist[:90], 0, 50))
    moved = wrist.copy()
    moved[60:] = moved[59]  # the hand stopped earlier: slower after the peak
    second = evidence._arrival(_obs(t, moved, 0, 50))
    assert second == slowed(t, moved, movement=50) != first

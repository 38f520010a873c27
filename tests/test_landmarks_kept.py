"""Counts of aperture peaks kept for a stream at rest are the counts made afresh.

:func:`perception.landmarks.count_peaks` keeps its last counts: the same
sequence (bytes) and prominence again returns the kept count, anything else
(a sequence changed in place, of another length, another prominence) is
counted again.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import find_peaks

from perception.landmarks import count_peaks


def _fresh(x, prominence):
    low = x.min()
    return len(find_peaks(np.r_[low, x, low], prominence=prominence)[0])


def test_kept_counts_are_the_fresh_ones():
    s = np.linspace(0, 1, 40)
    one = np.sin(np.pi * s)
    two = np.sin(2 * np.pi * s) ** 2
    for x, p in ((one, 0.1), (two, 0.1), (one, 0.1), (two, 2.0), (two, 0.1), (one[:-1], 0.1)):
        assert count_peaks(x, p) == _fresh(x, p)
    assert (count_peaks(one, 0.1), count_peaks(two, 0.1)) == (1, 2)


def test_a_sequence_changed_in_place_is_counted_again():
    s = np.linspace(0, 1, 40)
    x = np.sin(np.pi * s)
    assert count_peaks(x, 0.1) == 1
    x[:] = np.sin(2 * np.pi * s) ** 2  # the same array, another movement
    assert count_peaks(x, 0.1) == 2
    rng = np.random.default_rng(5)
    for _ in range(200):
        y = rng.normal(size=int(rng.integers(1, 30)))
        p = float(rng.choice([0.0, 0.5, 1.0]))
        assert count_peaks(y, p) == _fresh(y, p) == count_peaks(y.copy(), p)


def _old_progress_time(time, w, fraction):
    """The movement time's crossing as it was written before its progress was shared."""
    ok = np.isfinite(w).all(axis=1)
    if ok.sum() < 3:
        return float("nan")
    start, end = w[ok][0], w[ok][-1]
    total = float(np.linalg.norm(end - start))
    if total <= 0:
        return float("nan")
    progress = np.linalg.norm(w[ok] - start, axis=1) / total
    t = time[ok]
    i = int(np.argmax(progress >= fraction))
    if i == 0:
        return float(t[0])
    p0, p1 = progress[i - 1], progress[i]
    return float(t[i - 1] + (t[i] - t[i - 1]) * (fraction - p0) / max(p1 - p0, 1e-12))


def test_the_movement_time_reads_the_wrists_progress_once_bit_for_bit():
    from perception.landmarks import wrist_movement_time

    rng = np.random.default_rng(9)
    for n in (2, 3, 5, 40, 300):
        t = np.cumsum(rng.random(n) + 0.01)
        w = np.cumsum(rng.normal(size=(n, 2)), axis=0)
        w[rng.random((n, 2)) < 0.1] = np.nan
        for path in (w, np.zeros((n, 2))):
            want = (_old_progress_time(t, path, 0.9) - _old_progress_time(t, path, 0.1)) / 0.8
            got = wrist_movement_time(t, path, 0.8)
            assert np.float64(got).tobytes() == np.float64(want).tobytes(), n

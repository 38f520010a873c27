"""The landmarks' passes over every row of a stream cost what they must (issue 45, item
6), and give what the library functions they stand for give, bit for bit.

* the zero-lag filter is :func:`scipy.signal.filtfilt` with its steady state
  designed once per filter, not at every call;
* the median time step is taken once per clip, not by every pass;
* per-row tests and norms are taken a column at a time
  (:mod:`perception.rowwise`), equal to NumPy's reductions.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
import scipy.signal

from perception.rowwise import finite_rows, row_norm

landmarks = importlib.import_module("perception.landmarks")
cleaning = importlib.import_module("perception.cleaning")
zero_lag = importlib.import_module("perception.zero_lag")


@pytest.mark.parametrize("order", [1, 2, 4, 8])
@pytest.mark.parametrize("wn", [0.1, 0.667, 0.95])
def test_the_zero_lag_filter_is_filtfilt_bit_for_bit(order, wn):
    b, a, zi = zero_lag.design(order, wn)
    rng = np.random.default_rng(order)
    for n in (3 * max(len(a), len(b)) + 1, 40, 301):
        for k in (1, 2, 3):
            x = np.cumsum(rng.normal(size=(n, k)), axis=0)
            want = scipy.signal.filtfilt(b, a, x, axis=0)
            assert np.asarray(zero_lag.filtfilt(b, a, zi, x)).tobytes() == want.tobytes()


def _clip(n=400, fps=30.0, seed=0):
    """A reach then rest, with gaps: time, wrist (N, 2), aperture (N,)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fps
    s = np.clip((t - 0.5) / 1.2, 0, 1)
    x = 0.3 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    wrist = np.c_[x, 0.02 * x] + rng.normal(0, 3e-4, (n, 2))
    g = 0.02 + 0.06 * np.sin(np.pi * s) ** 2 + rng.normal(0, 3e-4, n)
    wrist[[50, 51, 200], 0] = np.nan
    g[[60, 300, 301, 302]] = np.nan
    return t, wrist, g


def test_a_movements_landmarks_design_the_filter_once(monkeypatch):
    """The steady state of the filter's step response is designed once per filter: a
    stream's landmarks designed it twice at every row (30 us each)."""
    designed = []
    zi = scipy.signal.lfilter_zi

    def counted(b, a):
        designed.append(1)
        return zi(b, a)

    monkeypatch.setattr(scipy.signal, "lfilter_zi", counted)
    monkeypatch.setattr(scipy.signal._signaltools, "lfilter_zi", counted)
    zero_lag.design.cache_clear()
    t, wrist, g = _clip()
    params = landmarks.LandmarkParams(cutoff=9.5)  # a filter no other test designed
    first = landmarks.movement_landmarks(t, wrist, g, params)
    for n in range(380, 400):
        landmarks.movement_landmarks(t[:n], wrist[:n], g[:n], params)
    assert len(designed) == 1
    assert repr(first) == repr(landmarks.movement_landmarks(t, wrist, g, params))


def test_the_step_is_found_once_for_the_landmarks_of_a_clip(monkeypatch):
    """observed_landmarks reads every row's time step once, not in each of its passes
    (the three markers' spike tests, two filters, the bounds: seven medians a row)."""
    calls, medians = [], []
    median, np_median = landmarks.median_step, np.median

    def counted(a):
        calls.append(len(a))
        return median(a)

    def np_counted(a, *args, **kw):  # nor any pass its own median of every step
        medians.append(len(a))
        return np_median(a, *args, **kw)

    t, wrist, g = _clip()
    raw = np.stack([wrist, wrist + [0.05, g[0]], wrist + [0.05, 0.0]], axis=1)
    obs = type("Obs", (), {"clip_time": t, "clip_raw": raw})()
    want = landmarks.observed_landmarks(obs)
    monkeypatch.setattr(landmarks, "median_step", counted)
    monkeypatch.setattr(np, "median", np_counted)
    cleaning._SPIKES.local.__dict__.clear()
    got = landmarks.observed_landmarks(obs)
    monkeypatch.undo()
    assert repr(got) == repr(want)
    assert calls.count(len(t)) == 1, calls  # the steps' median, once
    assert len(t) - 1 not in medians, medians
    assert got.onset_time == want.onset_time  # and it is np.median's
    assert landmarks._step(t) == float(np.median(np.diff(t)))


def test_rows_tested_and_measured_a_column_at_a_time_are_numpys():
    rng = np.random.default_rng(5)
    for k in (1, 2, 3, 4, 6, 9):
        x = rng.normal(size=(5000, k)) * rng.choice([1e-3, 1.0, 1e200], (5000, 1))
        x[rng.random(x.shape) < 0.02] = np.nan
        x[rng.random(x.shape) < 0.005] = np.inf
        for y in (x, x[:, ::-1], x[::3]):
            with np.errstate(over="ignore"):  # 1e200 squared: inf either way
                assert row_norm(y).tobytes() == np.linalg.norm(y, axis=1).tobytes()
            assert np.array_equal(finite_rows(y), np.isfinite(y).all(axis=1))
        assert np.array_equal(finite_rows(x.reshape(-1, 1, k)), np.isfinite(x).all(axis=1))
    assert finite_rows(np.zeros((0, 2))).shape == (0,)


def test_the_opening_speed_reads_the_gradient_of_its_rows_alone_bit_for_bit():
    rng = np.random.default_rng(7)
    for n in (2, 3, 11, 40):
        steps = (np.full(n, 0.25), rng.random(n) + 0.5, np.full(n, 1 / 30.0))
        for x in (np.cumsum(s) for s in steps):
            f = rng.normal(size=n)
            f[rng.random(n) < 0.1] = np.nan
            want = np.gradient(f, x)
            for lo in range(n):
                for hi in range(lo, n + 1):
                    got = zero_lag.gradient_rows(f, x, lo, hi)
                    assert got.tobytes() == want[lo:hi].tobytes(), (n, lo, hi)


def test_runs_a_gap_closed_are_filtered_once_and_alike():
    """A stream that loses a marker now and then: after every row, the low-passed path
    resumed from the row before is the fresh one, bitwise, and only the run still open
    at the end is filtered again (was every run at every row)."""
    rng = np.random.default_rng(3)
    n = 300
    t = np.arange(n) / 30.0
    x = np.cumsum(rng.normal(size=(n, 2)), axis=0)
    x[rng.choice(n, 25, replace=False)] = np.nan
    x[100:103] = np.nan
    params = landmarks.LandmarkParams()
    filtered = []
    filtfilt = zero_lag.filtfilt

    def counted(*args):
        filtered.append(len(args[3]))
        return filtfilt(*args)

    landmarks._LOWPASSED.local.__dict__.clear()
    for m in range(2, n + 1):
        resumed = params.lowpass(t[:m], x[:m])
        saved = dict(landmarks._LOWPASSED.local.__dict__)
        landmarks._LOWPASSED.local.__dict__.clear()
        assert resumed.tobytes() == params.lowpass(t[:m], x[:m]).tobytes(), m
        landmarks._LOWPASSED.local.__dict__.update(saved)
    landmarks._LOWPASSED.local.__dict__.clear()
    params.lowpass(t[:199], x[:199])
    zero_lag.filtfilt = counted
    try:
        for m in range(200, 300):
            params.lowpass(t[:m], x[:m])
    finally:
        zero_lag.filtfilt = filtfilt
    assert len(filtered) <= 100  # one open run a row at most, not the 20-odd closed ones


def test_the_markers_paths_are_copied_apart_bit_for_bit():
    raw = np.random.default_rng(4).normal(size=(50, 3, 2))
    raw[3, 1, 0] = np.nan
    raw[4, 2, 1] = -0.0
    raw.view(np.int64)[7, 0, 0] = 0x7FF8000000000123  # a NaN with a payload
    before = raw.copy()
    paths = landmarks._by_marker(raw)
    assert paths.shape == (3, 50, 2) and paths.flags.c_contiguous
    assert all(paths[k].tobytes() == raw[:, k].tobytes() for k in range(3))
    paths[:] = 0.0  # a copy: the observation's positions stay
    assert raw.tobytes() == before.tobytes()
    one = np.ones((4, 1, 2))
    landmarks._by_marker(one)[:] = 0.0
    assert (one == 1.0).all()

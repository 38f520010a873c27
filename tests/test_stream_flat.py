"""A stream's per-row passes that no longer read every row (issue 45, item 6), each
checked against the fresh pass over every prefix, bit for bit: rows appended to a
``Grown`` (proven without comparing), the order statistics kept in order, the open
run's zero-lag filter and the speed resumed."""

from __future__ import annotations

import numpy as np
import pytest

from perception import landmark_stream, zero_lag
from perception.resume import Grown, Kept, Ordered, extended, grown_of
from perception.rowwise import row_norm


def _bits(x) -> bytes:
    return np.asarray(x, dtype=float).tobytes()


def test_grown_rows_are_read_only_and_their_memory_is_never_written_again():
    g = Grown(np.arange(6.0).reshape(3, 2))
    first = g.rows()
    with pytest.raises(ValueError):
        first[0, 0] = 1.0
    with pytest.raises(ValueError):
        first.flags.writeable = True  # its memory is the Grown's, read-only
    for k in range(200):  # past the first memory: the old view keeps its rows
        g.append(np.full((1, 2), float(k)))
    assert np.array_equal(first, np.arange(6.0).reshape(3, 2))
    assert np.array_equal(g.rows()[:3], first) and len(g.rows()) == 203
    assert grown_of(g.rows()) is g and grown_of(first) is g
    assert grown_of(first[1:]) is None and grown_of(first.copy()) is None


def test_extended_is_concatenate_and_a_second_branch_gets_its_own_rows():
    base = extended(np.zeros((0, 2)), np.ones((4, 2)))
    a = extended(base, np.full((2, 2), 2.0))
    b = extended(base, np.full((3, 2), 3.0))  # base already extended: a copy, not a's
    assert np.array_equal(a, np.r_[np.ones((4, 2)), np.full((2, 2), 2.0)])
    assert np.array_equal(b, np.r_[np.ones((4, 2)), np.full((3, 2), 3.0)])
    assert grown_of(a) is not grown_of(b)


def test_kept_proves_a_grown_prefix_by_identity_and_compares_anything_else():
    kept = Kept(2)
    g = Grown(np.arange(5.0))
    kept.keep("k", (g.rows(),), "five")
    assert kept.local.entries[0][3] == (None,)  # no bytes copied for a Grown's rows
    g.append(np.array([5.0, 6.0]))
    assert kept.longest("k", (g.rows(),))[1] == "five"
    # the same values in another array: compared, and found alike
    assert kept.longest("k", (np.arange(7.0),))[1] == "five"
    other = np.arange(7.0)
    other[2] = -1.0
    assert kept.longest("k", (other,)) is None
    # another Grown with other rows: compared, not taken for this one
    h = Grown(np.r_[9.0, np.arange(1.0, 7.0)])
    assert kept.longest("k", (h.rows(),)) is None


def test_ordered_statistics_are_numpys_bit_for_bit():
    rng = np.random.default_rng(3)
    for trial in range(400):
        n = int(rng.integers(1, 300))
        x = rng.normal(size=n) if trial % 2 else rng.integers(0, 4, n) * 0.1  # ties
        x[rng.random(n) < 0.05] = np.nan
        o = Ordered(x)
        seen = x[np.isfinite(x)]
        if not len(seen):
            continue
        assert _bits(o.median()) == _bits(np.median(seen))
        for q in (0, 10, 37.5, 50, 90, 100):
            assert _bits(o.percentile(q)) == _bits(np.percentile(seen, q)), (n, q)
        k = int(rng.integers(0, n))
        y = np.r_[x[:k], rng.normal(size=n - k + 2)]
        moved = o.replaced(x[k:], y[k:], lambda y=y: y)
        assert _bits(moved.percentile(10)) == _bits(np.percentile(y[np.isfinite(y)], 10))
        # the first one was changed into the second: asked again, it orders afresh
        again = o.extended([0.5], lambda x=x: np.r_[x, 0.5])
        assert _bits(again.median()) == _bits(np.median(np.r_[seen, 0.5]))


@pytest.mark.parametrize("wn", [0.1, 0.4, 0.667, 0.95])
def test_the_open_runs_filter_resumed_is_filtfilts_at_every_row(wn, monkeypatch):
    import scipy.signal

    b, a, zi = zero_lag.design(2, wn)
    rng = np.random.default_rng(4)
    x = np.cumsum(rng.normal(size=(800, 2)), axis=0)
    rows = []
    lfilter = scipy.signal.lfilter

    def counted(b, a, x, *args, **kw):
        rows.append(len(x))
        return lfilter(b, a, x, *args, **kw)

    monkeypatch.setattr(scipy.signal, "lfilter", counted)
    last = None
    for n in range(10, 800):
        want = zero_lag.filtfilt(b, a, zi, x[:n])
        rows.clear()
        done = zero_lag.filtfilt_resumed(b, a, zi, x[:n], last)
        assert done.y.tobytes() == want.tobytes(), n
        last = done
    # the last row's passes: forward over the new row, back until they met the last one's
    assert sum(rows) <= zero_lag.DEPTH + 2 * zero_lag.STRIDE, rows
    last = None
    for n in range(10, 500, 41):  # several rows at a time
        done = zero_lag.filtfilt_resumed(b, a, zi, x[:n], last)
        assert done.y.tobytes() == zero_lag.filtfilt(b, a, zi, x[:n]).tobytes(), n
        last = done


def test_the_speed_and_its_floor_resumed_are_numpys_at_every_row():
    rng = np.random.default_rng(6)
    n = 260
    t = np.arange(n) / 30.0
    t[150:] += 0.004  # a late step unlike the others: np.gradient's other formula
    p = np.cumsum(rng.normal(0, 1e-3, (n, 2)), axis=0)
    p[[40, 41, 200]] = np.nan
    p[60:100] = np.nan  # a long loss: fewer speeds in order than rows before
    landmark_stream._SPEEDS.local.__dict__.clear()
    for m in range(3, n):
        q = p[:m].copy()
        if m % 17 == 0:  # the low-pass of a stream's last rows changes with a row more
            q[max(0, m - 30):] += 1e-9
        speed, floor = landmark_stream.speed_and_floor(t[:m], q, 10)
        want = row_norm(np.gradient(q, t[:m], axis=0))
        assert speed.tobytes() == want.tobytes(), m
        seen = want[np.isfinite(want)]
        assert _bits(floor) == _bits(np.percentile(seen, 10) if len(seen) else 0.0), m


def test_the_median_step_resumed_is_numpys():
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.choice([1 / 30, 1 / 30, 1 / 29, 1 / 31], 300))
    landmark_stream._STEPS.local.__dict__.clear()
    for m in range(2, 300):
        assert _bits(landmark_stream.median_step(t[:m])) == _bits(np.median(np.diff(t[:m])))
    t[100] = np.nan
    assert np.isnan(landmark_stream.median_step(t))


def test_a_row_that_cannot_be_taken_leaves_the_rows_as_they_were():
    from perception.online import _Rows

    rows = _Rows(4)
    rows.append(0, 0.0, np.zeros((4, 2)), 1.0, 0)
    with pytest.raises(ValueError):
        rows.append(1, 1 / 30, np.zeros((4, 2)), np.ones(3), 0)  # a likelihood short
    rows.append(1, 1 / 30, np.ones((4, 2)), np.ones(4), np.zeros(4))
    got = rows.arrays(views=True)
    assert {k: len(v) for k, v in got.items()} == dict.fromkeys(got, 2)
    assert not got["position"].flags.writeable and rows.arrays()["position"].flags.writeable
    assert np.array_equal(got["position"][1], np.ones((4, 2)))


def test_a_grown_its_owner_alone_appends_to_is_not_extended_by_others():


    g = Grown(np.arange(3.0), extendable=False)
    out = extended(g.rows(), np.array([9.0]))
    assert g.n == 3 and list(g.rows()) == [0.0, 1.0, 2.0]  # its own rows unchanged
    assert list(out) == [0.0, 1.0, 2.0, 9.0]
    free = Grown(np.arange(3.0))
    assert list(extended(free.rows(), np.array([9.0]))) == [0.0, 1.0, 2.0, 9.0]
    assert free.n == 4  # appended in place


def test_an_ordered_read_after_it_was_replaced_is_refused():


    old = Ordered(np.array([1.0, 2.0, 3.0]))
    new = old.extended(np.array([4.0, 5.0]), lambda: np.arange(1.0, 6.0))
    assert new.median() == 3.0
    with pytest.raises(RuntimeError):
        old.median()

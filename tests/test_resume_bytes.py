"""What a resumed pass tests its series with, and what it keeps (issue 45, item 6: a
stream whose per-row cost does not grow with its length).

A kept series is compared with the new one as bytes (a NaN is its own bits,
-0.0 is not 0.0), and kept as bytes: the caller's arrays may change after.
"""

from __future__ import annotations

import numpy as np

from perception.resume import Kept, begins_with


def test_a_sign_of_zero_is_not_the_same_series():
    """-0.0 == 0.0 as numbers, but a pass may tell them apart (1 / x): not resumed."""
    t = np.arange(4.0)
    x = np.zeros((4, 2))
    kept = x[:3].copy()
    kept[1, 0] = -0.0
    assert not begins_with((t, x), (t[:3], kept))
    assert begins_with((t, x), (t[:3], x[:3].copy()))


def test_another_dtype_is_not_the_same_series():
    t = np.arange(4.0)
    assert not begins_with((t,), (t[:3].astype(np.float32),))
    assert begins_with((np.arange(5),), (np.arange(3),))  # integers: their bytes too


def test_kept_series_are_copies_handed_back_read_only():
    kept = Kept(2)
    t = np.arange(6.0)
    xy = np.arange(12.0).reshape(6, 2)[:, ::-1]  # not contiguous: kept in row order
    kept.keep("k", (t[:4], xy[:4]), "four")
    t[0] = 99.0  # the caller's arrays change after: what was kept does not
    series, value = kept.longest("k", (np.arange(6.0), np.arange(12.0).reshape(6, 2)[:, ::-1]))
    assert value == "four"
    assert np.array_equal(series[0], np.arange(4.0))
    assert np.array_equal(series[1], np.arange(12.0).reshape(6, 2)[:4, ::-1])
    assert not series[0].flags.writeable and not series[1].flags.writeable
    assert kept.longest("k", (t, xy)) is None  # the changed row is not the kept one
    assert kept.longest("other", (np.arange(6.0), np.arange(12.0).reshape(6, 2)[:, ::-1])) is None


def test_the_longest_kept_series_the_new_one_begins_with_and_the_superseded_one_dropped():
    kept = Kept(3)
    t = np.arange(10.0)
    kept.keep("k", (t[:3],), 3)
    kept.keep("k", (t[:5],), 5)
    other = t.copy()
    other[4] = -1.0
    kept.keep("k", (other[:6],), 6)
    assert kept.longest("k", (t,))[1] == 5  # the 6-row one is another series
    assert kept.longest("k", (t[:5],), shorter=True)[1] == 3
    found = kept.longest("k", (t,))
    kept.keep("k", (t[:7],), 7, superseded=found)
    values = sorted(e[2] for e in kept.local.entries)
    assert values == [3, 6, 7]

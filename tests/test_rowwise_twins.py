"""The cheaper twins of NumPy calls a stream's every row makes are those calls, bit for bit.

:func:`perception.rowwise.last_norm` (``np.linalg.norm(x, axis=-1)``) and
:func:`perception.rowwise.run_edges` (``np.diff(np.r_[0, mask, 0])``'s rises and
falls) over many inputs, NaN, infinities, signed zeros and empty ones included;
and the engine's terms, whose norms are now taken once, against the rules given
their own.
"""

from __future__ import annotations

import numpy as np
import pytest

from perception.recognition.scoring import likelihood_rule
from perception.rowwise import last_norm, run_edges


def _awkward(rng, shape):
    x = rng.normal(size=shape) * rng.choice([1e-300, 1e-3, 1.0, 1e150], shape)
    x[rng.random(shape) < 0.03] = np.nan
    x[rng.random(shape) < 0.01] = np.inf
    x[rng.random(shape) < 0.01] = -np.inf
    x[rng.random(shape) < 0.02] = -0.0
    return x


@pytest.mark.parametrize("k", [1, 2, 3, 4, 8])
def test_the_norm_along_the_last_axis_is_numpys_bit_for_bit(k):
    rng = np.random.default_rng(k)
    for shape in ((0, k), (1, k), (7, k), (16, 3, k), (5, 2, 4, k), (3, 0, k)):
        x = _awkward(rng, shape)
        for y in (x, x[..., ::-1], x[::2], np.swapaxes(x, 0, -2) if x.ndim > 2 else x):
            with np.errstate(over="ignore", under="ignore"):
                want = np.linalg.norm(y, axis=-1)
                got = last_norm(y)
            assert got.shape == want.shape
            assert got.tobytes() == want.tobytes(), shape


def test_the_norm_of_integers_is_of_their_floats():
    x = np.arange(12).reshape(3, 2, 2)
    assert last_norm(x).tobytes() == np.linalg.norm(x, axis=-1).tobytes()


def _np_r_edges(mask):
    edges = np.diff(np.r_[0, np.asarray(mask).astype(np.int8), 0])
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def test_the_runs_of_a_mask_are_np_rs():
    rng = np.random.default_rng(3)
    masks = [np.zeros(0, bool), np.ones(1, bool), np.zeros(1, bool), np.ones(9, bool)]
    masks += [rng.random(n) < p for n in (2, 3, 17, 300) for p in (0.05, 0.5, 0.95)]
    for mask in masks:
        want, got = _np_r_edges(mask), run_edges(mask)
        for w, g in zip(want, got):
            assert np.array_equal(w, g) and g.dtype == w.dtype, mask
        assert len(got[0]) == len(got[1])


def test_the_likelihood_rule_given_its_norms_is_the_rule_that_takes_them():
    """The engine hands the rule the predicted r and g it took for the thesis rule:
    the same numbers as the rule's own norms, bit for bit."""
    rng = np.random.default_rng(11)
    m, n = 6, 9
    mid, opening = _awkward(rng, (m, n, 2)), _awkward(rng, (m, n, 2))
    a = rng.normal(size=(m, n, 3, 2, 2)) * 1e-3
    cov = a @ np.swapaxes(a, -1, -2) + 1e-8 * np.eye(2)
    r_obs, g_obs = rng.random(n), rng.random(n)
    valid = rng.random((m, n)) < 0.8
    with np.errstate(all="ignore"):
        want = likelihood_rule(r_obs, g_obs, mid, opening, cov, valid, 1e-3)
        norms = (np.linalg.norm(mid, axis=-1), np.linalg.norm(opening, axis=-1))
        got = likelihood_rule(r_obs, g_obs, mid, opening, cov, valid, 1e-3, norms=norms)
    for w, g in zip(want, got):
        assert g.tobytes() == w.tobytes()

import numpy as np
import pytest

from minvar.kinematics import TwoLinkChain


@pytest.fixture
def arm():
    return TwoLinkChain(0.3, 0.3, base=(0.05, -0.1))


def test_forward_inverse_round_trip_both_branches(arm):
    rng = np.random.default_rng(0)
    r = rng.uniform(0.05, 0.59, 200)
    a = rng.uniform(-np.pi, np.pi, 200)
    p = np.asarray(arm.base) + np.stack([r * np.cos(a), r * np.sin(a)], -1)
    for elbow in (1, -1):
        q = arm.inverse(p, elbow)
        np.testing.assert_allclose(arm.forward(q), p, atol=1e-12)
        assert np.all(np.sign(q[:, 1]) == elbow)


def test_known_configuration():
    chain = TwoLinkChain(1.0, 1.0)
    np.testing.assert_allclose(chain.forward([0, np.pi / 2]), [1, 1], atol=1e-15)
    np.testing.assert_allclose(chain.inverse([1, 1], elbow=1), [0, np.pi / 2], atol=1e-12)
    np.testing.assert_allclose(chain.inverse([1, 1], elbow=-1), [np.pi / 2, -np.pi / 2], atol=1e-12)


def test_jacobian_matches_finite_differences(arm):
    q = np.array([0.4, 1.1])
    eps = 1e-7
    fd = np.stack([(arm.forward(q + eps * e) - arm.forward(q - eps * e)) / (2 * eps)
                   for e in np.eye(2)], axis=-1)
    np.testing.assert_allclose(arm.jacobian(q), fd, atol=1e-7)


def test_inverse_path_is_continuous(arm):
    # a path crossing the -x axis, where atan2 wraps, and near full extension
    t = np.linspace(0, 1, 200)
    ang = np.pi * 0.8 + 0.4 * np.pi * t
    p = np.asarray(arm.base) + 0.5 * np.stack([np.cos(ang), np.sin(ang)], -1)
    q = arm.inverse_path(p, q_start=arm.inverse(p[0], -1))
    assert np.all(np.abs(np.diff(q, axis=0)) < 0.05)
    assert np.all(q[:, 1] < 0)  # stays on the branch it started on
    np.testing.assert_allclose(arm.forward(q), p, atol=1e-12)


@pytest.mark.parametrize("p", [(0.7, -0.1), (np.nan, 0.0)])
def test_unreachable_target(arm, p):
    with pytest.raises(ValueError, match="out of reach"):
        arm.inverse(p)


def test_too_close_for_unequal_links():
    with pytest.raises(ValueError, match=r"in \[0.050, 0.150\]"):
        TwoLinkChain(0.1, 0.05).inverse((0.02, 0.0))


def test_bad_chain():
    with pytest.raises(ValueError, match="l1"):
        TwoLinkChain(0.0, 0.3)

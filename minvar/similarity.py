"""How alike two movements are: mean-square difference in joint space (thesis eq. A.2)
and the spatial distance between two paths.

Eq. A.2 compares two movements sample by sample over their common length,
summing the squared differences of every joint angle::

    d(alpha, beta) = sum_{n=0}^{min(T_alpha, T_beta)} sum_{j=1}^{J} (alpha_n^j - beta_n^j)^2

The thesis (after Pomplun & Mataric) works in joint space so that arms of
different lengths compare fairly; hand paths are mapped to the joint angles of
a two-link arm by inverse kinematics. Pomplun & Mataric's "combined
segmentation" (for sequences of movements) is not described in the thesis;
single movements are compared sample by sample, which is what it reduces to.
Both movements must be sampled at the same interval.
"""

from __future__ import annotations

import numpy as np

from .kinematics import TwoLinkChain

__all__ = ["msd", "joint_msd", "path_distance"]


def _samples(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[0] < 1 or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected finite samples shaped (T, J), got shape {arr.shape}")
    return arr


def msd(alpha, beta, *, mean: bool = False) -> float:
    """Mean-square difference of two sampled movements (thesis eq. A.2).

    Parameters
    ----------
    alpha, beta : (T_alpha, J), (T_beta, J) array_like
        Movements sampled at the same interval (joint angles in rad for eq. A.2;
        any coordinates work). Only the first ``min(T_alpha, T_beta)`` samples
        are compared.
    mean : bool
        False (default): eq. A.2 as printed, the sum over samples and
        coordinates (rad^2). True: divided by the number of samples compared,
        so movements of different lengths compare fairly.

    Returns
    -------
    float
        0 for identical movements.
    """
    a, b = _samples("msd: alpha", alpha), _samples("msd: beta", beta)
    if a.shape[1] != b.shape[1]:
        raise ValueError(
            f"msd: alpha has {a.shape[1]} coordinates per sample, beta {b.shape[1]}"
        )
    n = min(len(a), len(b))
    total = float(np.sum((a[:n] - b[:n]) ** 2))
    return total / n if mean else total


def joint_msd(
    path_a,
    path_b,
    *,
    chain: TwoLinkChain | None = None,
    elbow: int = 1,
    mean: bool = False,
) -> float:
    """Eq. A.2 between two hand paths, in the joint space of a two-link arm.

    Parameters
    ----------
    path_a, path_b : (T, 2) array_like
        Hand positions, m, sampled at the same interval, in the chain's frame.
    chain : TwoLinkChain, optional
        The arm (default: two 0.30 m links, shoulder at the origin).
    elbow : {1, -1}
        Elbow branch at each path's start (then kept continuous).
    mean : bool
        Divide by the number of samples compared (see :func:`msd`).

    Returns
    -------
    float
        rad^2 (or rad^2 per sample with ``mean=True``).

    Raises
    ------
    ValueError
        If a position is out of the arm's reach.
    """
    chain = TwoLinkChain() if chain is None else chain
    a = _samples("joint_msd: path_a", path_a)
    b = _samples("joint_msd: path_b", path_b)
    qa = chain.inverse_path(a, chain.inverse(a[0], elbow))
    qb = chain.inverse_path(b, chain.inverse(b[0], elbow))
    return msd(qa, qb, mean=mean)


def _to_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """(P,) distance of each point to the nearest segment of a polyline (S, 2)."""
    if len(line) == 1:
        return np.linalg.norm(points - line[0], axis=-1)
    a, d = line[:-1], np.diff(line, axis=0)  # segments a + s d, 0 <= s <= 1
    rel = points[:, None, :] - a[None]
    length2 = np.sum(d * d, axis=-1)
    s = np.clip(np.sum(rel * d, axis=-1) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    return np.min(np.linalg.norm(rel - s[..., None] * d, axis=-1), axis=1)


def path_distance(path_a, path_b) -> float:
    """Symmetric Hausdorff distance between two paths, ignoring timing, m.

    The largest distance from a point of either path to the nearest point of
    the other path (taken as the polyline through its samples, so sampling
    density does not inflate it): how far apart the drawn shapes are, however
    fast each was drawn.

    Parameters
    ----------
    path_a, path_b : (S, 2) array_like
        Sampled paths, m.
    """
    a = _samples("path_distance: path_a", path_a)
    b = _samples("path_distance: path_b", path_b)
    if a.shape[1] != 2 or b.shape[1] != 2:
        raise ValueError(f"path_distance: expected (S, 2) paths, got {a.shape} and {b.shape}")
    return float(max(_to_polyline(a, b).max(), _to_polyline(b, a).max()))

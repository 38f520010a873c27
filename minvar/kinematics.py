"""Two-link planar chains: forward and inverse kinematics, Jacobian.

Angles in rad: ``q[..., 0]`` is the first link's angle from the +x axis of the
chain's frame, ``q[..., 1]`` the second link's angle relative to the first.
Positions in m. All functions broadcast over leading dimensions.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from minvar.validation import Positive, Tuple, declared

__all__ = ["TwoLinkChain"]


@declared
class TwoLinkChain:
    """A planar chain of two rigid links with revolute joints.

    Parameters
    ----------
    l1, l2 : float
        Link lengths, m.
    base : (2,) tuple
        Position of the first joint in the parent frame, m.
    """

    l1: Positive = 0.30
    l2: Positive = 0.30
    base: Annotated[tuple[float, float], Tuple] = (0.0, 0.0)

    @property
    def reach(self) -> tuple[float, float]:
        """Smallest and largest distance of the tip from the base, m."""
        return abs(self.l1 - self.l2), self.l1 + self.l2

    def elbow(self, q: np.ndarray) -> np.ndarray:
        """Position of the middle joint for joint angles ``q`` (..., 2); returns (..., 2) m."""
        q = np.asarray(q, dtype=float)
        link = np.stack([np.cos(q[..., 0]), np.sin(q[..., 0])], axis=-1)
        return np.asarray(self.base) + self.l1 * link

    def forward(self, q: np.ndarray) -> np.ndarray:
        """Tip position for joint angles ``q`` (..., 2); returns (..., 2) m."""
        q = np.asarray(q, dtype=float)
        a = q[..., 0] + q[..., 1]
        return self.elbow(q) + self.l2 * np.stack([np.cos(a), np.sin(a)], -1)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """d tip / d q for joint angles ``q`` (..., 2); returns (..., 2, 2)."""
        q = np.asarray(q, dtype=float)
        a = q[..., 0] + q[..., 1]
        s1, c1, s12, c12 = np.sin(q[..., 0]), np.cos(q[..., 0]), np.sin(a), np.cos(a)
        J = np.empty(q.shape[:-1] + (2, 2))
        J[..., 0, 0] = -self.l1 * s1 - self.l2 * s12
        J[..., 0, 1] = -self.l2 * s12
        J[..., 1, 0] = self.l1 * c1 + self.l2 * c12
        J[..., 1, 1] = self.l2 * c12
        return J

    def inverse(self, p: np.ndarray, elbow: int = 1) -> np.ndarray:
        """Joint angles placing the tip at ``p``.

        Parameters
        ----------
        p : (..., 2) array_like
            Tip positions, m.
        elbow : {1, -1}
            Branch: the sign of the second joint angle.

        Returns
        -------
        (..., 2) array
            Joint angles, rad; the first wrapped to (-pi, pi].

        Raises
        ------
        ValueError
            If a position is out of the chain's reach.
        """
        if elbow not in (1, -1):
            raise ValueError(f"TwoLinkChain.inverse: elbow must be 1 or -1, got {elbow!r}")
        rel = np.asarray(p, dtype=float) - np.asarray(self.base)
        d2 = np.sum(rel**2, axis=-1)
        lo, hi = self.reach
        tol = 1e-12 * hi
        d = np.sqrt(d2)
        bad = (d > hi + tol) | (d < lo - tol) | ~np.isfinite(d)
        if np.any(bad):
            worst = np.asarray(p, dtype=float).reshape(-1, 2)[np.argmax(np.ravel(bad))]
            raise ValueError(
                f"TwoLinkChain: target {tuple(np.round(worst, 4))} m is out of reach: its "
                f"distance from the base {self.base} must lie in [{lo:.3f}, {hi:.3f}] m"
            )
        c2 = np.clip((d2 - self.l1**2 - self.l2**2) / (2 * self.l1 * self.l2), -1.0, 1.0)
        q2 = elbow * np.arccos(c2)
        q1 = np.arctan2(rel[..., 1], rel[..., 0]) - np.arctan2(
            self.l2 * np.sin(q2), self.l1 + self.l2 * np.cos(q2)
        )
        q1 = np.angle(np.exp(1j * q1))
        return np.stack([q1, q2], axis=-1)

    def inverse_path(self, path: np.ndarray, q_start: np.ndarray | None = None) -> np.ndarray:
        """Joint angles along a tip path, choosing the branch that keeps angles continuous.

        Parameters
        ----------
        path : (S, 2) array_like
            Tip positions, m.
        q_start : (2,) array_like, optional
            Configuration the path starts from (picks the initial branch and the
            2 pi offset of the first angle); default: the elbow = 1 branch.

        Returns
        -------
        (S, 2) array
            Joint angles, rad, unwrapped so consecutive rows differ by less than pi.
        """
        path = np.asarray(path, dtype=float)
        up, down = self.inverse(path, 1), self.inverse(path, -1)
        q = np.empty_like(up)
        prev = up[0] if q_start is None else np.asarray(q_start, dtype=float)
        for i in range(len(path)):
            cands = np.stack([up[i], down[i]])
            # shift each candidate's first angle by 2 pi k to lie nearest the previous one
            cands[:, 0] += 2 * np.pi * np.round((prev[0] - cands[:, 0]) / (2 * np.pi))
            prev = q[i] = cands[np.argmin(np.abs(cands - prev).sum(axis=1))]
        return q

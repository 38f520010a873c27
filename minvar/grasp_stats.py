"""Statistics of grasps (thesis chapter 4): grip aperture, variability, end-points.

Two kinds of function. The measures (:func:`grip_aperture`,
:func:`max_grip_aperture`, :func:`path_sd`, :func:`peak`,
:func:`peak_deviation`, :func:`bootstrap_peak`) take arrays (anything
``numpy.asarray`` reads), so they serve simulated and observed grasps alike;
a :class:`~minvar.grasp.GraspResult`'s own ``aperture``, ``mga``,
``wrist_sd``, ... properties call them too. The summaries take grasp objects:
:func:`grasp_moments` a :class:`~minvar.grasp.GraspPlan`,
:func:`summarize_grasp` a :class:`~minvar.grasp.GraspResult` (and,
optionally, its :class:`GraspMoments`), :func:`end_distance` a
:class:`GraspMoments`. This module needs nothing of :mod:`minvar.grasp` at
run time (its classes are imported for type checking only, and read by
attribute), so :mod:`minvar.grasp` can build on it. :func:`grasp_moments`
gives the variabilities without sampling error, from the exact joint-space
moments of each chain's plan (:func:`minvar.moments.state_moments`) mapped
through the kinematics to first order — exact up to terms of order (noise
SD / link length)^2, i.e. to a part in 10^4 at the thesis's 1 % execution
noise.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .analysis import endpoint_stats, expected_distance
from .moments import state_moments
from .plant import POSITION

if TYPE_CHECKING:  # pragma: no cover - minvar.grasp imports this module
    from numpy.typing import ArrayLike

    from .grasp import GraspPlan, GraspResult

__all__ = [
    "GraspMoments",
    "GraspSummary",
    "bootstrap_peak",
    "end_distance",
    "grasp_moments",
    "grip_aperture",
    "max_grip_aperture",
    "path_sd",
    "peak",
    "peak_deviation",
    "summarize_grasp",
]


def grip_aperture(finger: ArrayLike, thumb: ArrayLike) -> np.ndarray:
    """Grip aperture: the distance between the finger and thumb tips.

    Parameters
    ----------
    finger, thumb : (..., 2) array_like
        Tip positions (any frame, the same for both), m.

    Returns
    -------
    (...) array
        ``|finger - thumb|``, m.
    """
    d = np.asarray(finger, dtype=float) - np.asarray(thumb, dtype=float)
    return np.hypot(d[..., 0], d[..., 1])


def max_grip_aperture(aperture: ArrayLike,
                      relative_time: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Maximum grip aperture (MGA) of each repetition and when it occurs.

    Parameters
    ----------
    aperture : (trials, S+1) or (S+1,) array_like
        Grip aperture over time, m (one repetition may be given as 1-D).
    relative_time : (S+1,) array_like
        Time of each sample as a fraction of the movement.

    Returns
    -------
    mga : (trials,) array
        Maximum aperture, m.
    time : (trials,) array
        Its time, fraction of the movement.
    """
    aperture = np.atleast_2d(np.asarray(aperture, dtype=float))
    i = np.argmax(aperture, axis=1)
    return aperture[np.arange(len(i)), i], np.asarray(relative_time, dtype=float)[i]


def path_sd(paths: ArrayLike) -> np.ndarray:
    """Standard deviation across repetitions at each time step.

    Parameters
    ----------
    paths : (trials, S+1) or (trials, S+1, 2) array_like
        A scalar (e.g. aperture, m) or a 2-D position (m) over time. For
        positions the SD is ``sqrt(var x + var y)``.

    Returns
    -------
    (S+1,) array
        SD, in the unit of ``paths``.
    """
    paths = np.asarray(paths, dtype=float)
    var = paths.var(axis=0, ddof=1)
    return np.sqrt(var.sum(axis=-1)) if paths.ndim == 3 else np.sqrt(var)


def peak(curve: ArrayLike, relative_time: ArrayLike) -> tuple[float, float]:
    """Largest value of a curve and its time.

    Parameters
    ----------
    curve : (S+1,) array_like
        E.g. an SD over time.
    relative_time : (S+1,) array_like
        Time of each sample (any unit; fractions of the movement here).

    Returns
    -------
    value, time : float
        The largest value and the time of its first occurrence.
    """
    curve = np.asarray(curve, dtype=float)
    i = int(np.argmax(curve))
    return float(curve[i]), float(np.asarray(relative_time, dtype=float)[i])


def peak_deviation(paths: ArrayLike,
                   relative_time: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Each repetition's largest deviation from the mean path, and its time.

    The per-repetition measure of variability that one-way ANOVA compares
    across settings (the SD over time is its across-trial root mean square at
    each step): a setting with more variable movements has larger peak
    deviations on average.

    Parameters
    ----------
    paths : (trials, S+1) or (trials, S+1, 2) array_like
        Scalar or 2-D positions over time, m.
    relative_time : (S+1,) array_like
        Time of each sample as a fraction of the movement.

    Returns
    -------
    deviation : (trials,) array
        ``max_t |path(t) - mean path(t)|``, m.
    time : (trials,) array
        When it occurs, fraction of the movement.
    """
    paths = np.asarray(paths, dtype=float)
    dev = paths - paths.mean(axis=0)
    dist = np.sqrt((dev**2).sum(axis=-1)) if paths.ndim == 3 else np.abs(dev)
    i = np.argmax(dist, axis=1)
    return dist[np.arange(len(i)), i], np.asarray(relative_time, dtype=float)[i]


def bootstrap_peak(
    paths: ArrayLike, relative_time: ArrayLike, draws: int, rng: np.random.Generator
) -> np.ndarray:
    """Bootstrap draws of the peak of the SD over time, and of its time.

    The repetitions are resampled with replacement ``draws`` times; each
    resample's SD curve (:func:`path_sd`) gives one (peak, time) pair. Their
    spread is what the repetitions can resolve: a confidence interval for the
    peak SD and its timing, and, across settings, for their differences.

    Parameters
    ----------
    paths : (trials, S+1) or (trials, S+1, 2) array_like
        Scalar (e.g. aperture, m) or 2-D positions (m) over time.
    relative_time : (S+1,) array_like
        Time of each sample, fraction of the movement.
    draws : int
        Number of resamples (>= 1).
    rng : numpy.random.Generator
        Randomness of the resampling.

    Returns
    -------
    (draws, 2) array
        Peak SD (unit of ``paths``) and its time, per resample.
    """
    x = np.asarray(paths, dtype=float)
    n = x.shape[0]
    flat = x.reshape(n, -1)
    flat = flat - flat.mean(axis=0)  # centred: the sums below lose no precision
    # resampling as multinomial counts: every draw's moments by two matrix products
    counts = rng.multinomial(n, np.full(n, 1.0 / n), size=int(draws)).astype(float)
    mean = counts @ flat / n
    var = (counts @ flat**2 / n - mean**2) * n / (n - 1)
    var = var.reshape((int(draws), *x.shape[1:]))
    sd = np.sqrt(np.maximum(var.sum(axis=-1) if x.ndim == 3 else var, 0.0))
    i = np.argmax(sd, axis=1)
    return np.stack([sd[np.arange(len(i)), i], np.asarray(relative_time, dtype=float)[i]],
                    axis=1)


@dataclass(frozen=True, eq=False)
class GraspMoments:
    """Exact (first-order) means and covariances of a planned grasp's execution.

    Attributes
    ----------
    relative_time : (S+1,) array
        Time as a fraction of the movement.
    wrist_mean, finger_mean, thumb_mean : (S+1, 2) arrays
        Positions of the mean joint angles, world frame, m.
    wrist_cov, finger_cov, thumb_cov : (S+1, 2, 2) arrays
        Position covariances, m^2.
    aperture_mean, aperture_sd : (S+1,) arrays
        Grip aperture and its SD, m (first order; poor where the aperture is
        within a few SDs of zero, e.g. with the digits closed).
    """

    relative_time: np.ndarray = field(repr=False)
    wrist_mean: np.ndarray = field(repr=False)
    finger_mean: np.ndarray = field(repr=False)
    thumb_mean: np.ndarray = field(repr=False)
    wrist_cov: np.ndarray = field(repr=False)
    finger_cov: np.ndarray = field(repr=False)
    thumb_cov: np.ndarray = field(repr=False)
    aperture_mean: np.ndarray = field(repr=False)
    aperture_sd: np.ndarray = field(repr=False)

    @property
    def wrist_sd(self) -> np.ndarray:
        """(S+1,) wrist SD, ``sqrt(var x + var y)``, m."""
        return np.sqrt(np.trace(self.wrist_cov, axis1=1, axis2=2))

    @property
    def finger_end_sd(self) -> np.ndarray:
        """(2,) SD of the final finger-tip position in x and y, m."""
        return np.sqrt(np.diag(self.finger_cov[-1]))

    @property
    def thumb_end_sd(self) -> np.ndarray:
        """(2,) SD of the final thumb-tip position in x and y, m."""
        return np.sqrt(np.diag(self.thumb_cov[-1]))

    def with_transport(self, other: GraspMoments) -> GraspMoments:
        """This grasp's grip carried by ``other``'s transport.

        The chains are independent and the grip is planned in the hand frame,
        so a grasp that differs only in its transport (e.g. its distance) has
        this grasp's hand-frame digit moments and ``other``'s wrist moments:
        the result is exact, without planning the grip again.

        Parameters
        ----------
        other : GraspMoments
            Moments of a grasp with the same number of steps.
        """
        if other.wrist_mean.shape != self.wrist_mean.shape:
            raise ValueError("GraspMoments.with_transport: other: expected the same number "
                             f"of steps, got {len(other.wrist_mean)} vs {len(self.wrist_mean)}")
        dm = other.wrist_mean - self.wrist_mean
        dc = other.wrist_cov - self.wrist_cov
        return GraspMoments(
            relative_time=self.relative_time,
            wrist_mean=other.wrist_mean,
            finger_mean=self.finger_mean + dm,
            thumb_mean=self.thumb_mean + dm,
            wrist_cov=other.wrist_cov,
            finger_cov=self.finger_cov + dc,
            thumb_cov=self.thumb_cov + dc,
            aperture_mean=self.aperture_mean,
            aperture_sd=self.aperture_sd,
        )


def grasp_moments(plan: GraspPlan) -> GraspMoments:
    """Means and covariances of wrist, tips and aperture without sampling error.

    Propagates each chain's exact joint-space moments under its execution
    noise model, then maps them through the forward kinematics to first order
    (the chains are independent; the digit bases move with the wrist).

    Parameters
    ----------
    plan : GraspPlan
        The grasp, from :func:`minvar.grasp.plan_grasp`.

    Returns
    -------
    GraspMoments
    """
    mq, cq = {}, {}
    for name, cp in plan.chains.items():
        mean, cov = state_moments(cp.execution, cp.solution.K, cp.solution.L)
        mq[name], cq[name] = mean[:, POSITION], cov[:, POSITION, POSITION]

    def mapped(cp, name):
        J = cp.chain.jacobian(mq[name])
        return cp.chain.forward(mq[name]), J, J @ cq[name] @ np.swapaxes(J, 1, 2)

    wrist, _, w_cov = mapped(plan.arm, "arm")
    f_pos, _, f_cov = mapped(plan.finger, "finger")
    t_pos, _, t_cov = mapped(plan.thumb, "thumb")
    d = f_pos - t_pos
    a = grip_aperture(f_pos, t_pos)
    # direction of the aperture; undefined with the tips together, where any
    # unit vector gives the (then meaningless) first-order value
    u = np.where(a[:, None] > 1e-12, d / np.maximum(a, 1e-12)[:, None], [1.0, 0.0])
    a_var = np.einsum("ti,tij,tj->t", u, f_cov + t_cov, u)
    return GraspMoments(
        relative_time=plan.time / plan.task.duration,
        wrist_mean=wrist,
        finger_mean=wrist + f_pos,
        thumb_mean=wrist + t_pos,
        wrist_cov=w_cov,
        finger_cov=w_cov + f_cov,
        thumb_cov=w_cov + t_cov,
        aperture_mean=a,
        aperture_sd=np.sqrt(np.maximum(a_var, 0.0)),
    )


@dataclass(frozen=True)
class GraspSummary:
    """The chapter-4 measures of one grasp setting.

    Lengths in m, times as fractions of the movement. ``*_exact`` values come
    from :func:`grasp_moments` (no sampling error); the others from the
    repetitions.

    Attributes
    ----------
    trials : int
        Number of repetitions.
    mga_mean, mga_sd : float
        Maximum grip aperture: mean and SD across repetitions.
    mga_time_mean, mga_time_sd : float
        Relative time of the MGA: mean and SD.
    wrist_sd_peak, wrist_sd_peak_time : float
        Largest wrist-position SD over the movement, and when.
    aperture_sd_peak, aperture_sd_peak_time : float
        Largest aperture SD, and when.
    finger_distance_mean, finger_distance_sd : float
        Distance of the final finger tip from its target: mean and SD.
    finger_sd_x, finger_sd_y : float
        SD of the final finger-tip position in x and y.
    thumb_distance_mean, thumb_distance_sd, thumb_sd_x, thumb_sd_y : float
        The same for the thumb.
    wrist_sd_peak_exact, wrist_sd_peak_time_exact : float
        Peak wrist SD and its time, exact.
    aperture_sd_peak_exact, aperture_sd_peak_time_exact : float
        Peak aperture SD and its time, exact.
    finger_sd_x_exact, finger_sd_y_exact, thumb_sd_x_exact, thumb_sd_y_exact : float
        End-point SDs, exact.
    finger_distance_exact, thumb_distance_exact : float
        Mean end-point distance from the target, exact
        (:func:`minvar.analysis.expected_distance` of the exact moments).
    mga_exact, mga_time_exact : float
        Maximum of the exact mean aperture, and its time.
    """

    trials: int
    mga_mean: float
    mga_sd: float
    mga_time_mean: float
    mga_time_sd: float
    wrist_sd_peak: float
    wrist_sd_peak_time: float
    aperture_sd_peak: float
    aperture_sd_peak_time: float
    finger_distance_mean: float
    finger_distance_sd: float
    finger_sd_x: float
    finger_sd_y: float
    thumb_distance_mean: float
    thumb_distance_sd: float
    thumb_sd_x: float
    thumb_sd_y: float
    wrist_sd_peak_exact: float = float("nan")
    wrist_sd_peak_time_exact: float = float("nan")
    aperture_sd_peak_exact: float = float("nan")
    aperture_sd_peak_time_exact: float = float("nan")
    finger_sd_x_exact: float = float("nan")
    finger_sd_y_exact: float = float("nan")
    thumb_sd_x_exact: float = float("nan")
    thumb_sd_y_exact: float = float("nan")
    finger_distance_exact: float = float("nan")
    thumb_distance_exact: float = float("nan")
    mga_exact: float = float("nan")
    mga_time_exact: float = float("nan")

    @property
    def finger_sd(self) -> float:
        """Total final finger-tip SD, ``sqrt(sd_x^2 + sd_y^2)``, m."""
        return float(np.hypot(self.finger_sd_x, self.finger_sd_y))

    @property
    def thumb_sd(self) -> float:
        """Total final thumb-tip SD, m."""
        return float(np.hypot(self.thumb_sd_x, self.thumb_sd_y))

    def as_dict(self) -> dict[str, float]:
        """All fields as a flat dict (one table row)."""
        from dataclasses import asdict

        return asdict(self)


def end_distance(moments: GraspMoments, digit: str, target: ArrayLike) -> float:
    """Exact mean distance of a digit's final position from its target, m.

    Parameters
    ----------
    moments : GraspMoments
        Exact moments of the grasp.
    digit : {"finger", "thumb"}
        Which tip.
    target : (2,) array_like
        Its target, world frame, m.
    """
    mean, cov = getattr(moments, f"{digit}_mean")[-1], getattr(moments, f"{digit}_cov")[-1]
    return expected_distance(mean - np.asarray(target, dtype=float), cov)


def summarize_grasp(result: GraspResult, moments: GraspMoments | None = None) -> GraspSummary:
    """The chapter-4 measures of a simulated grasp.

    Parameters
    ----------
    result : GraspResult
        Repetitions of one grasp (at least 2).
    moments : GraspMoments, optional
        Exact moments of the same plan, for the ``*_exact`` fields (left NaN
        without them).

    Returns
    -------
    GraspSummary
    """
    if result.trials < 2:
        raise ValueError(f"summarize_grasp: result: need >= 2 repetitions, got {result.trials}")
    rt = result.relative_time
    mga, mga_t = max_grip_aperture(result.aperture, rt)
    w_peak = peak(path_sd(result.wrist), rt)
    a_peak = peak(path_sd(result.aperture), rt)
    fs = endpoint_stats(result.finger_end, result.task.finger_target)
    ts = endpoint_stats(result.thumb_end, result.task.thumb_target)
    exact = {}
    if moments is not None:
        mw = peak(moments.wrist_sd, moments.relative_time)
        ma = peak(moments.aperture_sd, moments.relative_time)
        mg = peak(moments.aperture_mean, moments.relative_time)
        exact = dict(
            wrist_sd_peak_exact=mw[0],
            wrist_sd_peak_time_exact=mw[1],
            aperture_sd_peak_exact=ma[0],
            aperture_sd_peak_time_exact=ma[1],
            finger_sd_x_exact=float(moments.finger_end_sd[0]),
            finger_sd_y_exact=float(moments.finger_end_sd[1]),
            thumb_sd_x_exact=float(moments.thumb_end_sd[0]),
            thumb_sd_y_exact=float(moments.thumb_end_sd[1]),
            finger_distance_exact=end_distance(moments, "finger", result.task.finger_target),
            thumb_distance_exact=end_distance(moments, "thumb", result.task.thumb_target),
            mga_exact=mg[0],
            mga_time_exact=mg[1],
        )
    return GraspSummary(
        trials=result.trials,
        mga_mean=float(mga.mean()),
        mga_sd=float(mga.std(ddof=1)),
        mga_time_mean=float(mga_t.mean()),
        mga_time_sd=float(mga_t.std(ddof=1)),
        wrist_sd_peak=w_peak[0],
        wrist_sd_peak_time=w_peak[1],
        aperture_sd_peak=a_peak[0],
        aperture_sd_peak_time=a_peak[1],
        finger_distance_mean=fs.distance_mean,
        finger_distance_sd=fs.distance_sd,
        finger_sd_x=float(fs.sd[0]),
        finger_sd_y=float(fs.sd[1]),
        thumb_distance_mean=ts.distance_mean,
        thumb_distance_sd=ts.distance_sd,
        thumb_sd_x=float(ts.sd[0]),
        thumb_sd_y=float(ts.sd[1]),
        **exact,
    )

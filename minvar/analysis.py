"""Measures of reaching movements and the speed-accuracy sweep (thesis 3.3).

Functions take arrays (paths, speed profiles, end-points) and return numbers
or small tables, so they serve simulated and observed movements alike.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from .lqg import solve
from .plant import PointMassPlant
from .reach import simulate_reach
from .task import ReachTask, reach_problem

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

# pandas is imported when a table is asked for: `import minvar` stays light
# (pandas takes about half a second to import).

__all__ = [
    "EndpointStats",
    "SpeedAccuracy",
    "closest_approach",
    "count_speed_peaks",
    "endpoint_stats",
    "expected_distance",
    "path_deviation",
    "peak_to_mean_speed",
    "speed_accuracy",
    "THESIS_DURATIONS",
]

#: Movement times of the thesis's speed-accuracy figures (3.5, 3.7), s.
THESIS_DURATIONS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2)


def peak_to_mean_speed(speed: np.ndarray, time: np.ndarray) -> float:
    """Ratio of peak to time-averaged speed of one profile (humans: about 1.875).

    Parameters
    ----------
    speed : (S,) array
        Speed profile, m/s.
    time : (S,) array
        Sample times, s.
    """
    speed = np.asarray(speed, dtype=float)
    time = np.asarray(time, dtype=float)
    mean = np.trapezoid(speed, time) / (time[-1] - time[0])
    return float(speed.max() / mean)


def count_speed_peaks(speed: np.ndarray, prominence: float = 0.05) -> int:
    """Number of peaks in a speed profile.

    Parameters
    ----------
    speed : (S,) array
        Speed profile, m/s.
    prominence : float
        Minimum peak prominence as a fraction of the profile's maximum; smaller
        ripples are not counted.
    """
    # imported here: scipy.signal takes half a second to import, and every
    # command and batch worker imports this module
    from scipy.signal import find_peaks

    speed = np.asarray(speed, dtype=float)
    padded = np.concatenate([[0.0], speed, [0.0]])  # a peak at either end still counts
    peaks, _ = find_peaks(padded, prominence=prominence * speed.max())
    return int(len(peaks))


def path_deviation(path: np.ndarray, start, goal) -> np.ndarray:
    """Signed perpendicular distance of each point from the start-goal line.

    Parameters
    ----------
    path : (..., S, 2) array
        Positions, m.
    start, goal : (2,) array_like
        Ends of the straight line, m.

    Returns
    -------
    (..., S) array
        Distance, m; positive to the left of the start-to-goal direction.
    """
    start = np.asarray(start, dtype=float)
    d = np.asarray(goal, dtype=float) - start
    d = d / np.linalg.norm(d)
    rel = np.asarray(path, dtype=float) - start
    return rel[..., 1] * d[0] - rel[..., 0] * d[1]


def closest_approach(path: np.ndarray, point) -> float:
    """Smallest distance (m) from a path ``(S, 2)`` to ``point``."""
    return float(np.min(np.linalg.norm(np.asarray(path) - np.asarray(point), axis=-1)))


@dataclass(frozen=True)
class EndpointStats:
    """Spread of movement end-points about a target.

    Attributes
    ----------
    mean : (2,) array
        Mean end-point, m.
    sd : (2,) array
        Standard deviation in x and y, m.
    sd_total : float
        sqrt(sd_x^2 + sd_y^2), m.
    distance_mean, distance_sd : float
        Mean and SD of the distance of each end-point to the target, m.
    """

    mean: np.ndarray
    sd: np.ndarray
    sd_total: float
    distance_mean: float
    distance_sd: float


def endpoint_stats(endpoints: np.ndarray, target) -> EndpointStats:
    """End-point statistics of repetitions about a target.

    Parameters
    ----------
    endpoints : (trials, 2) array
        Final positions, m.
    target : (2,) array_like
        Target position, m.
    """
    endpoints = np.asarray(endpoints, dtype=float)
    sd = endpoints.std(axis=0, ddof=1)
    dist = np.linalg.norm(endpoints - np.asarray(target, dtype=float), axis=1)
    return EndpointStats(
        mean=endpoints.mean(axis=0),
        sd=sd,
        sd_total=float(np.hypot(*sd)),
        distance_mean=float(dist.mean()),
        distance_sd=float(dist.std(ddof=1)),
    )


#: Gauss-Hermite nodes and weights (probabilists') for :func:`expected_distance`.
_GH_NODES, _GH_WEIGHTS = np.polynomial.hermite_e.hermegauss(48)
_GH_WEIGHTS = _GH_WEIGHTS / _GH_WEIGHTS.sum()
_GH_NODES.setflags(write=False)  # constants: no module-level mutable state
_GH_WEIGHTS.setflags(write=False)


def expected_distance(offset, cov) -> float:
    """Mean distance from a target of normally distributed end-points, without sampling.

    The exact counterpart of :attr:`EndpointStats.distance_mean` for end-points
    ``N(target + offset, cov)`` (e.g. from :func:`minvar.moments.state_moments`),
    by Gauss-Hermite quadrature along the principal axes (48 nodes each). The
    error is below 0.3 % even with the mean on the target, where ``|x|`` has a
    kink, and far smaller once the systematic error is a few SDs: well under
    the 2-3 % sampling error of a mean over 500 repetitions.

    Parameters
    ----------
    offset : (2,) array_like
        Mean end-point minus the target (the systematic error), m.
    cov : (2, 2) array_like
        End-point covariance, m^2.

    Returns
    -------
    float
        ``E |offset + e|``, ``e ~ N(0, cov)``, m.
    """
    offset = np.asarray(offset, dtype=float)
    w, v = np.linalg.eigh(np.asarray(cov, dtype=float))
    sd = np.sqrt(np.maximum(w, 0.0))
    z = (_GH_NODES[:, None, None] * sd[0] * v[:, 0]
         + _GH_NODES[None, :, None] * sd[1] * v[:, 1])
    dist = np.linalg.norm(offset + z, axis=-1)
    return float(np.einsum("i,j,ij->", _GH_WEIGHTS, _GH_WEIGHTS, dist))


@dataclass(frozen=True, eq=False)
class SpeedAccuracy:
    """A speed-accuracy sweep (thesis Figs. 3.5, 3.7).

    Attributes
    ----------
    trials : pandas.DataFrame
        One row per repetition: duration (s), trial, end_x, end_y, distance (m).
    summary : pandas.DataFrame
        One row per duration: duration, sd_x, sd_y, sd_total, distance_mean,
        distance_sd (m), peak_to_mean (of the mean speed profile).
    """

    trials: pd.DataFrame
    summary: pd.DataFrame

    def to_pandas(self) -> pd.DataFrame:
        """The per-duration summary."""
        return self.summary


def speed_accuracy(
    task: ReachTask,
    durations=THESIS_DURATIONS,
    trials: int = 200,
    *,
    seed: int = 0,
    plant: PointMassPlant | None = None,
) -> SpeedAccuracy:
    """Repeat ``task`` at several movement times and measure end-point spread.

    Parameters
    ----------
    task : ReachTask
        The movement; its ``duration`` is replaced by each of ``durations``.
    durations : sequence of float
        Movement times, s (thesis: 0.5 to 1.2 s).
    trials : int
        Repetitions per duration (thesis: 200): an integer >= 2, an SD needs two.
    seed : int
        Each duration draws from its own child of this seed, so adding a
        duration does not change the others.
    plant : PointMassPlant, optional
        Plant and noise parameters.

    Returns
    -------
    SpeedAccuracy
    """
    import pandas as pd

    durations = [float(d) for d in durations]
    if not durations:
        raise ValueError("speed_accuracy: durations must not be empty")
    if isinstance(trials, bool) or not isinstance(trials, int | np.integer) or trials < 2:
        raise ValueError(f"speed_accuracy: trials: expected an integer >= 2 (an SD needs two "
                         f"repetitions), got {trials!r}")
    plant = PointMassPlant() if plant is None else plant
    seeds = np.random.SeedSequence(seed).spawn(len(durations))
    rows, summary = [], []
    for duration, child in zip(durations, seeds):
        t = replace(task, duration=duration)
        sol = solve(reach_problem(t, plant))
        rng = np.random.default_rng(child)
        res = simulate_reach(t, trials, seed=rng, plant=plant, solution=sol)
        end = res.endpoint
        stats = endpoint_stats(end, t.goal)
        dist = np.linalg.norm(end - np.asarray(t.goal), axis=1)
        rows.append(
            pd.DataFrame(
                {
                    "duration": duration,
                    "trial": np.arange(trials),
                    "end_x": end[:, 0],
                    "end_y": end[:, 1],
                    "distance": dist,
                }
            )
        )
        summary.append(
            {
                "duration": duration,
                "sd_x": stats.sd[0],
                "sd_y": stats.sd[1],
                "sd_total": stats.sd_total,
                "distance_mean": stats.distance_mean,
                "distance_sd": stats.distance_sd,
                "peak_to_mean": peak_to_mean_speed(res.mean_speed, res.time),
            }
        )
    return SpeedAccuracy(trials=pd.concat(rows, ignore_index=True), summary=pd.DataFrame(summary))

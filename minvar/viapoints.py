"""Via-point representation of movements (thesis appendix A, section 3.2).

A movement is stored as its start, goal, duration and via-points (position and
normalised time); the minimum variance model replays it (:func:`replay`).
Appendix A asks where to put the via-points of an observed movement: at the
maxima and minima of its speed, of its acceleration, or of its
spatio-temporal curvature (eq. A.1, after Rao et al.), judged by how well the
replay matches the original (mean-square difference in joint space, eq. A.2)
for how few points (:func:`compare_criteria`, Figs. A.1-A.2). The same
representation generalises a movement in time (eq. A.3, :meth:`ViaPointMovement.retime`)
and space (eqs. A.4-A.5, :meth:`ViaPointMovement.transform`); the letter 'a'
of Figs. 3.8, 3.9 and A.3 is one such movement (:func:`letter_a`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Annotated

import numpy as np
import pandas as pd
from scipy.signal import find_peaks

from .errors import ParameterError
from .kinematics import TwoLinkChain
from .lqg import solve
from .plant import POSITION, PointMassPlant
from .similarity import joint_msd, path_distance
from .task import ReachTask, ViaPoint, reach_problem
from .validation import Point, Positive, Tuple, checked, declared

__all__ = [
    "CRITERIA",
    "CriteriaComparison",
    "ViaPointMovement",
    "compare_criteria",
    "criterion_signal",
    "expected_path",
    "extract_via_points",
    "letter_a",
    "local_extrema",
    "replay",
    "spatiotemporal_curvature",
    "viapoint_timing",
]

#: Via-point selection criteria of appendix A: extrema of these signals.
CRITERIA = ("speed", "acceleration", "curvature")


def _trajectory(owner: str, position, time) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(position, dtype=float)
    t = np.asarray(time, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3:
        raise ValueError(f"{owner}: position must be (S, 2) with S >= 3, got shape {p.shape}")
    if t.shape != (len(p),):
        raise ValueError(f"{owner}: time must be ({len(p)},) to match position, got {t.shape}")
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(t))):
        raise ValueError(f"{owner}: position and time must be finite")
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{owner}: time must increase strictly")
    return p, t


def _derivatives(p: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.gradient(p, t, axis=0, edge_order=2)
    return v, np.gradient(v, t, axis=0, edge_order=2)


def spatiotemporal_curvature(position, time, *, unit: float = 1.0) -> np.ndarray:
    """Curvature of the spatio-temporal trajectory ``(x(t), y(t), t)`` (thesis eq. A.1).

    ``kappa = sqrt(x''^2 + y''^2 + (x' y'' - x'' y')^2) / (x'^2 + y'^2 + 1)^(3/2)``,
    derivatives by second-order finite differences. The time axis (s) sits
    beside positions measured in ``unit``, so kappa depends on that unit (the
    thesis does not give it): a straight line at constant speed has kappa = 0;
    a circle of radius R at angular speed w has ``kappa = R w^2 / (1 + R^2 w^2)``.
    In metres, hand speeds are well under 1, the ``+ 1`` dominates the
    denominator and ``|a|^2`` the numerator, so kappa is close to the
    acceleration's magnitude; in centimetres or millimetres it is closer to
    the path's ordinary curvature wherever the hand moves.

    Parameters
    ----------
    position : (S, 2) array_like
        Sampled path, m.
    time : (S,) array_like
        Sample times, s, strictly increasing.
    unit : float
        Length unit of eq. A.1, m (1: metres, 0.01: centimetres, 0.001: mm).

    Returns
    -------
    (S,) array
        kappa at each sample (units of the thesis's mixed expression).
    """
    p, t = _trajectory("spatiotemporal_curvature", position, time)
    if not (np.isfinite(unit) and unit > 0):
        raise ValueError(f"spatiotemporal_curvature: unit must be a length > 0 in m, got {unit}")
    v, a = _derivatives(p / unit, t)
    cross = v[:, 0] * a[:, 1] - a[:, 0] * v[:, 1]
    num = np.sqrt(a[:, 0] ** 2 + a[:, 1] ** 2 + cross**2)
    return num / (v[:, 0] ** 2 + v[:, 1] ** 2 + 1.0) ** 1.5


def criterion_signal(position, time, criterion: str, *, unit: float = 1.0) -> np.ndarray:
    """The signal whose extrema give via-points under one appendix A criterion.

    Parameters
    ----------
    position : (S, 2) array_like
        Sampled path, m.
    time : (S,) array_like
        Sample times, s.
    criterion : {"speed", "acceleration", "curvature"}
        Speed (m/s), acceleration magnitude (m/s^2) or spatio-temporal
        curvature (eq. A.1).
    unit : float
        Length unit of eq. A.1, m (curvature only: the extrema of speed and
        acceleration do not depend on units).

    Returns
    -------
    (S,) array
    """
    p, t = _trajectory("criterion_signal", position, time)
    if criterion not in CRITERIA:
        raise ValueError(f"criterion: expected one of {CRITERIA}, got {criterion!r}")
    if criterion == "curvature":
        return spatiotemporal_curvature(p, t, unit=unit)
    v, a = _derivatives(p, t)
    x = v if criterion == "speed" else a
    return np.hypot(x[:, 0], x[:, 1])


def local_extrema(signal, *, prominence: float = 0.05) -> np.ndarray:
    """Indices of the interior maxima and minima of a sampled signal.

    Parameters
    ----------
    signal : (S,) array_like
        Samples.
    prominence : float
        Minimum prominence of an extremum as a fraction of the signal's range
        (max - min); smaller ripples (noise) are ignored. 0 keeps every one.

    Returns
    -------
    (E,) int array
        Sorted indices, never the first or last sample.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or not np.all(np.isfinite(x)):
        raise ValueError(f"signal: expected a finite 1-D array, got shape {x.shape}")
    if not (np.isfinite(prominence) and prominence >= 0):
        raise ValueError(f"prominence: expected a fraction >= 0, got {prominence}")
    span = float(np.ptp(x)) if x.size else 0.0
    if span == 0.0:
        return np.zeros(0, dtype=int)
    level = prominence * span
    maxima, _ = find_peaks(x, prominence=level)
    minima, _ = find_peaks(-x, prominence=level)
    return np.union1d(maxima, minima).astype(int)


def extract_via_points(
    position, time, criterion: str = "curvature", *, prominence: float = 0.05,
    unit: float = 1.0,
) -> np.ndarray:
    """Sample indices of candidate via-points: the extrema of ``criterion``.

    Parameters
    ----------
    position : (S, 2) array_like
        Observed path, m.
    time : (S,) array_like
        Sample times, s.
    criterion : {"speed", "acceleration", "curvature"}
        Which signal's maxima and minima to take (appendix A.1).
    prominence : float
        Ripples smaller than this fraction of the signal's range are ignored.
    unit : float
        Length unit of eq. A.1, m (:func:`spatiotemporal_curvature`).

    Returns
    -------
    (E,) int array
        Sorted interior indices (start and goal are part of every
        representation already).
    """
    return local_extrema(criterion_signal(position, time, criterion, unit=unit),
                         prominence=prominence)


@declared
class ViaPointMovement:
    """A movement as start, goal, duration and via-points at normalised times (appendix A.2).

    Parameters
    ----------
    start, goal : (2,) array_like
        Start and goal positions, m.
    duration : float
        Movement time, s.
    via_positions : sequence of (2,) array_like
        Via-point positions, m, in the order they are passed.
    via_fractions : sequence of float
        Their times as fractions of the duration, strictly increasing in (0, 1).
    """

    start: Point
    goal: Point
    duration: Positive
    via_positions: Annotated[tuple[Point, ...], Tuple] = ()
    via_fractions: Annotated[tuple[float, ...], Tuple] = ()

    def __post_init__(self):
        if len(self.via_positions) != len(self.via_fractions):
            raise ParameterError(f"{len(self.via_positions)} via_positions but "
                                 f"{len(self.via_fractions)} via_fractions",
                                 location=("ViaPointMovement", "via_fractions"))
        if not np.all(np.diff(np.r_[0.0, self.via_fractions, 1.0]) > 0):
            raise ParameterError(f"expected strictly increasing fractions in (0, 1), got "
                                 f"{list(self.via_fractions)}",
                                 location=("ViaPointMovement", "via_fractions"))

    @classmethod
    def from_task(cls, task: ReachTask) -> ViaPointMovement:
        """The representation of a :class:`~minvar.task.ReachTask` (via-points in its order).

        Parameters
        ----------
        task : ReachTask
            Its via-points may be given in seconds or as fractions.
        """
        return cls(
            start=task.start,
            goal=task.goal,
            duration=task.duration,
            via_positions=tuple(v.position for v in task.via_points),
            via_fractions=tuple(v.time_s(task.duration) / task.duration for v in task.via_points),
        )

    @classmethod
    def from_samples(cls, position, time, indices=()) -> ViaPointMovement:
        """Represent an observed movement by its ends and the samples at ``indices``.

        Parameters
        ----------
        position : (S, 2) array_like
            Observed path, m.
        time : (S,) array_like
            Sample times, s; the movement spans ``time[0]`` to ``time[-1]``.
        indices : sequence of int
            Interior samples to keep as via-points (e.g. from
            :func:`extract_via_points`).
        """
        p, t = _trajectory("ViaPointMovement.from_samples", position, time)
        idx = np.asarray(indices, dtype=int).ravel()
        if idx.size and (idx.min() <= 0 or idx.max() >= len(p) - 1 or np.any(np.diff(idx) <= 0)):
            raise ValueError(
                f"ViaPointMovement.from_samples: indices must increase strictly inside "
                f"1..{len(p) - 2}, got {idx.tolist()}"
            )
        duration = t[-1] - t[0]
        return cls(
            start=p[0],
            goal=p[-1],
            duration=duration,
            via_positions=tuple(map(tuple, p[idx])),
            via_fractions=tuple((t[idx] - t[0]) / duration),
        )

    @property
    def n_points(self) -> int:
        """Points stored: start, goal and the via-points."""
        return len(self.via_positions) + 2

    @property
    def via_times(self) -> np.ndarray:
        """(k,) via-point times, s."""
        return np.asarray(self.via_fractions) * self.duration

    def points(self) -> np.ndarray:
        """(k+2, 2) start, via-points and goal, m, in the order they are passed."""
        return np.array([self.start, *self.via_positions, self.goal], dtype=float)

    def retime(self, duration: float) -> ViaPointMovement:
        """Temporal generalisation (eq. A.3): the same via-points at the same fractions of
        a new movement time.

        Parameters
        ----------
        duration : float
            New movement time T_new, s; via-point times become
            ``(V_old / T_old) T_new``.
        """
        return replace(self, duration=duration)

    def transform(self, *, start=None, scale: float = 1.0) -> ViaPointMovement:
        """Spatial generalisation (eqs. A.4-A.5): scale about the start, then move the start.

        ``G_new = scale (G_old - S_old) + S_new`` and likewise every via-point.

        Parameters
        ----------
        start : (2,) array_like, optional
            New start S_new, m (default: the old start).
        scale : float
            Scaling factor alpha (> 0).
        """
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"ViaPointMovement.transform: scale must be > 0, got {scale}")
        s_old = np.asarray(self.start)
        s_new = s_old if start is None else \
            np.asarray(checked(start, Point, ("transform", "start")))

        def move(p):
            return tuple(scale * (np.asarray(p) - s_old) + s_new)

        return replace(
            self,
            start=tuple(s_new),
            goal=move(self.goal),
            via_positions=tuple(move(v) for v in self.via_positions),
        )

    def to_task(self, **weights) -> ReachTask:
        """The :class:`~minvar.task.ReachTask` that replays this movement.

        Parameters
        ----------
        **weights
            ``r``, ``w_v``, ``w_f``, ``form`` passed to :class:`~minvar.task.ReachTask`
            (default: its defaults).
        """
        vias = tuple(
            ViaPoint(p, fraction=f) for p, f in zip(self.via_positions, self.via_fractions)
        )
        return ReachTask(self.start, self.goal, self.duration, vias, **weights)

    def to_pandas(self) -> pd.DataFrame:
        """One row per stored point: kind (start/via/goal), x, y (m), fraction, time (s)."""
        k = len(self.via_positions)
        fractions = np.r_[0.0, self.via_fractions, 1.0]
        pts = self.points()
        return pd.DataFrame(
            {
                "kind": ["start"] + ["via"] * k + ["goal"],
                "x": pts[:, 0],
                "y": pts[:, 1],
                "fraction": fractions,
                "time": fractions * self.duration,
            }
        )


def expected_path(task: ReachTask, plant: PointMassPlant | None = None):
    """Plan ``task`` and return its expected (noise-averaged) hand path.

    With zero-mean signal-dependent noise the mean of many repetitions follows
    the noiseless closed loop exactly, so no Monte Carlo is needed.

    Parameters
    ----------
    task : ReachTask
        The movement.
    plant : PointMassPlant, optional
        Plant and noise parameters (default: :class:`~minvar.plant.PointMassPlant`'s,
        docs/model.md).

    Returns
    -------
    time : (T+1,) array
        s.
    position : (T+1, 2) array
        m.
    """
    plant = PointMassPlant() if plant is None else plant
    solution = solve(reach_problem(task, plant))
    time = np.arange(solution.mean_states.shape[0]) * plant.dt
    return time, solution.mean_states[:, POSITION].copy()


def replay(movement: ViaPointMovement, *, plant: PointMassPlant | None = None, **weights):
    """Replay a via-point movement with the minimum variance model (expected path).

    Parameters
    ----------
    movement : ViaPointMovement
        Start, goal, duration and via-points.
    plant : PointMassPlant, optional
        Plant and noise parameters.
    **weights
        Cost weights ``r``, ``w_v``, ``w_f`` and ``form`` for
        :class:`~minvar.task.ReachTask`.

    Returns
    -------
    time : (T+1,) array
        s.
    position : (T+1, 2) array
        m.
    """
    return expected_path(movement.to_task(**weights), plant)


@dataclass(frozen=True, eq=False)
class CriteriaComparison:
    """Via-point criteria compared on observed movements (thesis Fig. A.1).

    Attributes
    ----------
    table : pandas.DataFrame
        One row per trajectory and criterion: trajectory, criterion, n_via,
        n_points (via-points + start + goal), indices (tuple of sample
        indices), msd (eq. A.2, rad^2, summed over samples), msd_per_sample
        (rad^2), score (msd_per_sample x n_points; lower is better).
    summary : pandas.DataFrame
        One row per criterion: mean n_points, msd_per_sample and score over the
        trajectories, and ``wins``: on how many trajectories it had the lowest score.
    """

    table: pd.DataFrame
    summary: pd.DataFrame

    @property
    def best(self) -> str:
        """The criterion with the lowest mean score."""
        return str(self.summary.sort_values("score").iloc[0]["criterion"])

    def to_pandas(self) -> pd.DataFrame:
        """The per-trajectory table."""
        return self.table


def compare_criteria(
    trajectories: Sequence[tuple[np.ndarray, np.ndarray]],
    *,
    criteria: Sequence[str] = CRITERIA,
    prominence: float = 0.05,
    chain: TwoLinkChain | None = None,
    plant: PointMassPlant | None = None,
    unit: float = 1.0,
    weights: Mapping[str, object] | None = None,
) -> CriteriaComparison:
    """Extract via-points by each criterion, replay, and score the replays (Fig. A.1).

    For each observed trajectory and criterion: via-points at the criterion's
    extrema (:func:`extract_via_points`), the movement replayed from its start,
    goal and those via-points by the minimum variance model (expected path,
    :func:`replay`), and the replay compared with the original by eq. A.2 in
    the joint space of ``chain``. The score balances fidelity against size:
    mean-square difference per sample times the number of points stored
    (Fig. A.1(b); per sample so that long trajectories do not dominate the
    average over trajectories).

    Parameters
    ----------
    trajectories : sequence of (time, position)
        Observed movements: time (S,) s from 0 in steps of the plant's dt,
        position (S, 2) m within the arm's reach.
    criteria : sequence of str
        Subset of :data:`CRITERIA`.
    prominence : float
        Extrema smaller than this fraction of the signal's range are ignored.
    chain : TwoLinkChain, optional
        Arm for the joint-space comparison (default: two 0.30 m links).
    plant : PointMassPlant, optional
        Plant of the replay; its ``dt`` must match the trajectories' sampling.
    unit : float
        Length unit of eq. A.1, m (curvature only; see
        :func:`spatiotemporal_curvature`).
    weights : mapping, optional
        Cost weights and form of the replays' :class:`~minvar.task.ReachTask`
        (``r``, ``w_v``, ``w_f``, ``form``; default: its defaults).

    Returns
    -------
    CriteriaComparison
    """
    plant = PointMassPlant() if plant is None else plant
    criteria = tuple(criteria)
    for c in criteria:
        if c not in CRITERIA:
            raise ValueError(f"compare_criteria: criterion must be one of {CRITERIA}, got {c!r}")
    if not len(trajectories):
        raise ValueError("compare_criteria: trajectories must not be empty")
    rows = []
    for k, (time, position) in enumerate(trajectories):
        p, t = _trajectory(f"compare_criteria: trajectories[{k}]", position, time)
        if not np.allclose(np.diff(t), plant.dt, rtol=1e-6, atol=1e-9):
            raise ValueError(
                f"compare_criteria: trajectories[{k}] must be sampled every plant.dt = {plant.dt} s"
            )
        for c in criteria:
            idx = extract_via_points(p, t, c, prominence=prominence, unit=unit)
            movement = ViaPointMovement.from_samples(p, t, idx)
            _, copy = replay(movement, plant=plant, **dict(weights or {}))
            d = joint_msd(p, copy, chain=chain)
            n = min(len(p), len(copy))
            rows.append(
                {
                    "trajectory": k,
                    "criterion": c,
                    "n_via": len(idx),
                    "n_points": movement.n_points,
                    "indices": tuple(int(i) for i in idx),
                    "msd": d,
                    "msd_per_sample": d / n,
                    "score": d / n * movement.n_points,
                }
            )
    table = pd.DataFrame(rows)
    winners = table.loc[table.groupby("trajectory")["score"].idxmin(), "criterion"]
    summary = (
        table.groupby("criterion", sort=False)[["n_points", "msd_per_sample", "score"]]
        .mean()
        .reset_index()
    )
    summary["wins"] = summary["criterion"].map(winners.value_counts()).fillna(0).astype(int)
    return CriteriaComparison(table=table, summary=summary)


def viapoint_timing(
    task: ReachTask,
    shifts,
    *,
    via_index: int = 0,
    chain: TwoLinkChain | None = None,
    plant: PointMassPlant | None = None,
) -> pd.DataFrame:
    """How much moving a via-point in time changes the movement (thesis Fig. 3.2(b)).

    Parameters
    ----------
    task : ReachTask
        Reference movement with at least one via-point.
    shifts : sequence of float
        Time offsets applied to the via-point, s (negative = earlier).
    via_index : int
        Which via-point to move.
    chain : TwoLinkChain, optional
        Arm for the joint-space MSD (default: two 0.30 m links).
    plant : PointMassPlant, optional
        Plant and noise parameters.

    Returns
    -------
    pandas.DataFrame
        One row per shift: shift (s), via_time (s), msd (eq. A.2 against the
        reference, rad^2), path_distance (Hausdorff distance between the
        expected paths, m), max_distance (largest distance between the hands
        at the same instant, m).
    """
    if not task.via_points:
        raise ValueError("viapoint_timing: task must have at least one via-point")
    if not -len(task.via_points) <= via_index < len(task.via_points):
        raise ValueError(
            f"viapoint_timing: via_index {via_index} out of range for "
            f"{len(task.via_points)} via-points"
        )
    _, ref = expected_path(task, plant)
    base = task.via_points[via_index]
    t0 = base.time_s(task.duration)
    rows = []
    for s in np.asarray(shifts, dtype=float).ravel():
        vias = list(task.via_points)
        vias[via_index] = ViaPoint(base.position, seconds=t0 + s)
        _, path = expected_path(replace(task, via_points=tuple(vias)), plant)
        rows.append(
            {
                "shift": s,
                "via_time": t0 + s,
                "msd": joint_msd(ref, path, chain=chain),
                "path_distance": path_distance(ref, path),
                "max_distance": float(np.linalg.norm(ref - path, axis=1).max()),
            }
        )
    return pd.DataFrame(rows)


def letter_a(
    start=(0.05, 0.40), *, height: float = 0.10, duration: float = 1.5
) -> ViaPointMovement:
    """Via-points that draw a handwritten letter 'a' (thesis Figs. 3.8, 3.9, A.3).

    The pen starts at the upper right of the bowl, goes anticlockwise round
    the bowl and back up to its top right, then reverses down the stem to a
    small tail. The turn at the top of the stem, placed at 70 % of the
    movement (where the thesis's Fig. 3.8 shows the velocity dropping to
    zero), is a direction reversal: the speed must fall to about zero there.
    The thesis does not give its via-points; these are ours.

    Parameters
    ----------
    start : (2,) array_like
        Where the pen starts (upper right of the bowl), m.
    height : float
        Height of the letter, m.
    duration : float
        Movement time, s.
    """
    if not (np.isfinite(height) and height > 0):
        raise ValueError(f"letter_a: height must be > 0 m, got {height}")
    # The letter in units of its height, origin at the pen's start.
    vias = [
        ((-0.30, 0.12), 0.10),   # top of the bowl
        ((-0.60, -0.25), 0.24),  # left side
        ((-0.35, -0.70), 0.38),  # bottom
        ((0.02, -0.50), 0.50),   # lower right, turning up
        ((0.07, -0.15), 0.60),   # up the right side, closing the bowl
        ((0.08, 0.18), 0.70),    # top of the stem: the reversal
        ((0.08, -0.50), 0.84),   # down the stem
    ]
    goal = (0.18, -0.80)  # the tail
    s = np.asarray(checked(start, Point, ("letter_a", "start")))
    return ViaPointMovement(
        start=tuple(s),
        goal=tuple(s + height * np.asarray(goal)),
        duration=duration,
        via_positions=tuple(tuple(s + height * np.asarray(p)) for p, _ in vias),
        via_fractions=tuple(f for _, f in vias),
    )


"""Reach-to-grasp with the minimum variance model (thesis chapter 4): planning and execution.

The task — the arm and gripper geometry, targets and via-points — is
:class:`~minvar.grasp_task.GraspTask` (:mod:`minvar.grasp_task`).

Planning: transport and grip are planned separately, one joint-space LQG per
2-joint chain (a :class:`~minvar.plant.PointMassPlant` in joint coordinates:
rad, unit inertia), targets from inverse kinematics of the Cartesian targets
(the digits' in the hand frame at the wrist target). Execution: the three
plans run together; each joint's command gets signal-dependent noise with
``execution_cv`` (1 %) coefficient of variation, independently per joint
(``C = cv diag(1, 0), cv diag(0, 1)``), instead of the planning noise
(``sigma_u = 0.4``). The thesis says nothing of sensory noise at execution:
by default there is none (``execution_sigma_s = 0``; the Kalman filter then
sees the exact joint positions, velocities and torques), so the variability
is the signal-dependent noise alone. Wrist and tip paths follow by forward
kinematics, the digit bases moving with the simulated wrist.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .execution import simulate
from .grasp_stats import grip_aperture, max_grip_aperture, path_sd
from .grasp_task import CHAINS, GraspTask, GripVia
from .kinematics import TwoLinkChain
from .limits import (
    check_memory,
    simulation_bytes,
)
from .lqg import LQGSolution, kernel_engine, solve
from .plant import POSITION, VELOCITY
from .problem import LQGProblem
from .task import ReachTask, ViaPoint, reach_problem

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

# pandas is imported when a table is asked for: `import minvar` stays light
# (pandas takes about half a second to import).

__all__ = [
    "GripVia",
    "GraspTask",
    "ChainPlan",
    "GraspPlan",
    "GraspResult",
    "plan_grasp",
    "simulate_grasp",
    "check_grasp_simulation",
    "CHAINS",
]

@dataclass(frozen=True, eq=False)
class ChainPlan:
    """The movement plan of one 2-joint chain: a joint-space LQG and its gains.

    This is a HAMMER inverse model (``solution.L``, ``solution.K``) with its
    forward model (``problem.A``, ``problem.B``).

    Attributes
    ----------
    name : str
        ``"arm"``, ``"finger"`` or ``"thumb"``.
    chain : TwoLinkChain
        Kinematics (arm: world frame; digits: hand frame, base at the wrist).
    elbow : int
        The inverse-kinematics branch used (sign of the second joint angle).
    task : ReachTask
        The joint-space task (start, goal, via-points in rad).
    problem : LQGProblem
        Planning problem (plant noise model).
    execution : LQGProblem
        The same problem with the execution noise model.
    solution : LQGSolution
        Filter and control gains.
    q_start, q_goal : (2,) arrays
        Joint angles at the start and the goal, rad.
    q_via : (V, 2) array
        Joint angles of the via-points, rad.
    via_fractions : (V,) array
        Their times as fractions of the movement.
    """

    name: str
    chain: TwoLinkChain
    elbow: int
    task: ReachTask
    problem: LQGProblem = field(repr=False)
    execution: LQGProblem = field(repr=False)
    solution: LQGSolution = field(repr=False)
    q_start: np.ndarray = field(repr=False)
    q_goal: np.ndarray = field(repr=False)
    q_via: np.ndarray = field(repr=False)
    via_fractions: np.ndarray = field(repr=False)

    @property
    def nominal_q(self) -> np.ndarray:
        """(T+1, 2) noise-free joint angles of the plan, rad."""
        return self.solution.mean_states[:, POSITION]

    @property
    def nominal_qd(self) -> np.ndarray:
        """(T+1, 2) noise-free joint velocities of the plan, rad/s."""
        return self.solution.mean_states[:, VELOCITY]


@dataclass(frozen=True, eq=False)
class GraspPlan:
    """The three chain plans of a grasp and its Cartesian targets.

    Attributes
    ----------
    task : GraspTask
        The planned task.
    arm, finger, thumb : ChainPlan
        Transport and grip plans.
    wrist_start, wrist_target : (2,) arrays
        World frame, m.
    finger_target, thumb_target : (2,) arrays
        Digit targets on the object surface, world frame, m.
    finger_via, thumb_via : (V, 2) arrays
        Digit via-points in the hand frame (relative to the wrist), m.
    via_fractions : (V,) array
        Via-point times as fractions of the movement.
    """

    task: GraspTask
    arm: ChainPlan
    finger: ChainPlan
    thumb: ChainPlan
    wrist_start: np.ndarray
    wrist_target: np.ndarray
    finger_target: np.ndarray
    thumb_target: np.ndarray
    finger_via: np.ndarray
    thumb_via: np.ndarray
    via_fractions: np.ndarray

    @property
    def chains(self) -> dict[str, ChainPlan]:
        """The three chain plans by name (``CHAINS`` order)."""
        return {"arm": self.arm, "finger": self.finger, "thumb": self.thumb}

    @property
    def time(self) -> np.ndarray:
        """(T+1,) time of each state, s."""
        return self.task.time

    def nominal(self) -> GraspResult:
        """The noise-free movement (the plan's mean states) as a one-trial result."""
        q = {k: c.nominal_q[None] for k, c in self.chains.items()}
        qd = {k: c.nominal_qd[None] for k, c in self.chains.items()}
        return _result(self, q, qd)


def _ik(chain: TwoLinkChain, point, elbow: int, ref: np.ndarray | None = None) -> np.ndarray:
    """Joint angles on branch ``elbow``, first angle within pi of ``ref[0]`` (continuity)."""
    q = chain.inverse(np.asarray(point, dtype=float), elbow)
    if ref is not None:
        q[..., 0] += 2 * np.pi * np.round((ref[0] - q[..., 0]) / (2 * np.pi))
    return q


def _chain_plan(name, chain, elbow, p_start, p_goal, vias, fractions, task: GraspTask):
    q0 = _ik(chain, p_start, elbow)
    qg = _ik(chain, p_goal, elbow, q0)
    qv = np.array([_ik(chain, p, elbow, q0) for p in vias]).reshape(-1, 2)
    jtask = ReachTask(
        tuple(q0),
        tuple(qg),
        task.duration,
        tuple(ViaPoint(tuple(q), fraction=f) for q, f in zip(qv, fractions)),
        r=task.r,
        w_v=task.w_v,
        w_f=task.w_f,
        form=task.form,
    )
    problem = reach_problem(jtask, task.plant)
    cv = task.execution_cv
    # each joint's command gets its own noise: u_i (1 + cv eps_i)
    noise = [cv * np.diag([1.0, 0.0]), cv * np.diag([0.0, 1.0])]
    execution = problem.with_noise(C=noise,
                                   D0=task.execution_sigma_s * np.diag(task.plant.sensory_sd))
    return ChainPlan(
        name=name,
        chain=chain,
        elbow=elbow,
        task=jtask,
        problem=problem,
        execution=execution,
        solution=_solve(problem),
        q_start=q0,
        q_goal=qg,
        q_via=qv,
        via_fractions=np.asarray(fractions, dtype=float),
    )


#: Recently solved chain problems by content (see :func:`_solve`).
_SOLVED: OrderedDict[bytes, LQGSolution] = OrderedDict()
_SOLVED_MAX = 64
_SOLVED_LOCK = threading.Lock()


def _solve(problem: LQGProblem) -> LQGSolution:
    """:func:`~minvar.lqg.solve`, reusing the solution of an identical problem.

    Grasps often share a chain's problem exactly — the arm of a grasp and of
    the reach-only movement with the same transport, or one model re-planned
    for several clips of a scene — and the solution of the same arrays is the
    same (it is read-only, so it is shared as it is).
    """
    h = hashlib.blake2b(digest_size=20)
    h.update(kernel_engine().encode())  # each engine's own solutions
    for name in ("A", "B", "C", "C0", "H", "D", "D0", "E0", "Q", "R", "X1", "S1"):
        a = getattr(problem, name)
        h.update(repr(a.shape).encode())
        h.update(np.ascontiguousarray(a).data)
    key = h.digest()
    with _SOLVED_LOCK:
        sol = _SOLVED.get(key)
        if sol is not None:
            _SOLVED.move_to_end(key)
            return sol
    sol = solve(problem)  # outside the lock: plans may run in several threads
    with _SOLVED_LOCK:
        _SOLVED[key] = sol
        while len(_SOLVED) > _SOLVED_MAX:
            _SOLVED.popitem(last=False)
    return sol


def plan_grasp(task: GraspTask) -> GraspPlan:
    """Plan transport and grip of a grasp: one joint-space LQG per chain.

    Parameters
    ----------
    task : GraspTask
        The grasp.

    Returns
    -------
    GraspPlan
        Chains, joint-space problems, gains and targets.
    """
    if not isinstance(task, GraspTask):
        raise ValueError(f"plan_grasp: task: expected a GraspTask, got {type(task).__name__}")
    chains = task.chains()
    # Right arm (shoulder at +x of the wrist): the elbow bends outward, to the
    # right of the shoulder-to-wrist line, which is the q2 > 0 branch.
    arm_elbow = 1 if task.shoulder_offset[0] >= 0 else -1
    arm = _chain_plan(
        "arm", chains["arm"], arm_elbow, task.wrist_start, task.wrist_target, [], [], task
    )
    vias = task.via_schedule
    fractions = [v.fraction for v in vias]
    finger_via = np.array([(v.half_aperture, task.wrist_offset + v.height) for v in vias])
    finger_via = finger_via.reshape(-1, 2)
    thumb_via = finger_via * np.array([-1.0, 1.0])
    start = (0.0, task.tip_start)
    finger_goal = np.asarray(task.finger_goal_hand)
    thumb_goal = finger_goal * np.array([-1.0, 1.0])
    # The finger's middle joint lies to +x of the tip (right of the wrist-tip
    # line: q2 > 0), the thumb's to -x (q2 < 0): each bends out on its own side.
    finger = _chain_plan(
        "finger", chains["finger"], 1, start, finger_goal, finger_via, fractions, task
    )
    thumb = _chain_plan(
        "thumb", chains["thumb"], -1, start, thumb_goal, thumb_via, fractions, task
    )
    return GraspPlan(
        task=task,
        arm=arm,
        finger=finger,
        thumb=thumb,
        wrist_start=np.asarray(task.wrist_start),
        wrist_target=np.asarray(task.wrist_target),
        finger_target=np.asarray(task.finger_target),
        thumb_target=np.asarray(task.thumb_target),
        finger_via=finger_via,
        thumb_via=thumb_via,
        via_fractions=np.asarray(fractions, dtype=float),
    )


@dataclass(frozen=True, eq=False)
class GraspResult:
    """Noisy repetitions of one grasp, in the world frame.

    Attributes
    ----------
    task : GraspTask
        The grasp.
    plan : GraspPlan
        The plans that were executed.
    time : (S+1,) array
        Time of each state, s (S = ``task.steps``).
    wrist, finger, thumb : (trials, S+1, 2) arrays
        Wrist and digit-tip positions, m.
    wrist_velocity, finger_velocity, thumb_velocity : (trials, S+1, 2) arrays
        Their velocities, m/s.
    q_arm, q_finger, q_thumb : (trials, S+1, 2) arrays
        Joint angles of each chain, rad.
    """

    task: GraspTask
    plan: GraspPlan = field(repr=False)
    time: np.ndarray = field(repr=False)
    wrist: np.ndarray = field(repr=False)
    finger: np.ndarray = field(repr=False)
    thumb: np.ndarray = field(repr=False)
    wrist_velocity: np.ndarray = field(repr=False)
    finger_velocity: np.ndarray = field(repr=False)
    thumb_velocity: np.ndarray = field(repr=False)
    q_arm: np.ndarray = field(repr=False)
    q_finger: np.ndarray = field(repr=False)
    q_thumb: np.ndarray = field(repr=False)

    @property
    def trials(self) -> int:
        """Number of repetitions."""
        return self.wrist.shape[0]

    @property
    def relative_time(self) -> np.ndarray:
        """(S+1,) time as a fraction of the movement."""
        return self.time / self.task.duration

    @property
    def aperture(self) -> np.ndarray:
        """(trials, S+1) grip aperture ``|finger - thumb|``, m."""
        return grip_aperture(self.finger, self.thumb)

    @property
    def wrist_speed(self) -> np.ndarray:
        """(trials, S+1) wrist speed, m/s."""
        return np.hypot(self.wrist_velocity[..., 0], self.wrist_velocity[..., 1])

    @property
    def finger_speed(self) -> np.ndarray:
        """(trials, S+1) finger-tip speed (world frame), m/s."""
        return np.hypot(self.finger_velocity[..., 0], self.finger_velocity[..., 1])

    @property
    def thumb_speed(self) -> np.ndarray:
        """(trials, S+1) thumb-tip speed (world frame), m/s."""
        return np.hypot(self.thumb_velocity[..., 0], self.thumb_velocity[..., 1])

    # The measures below are those of minvar.grasp_stats applied to this
    # result, so simulated and observed grasps are measured the same way.
    @property
    def mga(self) -> np.ndarray:
        """(trials,) maximum grip aperture of each repetition, m."""
        return max_grip_aperture(self.aperture, self.relative_time)[0]

    @property
    def mga_time(self) -> np.ndarray:
        """(trials,) time of each repetition's maximum aperture, fraction of the movement."""
        return max_grip_aperture(self.aperture, self.relative_time)[1]

    @property
    def wrist_sd(self) -> np.ndarray:
        """(S+1,) SD of the wrist position across repetitions, ``sqrt(var x + var y)``, m."""
        return path_sd(self.wrist)

    @property
    def aperture_sd(self) -> np.ndarray:
        """(S+1,) SD of the grip aperture across repetitions, m."""
        return path_sd(self.aperture)

    @property
    def finger_end(self) -> np.ndarray:
        """(trials, 2) final finger-tip positions, m."""
        return self.finger[:, -1]

    @property
    def thumb_end(self) -> np.ndarray:
        """(trials, 2) final thumb-tip positions, m."""
        return self.thumb[:, -1]

    def to_pandas(self) -> pd.DataFrame:
        """One tidy row per repetition and time step.

        Columns: trial, step, time (s), wrist_x, wrist_y, finger_x, finger_y,
        thumb_x, thumb_y, aperture (m), arm_q1, arm_q2, finger_q1, finger_q2,
        thumb_q1, thumb_q2 (rad).
        """
        import pandas as pd

        trials, steps = self.wrist.shape[:2]
        cols = {
            "trial": np.repeat(np.arange(trials), steps),
            "step": np.tile(np.arange(steps), trials),
            "time": np.tile(self.time, trials),
        }
        for name in ("wrist", "finger", "thumb"):
            arr = getattr(self, name)
            cols[f"{name}_x"] = arr[..., 0].ravel()
            cols[f"{name}_y"] = arr[..., 1].ravel()
        cols["aperture"] = self.aperture.ravel()
        for name in CHAINS:
            q = getattr(self, f"q_{name}")
            cols[f"{name}_q1"] = q[..., 0].ravel()
            cols[f"{name}_q2"] = q[..., 1].ravel()
        return pd.DataFrame(cols)


def _result(plan: GraspPlan, q: dict, qd: dict) -> GraspResult:
    """Cartesian paths by forward kinematics of joint angles ``q`` and velocities ``qd``."""
    arm, finger, thumb = plan.arm.chain, plan.finger.chain, plan.thumb.chain
    wrist = arm.forward(q["arm"])
    wrist_v = np.einsum("...ij,...j->...i", arm.jacobian(q["arm"]), qd["arm"])
    f_v = np.einsum("...ij,...j->...i", finger.jacobian(q["finger"]), qd["finger"])
    t_v = np.einsum("...ij,...j->...i", thumb.jacobian(q["thumb"]), qd["thumb"])
    return GraspResult(
        task=plan.task,
        plan=plan,
        time=plan.time,
        wrist=wrist,
        finger=wrist + finger.forward(q["finger"]),
        thumb=wrist + thumb.forward(q["thumb"]),
        wrist_velocity=wrist_v,
        finger_velocity=wrist_v + f_v,
        thumb_velocity=wrist_v + t_v,
        q_arm=q["arm"],
        q_finger=q["finger"],
        q_thumb=q["thumb"],
    )


#: Floats per repetition and step of a result beyond the chains' states: the
#: wrist, finger and thumb paths and velocities (2 each) and the temporaries
#: of their forward kinematics and Jacobians.
_RESULT_FLOATS = 20


def check_grasp_simulation(task: GraspTask, trials: int, what: str, *,
                           extra_floats: int = 0, max_trials: int | None = None) -> int:
    """Refuse, before planning, ``trials`` repetitions of ``task`` beyond the limits.

    The arrays must fit :data:`minvar.limits.MEMORY_BUDGET`: each chain's states are
    kept until the result is built, while the chain being simulated also
    holds its estimates, commands and the cost's temporary
    (:func:`minvar.limits.simulation_bytes`); then the Cartesian paths are
    computed.

    Parameters
    ----------
    task : GraspTask
        The grasp.
    trials : int
        Repetitions.
    what : str
        The argument or flag to name in the message.
    extra_floats : int
        Floats per repetition and step that the caller adds (e.g. the
        columns of a table of the result), counted in the same budget.
    max_trials : int, optional
        Also refuse more repetitions than this (the command line passes
        :data:`minvar.limits.MAX_TRIALS`).

    Returns
    -------
    int
        ``trials``.

    Raises
    ------
    ValueError
        If the repetitions or their memory exceed the limits.
    """
    if max_trials is not None and trials > max_trials:
        raise ValueError(f"{what}: {trials} repetitions are more than the {max_trials} "
                         f"allowed (MAX_TRIALS; see docs/model.md, Limits)")
    steps, plant = task.steps, task.plant
    # the arm has one positional target; each digit its goal and via-points
    states = [plant.n_states(1)] + 2 * [plant.n_states(1 + len(task.via_schedule))]
    per_step = 8 * trials * (steps + 1)
    kept = sum(per_step * n for n in states)
    running = max(simulation_bytes(trials, steps, n) - per_step * n for n in states)
    check_memory(kept + running + per_step * (_RESULT_FLOATS + extra_floats), what,
                 f"{trials} repetitions x {steps + 1} time points of 3 chains")
    return trials


def _seeds(seed) -> list[np.random.Generator]:
    """One generator per chain from an int, SeedSequence or Generator."""
    if isinstance(seed, np.random.Generator):
        return seed.spawn(len(CHAINS))
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    return [np.random.default_rng(s) for s in ss.spawn(len(CHAINS))]


def simulate_grasp(
    task: GraspTask,
    trials: int = 500,
    seed: int | np.random.SeedSequence | np.random.Generator | None = 0,
    plan: GraspPlan | None = None,
) -> GraspResult:
    """Plan a grasp (unless given) and execute ``trials`` noisy repetitions.

    Each chain runs all repetitions in one vectorised pass with the execution
    noise model; the three chains are independent, and each draws from its own
    child of ``seed``.

    Parameters
    ----------
    task : GraspTask
        The grasp.
    trials : int
        Number of repetitions (>= 1; thesis 500; their arrays within
        :data:`minvar.limits.MEMORY_BUDGET`, checked before planning).
    seed : int, numpy.random.SeedSequence or numpy.random.Generator, optional
        Randomness; the same seed gives the same result.
    plan : GraspPlan, optional
        A plan of this very task from :func:`plan_grasp` (skips planning).

    Returns
    -------
    GraspResult
    """
    if not isinstance(task, GraspTask):
        raise ValueError(f"simulate_grasp: task: expected a GraspTask, got {type(task).__name__}")
    if isinstance(trials, bool) or not isinstance(trials, int | np.integer) or trials < 1:
        raise ValueError(f"simulate_grasp: trials: expected an integer >= 1, got {trials!r}")
    check_grasp_simulation(task, int(trials), "simulate_grasp: trials")  # before planning
    if plan is None:
        plan = plan_grasp(task)
    elif not isinstance(plan, GraspPlan) or plan.task != task:
        raise ValueError("simulate_grasp: plan: expected a GraspPlan made for this task")
    q, qd = {}, {}
    for (name, cp), rng in zip(plan.chains.items(), _seeds(seed)):
        X = simulate(cp.problem, cp.solution, int(trials), seed=rng, execution=cp.execution).states
        q[name], qd[name] = X[..., POSITION], X[..., VELOCITY]
    return _result(plan, q, qd)

"""Planning HAMMER-MV models with the minimum variance grasp model (:func:`minvar.plan_grasp`)."""

from __future__ import annotations

import os
import weakref
from collections.abc import Iterable

import numpy as np

from minvar import plan_grasp
from minvar.moments import estimation_error_covariance
from perception.errors import PlanningError
from perception.recognition.models import (
    KINDS,
    ChainModel,
    ModelSpec,
    MotorModel,
    SceneSpec,
    model_substeps,
)

__all__ = ["DEFAULT_DURATIONS", "build_model", "build_models", "default_specs",
           "planning_threads"]

#: Movement-time variants of the default repertoire, s.
DEFAULT_DURATIONS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2)


#: The joint-angle error covariance of each solution still in use (identical
#: chain problems share one solution: see minvar.grasp).
_ERROR_COV: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _chain_model(role: str, chain_plan) -> ChainModel:
    problem, solution = chain_plan.problem, chain_plan.solution
    P = _ERROR_COV.get(solution)
    if P is None:
        P = estimation_error_covariance(problem, solution.K, solution.L)[:, :2, :2]
        P.setflags(write=False)
        _ERROR_COV[solution] = P
    q_ref = np.asarray(chain_plan.q_goal, dtype=float)
    chain = chain_plan.chain
    return ChainModel(
        role=role,
        l1=float(chain.l1),
        l2=float(chain.l2),
        base=np.asarray(chain.base, dtype=float),
        elbow=1 if q_ref[1] >= 0 else -1,
        A=np.asarray(problem.A),
        B=np.asarray(problem.B),
        H=np.asarray(problem.H),
        K=np.asarray(solution.K),
        L=np.asarray(solution.L),
        P=P,
        x0=np.asarray(problem.X1),
    )


def build_model(spec: ModelSpec, scene: SceneSpec) -> MotorModel:
    """Plan ``spec`` in ``scene`` with the minimum variance grasp model.

    Parameters
    ----------
    spec : ModelSpec
        The movement.
    scene : SceneSpec
        Distance, object size and frame period.

    Raises
    ------
    PlanningError
        The movement cannot be planned in this scene (the object out of
        reach, a duration shorter than two of its steps, ...).
    """
    try:
        # the task's own checks: an object out of the arm's or the digits' reach,
        # a movement too short for the frame period (a wrong scale puts a clip's
        # object metres away). What the solver raises after them is a bug.
        task = spec.grasp_task(scene)
    except ValueError as exc:
        raise PlanningError(f"cannot plan model '{spec.name}' for a scene with the object "
                            f"{scene.distance:.3f} m away, {scene.object_size:.3f} m wide, "
                            f"at {1 / scene.frame_period:.4g} frames/s: {exc}", field="",
                            location=getattr(exc, "location", ())) from None
    plan = plan_grasp(task)
    return MotorModel(
        spec=spec,
        scene=scene,
        substeps=model_substeps(scene.frame_period),
        dt=task.plant.dt,
        arm=_chain_model("arm", plan.arm),
        finger=_chain_model("finger", plan.finger),
        thumb=_chain_model("thumb", plan.thumb),
    )


def planning_threads() -> int:
    """Threads :func:`build_models` uses by default: the cores this process may use, at most 4.

    The solver's compiled passes (two thirds of planning) release the GIL, so
    several models plan at once (on 2 idle cores a new scene's 10 default
    models took 144 ms, against 165-197 ms on one thread; on a busy machine
    threads gain nothing). Past 4, the Python third, which holds the GIL, is
    all that is left. A batch's workers pass 1: they already use every core.
    """
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on every platform
        cores = os.cpu_count() or 1
    return max(1, min(4, cores))


def build_models(specs: Iterable[ModelSpec], scene: SceneSpec, *,
                 threads: int | None = None) -> list[MotorModel]:
    """:func:`build_model` of every spec, in order, on ``threads`` threads.

    Parameters
    ----------
    specs : iterable of ModelSpec
        The movements.
    scene : SceneSpec
        The scene.
    threads : int, optional
        Threads that plan (default: :func:`planning_threads`); the models are
        the same whatever the number.
    """
    specs = list(specs)
    threads = min(planning_threads() if threads is None else max(1, int(threads)), len(specs))
    if threads <= 1:
        return [build_model(s, scene) for s in specs]
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(threads, thread_name_prefix="plan") as pool:
        return list(pool.map(lambda spec: build_model(spec, scene), specs))


def default_specs(durations: Iterable[float] = DEFAULT_DURATIONS) -> list[ModelSpec]:
    """Grasp and reach-only models at each movement time.

    Parameters
    ----------
    durations : iterable of float
        Movement times, s.
    """
    specs = []
    for kind in KINDS:
        for d in durations:
            specs.append(ModelSpec(f"{kind}-{d:.1f}s", kind, {"duration": float(d)}))
    return specs

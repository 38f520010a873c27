"""minvar: the minimum variance model of reaching and grasping.

Todorov's (2005) LQG with signal-dependent noise (:mod:`minvar.lqg`), the
point-mass/muscle plant of Todorov & Jordan 2002 (:mod:`minvar.plant`),
reaching tasks with via-points (:mod:`minvar.task`), vectorised Monte Carlo
execution (:mod:`minvar.simulate`, :mod:`minvar.reach`), two-link kinematics
(:mod:`minvar.kinematics`), the analyses of the thesis's chapter 3
(:mod:`minvar.analysis`), chapter 2's comparison models
(:mod:`minvar.baselines`), appendix A's via-point representation
(:mod:`minvar.viapoints`, :mod:`minvar.similarity`), and reach-to-grasp
(chapter 4): the arm-and-gripper model (:mod:`minvar.grasp`), its statistics
(:mod:`minvar.grasp_stats`) and experiments (:mod:`minvar.grasp_experiments`).
Figures of all of these are drawn on request by :mod:`minvar.plotting`.
numpy/scipy only: no video, no files. The model and its parameters are
described in docs/model.md.

Every submodule above is an attribute of the package (``minvar.grasp_experiments``),
imported the first time it is used, so ``import minvar`` loads neither
matplotlib nor pandas. The one exception is ``minvar.simulate``, which is the
function :func:`minvar.simulate.simulate`.
"""

from importlib import import_module as _import_module

from .analysis import endpoint_stats, peak_to_mean_speed, speed_accuracy
from .grasp import (
    ChainPlan,
    GraspPlan,
    GraspResult,
    GraspTask,
    GripVia,
    plan_grasp,
    simulate_grasp,
)
from .grasp_stats import GraspMoments, GraspSummary, grasp_moments, summarize_grasp
from .lqg import LQGProblem, LQGSolution, expected_cost, solve, state_moments
from .plant import PointMassPlant
from .reach import ReachResult, simulate_reach
from .simulate import Trajectories, simulate
from .task import ReachTask, ViaPoint, reach_problem

__version__ = "0.1.0"

__all__ = [
    "ChainPlan",
    "GraspMoments",
    "GraspPlan",
    "GraspResult",
    "GraspSummary",
    "GraspTask",
    "GripVia",
    "LQGProblem",
    "LQGSolution",
    "PointMassPlant",
    "ReachResult",
    "ReachTask",
    "Trajectories",
    "ViaPoint",
    "endpoint_stats",
    "expected_cost",
    "grasp_moments",
    "peak_to_mean_speed",
    "plan_grasp",
    "reach_problem",
    "simulate",
    "simulate_grasp",
    "simulate_reach",
    "solve",
    "speed_accuracy",
    "state_moments",
    "summarize_grasp",
]

# Submodules reachable as attributes of the package, imported on first use.
# Not "simulate": minvar.simulate is the function exported above (as it always
# was); its module is reached with `from minvar.simulate import ...`.
_SUBMODULES = (
    "analysis",
    "baselines",
    "grasp",
    "grasp_experiments",
    "grasp_stats",
    "kinematics",
    "lqg",
    "plant",
    "plotting",
    "reach",
    "similarity",
    "task",
    "viapoints",
)


def __getattr__(name: str):
    """``minvar.<submodule>`` without importing it first (PEP 562).

    Parameters
    ----------
    name : str
        The attribute asked for.
    """
    if name in _SUBMODULES:
        return _import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The package's names, its lazily imported submodules included."""
    return sorted({*globals(), *_SUBMODULES})

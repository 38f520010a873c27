"""minvar: the minimum variance model of reaching and grasping.

Todorov's (2005) LQG with signal-dependent noise (:mod:`minvar.lqg`), the
point-mass/muscle plant of Todorov & Jordan 2002 (:mod:`minvar.plant`),
reaching tasks with via-points (:mod:`minvar.task`), vectorised Monte Carlo
execution (:mod:`minvar.simulate`, :mod:`minvar.reach`) and the analyses of
the thesis's chapter 3 (:mod:`minvar.analysis`; figures in
:mod:`minvar.figures`), and reach-to-grasp (chapter 4): the arm-and-gripper
model (:mod:`minvar.grasp`), its statistics (:mod:`minvar.grasp_stats`),
experiments (:mod:`minvar.grasp_experiments`) and figures
(:mod:`minvar.grasp_figures`). numpy/scipy only: no video, no files.
"""

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

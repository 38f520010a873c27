"""minvar: the minimum variance model of reaching and grasping.

Todorov's (2005) LQG with signal-dependent noise (:mod:`minvar.lqg`), the
point-mass/muscle plant of Todorov & Jordan 2002 (:mod:`minvar.plant`),
reaching tasks with via-points (:mod:`minvar.task`), vectorised Monte Carlo
execution (:mod:`minvar.execution`, :mod:`minvar.reach`), two-link kinematics
(:mod:`minvar.kinematics`), the limits on sizes and positions checked before
anything is allocated (:mod:`minvar.limits`), the analyses of the thesis's chapter 3
(:mod:`minvar.analysis`), chapter 2's comparison models
(:mod:`minvar.baselines`), appendix A's via-point representation
(:mod:`minvar.viapoints`, :mod:`minvar.similarity`), and reach-to-grasp
(chapter 4): the arm-and-gripper model (:mod:`minvar.grasp`), its statistics
(:mod:`minvar.grasp_stats`) and experiments (:mod:`minvar.grasp_experiments`).
Figures of all of these are drawn on request by :mod:`minvar.plotting`.
numpy/scipy only: no video, no files. The model and its parameters are
described in docs/model.md.

Every name below and every submodule above is an attribute of the package
(``minvar.solve``, ``minvar.grasp_experiments``), imported the first time it
is used: ``import minvar`` itself loads nothing heavy (no scipy, pandas or
matplotlib), so a command that only asks for the version starts at once.
"""

from importlib import import_module as _import_module

from minvar._version import __version__

#: Public names and the submodule each comes from (imported on first use).
_NAMES = {
    'endpoint_stats': 'analysis',
    'peak_to_mean_speed': 'analysis',
    'speed_accuracy': 'analysis',
    'ChainPlan': 'grasp',
    'GraspPlan': 'grasp',
    'GraspResult': 'grasp',
    'GraspTask': 'grasp_task',
    'GripVia': 'grasp_task',
    'shoulder_for': 'grasp_task',
    'plan_grasp': 'grasp',
    'simulate_grasp': 'grasp',
    'GraspMoments': 'grasp_stats',
    'GraspSummary': 'grasp_stats',
    'grasp_moments': 'grasp_stats',
    'summarize_grasp': 'grasp_stats',
    'LQGProblem': 'lqg',
    'LQGSolution': 'lqg',
    'expected_cost': 'lqg',
    'solve': 'lqg',
    'state_moments': 'lqg',
    'PointMassPlant': 'plant',
    'ReachResult': 'reach',
    'simulate_reach': 'reach',
    'Trajectories': 'execution',
    'simulate': 'execution',
    'ReachTask': 'task',
    'ViaPoint': 'task',
    'reach_problem': 'task',
}

# Submodules reachable as attributes of the package, imported on first use.
_SUBMODULES = (
    "analysis",
    "baselines",
    "execution",
    "grasp",
    "grasp_experiments",
    "grasp_task",
    "grasp_stats",
    "kinematics",
    "limits",
    "lqg",
    "plant",
    "plotting",
    "reach",
    "similarity",
    "task",
    "viapoints",
)

__all__ = ["__version__", *sorted(_NAMES)]


def __getattr__(name: str):
    """``minvar.<name>`` and ``minvar.<submodule>`` without importing them first (PEP 562).

    Parameters
    ----------
    name : str
        The attribute asked for.
    """
    if name in _NAMES:
        value = getattr(_import_module(f"{__name__}.{_NAMES[name]}"), name)
        globals()[name] = value  # found once, then an ordinary attribute
        return value
    if name in _SUBMODULES:
        return _import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The package's names, its lazily imported names and submodules included."""
    return sorted({*globals(), *_NAMES, *_SUBMODULES})

"""Figures of the model's results, built on request.

Data flows one way: the model computes results (:mod:`minvar.reach`,
:mod:`minvar.grasp`, :mod:`minvar.grasp_experiments`, ...) and these modules
draw them. They import result classes only for type checking, so any object
with the same attributes can be drawn, and nothing in the model imports
matplotlib. Every function returns a :class:`matplotlib.figure.Figure` built
without pyplot's global state; save it with ``fig.savefig(path)``.

* :mod:`~minvar.plotting.canvas` — :func:`new_figure`, the blank figure.
* :mod:`~minvar.plotting.reach` — repeated reaches, speed-accuracy (Figs. 3.4-3.7).
* :mod:`~minvar.plotting.baselines` — minimum jerk family (Figs. 2.5-2.8).
* :mod:`~minvar.plotting.viapoints` — via-point movements (Figs. 3.2-3.3,
  3.8-3.9, A.1-A.3).
* :mod:`~minvar.plotting.grasp` — one grasp: set-up and repetitions (Figs. 4.1, 4.6).
* :mod:`~minvar.plotting.grasp_experiments` — the chapter-4 sweeps (Figs.
  4.2-4.5, 4.7-4.16); :func:`experiment_figures` builds all of one sweep's.
"""

from importlib import import_module as _import_module

from .canvas import new_figure

# The figure functions are imported from their modules on first use (PEP
# 562), so `from minvar.plotting import new_figure` costs matplotlib.figure
# alone, not the model modules the figures of every chapter need (scipy
# among them, about a second).
_HOMES = {
    "baselines": (
        "angle_jerk_hand_figure", "angle_jerk_joint_figure", "derivative_order_figure",
        "minimum_jerk_figure",
    ),
    "grasp": ("grasp_figure", "setup_figure"),
    "grasp_experiments": (
        "EXPERIMENT_FIGURES", "accuracy_figure", "experiment_figures", "mga_figure",
        "paths_figure", "sd_peaks_figure", "sd_time_figure", "viapoint_height_paths_figure",
    ),
    "reach": ("reach_figure", "speed_accuracy_figure"),
    "viapoints": (
        "criteria_figure", "curvature_figure", "generalisation_figure",
        "letter_durations_figure", "letter_figure", "merging_figure", "viapoint_timing_figure",
    ),
}
_HOME = {name: module for module, names in _HOMES.items() for name in names}

__all__ = ["new_figure", *sorted(_HOME)]


def __getattr__(name: str):
    """A figure function or plotting submodule, imported on first use (PEP 562).

    Parameters
    ----------
    name : str
        The attribute asked for.
    """
    if name in _HOME:
        return getattr(_import_module(f"{__name__}.{_HOME[name]}"), name)
    if name in _HOMES or name == "canvas":
        return _import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The package's names, its lazily imported functions and submodules included."""
    return sorted({*globals(), *_HOME, *_HOMES})

"""minvar: the minimum variance model of reaching and grasping.

Todorov's (2005) LQG with signal-dependent noise (the problem,
:mod:`minvar.problem`; its solver, :mod:`minvar.lqg`; the exact moments of any
gains, :mod:`minvar.moments`), the point-mass/muscle plant of Todorov & Jordan
2002 (:mod:`minvar.plant`), reaching tasks with via-points
(:mod:`minvar.task`), vectorised Monte Carlo execution
(:mod:`minvar.execution`, :mod:`minvar.reach`), two-link kinematics
(:mod:`minvar.kinematics`), the limits on sizes and positions checked before
anything is allocated (:mod:`minvar.limits`), the analyses of the thesis's
chapter 3 (:mod:`minvar.analysis`), chapter 2's comparison models
(:mod:`minvar.baselines`), appendix A's via-point representation
(:mod:`minvar.viapoints`, :mod:`minvar.similarity`), and reach-to-grasp
(chapter 4): the arm-and-gripper model (:mod:`minvar.grasp`), its statistics
(:mod:`minvar.grasp_stats`) and experiments (:mod:`minvar.grasp_experiments`).
Figures of all of these are drawn on request by :mod:`minvar.plotting`.
numpy/scipy only: no video, no files. The model and its parameters are
described in docs/model.md.

Every public name (``minvar.solve``) and every submodule above
(``minvar.grasp_experiments``) is an attribute of the package, imported the
first time it is used (``lazy_loader``, from the names ``__init__.pyi``
lists, which IDEs, type checkers and ``help(minvar)`` read too): ``import
minvar`` itself loads nothing heavy (no scipy, pandas or matplotlib), so a
command that only asks for the version starts at once.
"""

import lazy_loader as _lazy

from minvar._version import __version__ as __version__

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)

"""minvar: the minimum variance model of reaching and grasping.

Todorov's (2005) LQG with signal-dependent noise, the point-mass/muscle plant
of Todorov & Jordan (2002), reaching tasks with via-points (thesis ch. 3).
numpy/scipy only: no video, no files.
"""

__version__ = "0.1.0"

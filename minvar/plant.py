"""The point-mass / muscle plant (thesis 3.2.2-3.2.4; Todorov & Jordan 2002).

Each 2-D effector is a point mass driven through a second-order muscle filter::

    p' = p + dt v
    v' = v + dt f / m
    f' = (1 - dt/tau2) f + dt/tau2 g
    g' = (1 - dt/tau1) g + dt/tau1 u

State ``[p(2), v(2), f(2), g(2), then a pair of constant 1s per positional
target]``; the 1s let a quadratic state cost express ``(p - target)^2``.
The same plant serves in joint space for the grasp model (angles in rad,
unit inertia).

That Euler form is the project's (``form="project"``, the default). The thesis
prints another (lines 520-524; ``form="thesis"``): exact exponential decay,
the muscle state f~ taking the command at unit gain, and f taking f~ at the
gain ``exp(-dt/tau)``::

    f'  = exp(-dt/tau2) f + exp(-dt/tau2) g
    g'  = exp(-dt/tau1) g + u

(the thesis writes tau1 in both lines; the two are equal, 0.04 s). Its steady
force per unit command is ``e^-a / (1 - e^-a)^2`` with ``a = dt/tau`` (15.9
here) where the Euler form's is 1, so the same effort weight buys far more
force: the two forms differ in what ``r`` means (docs/thesis.md).
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np

from minvar.errors import ParameterError
from minvar.validation import NonNegative, Positive, Tuple, checked, declared

__all__ = ["PointMassPlant", "POSITION", "VELOCITY", "FORCE", "FILTER", "N_BASE", "FORMS"]

#: Indices of the plant's physical states within the state vector.
POSITION = slice(0, 2)
VELOCITY = slice(2, 4)
FORCE = slice(4, 6)
FILTER = slice(6, 8)
#: Number of physical states before the constant 1s.
N_BASE = 8
#: Forms of the model: the project's Euler filter and effort integral (default),
#: and the thesis's printed exponential filter and effort mean (lines 520-524, 558).
FORMS = ("project", "thesis")


@declared
class PointMassPlant:
    """A 2-D point mass with a second-order muscle filter and signal-dependent noise.

    Parameters
    ----------
    mass : float
        Point mass, kg (or kg m^2 in joint space).
    dt : float
        Time step, s.
    tau1, tau2 : float
        Time constants of the two muscle filter stages, s.
    sigma_u : float
        Scale of the control-dependent noise: ``C1 = sigma_u I``,
        ``C2 = sigma_u [[0, 1], [-1, 0]]``.
    sigma_s : float
        Scale of the sensory noise.
    sensory_sd : tuple of 6 floats
        Relative sensory noise SD of the observed ``p, v, f`` (m, m/s, N),
        multiplied by ``sigma_s``.
    """

    mass: Positive = 1.0
    dt: Positive = 0.01
    tau1: Positive = 0.04
    tau2: Positive = 0.04
    sigma_u: NonNegative = 0.4
    sigma_s: NonNegative = 0.4
    sensory_sd: Annotated[tuple[NonNegative, NonNegative, NonNegative, NonNegative, NonNegative,
                                NonNegative], Tuple] = (0.01, 0.01, 0.1, 0.1, 1.0, 1.0)

    def __post_init__(self):
        if self.dt > min(self.tau1, self.tau2):
            raise ParameterError(f"must not exceed the muscle time constants "
                                 f"({min(self.tau1, self.tau2)} s) or the filter is unstable, "
                                 f"got {self.dt}", location=("PointMassPlant", "dt"))

    def n_states(self, targets: int) -> int:
        """State dimension with ``targets`` positional targets."""
        return N_BASE + 2 * targets

    def dynamics(self, targets: int, form: str = "project") -> tuple[np.ndarray, np.ndarray]:
        """``A`` (n, n) and ``B`` (n, 2) for ``targets`` positional targets.

        Parameters
        ----------
        targets : int
            Number of positional targets (pairs of constant 1s).
        form : {"project", "thesis"}
            The Euler muscle filter (default), or the thesis's printed
            exponential one with the command entering f~ at unit gain (module
            docstring).
        """
        checked(form, Literal[FORMS], ("PointMassPlant.dynamics", "form"))
        n = self.n_states(targets)
        dt = self.dt
        A = np.eye(n)
        I2 = np.eye(2)
        A[POSITION, VELOCITY] = dt * I2
        A[VELOCITY, FORCE] = dt / self.mass * I2
        B = np.zeros((n, 2))
        if form == "thesis":
            decay_f, decay_g = np.exp(-dt / self.tau2), np.exp(-dt / self.tau1)
            A[FORCE, FORCE] = decay_f * I2
            A[FORCE, FILTER] = decay_f * I2
            A[FILTER, FILTER] = decay_g * I2
            B[FILTER] = I2
            return A, B
        A[FORCE, FORCE] = (1 - dt / self.tau2) * I2
        A[FORCE, FILTER] = dt / self.tau2 * I2
        A[FILTER, FILTER] = (1 - dt / self.tau1) * I2
        B[FILTER] = dt / self.tau1 * I2
        return A, B

    def control_noise(self) -> tuple[np.ndarray, np.ndarray]:
        """The two m x m control-noise matrices ``C1, C2`` (thesis ``C = B C_i``)."""
        s = self.sigma_u
        return s * np.eye(2), s * np.array([[0.0, 1.0], [-1.0, 0.0]])

    def observation(self, targets: int) -> tuple[np.ndarray, np.ndarray]:
        """``H`` (6, n) observing ``p, v, f`` and the sensory noise ``D0`` (6, 6)."""
        n = self.n_states(targets)
        H = np.zeros((6, n))
        H[:, :6] = np.eye(6)
        D0 = self.sigma_s * np.diag(self.sensory_sd)
        return H, D0

"""The verdict on a clip: normal, abnormal or reach, from calibrated familiarity.

(``unfamiliar``, the fourth, and the rules around familiarity are
:mod:`perception.recognition.rules`'.)

The likelihood rule says which model explains a demonstration *best*; it
does not say whether the best is any good. Familiarity does:

* **misfit** — the mean, over a clip's scored steps, of the squared
  Mahalanobis distance of the observed ``(r, g)`` from a model's prediction
  under its own predictive distribution (the per-step log-likelihood without
  its normalising term: ``-2 (log-likelihood + log 2 pi) - log det``);
* **familiarity** — the share of the model's own demonstrations
  (:mod:`perception.recognition.calibration`: its movement executed from its
  stored gains with human-scale variability, tracked and observed like a
  clip) that fit it worse than the clip does: 1 − F(misfit), with F the
  log-normal distribution fitted to their misfits (centre: the median of the
  log misfits; scale: their interquartile range in a normal distribution's
  standard deviations, ``scipy.stats.iqr(scale="normal")``, so that a few
  extreme demonstrations do not stretch the tail). 1 fits better than all of
  them, 0.5 like the typical one, near 0 worse than nearly all;
* **verdict** — take the model with the highest log-likelihood (the best
  grasp or reach model). If its familiarity is at least the threshold
  (``VerdictRules.familiarity_threshold``, 0.05: a one-sided test at the 5 %
  level that the clip is one of the model's own movements), the clip is
  ``normal`` (a grasp model) or ``reach`` (a reach model); otherwise no model
  explains it as well as 95 % of the models' own demonstrations and the
  verdict is ``abnormal``.

Misfits grow with the square of the frame period (a longer frame, a longer
one-step prediction; measured in docs/recognition.md), so a calibration made
at one frame rate is applied at another by rescaling the clip's misfit by
``(calibration frame period / clip frame period)^2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Annotated

import numpy as np
from pydantic import Field

from perception.validation import Int, NonNegative, Positive, declared

__all__ = ["VERDICTS", "Calibration", "CalibrationParams", "misfit"]

#: The four verdicts.
VERDICTS = ("normal", "abnormal", "reach", "unfamiliar")


@declared
class CalibrationParams:
    """How a model's own demonstrations are made for its calibration.

    Each demonstration is the model's movement executed from its stored
    gains and varied the way one person's grasps vary from one to the next
    (ranges drawn uniformly, from the prehension literature: movement time
    CV 5-10 %, time of maximum aperture SD 5-8 % of the movement, maximum
    aperture SD 5-10 %, gently curved hand paths), then seen through a
    camera with tracking noise and observed like a clip.

    Parameters
    ----------
    demonstrations : int
        Demonstrations per model.
    execution_cv : float
        Coefficient of variation of the command noise (the thesis's 1 %).
    time_scale : float
        Movement time scaled by a factor in ``1 ± time_scale``.
    grip_shift : float
        The grip runs up to this fraction of the movement ahead of or behind
        the transport (most in mid-movement, none at the start and end).
    aperture_scale : float
        The opening scaled by up to ``1 ± aperture_scale`` (most in mid-movement).
    path_bow : float
        Sideways bow of the whole hand's path at mid-movement, up to ± m.
    transport_skew : float
        The movement's clock runs ahead early by up to this (0..1): the wrist's
        speed peaks earlier than the model's (at 36-50 % of the movement in
        healthy adults, against the model's 48 %).
    noise_px : float
        Tracking noise, px, at ``px_per_m``.
    noise_spread : float
        Each demonstration's tracking noise is ``noise_px`` × (1 ± this).
    px_per_m : float
        Image scale of the demonstrations' camera, px/m.
    rest : float
        Stillness before and after the movement, s.
    marker_offset : float
        How far each digit's marker sits outside its tip, m.
    seed : int
        Seed of every draw: a repertoire's calibration is reproducible.
    """

    demonstrations: Annotated[Int, Field(ge=10)] = 50
    execution_cv: NonNegative = 0.01
    time_scale: Annotated[float, Field(ge=0, lt=0.5)] = 0.08
    grip_shift: Annotated[float, Field(ge=0, lt=0.25)] = 0.08
    aperture_scale: Annotated[float, Field(ge=0, lt=1)] = 0.10
    path_bow: NonNegative = 0.03
    transport_skew: Annotated[float, Field(ge=0, lt=1)] = 0.8
    noise_px: NonNegative = 0.4
    noise_spread: Annotated[float, Field(ge=0, lt=1)] = 0.5
    px_per_m: Positive = 800.0
    rest: Positive = 0.3
    marker_offset: NonNegative = 0.0065
    seed: Int = 0


@dataclass(frozen=True, eq=False)
class Calibration:
    """The misfits of one model's own demonstrations.

    Attributes
    ----------
    misfit : (K,) array
        Sorted misfits of K demonstrations (mean squared Mahalanobis distance per step).
    frame_period : float
        Frame period of the demonstrations, s (the model's scene).
    params : CalibrationParams
        How they were made.
    """

    misfit: np.ndarray
    frame_period: float
    params: CalibrationParams = field(default_factory=CalibrationParams)

    def __post_init__(self):
        m = np.sort(np.asarray(self.misfit, dtype=float).ravel())
        if m.size < 4 or not np.all(np.isfinite(m) & (m > 0)) or not self.frame_period > 0:
            raise ValueError("calibration: expected at least 4 positive misfits and a positive "
                             f"frame period, got {m.size} misfits, {self.frame_period!r} s")
        object.__setattr__(self, "misfit", m)

    @cached_property  # read at every frame of a stream
    def log_centre(self) -> float:
        """Median of the log misfits (the fitted log-normal's location)."""
        return float(np.median(np.log(self.misfit)))

    @cached_property
    def log_scale(self) -> float:
        """Interquartile range of the log misfits in standard deviations of a normal
        distribution (``scipy.stats.iqr(scale="normal")``: the fitted log-normal's scale)."""
        from scipy.stats import iqr

        return float(max(iqr(np.log(self.misfit), scale="normal"), 1e-6))

    def familiarity(self, misfit: float, frame_period: float | None = None) -> float:
        """Share of the model's own demonstrations that fit worse than ``misfit`` (fitted).

        Parameters
        ----------
        misfit : float
            A clip's misfit under this model.
        frame_period : float, optional
            The clip's frame period, s; its misfit is rescaled to the
            calibration's by the squared ratio of the two.
        """
        if not math.isfinite(misfit):
            return float("nan")
        if frame_period:
            misfit = misfit * (self.frame_period / frame_period) ** 2
        from scipy.special import ndtr

        z = (math.log(max(misfit, 1e-300)) - self.log_centre) / self.log_scale
        # scipy.stats.norm.sf(z) is ndtr(-z); called directly it costs 0.1 us instead of
        # the distribution object's 20 us, and it is called for every model every frame
        return float(ndtr(-z))


def misfit(mahalanobis: np.ndarray, scored: np.ndarray) -> np.ndarray:
    """Mean squared Mahalanobis distance per scored step of each model.

    Parameters
    ----------
    mahalanobis : (M, N) array
        Per-step squared Mahalanobis distances.
    scored : (M, N) bool array
        Steps that count.

    Returns
    -------
    (M,) array
        NaN for a model with no scored step.
    """
    n = scored.sum(axis=1)
    total = np.where(scored, mahalanobis, 0.0).sum(axis=1)
    return np.where(n > 0, total / np.maximum(n, 1), np.nan)

"""The engine one frame at a time: every model's score so far, for a stream.

:func:`perception.recognition.engine.recognize` scores a whole observation
at once; :class:`StepScorer` gives the same per-step terms as the frames
arrive, from the same pieces (the engine's one-frame prediction
``_advance``, its forward kinematics and the two rules of
:mod:`perception.recognition.scoring`), so that after frame *n* its sums
are the offline arrays' column *n*. Nothing here looks ahead.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import SimpleNamespace

import numpy as np

from perception.recognition.engine import (
    HammerParams,
    _advance,
    _model_steps,
    _observed_angles,
    _start,
    _to_cartesian,
)
from perception.recognition.leaves import Leaves
from perception.recognition.models import MotorModel
from perception.recognition.scoring import likelihood_rule, thesis_rule

__all__ = ["StepScorer"]

#: Model steps the stacked gains are first made for (grown by doubling when a
#: movement lasts longer; past a plan's horizon its gains stay the last ones).
_FIRST_STEPS = 256


class StepScorer:
    """Cumulative scores of every model over a movement that is still being observed.

    Parameters
    ----------
    models : sequence of MotorModel
        The models, planned for the clip's scene (one time step).
    params : HammerParams
        Rule weights, observation noise and filter gain.

    Attributes
    ----------
    confidence, log_likelihood : (M,) arrays
        Thesis-rule confidence and log-likelihood so far.
    mahalanobis : (M,) array
        Sum of the squared Mahalanobis distances of the scored steps.
    scored : (M,) int array
        Steps scored so far, per model.
    """

    def __init__(self, models: Sequence[MotorModel], params: HammerParams):
        self.models = list(models)
        self.params = params
        self.dt = self.models[0].dt
        self._leaves = Leaves(self.models, _FIRST_STEPS)
        self._grasp = np.array([m.kind == "grasp" for m in self.models])
        M = len(self.models)
        self.confidence = np.zeros(M)
        self.log_likelihood = np.zeros(M)
        self.mahalanobis = np.zeros(M)
        self.scored = np.zeros(M, dtype=int)
        self._time: list[float] = []
        self._x = None
        self._prev = None  # (model step, angles, all three seen, r, g) of the last frame

    @property
    def misfit(self) -> np.ndarray:
        """(M,) mean squared Mahalanobis distance per scored step so far (NaN before any)."""
        return np.where(self.scored > 0, self.mahalanobis / np.maximum(self.scored, 1), np.nan)

    def familiarity(self, index: int, frame_period: float) -> float:
        """Model ``index``'s familiarity of the movement so far (NaN without calibration).

        Parameters
        ----------
        index : int
            The model.
        frame_period : float
            The clip's frame period, s.
        """
        cal = self.models[index].calibration
        return float("nan") if cal is None else cal.familiarity(float(self.misfit[index]),
                                                                frame_period)

    def step(self, time: float, wrist, finger, thumb) -> None:
        """Score the next frame: ``time`` s since the onset, positions (2,) m in the model frame.

        Parameters
        ----------
        time : float
            Time since the movement's onset, s.
        wrist, finger, thumb : (2,) arrays
            Filtered positions (the digit tips), m; NaN where lost.
        """
        self._time.append(float(time))
        s = int(_model_steps(np.asarray(self._time), self.dt)[-1])
        if s >= len(self._leaves.P):
            self._leaves = Leaves(self.models, 2 * s)
        rows = [np.asarray(p, dtype=float)[None] for p in (wrist, finger, thumb)]
        q = _observed_angles(SimpleNamespace(wrist=rows[0], finger=rows[1], thumb=rows[2],
                                             n_frames=1), self._leaves.chains)[0]
        mid, opening = 0.5 * (rows[1] + rows[2]), rows[1] - rows[2]
        r, g = np.linalg.norm(mid, axis=-1), np.linalg.norm(opening, axis=-1)
        seen = bool(np.isfinite(np.concatenate(rows)).all())
        prev, self._prev = self._prev, (s, q, seen, r, g)
        if prev is None:
            self._x = _start(self._leaves, s)
            return
        q_pred, self._x = _advance(self._leaves, self._x, prev[1], prev[0], s,
                                   self.params.filter_gain)
        pred = _to_cartesian(self._leaves, q_pred[None], self._leaves.P[s][None],
                             len(self.models))
        p_mid, p_open = 0.5 * (pred.finger + pred.thumb), pred.finger - pred.thumb
        r_pred, g_pred = np.linalg.norm(p_mid, axis=-1), np.linalg.norm(p_open, axis=-1)
        # as the engine: the state predicted from was seen (all three markers),
        # and so were r and g then and now
        ok = prev[2] and bool(np.isfinite([prev[3][0], prev[4][0], r[0], g[0]]).all())
        valid = ok & np.isfinite(r_pred) & np.isfinite(g_pred)
        nan = np.full((len(self.models), 1), np.nan)
        dC_r, dC_g = thesis_rule(np.r_[prev[3], r], np.r_[prev[4], g],
                                 np.hstack([nan, r_pred]), np.hstack([nan, g_pred]),
                                 self._grasp, np.hstack([nan == 0, valid]),
                                 self.params.w_r, self.params.w_g, self.params.thesis_sign)
        dll, maha = likelihood_rule(r, g, p_mid, p_open, pred.cov, valid, self.params.obs_sd)
        self.confidence += dC_r[:, 1] + dC_g[:, 1]
        self.log_likelihood += dll[:, 0]
        self.mahalanobis += maha[:, 0]
        self.scored += valid[:, 0]

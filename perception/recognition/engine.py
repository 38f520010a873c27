"""The HAMMER-MV engine: every model predicts every step of a demonstration.

At each frame n the demonstrator's observed positions up to frame n-1 are
fed to each inverse model: its Kalman filter estimates the chain's full state
(joint angles, velocities, muscle forces) from the observed joint angles
only — its own plan supplies velocity and force — the motor command
``u = -L xhat`` is computed but not executed, and the forward model ``(A, B)``
predicts the state at frame n (several model steps per frame). Forward
kinematics turn the predicted joint angles into predicted wrist, finger and
thumb positions, from which the predicted distance-to-object ``r`` and grip
aperture ``g`` follow (thesis eqs. 5.3-5.5); :mod:`perception.recognition.scoring`
scores them. A step n counts only if all three hand markers were seen at
n-1 (the state the prediction starts from; the wrist anchors every chain)
and the digits at n (the outcome); otherwise neither rule updates and the
filters coast.

The engine predicts and scores only: the models come planned for the clip's
scene (:meth:`perception.recognition.repertoire.Repertoire.for_scene`) and
calibrated (:mod:`perception.recognition.verdict`); each model's familiarity
is read off its calibration.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from minvar.kinematics import TwoLinkChain
from perception.errors import InputError
from perception.observation import Observation
from perception.recognition.leaves import Leaves, forward_kinematics
from perception.recognition.models import ChainModel, MotorModel
from perception.recognition.result import Recognition
from perception.recognition.scoring import RULES, THESIS_SIGNS, likelihood_rule, thesis_rule
from perception.recognition.verdict import DEFAULT_THRESHOLD, UNFAMILIAR_THRESHOLD, misfit

__all__ = ["HammerParams", "RULES", "recognize"]


@dataclass(frozen=True)
class HammerParams:
    """Settings of the recognition engine.

    Parameters
    ----------
    rule : str
        Rule that picks the winner: ``likelihood`` (default) or ``thesis``.
    w_r, w_g : float
        Weights of the transport and grip terms of the thesis rule (w_r/w_g = 1/2).
    obs_sd : float
        SD of the tracked positions after filtering, m (likelihood rule).
    familiarity_threshold : float
        Lowest familiarity (0..1) of the best model for the verdict ``normal``
        (or ``reach``); below it the verdict is ``abnormal``
        (:mod:`perception.recognition.verdict`).
    unfamiliar_threshold : float
        Lowest familiarity (0..1) of the movement's transport alone (digits
        held closed) to the best reach model; below it nothing in the
        repertoire explains the movement as a human reach or grasp and the
        verdict is ``unfamiliar``.
    filter_gain : float
        How strongly observed positions correct each model's own estimate of
        velocity and force: 1 applies the plan's Kalman gains as designed, 0
        leaves the estimate to the plan alone. At 1 the estimate learns the
        demonstration's velocity within a few frames, so predictions drift
        toward the inertial continuation every model shares; lower values
        keep each model's own timing. Measured on the synthetic stimuli
        (README): the normal grasp's confidence and one-step prediction error
        do not change with it, while delayed and open-close-open grasps earn
        less for motion the plan did not expect (final confidence 86 % and
        64 % of normal at 1, 63 % and 46 % at the default 0.3).
    thesis_sign : str
        Reading of the sign in the thesis rule (eqs. 5.1, 5.7, 5.8): ``text``
        (default; +1 when the observed and predicted changes agree, -1 when
        not, as the thesis's words say) or ``printed`` (the equations as
        printed: the observed change's sign alone). See docs/recognition.md.
    """

    rule: str = "likelihood"
    w_r: float = 1.0
    w_g: float = 2.0
    obs_sd: float = 0.001
    filter_gain: float = 0.3
    familiarity_threshold: float = DEFAULT_THRESHOLD
    unfamiliar_threshold: float = UNFAMILIAR_THRESHOLD
    thesis_sign: str = "text"

    def __post_init__(self):
        if self.rule not in RULES:
            raise ValueError(f"rule: expected one of {RULES}, got {self.rule!r}")
        if self.thesis_sign not in THESIS_SIGNS:
            raise ValueError(f"thesis_sign: expected one of {THESIS_SIGNS}, got "
                             f"{self.thesis_sign!r}")
        if not (np.isfinite(self.w_r) and np.isfinite(self.w_g) and self.w_r >= 0
                and self.w_g >= 0):
            raise ValueError(f"w_r, w_g: expected finite weights >= 0, got {self.w_r}, "
                             f"{self.w_g}")
        if not 0 <= self.filter_gain <= 1:
            raise ValueError(f"filter_gain: expected a value in [0, 1], got {self.filter_gain}")
        if not (np.isfinite(self.obs_sd) and self.obs_sd > 0):
            raise ValueError(f"obs_sd: expected a positive SD in m, got {self.obs_sd}")
        if not 0 <= self.familiarity_threshold <= 1:
            raise ValueError("familiarity_threshold: expected a value in [0, 1], got "
                             f"{self.familiarity_threshold}")
        if not 0 <= self.unfamiliar_threshold <= 1:
            raise ValueError("unfamiliar_threshold: expected a value in [0, 1], got "
                             f"{self.unfamiliar_threshold}")


def _clamp_reach(p: np.ndarray, l1: float, l2: float) -> np.ndarray:
    """Pull positions radially into the annulus a chain can reach (tracking can overshoot)."""
    d = np.linalg.norm(p, axis=-1, keepdims=True)
    lo, hi = abs(l1 - l2) + 1e-6, l1 + l2 - 1e-6
    safe = np.where(d > 0, d, 1.0)
    return np.where((d < lo) | (d > hi), p / safe * np.clip(d, lo, hi), p)


def _ik(p: np.ndarray, c: ChainModel) -> np.ndarray:
    """Joint angles (..., 2) for tip positions relative to the chain base; NaN stays NaN."""
    p = _clamp_reach(p, c.l1, c.l2)
    ok = np.isfinite(p).all(axis=-1)
    q = np.full(p.shape, np.nan)
    q[ok] = TwoLinkChain(c.l1, c.l2).inverse(p[ok], elbow=c.elbow)
    return q


def _unwrap_to(q: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Shift the first angle of each row by 2 pi k to lie nearest ``ref``."""
    q = q.copy()
    q[..., 0] += 2 * np.pi * np.round((ref[..., 0] - q[..., 0]) / (2 * np.pi))
    return q


def _model_steps(time: np.ndarray, dt: float) -> np.ndarray:
    """Model step of each frame, from the clip's real time stamps.

    Dropped frames and jitter land on the right step; every frame is at
    least one step after the one before.
    """
    s_of = np.round(time / dt).astype(int)
    idx = np.arange(len(time))
    return np.maximum.accumulate(s_of - idx) + idx


def _observed_angles(obs: Observation, chains: list[ChainModel]) -> np.ndarray:
    """(N, L, 2) joint angles of every leaf for the observed positions; NaN where lost.

    The arm's tip is the wrist about the shoulder; a digit's is its tip
    about the wrist.
    """
    w, f, t = obs.wrist, obs.finger, obs.thumb
    q = np.empty((obs.n_frames, len(chains), 2))
    cache: dict[tuple, np.ndarray] = {}
    for i, c in enumerate(chains):
        key = (c.role, c.l1, c.l2, tuple(c.base), c.elbow)
        if key not in cache:
            if c.role == "arm":
                rel = w - c.base
            else:
                rel = (f if c.role == "finger" else t) - w - c.base
            cache[key] = _ik(rel, c)
        q[:, i] = cache[key]
    return q


def _start(leaves: Leaves, steps: int) -> np.ndarray:
    """Each model's estimate from its plan's start, run on its own for ``steps`` model steps."""
    x = leaves.x0.copy()
    for s in range(steps):
        x = leaves.step(x, s)
    return x


def _advance(leaves: Leaves, x: np.ndarray, y: np.ndarray, s0: int, s1: int,
             gain: float) -> tuple[np.ndarray, np.ndarray]:
    """One frame on: the prediction (L, 2) of step ``s1`` from the angles ``y`` (L, 2) seen
    at step ``s0``, and the filter's estimate (L, n) at ``s1``."""
    ok = np.isfinite(y).all(axis=1)
    y = np.where(ok[:, None], _unwrap_to(np.nan_to_num(y), x[:, :2]), x[:, :2])
    # Two states per leaf step together: the prediction, which starts from
    # the observed joint angles (the filter's estimate supplies only what
    # is not observed: velocity, force), and the filter itself, which runs
    # on; the frame's observation enters it at its first model step, the
    # other steps are pure prediction.
    innov = y - x[:, :2]
    both = np.stack([x, x], axis=1)
    both[:, 0, :2] = y
    both = leaves.step(both, s0)
    both[:, 1] += gain * np.einsum("lip,lp->li", leaves.Kp[s0], innov)
    for s in range(s0 + 1, s1):
        both = leaves.step(both, s)
    return both[:, 0, :2], both[:, 1]


def _predict(leaves: Leaves, q_obs: np.ndarray, s_of: np.ndarray,
             gain: float) -> tuple[np.ndarray, np.ndarray]:
    """One-step predictions of every leaf's joint angles and their covariance.

    Returns ``q_pred`` (N, L, 2) rad (NaN at n = 0) and ``P_pred`` (N, L, 2, 2).
    """
    N = len(s_of)
    # Each model's estimate starts from its plan's start, run on its own up to
    # the first frame's step (a fraction of a frame after the onset).
    x = _start(leaves, int(s_of[0]))
    q_pred = np.full((N, leaves.count, 2), np.nan)
    P_pred = np.zeros((N, leaves.count, 2, 2))
    for n in range(1, N):
        q_pred[n], x = _advance(leaves, x, q_obs[n - 1], int(s_of[n - 1]), int(s_of[n]), gain)
        P_pred[n] = leaves.P[int(s_of[n])]
    return q_pred, P_pred


class _Predicted(NamedTuple):
    """Cartesian predictions of every model: positions (M, N, 2) m, covariances (M, N, 3, 2, 2)."""

    wrist: np.ndarray
    finger: np.ndarray
    thumb: np.ndarray
    cov: np.ndarray


def _to_cartesian(leaves: Leaves, q_pred: np.ndarray, P_pred: np.ndarray,
                  n_models: int) -> _Predicted:
    """Forward kinematics of the predicted angles, and their covariance through the Jacobians."""
    N = q_pred.shape[0]
    tip, J = forward_kinematics(q_pred, leaves.l1, leaves.l2)  # (N, L, 2), (N, L, 2, 2)
    tip = (tip + leaves.base).reshape(N, n_models, 3, 2)
    J = J.reshape(N, n_models, 3, 2, 2)
    cov = J @ P_pred.reshape(N, n_models, 3, 2, 2) @ np.swapaxes(J, -1, -2)
    wrist = tip[:, :, 0]
    to_mn = lambda a: np.swapaxes(a, 0, 1)  # noqa: E731 - (N, M, ...) -> (M, N, ...)
    return _Predicted(to_mn(wrist), to_mn(wrist + tip[:, :, 1]), to_mn(wrist + tip[:, :, 2]),
                      to_mn(cov))


def _refuse_broken_models(models: Sequence[MotorModel], observable: np.ndarray,
                          valid: np.ndarray) -> None:
    """A model that predicts nothing finite where the hand was seen has unusable gains.

    Left alone it would score 0.0 at every frame, its familiarity NaN and the
    verdict null, reported as a normal result.
    """
    if not observable.any():
        return
    dead = ~valid[:, observable].any(axis=1)
    if dead.any():
        names = [m.name for m, d in zip(models, dead) if d]
        raise InputError(f"model{'s' if len(names) > 1 else ''} {', '.join(names)} predict"
                         f"{'' if len(names) > 1 else 's'} no finite hand position at any of the "
                         f"{int(observable.sum())} frames where the hand was seen: the stored "
                         "gains or dynamics are unusable (rebuild the repertoire)",
                         field="repertoire")


def _refuse_non_finite(models: Sequence[MotorModel], scores: dict[str, np.ndarray]) -> None:
    """Scores that are not finite would turn into 0.0 or null in every report."""
    for what, values in scores.items():
        bad = ~np.isfinite(values).all(axis=1)
        if bad.any():
            names = [m.name for m, b in zip(models, bad) if b]
            raise InputError(f"the {what} of model {', '.join(names)} is not finite: its "
                             "predictions overflow (rebuild the repertoire)", field="repertoire")


def recognize(
    observation: Observation,
    models: Sequence[MotorModel],
    params: HammerParams | None = None,
) -> Recognition:
    """Score a demonstration against every model.

    Parameters
    ----------
    observation : Observation
        The demonstration in the model frame (from :func:`perception.observation.observe`).
    models : sequence of MotorModel
        The models, planned for the demonstration's scene (a
        :class:`~perception.recognition.repertoire.Repertoire` or the list
        :meth:`~perception.recognition.repertoire.Repertoire.for_scene` returns).
    params : HammerParams, optional
        Rule and weights.

    Returns
    -------
    Recognition
    """
    params = HammerParams() if params is None else params
    obs = observation
    models = list(models)
    dts = {round(m.dt, 12) for m in models}
    if len(dts) != 1:
        raise ValueError(f"models disagree on their time step: {sorted(dts)} s")
    s_of = _model_steps(obs.time, models[0].dt)
    leaves = Leaves(models, int(s_of[-1]) + 1)
    q_pred, P_pred = _predict(leaves, _observed_angles(obs, leaves.chains), s_of,
                              params.filter_gain)
    pred = _to_cartesian(leaves, q_pred, P_pred, len(models))
    midpoint = 0.5 * (pred.finger + pred.thumb)
    opening = pred.finger - pred.thumb
    r_pred, g_pred = np.linalg.norm(midpoint, axis=-1), np.linalg.norm(opening, axis=-1)
    r_obs, g_obs = obs.r, obs.g
    # A step counts only if the state it predicts from was observed (all three
    # markers at n-1: the wrist anchors every chain) and the outcome is (the
    # digits at n).
    seen = np.isfinite(np.stack([obs.wrist, obs.finger, obs.thumb], axis=1)).all(axis=(1, 2))
    observed = np.concatenate([[False], seen[:-1]]) & np.isfinite(r_obs) & np.isfinite(g_obs)
    prev_ok = np.concatenate([[False], np.isfinite(r_obs[:-1]) & np.isfinite(g_obs[:-1])])
    valid = (observed & prev_ok)[None] & np.isfinite(r_pred) & np.isfinite(g_pred)
    _refuse_broken_models(models, observed & prev_ok, valid)
    grasp = np.array([m.kind == "grasp" for m in models])
    dC_r, dC_g = thesis_rule(r_obs, g_obs, r_pred, g_pred, grasp, valid, params.w_r, params.w_g,
                             params.thesis_sign)
    dll, maha = likelihood_rule(r_obs, g_obs, midpoint, opening, pred.cov, valid, params.obs_sd)
    _refuse_non_finite(models, {"confidence": dC_r + dC_g, "log-likelihood": dll})
    mis = misfit(maha, valid)
    familiarity = np.array([np.nan if m.calibration is None
                            else m.calibration.familiarity(float(x), obs.dt)
                            for m, x in zip(models, mis)])
    return Recognition(
        clip=obs.clip,
        time=obs.time,
        frame=obs.frame,
        names=[m.name for m in models],
        kinds=[m.kind for m in models],
        confidence=np.cumsum(dC_r + dC_g, axis=1),
        dC_r=dC_r,
        dC_g=dC_g,
        log_likelihood=np.cumsum(dll, axis=1),
        mahalanobis=maha,
        scored=valid,
        familiarity=familiarity,
        predicted={"wrist": pred.wrist, "finger": pred.finger, "thumb": pred.thumb},
        observation=obs,
        models=models,
        rule=params.rule,
        familiarity_threshold=params.familiarity_threshold,
        unfamiliar_threshold=params.unfamiliar_threshold,
    )

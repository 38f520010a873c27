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

import copy
from collections.abc import Sequence
from typing import Literal, NamedTuple

import numpy as np

from minvar.kinematics import TwoLinkChain
from perception.errors import InputError
from perception.observation import Observation
from perception.recognition.leaves import Leaves, forward_kinematics
from perception.recognition.models import ChainModel, MotorModel
from perception.recognition.result import Recognition
from perception.recognition.rules import VerdictRules, judge
from perception.recognition.scoring import RULES, THESIS_SIGNS, likelihood_rule, thesis_rule
from perception.resume import Kept
from perception.rowwise import last_norm
from perception.validation import NonNegative, Positive, Share, declared

__all__ = ["ClipScores", "HammerParams", "RULES", "StepScorer", "recognize", "score_clip"]

#: Model steps a :class:`StepScorer`'s stacked gains are first made for (doubled when
#: a movement lasts longer; past a plan's horizon its gains stay the last ones).
FIRST_STEPS = 256


@declared
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

    rule: Literal[RULES] = "likelihood"
    w_r: NonNegative = 1.0
    w_g: NonNegative = 2.0
    obs_sd: Positive = 0.001
    filter_gain: Share = 0.3
    thesis_sign: Literal[THESIS_SIGNS] = "text"


def _clamp_reach(p: np.ndarray, l1: float, l2: float) -> np.ndarray:
    """Pull positions radially into the annulus a chain can reach (tracking can overshoot)."""
    d = last_norm(p)[..., None]
    lo, hi = abs(l1 - l2) + 1e-6, l1 + l2 - 1e-6
    safe = np.where(d > 0, d, 1.0)
    return np.where((d < lo) | (d > hi), p / safe * np.clip(d, lo, hi), p)


def _ik(p: np.ndarray, c: ChainModel, chain: TwoLinkChain | None = None) -> np.ndarray:
    """Joint angles (..., 2) for tip positions relative to the chain base; NaN stays NaN
    (``chain``: ``c``'s links, where the caller holds them)."""
    p = _clamp_reach(p, c.l1, c.l2)
    ok = np.isfinite(p).all(axis=-1)
    q = np.full(p.shape, np.nan)
    chain = TwoLinkChain(c.l1, c.l2) if chain is None else chain
    q[ok] = chain.inverse(p[ok], elbow=c.elbow)
    return q


def _unwrap_to(q: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Shift the first angle of each row by 2 pi k to lie nearest ``ref``."""
    q = q.copy()
    q[..., 0] += 2 * np.pi * np.round((ref[..., 0] - q[..., 0]) / (2 * np.pi))
    return q


def _observed_angles(w: np.ndarray, f: np.ndarray, t: np.ndarray,
                     chains: list[ChainModel]) -> np.ndarray:
    """(N, L, 2) joint angles of every leaf for wrist, finger and thumb positions (N, 2);
    NaN where lost.

    The arm's tip is the wrist about the shoulder; a digit's is its tip
    about the wrist.
    """
    q = np.empty((len(w), len(chains), 2))
    for c, chain, cols in _chain_groups(chains):
        if c.role == "arm":
            rel = w - c.base
        else:
            rel = (f if c.role == "finger" else t) - w - c.base
        q[:, cols] = _ik(rel, c, chain)[:, None]
    return q


def _chain_groups(chains: list[ChainModel]) -> list[tuple[ChainModel, TwoLinkChain, np.ndarray]]:
    """The leaves whose angles are the same (one role, geometry and base): the first
    chain of each group, its links and the group's columns.

    A stream scores the same leaves at every frame: grouped once per list of
    chains, not at each call (grouping 48 chains cost a frame more than their
    kinematics).
    """
    hit = _GROUPS.get(id(chains))
    if hit is not None and hit[0] is chains:
        return hit[1]
    groups: dict[tuple, tuple[ChainModel, list[int]]] = {}
    for i, c in enumerate(chains):
        key = (c.role, c.l1, c.l2, tuple(c.base), c.elbow)
        groups.setdefault(key, (c, []))[1].append(i)
    out = [(c, TwoLinkChain(c.l1, c.l2), np.array(cols)) for c, cols in groups.values()]
    _GROUPS[id(chains)] = (chains, out)  # the list held: its id is not reused while kept
    while len(_GROUPS) > 8:
        _GROUPS.pop(next(iter(_GROUPS)))
    return out


#: :func:`_chain_groups` per list of chains (the stacked leaves' ``chains``).
_GROUPS: dict[int, tuple[list, list]] = {}


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
    # unseen angles take the estimate's, which unwrap to themselves
    y = _unwrap_to(np.where(ok[:, None], y, x[:, :2]), x[:, :2])
    # Two states per leaf step together: the prediction, which starts from
    # the observed joint angles (the filter's estimate supplies only what
    # is not observed: velocity, force), and the filter itself, which runs
    # on; the frame's observation enters it at its first model step, the
    # other steps are pure prediction.
    innov = y - x[:, :2]
    both = np.repeat(x[:, None], 2, axis=1)  # np.stack([x, x], axis=1), at a third of its cost
    both[:, 0, :2] = y
    both = leaves.step(both, s0)
    both[:, 1] += gain * (leaves.Kp[s0] @ innov[:, :, None])[:, :, 0]
    for s in range(s0 + 1, s1):
        both = leaves.step(both, s)
    return both[:, 0, :2], both[:, 1]


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


def _terms(r_obs: np.ndarray, g_obs: np.ndarray, pred: _Predicted, valid: np.ndarray,
           grasp: np.ndarray, params: HammerParams):
    """Both rules' per-step terms (M, N): ``dC_r, dC_g, log-likelihood, Mahalanobis``."""
    midpoint = 0.5 * (pred.finger + pred.thumb)
    opening = pred.finger - pred.thumb
    # the predicted r and g once, for both rules (each norm was taken four times a frame)
    r_pred, g_pred = last_norm(midpoint), last_norm(opening)
    valid = valid & np.isfinite(r_pred) & np.isfinite(g_pred)
    dC_r, dC_g = thesis_rule(r_obs, g_obs, r_pred, g_pred, grasp, valid, params.w_r,
                             params.w_g, params.thesis_sign)
    dll, maha = likelihood_rule(r_obs, g_obs, midpoint, opening, pred.cov, valid, params.obs_sd,
                                norms=(r_pred, g_pred))
    return dC_r, dC_g, dll, maha, valid


class StepScorer:
    """Every model's one-step predictions and scores, one frame at a time.

    The engine's only implementation of a step: :func:`score_clip` runs it
    over a whole observation (the predictions frame by frame, their scoring
    vectorised); fed one frame at a time (:meth:`step`), after frame *n* its
    sums equal :func:`score_clip`'s arrays' column *n*. Each step costs the
    same however many came before: the state is the filters' estimate and
    the last frame, never the history.

    Parameters
    ----------
    models : sequence of MotorModel
        The models, planned for the clip's scene (one time step).
    params : HammerParams, optional
        Rule weights, observation noise and filter gain.
    steps : int
        Model steps to stack the gains for at first.

    Attributes
    ----------
    confidence, log_likelihood : (M,) arrays
        Thesis-rule confidence and log-likelihood so far.
    mahalanobis : (M,) array
        Sum of the squared Mahalanobis distances of the scored steps.
    scored : (M,) int array
        Steps scored so far, per model.
    """

    def __init__(self, models: Sequence[MotorModel], params: HammerParams | None = None,
                 steps: int = FIRST_STEPS):
        self.models = list(models)
        self.params = HammerParams() if params is None else params
        dts = {round(m.dt, 12) for m in self.models}
        if len(dts) != 1:
            raise ValueError(f"models disagree on their time step: {sorted(dts)} s")
        self.dt = self.models[0].dt
        self.leaves = Leaves.of(self.models, max(int(steps), 1))
        self.grasp = np.array([m.kind == "grasp" for m in self.models])
        self.restart()

    def restart(self) -> None:
        """Start over, from before the first frame (the stacked gains are kept)."""
        M = len(self.models)
        self.confidence = np.zeros(M)
        self.log_likelihood = np.zeros(M)
        self.mahalanobis = np.zeros(M)
        self.scored = np.zeros(M, dtype=int)
        self.frames = 0
        self._shift = None  # the largest (model step - frame index) so far
        self._x = None
        self._prev = None  # (model step, angles, all three seen) of the last frame
        self._last = (np.nan, np.nan, False)  # its r, g and whether all three were seen

    @property
    def misfit(self) -> np.ndarray:
        """(M,) mean squared Mahalanobis distance per scored step so far (NaN before any)."""
        return np.where(self.scored > 0, self.mahalanobis / np.maximum(self.scored, 1), np.nan)

    def familiarity(self, frame_period: float) -> np.ndarray:
        """(M,) each model's familiarity of the movement so far (NaN without calibration).

        Parameters
        ----------
        frame_period : float
            The clip's frame period, s.
        """
        return np.array([np.nan if m.calibration is None
                         else m.calibration.familiarity(float(x), frame_period)
                         for m, x in zip(self.models, self.misfit)])

    def model_step(self, time: float) -> int:
        """The model step of the next frame at ``time`` s since the onset.

        Dropped frames and jitter land on the right step; every frame is at
        least one step after the one before.
        """
        s = int(np.round(time / self.dt)) - self.frames
        self._shift = s if self._shift is None else max(self._shift, s)
        self.frames += 1
        step = self._shift + self.frames - 1
        if step >= len(self.leaves.P):
            self.leaves = Leaves.of(self.models, 2 * step)
        return step

    def predict(self, step: int, angles: np.ndarray, seen: bool) -> np.ndarray | None:
        """Every leaf's prediction (L, 2) of model step ``step`` from the last frame's angles,
        and the filters advanced to it; then ``angles`` (L, 2) are this frame's.

        None at the first frame (nothing to predict from).
        """
        prev, self._prev = self._prev, (step, angles, seen)
        if prev is None:
            self._x = _start(self.leaves, step)
            return None
        q_pred, self._x = _advance(self.leaves, self._x, prev[1], prev[0], step,
                                   self.params.filter_gain)
        return q_pred

    def step(self, time: float, wrist, finger, thumb) -> None:
        """:meth:`score` one frame: ``time`` s since the onset, positions (2,) m."""
        self.score(np.atleast_1d(time), *(np.asarray(p, dtype=float)[None]
                                          for p in (wrist, finger, thumb)))

    def score(self, time: np.ndarray, wrist: np.ndarray, finger: np.ndarray,
              thumb: np.ndarray) -> _Steps:
        """Score the next frames, adding them to the sums; their per-step terms.

        The filters run frame by frame; the kinematics and the rules are
        vectorised over the frames given. A step counts only if the state it
        predicts from was observed (all three markers at n-1: the wrist
        anchors every chain) and the outcome is (the digits at n).

        Parameters
        ----------
        time : (N,) array
            Times since the movement's onset, s.
        wrist, finger, thumb : (N, 2) arrays
            Filtered positions (the digit tips), m; NaN where lost.
        """
        M, N = len(self.models), len(time)
        steps = [self.model_step(float(t)) for t in time]
        q_obs = _observed_angles(wrist, finger, thumb, self.leaves.chains)
        seen = np.isfinite(np.stack([wrist, finger, thumb], axis=1)).all(axis=(1, 2))
        q_pred = np.full((N, self.leaves.count, 2), np.nan)
        P_pred = np.zeros((N, self.leaves.count, 2, 2))
        for n, s in enumerate(steps):
            q = self.predict(s, q_obs[n], bool(seen[n]))
            if q is not None:
                q_pred[n], P_pred[n] = q, self.leaves.P[s]
        pred = _to_cartesian(self.leaves, q_pred, P_pred, M)
        # the frame before these, for the changes the rules score
        # (np.concatenate, not np.r_: 12 us a call, four calls a pass)
        r = np.concatenate(([self._last[0]], last_norm(0.5 * (finger + thumb))))
        g = np.concatenate(([self._last[1]], last_norm(finger - thumb)))
        seen = np.concatenate(([self._last[2]], seen))
        self._last = (r[-1], g[-1], seen[-1])
        ok = np.isfinite(r) & np.isfinite(g)
        observable = np.concatenate(([False], seen[:-1] & ok[:-1] & ok[1:]))
        pred = _Predicted(*(np.concatenate([np.full_like(a[:, :1], np.nan), a], axis=1)
                            for a in pred))
        terms = _terms(r, g, pred, observable[None].repeat(M, 0), self.grasp, self.params)
        terms = _Steps(*(x[:, 1:] for x in terms), _Predicted(*(a[:, 1:] for a in pred)),
                       observable[1:])
        self.confidence += (terms.dC_r + terms.dC_g).sum(axis=1)
        self.log_likelihood += terms.log_likelihood.sum(axis=1)
        self.mahalanobis += terms.mahalanobis.sum(axis=1)
        self.scored += terms.valid.sum(axis=1)
        return terms


class _Steps(NamedTuple):
    """Per-step terms (M, N) of :meth:`StepScorer.score`; ``observable``: (N,) the hand seen."""

    dC_r: np.ndarray
    dC_g: np.ndarray
    log_likelihood: np.ndarray
    mahalanobis: np.ndarray
    valid: np.ndarray
    predicted: _Predicted
    observable: np.ndarray


class ClipScores(NamedTuple):
    """Every model's scores over one observation (:func:`score_clip`): the arrays of a
    :class:`~perception.recognition.result.Recognition`, before any verdict."""

    names: list
    kinds: list
    confidence: np.ndarray
    dC_r: np.ndarray
    dC_g: np.ndarray
    log_likelihood: np.ndarray
    mahalanobis: np.ndarray
    scored: np.ndarray
    familiarity: np.ndarray
    predicted: dict
    rule: str

    def best(self, among: Sequence[int] | None = None) -> int:
        """Index of the model with the highest final log-likelihood (of ``among``)."""
        among = range(len(self.names)) if among is None else among
        among = list(among)
        return among[int(np.argmax(self.log_likelihood[among, -1]))]


def score_clip(observation: Observation, models: Sequence[MotorModel],
               params: HammerParams | None = None) -> ClipScores:
    """Score a demonstration against every model: one scoring pass, no verdict.

    Parameters
    ----------
    observation : Observation
        The demonstration in the model frame.
    models : sequence of MotorModel
        The models, planned for its scene.
    params : HammerParams, optional
        Rule and weights.
    """
    obs, models = observation, list(models)
    params = HammerParams() if params is None else params
    arrays = (obs.time, obs.wrist, obs.finger, obs.thumb)
    key = _key(models, params, obs.dt)
    # a stream judged row by row scores the same movement again once it has ended
    same = _SCORED.longest(key, arrays, first=lambda series: len(series[0]) == len(obs.time))
    if same is not None:
        return same[1][1]
    scorer, terms = _scored(models, key, obs, arrays)
    dC_r, dC_g, dll, maha, valid, pred, _ = terms
    _refuse_broken_models(models, terms.observable, valid)
    _refuse_non_finite(models, {"confidence": dC_r + dC_g, "log-likelihood": dll})
    scores = ClipScores(
        names=[m.name for m in models], kinds=[m.kind for m in models],
        confidence=np.cumsum(dC_r + dC_g, axis=1), dC_r=dC_r, dC_g=dC_g,
        log_likelihood=np.cumsum(dll, axis=1), mahalanobis=maha, scored=valid,
        familiarity=scorer.familiarity(obs.dt),
        predicted={"wrist": pred.wrist, "finger": pred.finger, "thumb": pred.thumb},
        rule=scorer.params.rule)
    for a in (*scores[2:9], *scores.predicted.values()):
        a.flags.writeable = False  # shared by every result made from the same scores
    _SCORED.keep(key, arrays, (models, scores))  # copied there
    return scores


def _key(models: list, params: HammerParams, dt: float) -> tuple:
    """What scores are kept under: the models themselves (by identity: the entries
    hold them, so their ids stay theirs), the settings and the frame period."""
    return tuple(map(id, models)), params, dt


def _scored(models: list, key: tuple, obs: Observation, arrays: tuple
            ) -> tuple[StepScorer, _Steps]:
    """The scorer after every frame of ``obs`` and their per-step terms: resumed after the
    longest movement scored before (in this thread, with these models and settings) that
    this one begins with, bitwise, else scored from the first frame.

    The online recogniser scores the rows so far after every row: each
    movement is the last one and a frame more. The filters are causal and the
    per-step terms of a frame read only it and the frame before, so the
    frames scored before are scored alike (the same operations on the same
    numbers); the sums are taken again over every frame, so that they are
    added in the order a pass from the first frame adds them.
    """
    params = key[1]
    best = _RESUMABLE.longest(key, arrays, shorter=True)
    if best is None:
        # gains stacked once for the whole clip
        scorer = StepScorer(models, params, steps=int(round(obs.time[-1] / models[0].dt))
                            + obs.n_frames + 1)
        terms = scorer.score(*arrays)
        terms = terms._replace(predicted=terms.predicted._replace(cov=None))
    else:
        n, (_, kept_scorer, old) = len(best[0][0]), best[1]
        scorer = copy.copy(kept_scorer)  # kept as it was after its frames: resumed on a copy
        for name in ("confidence", "log_likelihood", "mahalanobis", "scored"):
            setattr(scorer, name, getattr(scorer, name).copy())
        new = scorer.score(*(a[n:] for a in arrays))
        both = lambda a, b: np.concatenate([a, b], axis=-1 if a.ndim == 1 else 1)  # noqa: E731
        terms = _Steps(*(both(a, b) for a, b in zip(old[:5], new[:5])),
                       _Predicted(*(both(a, b) for a, b in zip(old.predicted[:3],
                                                               new.predicted[:3])), None),
                       both(old.observable, new.observable))
        # the sums in the order one pass adds them (a sum in two parts may differ in its
        # last bit)
        scorer.confidence = (terms.dC_r + terms.dC_g).sum(axis=1)
        scorer.log_likelihood = terms.log_likelihood.sum(axis=1)
        scorer.mahalanobis = terms.mahalanobis.sum(axis=1)
        scorer.scored = terms.valid.sum(axis=1)
    _RESUMABLE.keep(key, arrays, (models, scorer, terms), best)
    return scorer, terms


#: Scores kept per thread (the verdict's pass and the transport's of the last movements),
#: reused for the same movement, models and settings (:func:`score_clip`), and the
#: scorers after them, resumed by a longer movement that begins with one (:func:`_scored`).
KEPT_SCORES = 4
_SCORED = Kept(KEPT_SCORES)
_RESUMABLE = Kept(KEPT_SCORES)


def recognize(
    observation: Observation,
    models: Sequence[MotorModel],
    params: HammerParams | None = None,
    rules: VerdictRules | None = None,
) -> Recognition:
    """Score a demonstration against every model, and judge it on the scores alone.

    One pass at the observation's own scene, with the verdict of
    :func:`perception.recognition.rules.judge` on the best model's
    familiarity (no landmarks, no reference scale: a clip's recognition is
    :func:`perception.pipeline.recognize_tracks`).

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
    rules : VerdictRules, optional
        The verdict's rules (the result's :attr:`~Recognition.rules`).

    Returns
    -------
    Recognition
    """
    from perception.recognition.evidence import clip_landmarks, movement_evidence

    rules = VerdictRules() if rules is None else rules
    models = list(models)
    scores = score_clip(observation, models, params)
    evidence = movement_evidence(observation, scores.kinds, scores.log_likelihood[:, -1],
                                 scores.familiarity)
    return Recognition(
        clip=observation.clip, time=observation.time, frame=observation.frame,
        **scores._asdict(), observation=observation, models=models, rules=rules,
        evidence=evidence, decision=judge(evidence, rules),
        landmarks=clip_landmarks(observation, models, scores.log_likelihood[:, -1], rules))

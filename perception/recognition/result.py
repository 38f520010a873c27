"""The result of scoring one demonstration against a repertoire."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from perception.landmarks import Landmarks, longest_gap, model_landmarks, observed_landmarks
from perception.recognition.rules import (
    VERDICT_RULES,
    Evidence,
    Verdict,
    VerdictRules,
    judge,
    slowed,
)
from perception.recognition.verdict import misfit

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

    from perception.observation import Observation
    from perception.recognition.models import MotorModel
    from perception.recognition.shape import Normalisation

__all__ = ["VERDICT_RULES", "Recognition"]


#: The movement times (onset to end by the field's rule, s) the verdict was
#: validated on: the synthetic populations' 0.45-1.2 s grasps and a lab's real
#: Optotrak grasps (1.05-2.06 s).
VALIDATED_MOVEMENT_TIME = (0.4, 2.1)
#: The reach distances (wrist at rest to the object's centre, m) it was validated on.
VALIDATED_DISTANCE = (0.1, 0.7)

@dataclass(frozen=True, eq=False)
class Recognition:
    """Confidence of every model over one demonstration.

    Attributes
    ----------
    clip : str
        Clip name.
    time : (N,) array
        Time since movement onset, s.
    frame : (N,) int array
        Video frame of each sample.
    names, kinds : list of str
        Model names and kinds (M of them).
    confidence : (M, N) array
        Thesis-rule confidence C_n (C_0 = 0).
    dC_r, dC_g : (M, N) arrays
        Per-step transport and grip terms of the thesis rule.
    log_likelihood : (M, N) array
        Cumulative log-likelihood of the observed (r, g).
    mahalanobis : (M, N) array
        Squared Mahalanobis distance of each step's observed (r, g) from the
        prediction (0 where not scored).
    scored : (M, N) bool array
        Steps that count (both rules score 0 elsewhere).
    familiarity : (M,) array
        Each model's familiarity, 0..1 (NaN for a model without calibration).
    predicted : dict of (M, N, 2) arrays
        Predicted ``wrist``, ``finger``, ``thumb`` positions, m (NaN at n = 0).
    observation : Observation
        What was scored.
    models : list of MotorModel
        The models scored (for their nominal movements).
    rule : str
        The rule that picks the winner.
    rules : VerdictRules
        The verdict's rules (:mod:`perception.recognition.rules`).
    shape : Recognition or None
        The same demonstration brought to the repertoire's reference scale
        and scored against its models there (:mod:`perception.recognition.shape`):
        when present, the verdict, familiarity and margin are its.
    normalisation : Normalisation or None
        How it was brought to that scale.
    transport_familiarity : float
        Familiarity of the movement's transport alone (digits held closed, at
        the reference scale) to the best reach model; NaN if not measured.
    mirrored : bool
        The scene was found mirrored (the finger opening on the model's -x
        side) and its mirror image was scored: the opposite of ``--mirror``.
    measured : Landmarks, optional
        The demonstration's landmarks measured on better data than the
        observation holds (a 3D recording's own speed and aperture, on the
        observation's clock); otherwise they are measured on the observation.
    notes : tuple of str
        What was done to the clip before it was scored (a start without
        rest: :func:`perception.settling.settle_start`).
    """

    clip: str
    time: np.ndarray
    frame: np.ndarray
    names: list[str]
    kinds: list[str]
    confidence: np.ndarray = field(repr=False)
    dC_r: np.ndarray = field(repr=False)
    dC_g: np.ndarray = field(repr=False)
    log_likelihood: np.ndarray = field(repr=False)
    mahalanobis: np.ndarray = field(repr=False)
    scored: np.ndarray = field(repr=False)
    familiarity: np.ndarray = field(repr=False)
    predicted: dict = field(repr=False)
    observation: Observation = field(repr=False)
    models: list[MotorModel] = field(repr=False)
    rule: str = "likelihood"
    rules: VerdictRules = field(default_factory=VerdictRules, repr=False)
    shape: Recognition | None = field(default=None, repr=False)
    normalisation: Normalisation | None = None
    transport_familiarity: float = float("nan")
    mirrored: bool = False
    measured: Landmarks | None = field(default=None, repr=False)
    notes: tuple[str, ...] = ()

    def score(self, rule: str | None = None) -> np.ndarray:
        """(M, N) cumulative score under ``rule`` (default: the winner's rule)."""
        rule = rule or self.rule
        return self.log_likelihood if rule == "likelihood" else self.confidence

    def winner_at(self, n: int, rule: str | None = None) -> str:
        """Name of the best model after sample ``n`` (index into :attr:`time`) under ``rule``."""
        return self.names[int(np.argmax(self.score(rule)[:, n]))]

    @property
    def winner(self) -> str | None:
        """Best model at the end of the demonstration, by :attr:`rule` (None: no step scored)."""
        return self.winner_at(-1) if self.scored.any() else None

    @property
    def final_confidence(self) -> dict[str, float]:
        """Thesis-rule confidence of each model at the end."""
        return {n: float(c) for n, c in zip(self.names, self.confidence[:, -1])}

    @property
    def misfit(self) -> np.ndarray:
        """(M,) mean squared Mahalanobis distance per scored step of each model."""
        return misfit(self.mahalanobis, self.scored)

    @property
    def familiarity_threshold(self) -> float:
        """Lowest familiarity of the best model called familiar (``rules``')."""
        return self.rules.familiarity_threshold

    @property
    def unfamiliar_threshold(self) -> float:
        """Below this transport familiarity the verdict is ``unfamiliar`` (``rules``')."""
        return self.rules.unfamiliar_threshold

    @property
    def verdict_rule(self) -> str | None:
        """The rule that gave the verdict (one of :data:`VERDICT_RULES`; None without one)."""
        return self.decision.rule

    @property
    def evidence(self) -> Evidence:
        """What the verdict is judged on: the reference pass's scores and the movement's
        own landmarks, rest aperture and gaps (a lone pass, without a :attr:`shape`:
        its scores alone)."""
        if self.shape is None:
            return Evidence(self.kinds, self.log_likelihood[:, -1], self.familiarity)
        obs, shape = self.observation, self.shape
        scored = shape.scored.sum(axis=1).max() / max(shape.scored.shape[1] - 1, 1)
        raw = obs.raw or {}  # the filtered aperture coasts through a gap: the markers' own
        g = (np.linalg.norm(raw["finger"] - raw["thumb"], axis=1) if "finger" in raw
             and "thumb" in raw else obs.g)
        return Evidence(shape.kinds, shape.log_likelihood[:, -1], shape.familiarity,
                        self.transport_familiarity, obs.marker_separation, *self.landmarks,
                        longest_gap(obs.time, g), slowed(obs.time, obs.wrist), float(scored))

    @cached_property
    def decision(self) -> Verdict:
        """The verdict, judged once (:func:`perception.recognition.rules.judge`).

        With a :attr:`shape` pass, the scores are that pass's: the movement's
        coordination judged at the repertoire's reference scale, not its
        speed, size or camera.
        """
        return judge(self.evidence, self.rules)

    @property
    def verdict(self) -> str | None:
        """``normal``, ``abnormal``, ``reach`` or ``unfamiliar`` (None without calibrations)."""
        return self.decision.verdict

    @property
    def verdict_reason(self) -> str | None:
        """Why an ``unfamiliar`` or ``abnormal`` verdict was given, in words (None otherwise).

        ``unfamiliar`` is "not a human reach" (even the transport is like
        none of the reach models' own), "insufficient data" naming the digit
        lost longest and where (or the movements seen), or "incomplete";
        ``abnormal`` names the rule.
        """
        rule = self.verdict_rule
        if rule == "not-a-precision-grip":
            return (f"not a precision grip: the digits start "
                    f"{self.observation.marker_separation * 100:.0f} cm apart (the "
                    "verdict knows grasps whose digits start closed)")
        if rule == "not-a-human-reach":
            return (f"not a human reach: its transport fits the reach models worse than "
                    f"{1 - self.unfamiliar_threshold:.0%} of their own reaches")
        if rule == "insufficient-data" and self.verdict_detail == "several-movements":
            return (f"insufficient data: {self.landmarks[0].movements} movements in the clip "
                    "(the verdict judges one)")
        if rule == "insufficient-data" and self.evidence.scored_share < self.rules.min_scored:
            return (f"insufficient data: the digits are seen in two frames running on "
                    f"{self.evidence.scored_share:.0%} of the movement's steps (a verdict "
                    f"needs {self.rules.min_scored:.0%})")
        if rule == "insufficient-data":
            return "insufficient data: " + self._longest_loss()
        if rule == "incomplete":
            return (f"incomplete: the clip ends before the hand arrives (its transport slowed "
                    f"by {self.evidence.slowed:.0%} of its peak speed, not "
                    f"{self.rules.arrival:.0%})")
        if rule == "grip-departs":
            return "the grip opens late or twice (the field's landmarks)"
        if self.verdict == "abnormal":
            return (f"no model explains the movement as well as "
                    f"{1 - self.familiarity_threshold:.0%} of its own movements")
        return None


    def _longest_loss(self) -> str:
        """The digit lost longest during the movement, for how long and where."""
        obs, lm = self.observation, self.landmarks[0]
        worst = (0.0, "", math.nan)
        for name in ("finger", "thumb"):
            values = obs.raw.get(name) if obs.raw else None
            if values is None:
                continue
            gap = longest_gap(obs.time, values[:, 0])
            seen = obs.time[np.isfinite(values[:, 0])]
            if gap == worst[0] and worst[1]:
                worst = (gap, "digits", worst[2])
            elif gap > worst[0] and len(seen):
                steps = np.diff(np.r_[obs.time[0], seen, obs.time[-1]])
                k = int(np.argmax(steps))
                start = float(np.r_[obs.time[0], seen][k])
                worst = (gap, name, start)
        gap, name, start = worst
        if not name:
            return "the digits are seen too little to score"
        where = ""
        if math.isfinite(lm.onset_time) and lm.movement_time > 0:
            a = (start - lm.onset_time) / lm.movement_time
            b = (start + gap - lm.onset_time) / lm.movement_time
            where = f" at {max(a, 0):.0%}-{min(b, 1):.0%} of the movement"
        lost = "the digits were" if name == "digits" else f"the {name} was"
        lp = self.rules.landmarks
        return (f"{lost} lost {gap:.2f} s{where} (a gap over {lp.max_gap:.2f} s and "
                f"{lp.max_gap_share:.0%} of the movement may hide a second opening)")

    @property
    def warnings(self) -> list[str]:
        """Where the movement lies outside what the verdict was validated on (docs/mocap.md)."""
        out = []
        lm = self.landmarks[0]
        lo, hi = VALIDATED_MOVEMENT_TIME
        if math.isfinite(lm.movement_time) and not lo <= lm.movement_time <= hi:
            out.append(f"movement time {lm.movement_time:.2f} s is outside the "
                       f"{lo}-{hi} s the verdict was validated on")
        lo, hi = VALIDATED_DISTANCE
        d = self.observation.start_distance
        if not lo <= d <= hi:
            out.append(f"reach distance {d:.2f} m is outside the {lo}-{hi} m the verdict "
                       "was validated on")
        if math.isfinite(lm.movement_time) and lm.movement_time > 0 and self.shape is not None:
            n = self.normalisation
            if n is not None and abs(n.time_scale - 1) > 1e-9:
                out.append(f"judged at the repertoire's speed: times scaled by "
                           f"{n.time_scale:.2f}")
        return out

    @property
    def reference_model(self) -> str | None:
        """The grasp model with the highest log-likelihood (None if there is none)."""
        grasp = [i for i, k in enumerate(self.kinds) if k == "grasp"]
        if not grasp:
            return None
        return self.names[grasp[int(np.argmax(self.log_likelihood[grasp, -1]))]]

    def nominal(self, model: str) -> dict[str, np.ndarray]:
        """The model's own noise-free movement at this clip's sample times.

        What the model would do from its planned start (thesis Figs. 5.5-5.7
        draw it against the demonstration), aligned on the clip's movement onset.

        Parameters
        ----------
        model : str
            Model name.

        Returns
        -------
        dict of (N, 2) arrays
            ``wrist``, ``finger``, ``thumb`` positions, m.
        """
        from perception.recognition.rollout import rollout

        m = self.models[self.names.index(model)]
        steps = int(np.ceil(max(self.time[-1], 0.0) / m.dt)) + 1
        run = rollout([m], steps)
        out = {}
        for key in ("wrist", "finger", "thumb"):
            xy = getattr(run, key)[0, 0]
            out[key] = np.stack([np.interp(self.time, run.time, xy[:, 0]),
                                 np.interp(self.time, run.time, xy[:, 1])], axis=1)
        return out

    def own_landmarks(self, model: str) -> Landmarks:
        """The landmarks of a model's own noise-free movement (:func:`nominal`'s).

        Its movement from its planned start, run until half its planned
        duration past its end, bounded by the verdict rules' landmark
        definitions (``rules.landmarks``: onset and end at 5 % of the peak
        speed by default), as a clip's are.

        Parameters
        ----------
        model : str
            Model name.
        """
        from perception.recognition.rollout import rollout

        m = self.models[self.names.index(model)]
        run = rollout([m], int(np.ceil(1.5 * m.duration / m.dt)) + 1)
        return model_landmarks(run.time, run.wrist[0, 0], run.finger[0, 0], run.thumb[0, 0],
                               self.rules.landmarks)

    @cached_property
    def landmarks(self) -> tuple[Landmarks, Landmarks | None]:
        """The demonstration's landmarks and the reference grasp model's own (None without one)."""
        ref = self.reference_model
        observed = self.measured if self.measured is not None else observed_landmarks(
            self.observation, self.rules.landmarks)
        return (observed,
                self.own_landmarks(ref) if ref is not None else None)

    @property
    def kinematics(self) -> dict:
        """The ``kinematics`` of the report: ``observed``, ``reference``, ``reference_model``."""
        observed, reference = self.landmarks
        return {"observed": observed.to_dict(),
                "reference": reference.to_dict() if reference is not None else None,
                "reference_model": self.reference_model}

    @property
    def verdict_detail(self) -> str | None:
        """The kind of an ``abnormal`` verdict; None for any other.

        :func:`perception.recognition.rules.verdict_detail`.
        """
        return self.decision.detail

    @property
    def predicted_r(self) -> np.ndarray:
        """(M, N) predicted distance of the grip midpoint to the object, m."""
        mid = 0.5 * (self.predicted["finger"] + self.predicted["thumb"])
        return np.linalg.norm(mid, axis=-1)

    @property
    def predicted_g(self) -> np.ndarray:
        """(M, N) predicted grip aperture, m."""
        return np.linalg.norm(self.predicted["finger"] - self.predicted["thumb"], axis=-1)

    def columns(self) -> dict[str, np.ndarray]:
        """Per-step terms as columns, one row per model and sample.

        Columns: time, frame, model, kind, C, dC_r, dC_g, log_likelihood. The
        table of ``<clip>.confidence.csv`` and of :meth:`to_pandas`.
        """
        M, N = self.confidence.shape
        return {
            "time": np.tile(self.time, M),
            "frame": np.tile(self.frame, M),
            "model": np.repeat(self.names, N),
            "kind": np.repeat(self.kinds, N),
            "C": self.confidence.ravel(),
            "dC_r": self.dC_r.ravel(),
            "dC_g": self.dC_g.ravel(),
            "log_likelihood": self.log_likelihood.ravel(),
        }

    def to_pandas(self) -> pd.DataFrame:
        """Per-step terms, one row per model and sample (:meth:`columns`)."""
        import pandas as pd

        return pd.DataFrame(self.columns())

    def plot(self, kind: str = "confidence") -> Figure:
        """The clip's figure as a matplotlib ``Figure`` (matplotlib is imported here).

        Parameters
        ----------
        kind : str
            ``confidence``: every model's confidence and log-likelihood
            (:func:`~perception.report.figures.confidence_figure`, the
            report's ``<clip>.confidence.png``); ``paths``: the demonstration
            against the reference grasp model's own movement
            (:func:`~perception.report.figures.paths_figure`, ``<clip>.paths.png``).
        """
        from perception.report.figures import confidence_figure, paths_figure
        from perception.report.kinematics import kinematics_figure

        figures = {"confidence": confidence_figure, "paths": paths_figure,
                   "kinematics": kinematics_figure}
        if kind not in figures:
            raise ValueError(f"Recognition.plot: kind must be one of {sorted(figures)}, "
                             f"not {kind!r}")
        return figures[kind](self)

    def to_dict(self) -> dict:
        """The recognition report (``<clip>.recognition.json``); NaN becomes None."""
        d = self.decision
        transport = np.cumsum(self.dC_r, axis=1)
        return {
            "clip": self.clip,
            "models": [
                {"name": n, "kind": k, "final_confidence": float(c),
                 "final_log_likelihood": float(ll), "misfit": _num(mf),
                 "familiarity": _num(f)}
                for n, k, c, ll, mf, f in zip(self.names, self.kinds, self.confidence[:, -1],
                                              self.log_likelihood[:, -1], self.misfit,
                                              self.familiarity)
            ],
            "winner": self.winner,
            "rule": self.rule,
            "verdict": d.verdict,
            "verdict_detail": self.verdict_detail,
            "verdict_rule": self.verdict_rule,
            "verdict_rules": self.rules.to_dict(),
            "verdict_reason": self.verdict_reason,
            "warnings": self.warnings,
            "notes": list(self.notes),
            "familiarity": _num(d.familiarity),
            "margin": _num(d.margin),
            "familiarity_threshold": float(self.familiarity_threshold),
            "reference_model": self.reference_model,
            "shape": _shape_summary(self),
            "passes": _passes(self),
            "mirrored": bool(self.mirrored),
            "time": [float(t) for t in self.time],
            "confidence": {n: [float(c) for c in row]
                           for n, row in zip(self.names, self.confidence)},
            "transport_confidence": {n: [float(c) for c in row]
                                     for n, row in zip(self.names, transport)},
            "aperture": [_num(g) for g in self.observation.g],
            "kinematics": self.kinematics,
        }


def _shape_summary(rec: Recognition) -> dict | None:
    if rec.shape is None:
        return None
    d = rec.shape.decision
    out = {"model": rec.shape.names[d.best], "familiarity": _num(d.familiarity),
           "margin": _num(d.margin), "transport_familiarity": _num(rec.transport_familiarity)}
    if rec.normalisation is not None:
        out.update({k: _num(v) for k, v in rec.normalisation.to_dict().items()})
    return out


def _passes(rec: Recognition) -> dict:
    """Which scoring pass gave what: ``winner`` and the profiles come from the clip's own
    scene, the verdict from the reference pass (the scene's without one)."""
    out = {"scene": {"models": list(rec.names), "winner": rec.winner},
           "winner_from": "scene", "verdict_from": "scene" if rec.shape is None else "reference"}
    if rec.shape is not None:
        d = rec.decision
        out["reference"] = {"models": list(rec.shape.names), "best": rec.shape.names[d.best],
                            "familiarity": _num(d.familiarity)}
        out["transport"] = {"familiarity": _num(rec.transport_familiarity)}
    return out


def _num(x: float) -> float | None:
    """A float for JSON: None where it is not finite (JSON has no NaN)."""
    x = float(x)
    return x if np.isfinite(x) else None

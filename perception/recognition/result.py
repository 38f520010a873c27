"""The result of scoring one demonstration against a repertoire."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from perception.landmarks import Landmarks, longest_gap
from perception.recognition.evidence import model_own_landmarks, reference_model
from perception.recognition.rules import VERDICT_RULES, Evidence, Verdict, VerdictRules, reason
from perception.recognition.verdict import misfit

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

    from perception.observation import Observation
    from perception.recognition.models import MotorModel
    from perception.recognition.shape import Normalisation

__all__ = ["VALIDATED_DISTANCE", "VALIDATED_MOVEMENT_TIME", "VALIDATED_PEAK_SPEED", "VERDICT_RULES",
           "Recognition", "ValidationWarning", "warnings_summary"]


#: The movement times (onset to end by the field's rule, s) the verdict was
#: validated on: the synthetic populations' 0.45-1.2 s grasps and a lab's real
#: Optotrak grasps (1.05-2.06 s).
VALIDATED_MOVEMENT_TIME = (0.4, 2.1)
#: A wrist that keeps its offset from the grip midpoint within this, m, in every sample
#: was placed there, not tracked (:attr:`Recognition.wrist_synthesised`).
SYNTHESISED_TOLERANCE = 1e-6
#: The reach distances (wrist at rest to the object's centre, m, as the observation
#: measures it: a motion-capture reach's wrist is placed 6 cm behind the grip) it was
#: validated on: the synthetic populations' 0.22-0.40 m and the shared Optotrak table's
#: 60 grasps (the rules chosen on its even trials, checked on its odd ones: docs/mocap.md),
#: 0.55-0.715 m.
VALIDATED_DISTANCE = (0.1, 0.72)
#: The peak speeds (the transport's, m/s) it was validated on: the synthetic
#: populations' 0.22-0.40 m in 0.45-1.4 s (about 0.3-2 m/s) and the shared Optotrak
#: grasps' 0.74-1.32 m/s. A hand far slower is often a unit too small for the numbers
#: (centimetres read as millimetres), which perception.plausibility cannot refuse.
VALIDATED_PEAK_SPEED = (0.25, 2.5)


@dataclass(frozen=True)
class ValidationWarning:
    """Where a movement lies outside what the verdict was validated on.

    Attributes
    ----------
    kind : str
        ``movement_time`` (s), ``distance`` (the reach's, m), ``peak_speed``
        (the transport's, m/s) or ``time_scale`` (the shape pass's speed
        rescaling, a factor).
    value : float
        The movement's, in that unit.
    text : str
        The same in a sentence (the report's ``warnings``).
    """

    kind: str
    value: float
    text: str

    def to_dict(self) -> dict:
        """``{"kind": ..., "value": ...}``: the report's ``warning_values``."""
        return {"kind": self.kind, "value": _num(self.value)}


def warnings_summary(trials: Sequence[tuple[str, Sequence[dict]]], what: str = "trials"
                     ) -> list[str]:
    """One line per kind of warning for many trials, in place of a line per trial.

    ``"58 of 60 trials judged at the repertoire's speed (times scaled by
    0.65-0.87)"``; a kind that few trials have names them. Each trial's own
    warnings stay in its report.

    Parameters
    ----------
    trials : sequence of (str, sequence of dict)
        Each trial's name and its warnings' ``{"kind", "value"}``
        (:meth:`ValidationWarning.to_dict`: the report's ``warning_values``).
    what : str
        What a trial is called in the lines (``trials``, ``clips``).
    """
    by_kind: dict[str, list[tuple[str, float]]] = {}
    for name, warnings in trials:
        for w in warnings:
            value = w.get("value")
            by_kind.setdefault(w.get("kind", "other"), []).append(
                (name, math.nan if value is None else float(value)))
    total, out = len(trials), []
    for kind, hits in by_kind.items():
        values = np.array([v for _, v in hits], dtype=float)
        values = values[np.isfinite(values)]
        span = ""
        if values.size:
            unit, digits = _WARNING_UNITS.get(kind, ("", 2))
            bounds = _WARNING_RANGES[kind][1] if kind in _WARNING_RANGES else None
            lo, hi = (_beyond(x, bounds, digits) for x in (values.min(), values.max()))
            span = f"{lo}{unit}" if lo == hi else f"{lo}-{hi}{unit}"
        count = f"{len(hits)} of {total} {what}"
        if kind == "time_scale":
            line = f"{count} judged at the repertoire's speed (times scaled by {span})"
        elif kind in _WARNING_RANGES:
            label, (lo, hi), unit = _WARNING_RANGES[kind]
            line = (f"{count}: {label} {span}, outside the {lo}-{hi}{unit} the verdict was "
                    "validated on")
        else:
            line = f"{count}: {kind} {span}"
        if len(hits) <= 3:
            line += f" ({', '.join(name for name, _ in hits)})"
        out.append(line)
    return out


#: The unit and decimals of each kind of warning's value in :func:`warnings_summary`.
_WARNING_UNITS = {"movement_time": (" s", 2), "distance": (" m", 2), "time_scale": ("", 2),
                  "peak_speed": (" m/s", 2)}
#: Each range-checked kind: its words, its validated range and unit.
_WARNING_RANGES = {"movement_time": ("movement time", VALIDATED_MOVEMENT_TIME, " s"),
                   "peak_speed": ("peak speed", VALIDATED_PEAK_SPEED, " m/s"),
                   "distance": ("reach distance", VALIDATED_DISTANCE, " m")}


def _beyond(value: float, bounds: tuple[float, float] | None, digits: int = 2) -> str:
    """``value`` with ``digits`` decimals, or up to two more where fewer would read as
    inside ``bounds``: a 0.398 s movement is "0.398", not "0.40", beside a 0.4 s bound."""
    text = f"{value:.{digits}f}"
    for more in range(1, 3):
        if bounds is None or not bounds[0] <= float(text) <= bounds[1]:
            break
        text = f"{value:.{digits + more}f}"
    return text


#: What a warning's likely cause may be, where one is known.
_WARNING_HINTS = {"peak_speed": " (a motion-capture file's `units`?)"}

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
    scored_observation : Observation or None
        What was scored: the demonstration brought to the repertoire's
        reference scale (:mod:`perception.recognition.shape`), on the
        reference clock (``time`` above is the same samples on the clip's);
        None where the observation itself was scored (a lone engine pass).
    normalisation : Normalisation or None
        How it was brought to that scale.
    judged : tuple of int or None
        The models the verdict judged: those of the kind the grip shows
        (None: every model).
    evidence : Evidence
        What the verdict was judged on (:mod:`perception.recognition.evidence`).
    decision : Verdict
        The verdict, judged once when the recognition was made
        (:func:`perception.recognition.rules.judge`).
    landmarks : (Landmarks, Landmarks or None)
        The demonstration's landmarks (measured on the observation, or on a
        3D recording's own speed and aperture) and the reference grasp
        model's own (None without a grasp model).
    transport_familiarity : float
        Familiarity of the movement's transport alone (digits held closed, at
        the reference scale) to the best reach model; NaN if not measured.
    mirrored : bool
        The scene was found mirrored (the finger opening on the model's -x
        side) and its mirror image was scored: the opposite of ``--mirror``.
    notes : tuple of str
        What was done to the clip before it was scored (a start without
        rest: :func:`perception.settling.settle_start`).
    time_origin : float
        The recording's own clock at the observation clock's zero, s: a time
        of :attr:`time`, of ``observation.clip_time`` or of the landmarks plus
        it is on the recording's clock (a motion-capture file's time column or
        first sample, a video's first frame); NaN where the caller did not
        say (the figures then stay on the observation's clock, from the
        scored movement's start, and say so).
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
    scored_observation: Observation | None = field(default=None, repr=False)
    normalisation: Normalisation | None = None
    judged: tuple[int, ...] | None = None
    evidence: Evidence | None = field(default=None, repr=False)
    decision: Verdict | None = field(default=None, repr=False)
    landmarks: tuple[Landmarks, Landmarks | None] | None = field(default=None, repr=False)
    transport_familiarity: float = float("nan")
    mirrored: bool = False
    notes: tuple[str, ...] = ()
    time_origin: float = math.nan

    def score(self, rule: str | None = None) -> np.ndarray:
        """(M, N) cumulative score under ``rule`` (default: the winner's rule)."""
        rule = rule or self.rule
        return self.log_likelihood if rule == "likelihood" else self.confidence

    def winner_at(self, n: int, rule: str | None = None) -> str:
        """Name of the best model after sample ``n`` (index into :attr:`time`) under ``rule``."""
        return self.names[int(np.argmax(self.score(rule)[:, n]))]

    @property
    def winner(self) -> str | None:
        """Best model at the end of the demonstration by :attr:`rule`, of the models the
        verdict judged (:attr:`judged`; None: no step scored)."""
        if not self.scored.any():
            return None
        among = list(range(len(self.names)) if self.judged is None else self.judged)
        return self.names[among[int(np.argmax(self.score()[among, -1]))]]

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
    def judged_names(self) -> list[str]:
        """The names of the models the verdict judged (:attr:`judged`)."""
        return self.names if self.judged is None else [self.names[i] for i in self.judged]

    @property
    def verdict(self) -> str | None:
        """``normal``, ``abnormal``, ``reach`` or ``unfamiliar`` (None without calibrations)."""
        return self.decision.verdict

    @property
    def wrist_synthesised(self) -> bool:
        """Whether the observation's wrist was placed from the grip rather than recorded.

        A motion-capture reach's tracks carry the models' wrist
        (`ReachParams.wrist_behind` behind the grip midpoint,
        :func:`perception.reach_plane.reach_tracks`): it keeps one offset from
        the grip midpoint, to the micrometre, in every sample, as no tracked
        wrist does. Its paths and speed are the grip midpoint's, moved.
        """
        obs = self.observation
        if obs.clip_raw is not None:
            wrist, finger, thumb = (obs.clip_raw[:, k] for k in range(3))
        elif obs.raw and all(k in obs.raw for k in ("wrist", "finger", "thumb")):
            wrist, finger, thumb = obs.raw["wrist"], obs.raw["finger"], obs.raw["thumb"]
        else:
            return False
        offset = np.asarray(wrist, dtype=float) - 0.5 * (np.asarray(finger, dtype=float)
                                                         + np.asarray(thumb, dtype=float))
        offset = offset[np.isfinite(offset).all(axis=1)]
        return len(offset) > 2 and float(np.ptp(offset, axis=0).max()) < SYNTHESISED_TOLERANCE

    @property
    def transport_point(self) -> str:
        """What the figures' and traces' transport speed is the speed of: ``wrist``, or
        ``grip midpoint`` where the wrist was synthesised from it (:attr:`wrist_synthesised`)."""
        return "grip midpoint" if self.wrist_synthesised else "wrist"

    @property
    def verdict_model(self) -> str | None:
        """The model the verdict was judged on: the best by log-likelihood of the models
        it judged (:attr:`judged`)."""
        names = self.judged_names
        return names[self.decision.best] if len(names) else None

    @property
    def verdict_reason(self) -> str:
        """Why the verdict was given, in words, with each measured value against its
        rule's threshold (:func:`perception.recognition.rules.reason`).

        Every verdict has one: the rule that fired ("delayed-opening: the grip
        starts to open at 62 % of the movement, after the 55 % threshold
        (late_opening); best model grasp-1.0s familiarity 0.40 >= 0.05 ...");
        a movement whose digits were lost too long names the digit lost
        longest and where.
        """
        lost = self._longest_loss() if self.observation.raw else None
        return reason(self.decision, self.evidence, self.rules, self.judged_names, lost=lost)

    @property
    def winner_note(self) -> str | None:
        """Where the winner's kind contradicts the verdict ("normal", a reach model
        winning), what the winner is, in words; None where they agree.

        The winner is the best of the judged models by :attr:`rule`; where
        the grip showed no kind (every model judged) it may be of the other
        kind than the verdict's. A report names the winner "closest model"
        then, not "winner".
        """
        winner, verdict = self.winner, self.verdict
        if winner is None or verdict not in ("normal", "abnormal", "reach"):
            return None
        kind = self.kinds[self.names.index(winner)]
        if (kind == "reach") == (verdict == "reach"):
            return None
        scale = "the repertoire's" if self.normalisation is not None else "the clip's own"
        judged = "a reach" if verdict == "reach" else "a grasp"
        return (f"closest model {winner}: a {kind} model fits the clip best at {scale} "
                f"scale; the verdict judges it as {judged}, where {self.verdict_model} "
                "fits best")

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
        # the reason (rules.reason) adds the rule it breaks, with its thresholds' names
        return f"{lost} lost {gap:.2f} s{where}"

    @property
    def validation_warnings(self) -> list[ValidationWarning]:
        """Where the movement lies outside what the verdict was validated on
        (docs/mocap.md), each with its kind and measured value."""
        out = []
        lm = self.landmarks[0]
        measured = {"movement_time": lm.movement_time, "peak_speed": lm.peak_speed,
                    "distance": self.observation.start_distance}
        for kind, (label, (lo, hi), unit) in _WARNING_RANGES.items():  # one table of ranges
            v = measured[kind]
            if math.isfinite(v) and not lo <= v <= hi:
                out.append(ValidationWarning(
                    kind, v, f"{label} {_beyond(v, (lo, hi))}{unit} is outside the "
                    f"{lo}-{hi}{unit} the verdict was validated on"
                    f"{_WARNING_HINTS.get(kind, '')}"))
        if math.isfinite(lm.movement_time) and lm.movement_time > 0:
            n = self.normalisation
            if n is not None and abs(n.time_scale - 1) > 1e-9:
                out.append(ValidationWarning(
                    "time_scale", n.time_scale,
                    f"judged at the repertoire's speed: times scaled by {n.time_scale:.2f}"))
        return out

    @property
    def warnings(self) -> list[str]:
        """Where the movement lies outside what the verdict was validated on, in words
        (:attr:`validation_warnings`)."""
        return [w.text for w in self.validation_warnings]

    @property
    def reference_model(self) -> str | None:
        """The grasp model with the highest log-likelihood (None if there is none)."""
        return reference_model(self.names, self.kinds, self.log_likelihood[:, -1])

    def nominal(self, model: str) -> dict[str, np.ndarray]:
        """The model's own noise-free movement at this clip's sample times.

        What the model would do from its planned start (thesis Figs. 5.5-5.7
        draw it against the demonstration), aligned on the clip's movement onset,
        at the scale the demonstration was scored at (:attr:`scored_observation`).

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
        time = self.scored_movement.time
        steps = int(np.ceil(max(time[-1], 0.0) / m.dt)) + 1
        run = rollout([m], steps)
        out = {}
        for key in ("wrist", "finger", "thumb"):
            xy = getattr(run, key)[0, 0]
            out[key] = np.stack([np.interp(time, run.time, xy[:, 0]),
                                 np.interp(time, run.time, xy[:, 1])], axis=1)
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
        return model_own_landmarks(self.models[self.names.index(model)], self.rules)

    @property
    def scored_movement(self) -> Observation:
        """What was scored (:attr:`scored_observation`, else the observation)."""
        return self.scored_observation if self.scored_observation is not None else self.observation

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
            (:func:`~perception.report.figures.paths_figure`, ``<clip>.paths.png``);
            ``kinematics``: the trial at a glance, its speed and grip aperture
            with their landmarks
            (:func:`~perception.report.kinematics.kinematics_figure`,
            ``<clip>.kinematics.png``).
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
            "warning_values": [w.to_dict() for w in self.validation_warnings],
            "winner_note": self.winner_note,
            "verdict_model": self.verdict_model,
            "transport_point": self.transport_point,
            "time_origin": _num(self.time_origin),
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
            "aperture": [_num(g) for g in self.scored_movement.g],
            "kinematics": self.kinematics,
        }


def _shape_summary(rec: Recognition) -> dict | None:
    if rec.normalisation is None:
        return None
    d = rec.decision
    return {"model": rec.verdict_model, "familiarity": _num(d.familiarity),
            "margin": _num(d.margin), "transport_familiarity": _num(rec.transport_familiarity),
            **{k: _num(v) for k, v in rec.normalisation.to_dict().items()}}


def _passes(rec: Recognition) -> dict:
    """The scoring passes: every model at one scale (the repertoire's reference scale,
    where the clip was brought to it), the verdict and the winner from the models of
    the kind the grip shows, and the transport's own pass."""
    scale = "reference" if rec.normalisation is not None else "scene"
    out = {scale: {"models": list(rec.names), "judged": rec.judged_names,
                   "best": rec.verdict_model, "winner": rec.winner,
                   "familiarity": _num(rec.decision.familiarity)},
           "winner_from": scale, "verdict_from": scale}
    if rec.normalisation is not None:
        out["transport"] = {"familiarity": _num(rec.transport_familiarity)}
    return out


def _num(x: float) -> float | None:
    """A float for JSON: None where it is not finite (JSON has no NaN)."""
    x = float(x)
    return x if np.isfinite(x) else None

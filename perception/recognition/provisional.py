"""The provisional verdict of a movement still being seen, and when it is settled.

:func:`provisional` applies the offline verdict rule to what has been seen
so far; :class:`SettleRule` says when that verdict is trusted;
:class:`OnlineState` is what :class:`perception.online.OnlineRecognizer`
returns after every frame. See docs/online.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from perception.errors import InputError
from perception.landmarks import (
    OPENING_LEVEL,
    PEAK_MIN_PROMINENCE,
    PEAK_PROMINENCE,
    count_peaks,
)
from perception.recognition.online import StepScorer
from perception.recognition.result import Recognition
from perception.recognition.shape import opens

__all__ = ["LATE_OPENING_PROGRESS", "Decision", "OnlineState", "SettleRule", "decision_summary",
           "provisional"]


@dataclass(frozen=True)
class SettleRule:
    """When a provisional verdict is trusted: it is *settled* at the first frame where

    * the wrist has covered at least ``min_progress`` of its way from rest to
      where the models' wrists stop (``start distance - 0.06 m``) —
      ``reach_progress`` for a ``reach``: a grasp that opens late looks like
      a reach until it opens —, and
    * the leading model's familiarity is at least ``margin`` natural-log
      units from the familiarity threshold (``|ln(familiarity / threshold)|``;
      a second opening of the grip counts as decisive), and
    * the provisional verdict has not changed for ``hold`` s.

    The defaults were chosen on the dev population (seeds 1000 + k,
    ``tools/evaluate_online.py --set dev``), never on the held-out one: there
    no finite margin let a verdict resting on familiarity alone settle
    before the end without disagreeing with the offline verdict on some
    clip (the provisional verdict does not know the movement time yet), so
    the default ``margin`` is infinite — only a grip seen to depart
    (``re-opening``, ``delayed-opening``) settles early; ``normal``,
    ``reach`` and the other ``abnormal`` verdicts are decided at the end.

    Parameters
    ----------
    min_progress, reach_progress : float
        Share of the transport, 0..1.
    margin : float
        Evidence margin, natural-log units of familiarity.
    hold : float
        Time the verdict must have stood, s.
    """

    min_progress: float = 0.5
    reach_progress: float = 0.98
    margin: float = math.inf
    hold: float = 0.0

    def __post_init__(self):
        if not (0 <= self.min_progress <= 1 and 0 <= self.reach_progress <= 1
                and self.margin >= 0 and self.hold >= 0):
            raise InputError("expected 0 <= min_progress, reach_progress <= 1, margin >= 0, "
                             f"hold >= 0, got {self}", field="SettleRule")


@dataclass(frozen=True)
class Decision:
    """A settled verdict.

    Attributes
    ----------
    verdict : str
        ``normal``, ``abnormal`` or ``reach``.
    detail : str or None
        ``re-opening`` for a grip seen to open twice, else None.
    time : float
        Stream time of the frame it settled at, s.
    since_onset : float
        Time since the (online) movement onset, s.
    frame : int
        That frame's index.
    """

    verdict: str
    detail: str | None
    time: float
    since_onset: float
    frame: int


@dataclass(frozen=True, eq=False)
class OnlineState:
    """The judgement after one frame.

    Attributes
    ----------
    frame : int
        Index of the frame (rows received so far - 1).
    time : float
        Its time on the stream's clock, s.
    phase : str
        ``start`` (first frames: tracking warms up, the scene is not fixed
        yet), ``rest`` (scene fixed, models planned, no movement yet) or
        ``moving`` (scored from the onset on).
    names : list of str
        Model names.
    confidence, log_likelihood : (M,) arrays
        Each model's thesis-rule confidence and log-likelihood so far (zeros
        before the onset).
    since_onset : float
        Time since the movement's onset, s (NaN before it).
    progress : float
        Share of the wrist's way to the object covered so far, 0..1.
    leading : str or None
        The model the provisional verdict rests on (best by log-likelihood
        among the kind the grip shows so far).
    verdict : str or None
        Provisional verdict: ``normal``, ``abnormal`` or ``reach`` (None before the onset).
    verdict_detail : str or None
        ``re-opening`` where a second opening has been seen.
    familiarity : float
        The leading model's familiarity so far.
    evidence : float
        How far it is from the familiarity threshold, ``|ln(familiarity /
        threshold)|`` (inf for a second opening of the grip; 0 without one).
    settled : bool
        Whether :attr:`decision` has been reached (at this frame or before).
    decision : Decision or None
        The first settled verdict (it stays; see docs/online.md).
    """

    frame: int
    time: float
    phase: str
    names: list[str]
    confidence: np.ndarray = field(repr=False)
    log_likelihood: np.ndarray = field(repr=False)
    since_onset: float = math.nan
    progress: float = 0.0
    leading: str | None = None
    verdict: str | None = None
    verdict_detail: str | None = None
    familiarity: float = math.nan
    evidence: float = 0.0
    decision: Decision | None = None

    @property
    def settled(self) -> bool:
        """Whether a verdict has settled."""
        return self.decision is not None


#: The grip starts to open late (``delayed-opening``) when the wrist has covered more than
#: this share of its way by then: the causal stand-in for the landmarks' 40 % of the
#: movement time (:data:`perception.landmarks.LATE_OPENING`), whose end is not known yet.
LATE_OPENING_PROGRESS = 0.5


def provisional(kinds: list[str], scorer: StepScorer, aperture: np.ndarray, progress: np.ndarray,
                object_size: float, frame_period: float,
                threshold: float) -> tuple[int, str, str | None, float]:
    """The offline verdict rule on the movement so far: leading model, verdict, detail,
    familiarity.

    As the shape pass (:func:`perception.pipeline._shape_pass`): the models of
    the kind the grip shows (grasp once it has opened as a grasp must,
    :func:`~perception.recognition.shape.opens`; reach until then), the best
    of them by log-likelihood, and its familiarity against ``threshold``. A
    grip seen to open twice (two aperture peaks, :func:`~perception.landmarks.count_peaks`,
    as the landmarks count them), or to start opening only once the wrist has
    covered :data:`LATE_OPENING_PROGRESS` of its way, is ``abnormal`` whatever
    the familiarity.
    Unlike the shape pass, the movement is judged in its own scene and time
    (its movement time is not known yet).

    Parameters
    ----------
    kinds : list of str
        Kind of each model.
    scorer : StepScorer
        The scores so far.
    aperture : (N,) array
        Grip aperture from the onset, m.
    progress : (N,) array
        The wrist's share of its way covered, at each of those frames.
    object_size : float
        Object diameter, m.
    frame_period : float
        The clip's frame period, s.
    threshold : float
        Lowest familiarity called familiar.
    """
    grasp = opens(SimpleNamespace(g=aperture, object_diameter=object_size))
    want = "grasp" if grasp else "reach"
    idx = [i for i, k in enumerate(kinds) if k == want] or list(range(len(kinds)))
    best = idx[int(np.argmax(scorer.log_likelihood[idx]))]
    fam = scorer.familiarity(best, frame_period)
    if grasp:
        g = aperture[np.isfinite(aperture)]
        prominence = max(PEAK_PROMINENCE * (g.max() - g[0]), PEAK_MIN_PROMINENCE)
        if count_peaks(g, prominence) >= 2:
            return best, "abnormal", "re-opening", fam
        level = g[0] + OPENING_LEVEL * (g.max() - g[0])
        if progress[np.isfinite(aperture)][np.argmax(g > level)] > LATE_OPENING_PROGRESS:
            return best, "abnormal", "delayed-opening", fam
    if not fam >= threshold:  # NaN (no calibration) is not familiar
        return best, "abnormal", None, fam
    return best, want if want == "reach" else "normal", None, fam


def decision_summary(rec: Recognition, decision: Decision | None) -> dict:
    """When the verdict settled, against the offline result ``rec`` of the same stream.

    ``decision_time`` is s after the offline movement onset, ``decision_fraction``
    its share of the scored movement (onset to end of activity). A stream that
    ends before a verdict settles is decided by the offline result at its end
    (``settled_early`` false).

    Parameters
    ----------
    rec : Recognition
        The offline recognition (:meth:`OnlineRecognizer.finish`).
    decision : Decision or None
        The first settled verdict.
    """
    # the online onset is the offline one: the same rule on the same frames
    span = float(rec.observation.time[-1])
    if decision is None:
        t, verdict, detail = span, rec.verdict, rec.verdict_detail
    else:
        t, verdict, detail = decision.since_onset, decision.verdict, decision.detail
    return {"settled_verdict": verdict, "settled_detail": detail,
            "settled_early": decision is not None,
            "decision_time": float(t), "decision_fraction": float(t / span) if span > 0 else None,
            "agrees": verdict == rec.verdict}

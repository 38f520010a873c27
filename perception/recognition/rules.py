"""The verdict as one declared policy: every threshold in :class:`VerdictRules`, one :func:`judge`.

A verdict is judged from :class:`Evidence` — each model's score and
familiarity, the movement's transport familiarity, its landmarks and how
long its digits went unseen — by an ordered table of rules
(:data:`RULE_TABLE`); the first that fires gives the verdict and names
itself (``verdict_rule`` in the report). The offline recognition
(:attr:`perception.recognition.result.Recognition.decision`) and the online
one (:class:`perception.online.OnlineRecognizer`) judge through the same
:func:`judge` with the same :class:`VerdictRules` (``RecognitionSettings.rules``,
written to the report as ``verdict_rules``; ``--verdict-rules FILE.toml``).
docs/recognition.md §5 gives each rule's source.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Annotated

import numpy as np
from pydantic import Field

from perception.landmarks import LandmarkParams, Landmarks
from perception.observation import ObserveParams
from perception.rowwise import row_norm
from perception.validation import Int, Share, declared

__all__ = ["AT_END", "DETAILS", "HAND_SPAN", "REASONS", "RULE_TABLE", "VERDICT_RULES", "Evidence",
           "Verdict", "VerdictRules", "grip_departs", "judge", "peak_and_least", "reason", "slowed",
           "speeds", "verdict_detail"]

#: Kinds of an abnormal verdict (:func:`verdict_detail`).
DETAILS = ("delayed-opening", "re-opening", "no-opening", "other")


#: Widest a hand opens, m (thumb to index tip, a large adult hand): no grip is read beyond it.
HAND_SPAN = 0.3


@declared
class VerdictRules:
    """Every threshold that decides a verdict.

    Parameters
    ----------
    familiarity_threshold : float
        Lowest familiarity (0..1) of the best model for ``normal`` (or
        ``reach``); below it ``abnormal``: a one-sided test at this level
        that the movement is one of the model's own. Strictly between 0
        and 1: at 0 no grasp is abnormal, at 1 every one is.
    unfamiliar_threshold : float
        Lowest familiarity of the movement's transport alone (digits held
        closed) to the best reach model; below it the verdict is
        ``unfamiliar`` (no human reach). Strictly between 0 and 1, as
        ``familiarity_threshold``.
    late_opening : float
        ``delayed-opening``: the grip starts to open (exceeds
        ``landmarks.opening_level`` of its opening) after this share of the
        movement. Real healthy grips start at 3-68 % by the field's
        definitions (a lab's Optotrak grasps: up to 50 % on all but 2 of 30
        dev trials), the chapter 5 delayed stimuli at 52-70 %: chosen
        between, on dev sets only (docs/mocap.md). Above 0 (at 0 every grip
        opens late); 1 turns the rule off.
    late_mga : float
        ... or the MGA comes after this share while the reference model's
        comes earlier. Above 0, at most 1 (off), as ``late_opening``.
    no_opening : float
        ``no-opening``: the opening is below this share of the reference model's.
    grasp_opening : float
        The grip opens as a grasp must when it exceeds its rest aperture by
        this share of the object's diameter (healthy adults open 1.5-3.5 cm
        beyond the object, Jeannerod 1984): judged against the grasp
        models, otherwise against the reach models. At most 2: twice the
        diameter beyond rest is past what a hand opens for any object it
        grasps with two digits.
    grasp_rest_frames : int
        The rest aperture is the mean of this many first seen frames: 1 to
        1000 (a second of rest even at a motion-capture 1000 Hz; more would
        take the movement itself for the rest).
    mirror_opening : float
        Least grip opening, m, at which the side the finger is on is read.
        At most :data:`HAND_SPAN` (wider, no side is ever read).
    mirror_majority : float
        The scene is mirrored when more than this share of those frames
        have the finger on the model's -x side. At least 0.5 (a majority)
        and below 1 (at 1 no scene is mirrored).
    min_transport : float
        Least wrist travel, m, of a movement that can be judged as a reach.
        At most 1 m: no seated reach to an object travels further.
    arrival : float
        The hand has arrived when the transport, after its peak speed, has
        slowed by this share of it; a clip that ends before is ``incomplete``.
    min_scored : float
        Least share of the movement's steps scored (the digits seen in two
        frames running) for a verdict; fewer: ``digits-unseen``.
    precision_grip_aperture : float
        Digits further apart at rest than this, m, make a whole-hand grasp
        (``unfamiliar``: the verdict knows precision grips). By default the
        observation's own rest rule for clips (``ObserveParams.max_rest_aperture``).
        Above 0, at most :data:`HAND_SPAN`.
    span_fraction : float
        The time scale the models are compared at: a movement's time is
        ``(t90 - t10) / span_fraction``, where the wrist covers the middle
        80 % of its path (10 % to 90 %) between ``t10`` and ``t90``; a model
        covers it in this share of its movement time (measured on the
        default grasp models' own movements at 0.8, 1.0 and 1.2 s: 0.458,
        0.467, 0.472, never on test clips). The span does not depend on
        where the onset is placed, which the start of a movement leaves
        uncertain.
    landmarks : LandmarkParams
        How the landmarks the rules read are measured: the movement's
        bounds, the aperture's peaks and opening, the gaps that may hide a
        second opening.
    """

    # the bounds: what each rule can mean; past them a rule fires for every movement or none
    familiarity_threshold: Annotated[float, Field(gt=0, lt=1)] = 0.05
    unfamiliar_threshold: Annotated[float, Field(gt=0, lt=1)] = 0.01
    late_opening: Annotated[float, Field(gt=0, le=1)] = 0.55
    late_mga: Annotated[float, Field(gt=0, le=1)] = 0.95
    no_opening: Share = 0.30
    grasp_opening: Annotated[float, Field(ge=0, le=2)] = 0.5
    grasp_rest_frames: Annotated[Int, Field(ge=1, le=1000)] = 5
    mirror_opening: Annotated[float, Field(ge=0, le=HAND_SPAN)] = 0.02
    mirror_majority: Annotated[float, Field(ge=0.5, lt=1)] = 0.5
    min_transport: Annotated[float, Field(ge=0, le=1)] = 0.02
    arrival: Share = 0.6
    min_scored: Share = 0.5
    precision_grip_aperture: Annotated[float, Field(gt=0, le=HAND_SPAN)] = \
        ObserveParams.max_rest_aperture
    span_fraction: Annotated[float, Field(gt=0, le=1)] = 0.467
    landmarks: LandmarkParams = field(default_factory=LandmarkParams)

    def to_dict(self) -> dict:
        """The rules as the report's ``verdict_rules`` (landmark settings nested)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: dict, path=None) -> VerdictRules:
        """From :meth:`to_dict`'s output or a TOML ``[verdict]`` table (unknown keys are errors).

        Parameters
        ----------
        d : dict
            The rules; ``landmarks`` a nested table of :class:`LandmarkParams`.
        path : str or os.PathLike, optional
            The file, named in errors.
        """
        from perception.io.config import from_table, sub_table

        # a list (``[[verdict]]``) or a number is refused as a table, not read as pairs
        d = dict(sub_table(d, None, "[verdict]", path))
        landmarks = from_table(LandmarkParams, d.pop("landmarks", {}), "[verdict.landmarks]",
                               path)
        return from_table(cls, d, "[verdict]", path, landmarks=landmarks)


@dataclass(frozen=True)
class Verdict:
    """A judged verdict.

    Attributes
    ----------
    verdict : str or None
        ``normal``, ``abnormal``, ``reach`` or ``unfamiliar``; None if the
        best model has no calibration.
    best : int
        Index of the model with the highest log-likelihood.
    familiarity : float
        The best model's familiarity (NaN without calibration).
    margin : float
        Its log-likelihood minus the runner-up's (NaN with one model).
    rule : str or None
        The rule that gave it (one of :data:`VERDICT_RULES`).
    detail : str or None
        The kind of an ``abnormal`` verdict (one of :data:`DETAILS`).
    """

    verdict: str | None
    best: int
    familiarity: float
    margin: float
    rule: str | None = None
    detail: str | None = None


@dataclass(frozen=True)
class Evidence:
    """What a verdict is judged on (offline: the whole movement; online: what is seen so far).

    Attributes
    ----------
    kinds : list of str
        Kind of each model judged.
    log_likelihood : (M,) array
        Each model's log-likelihood.
    familiarity : (M,) array
        Each model's familiarity (NaN without calibration).
    transport_familiarity : float
        The transport's alone to the best reach model (NaN: not measured).
    rest_aperture : float
        Digit separation at rest, m (NaN: not measured).
    observed, reference : Landmarks, optional
        The movement's landmarks and the reference grasp model's own.
    aperture_gap : float
        Longest stretch without an aperture during the movement, s.
    slowed : float
        How far the transport slowed after its peak speed, as a share of it
        (:func:`slowed`; 1: the hand came to rest).
    scored_share : float
        Share of the movement's steps scored.
    opening_progress, opening, closing, progress, reopened
        The grip's course (:func:`~perception.recognition.evidence.grip_course`):
        the wrist's progress when the grip started to open, 0..1 (NaN: it has not
        opened as a grasp's must); how far it opened beyond its rest, m; the share
        of that opening closed since its maximum; the largest share of the wrist's
        way covered, 0..1; whether it opened, closed and opened again. Known before
        the movement's end that the landmarks need: what the online settle rule
        reads while the movement is under way (the verdict does not).
    """

    kinds: list[str]
    log_likelihood: np.ndarray
    familiarity: np.ndarray
    transport_familiarity: float = math.nan
    rest_aperture: float = math.nan
    observed: Landmarks | None = None
    reference: Landmarks | None = None
    aperture_gap: float = 0.0
    slowed: float = 1.0
    scored_share: float = 1.0
    opening_progress: float = math.nan
    opening: float = 0.0
    closing: float = 0.0
    progress: float = 0.0
    reopened: bool = False


def slowed(time: np.ndarray, wrist: np.ndarray, movement: int | None = None) -> float:
    """How far the wrist's speed fell after its peak, as a share of the peak: 0..1.

    The speed between consecutive samples (NaN skipped), as the online
    recogniser reads it frame by frame: a clip cut while the hand still
    travels gives little, one that ends with the hand at rest nearly 1.

    Parameters
    ----------
    time : (N,) array
        Times, s.
    wrist : (N, 2) array
        Positions, m (the observation's filtered wrist).
    movement : int, optional
        The first ``movement`` samples are the movement, whose peak counts;
        the samples after it count for how far the speed fell (default:
        every sample is the movement's).
    """
    found = peak_and_least(time, wrist, movement)
    return 0.0 if found is None else float(1.0 - found[1] / found[0])


def speeds(time: np.ndarray, wrist: np.ndarray) -> np.ndarray:
    """The wrist's speed between consecutive samples, m/s (NaN where one is lost): what
    :func:`slowed` reads.

    Parameters
    ----------
    time : (N,) array
        Times, s.
    wrist : (N, 2) array
        Positions, m.
    """
    return row_norm(np.diff(wrist, axis=0)) / np.maximum(np.diff(time), 1e-9)


def peak_and_least(time: np.ndarray, wrist: np.ndarray, movement: int | None = None
                   ) -> tuple[float, float] | None:
    """:func:`slowed`'s peak speed within the movement and the slowest finite speed from
    it on, m/s; None where the movement has no speed above 0.

    Parameters
    ----------
    time, wrist, movement
        As :func:`slowed`'s.
    """
    speed = speeds(time, wrist)
    within = np.isfinite(speed)
    if movement is not None:
        within[max(movement - 1, 0):] = False
    if not within.any() or speed[within].max() <= 0:
        return None
    peak = int(np.flatnonzero(within)[np.argmax(speed[within])])
    after = speed[peak:]
    return float(speed[peak]), float(after[np.isfinite(after)].min())


def grip_departs(observed: Landmarks, rules: VerdictRules | None = None) -> bool:
    """Whether the grip opens late (after ``late_opening`` of the movement) or twice.

    Real healthy adults start to open anywhere up to about half-way; a
    normal grasp opens once. The one-step predictions weigh a late or a
    second opening weakly once the model's filter has followed it.

    Parameters
    ----------
    observed : Landmarks
        The movement's landmarks.
    rules : VerdictRules, optional
    """
    rules = VerdictRules() if rules is None else rules
    peaks = observed.aperture_peaks
    return bool((peaks is not None and peaks >= 2) or observed.opening_time > rules.late_opening)


def verdict_detail(observed: Landmarks, reference: Landmarks | None,
                   rules: VerdictRules | None = None) -> str:
    """What kind of abnormal grasp the landmarks describe (one of :data:`DETAILS`).

    In this order: ``no-opening`` (the opening is below ``no_opening`` of
    the reference model's); ``re-opening`` (two or more aperture peaks);
    ``delayed-opening`` (the grip starts to open after ``late_opening`` of
    the movement, or its MGA comes after ``late_mga`` while the reference's
    comes earlier); ``other``.

    Parameters
    ----------
    observed : Landmarks
        The movement's.
    reference : Landmarks, optional
        The reference grasp model's own movement's (None: no ``no-opening``,
        and a late MGA counts on its own).
    rules : VerdictRules, optional
    """
    rules = VerdictRules() if rules is None else rules
    ref_opening = reference.opening if reference is not None else math.nan
    if math.isfinite(observed.opening) and math.isfinite(ref_opening) and ref_opening > 0:
        if observed.opening < rules.no_opening * ref_opening:
            return "no-opening"
    if observed.aperture_peaks is not None and observed.aperture_peaks >= 2:
        return "re-opening"
    ref_mga_time = reference.mga_time if reference is not None else math.nan
    late_mga = observed.mga_time > rules.late_mga and not ref_mga_time > rules.late_mga
    if observed.opening_time > rules.late_opening or late_mga:
        return "delayed-opening"
    return "other"


def _familiar(e: Evidence, rules: VerdictRules, best: int) -> str | None:
    fam = float(e.familiarity[best])
    if not math.isfinite(fam):
        return None
    if fam < rules.familiarity_threshold:
        return "abnormal"
    return "reach" if e.kinds[best] == "reach" else "normal"


def _movement_time(e: Evidence) -> float:
    return e.observed.movement_time if e.observed is not None else math.nan


def _peaks_hidden(e: Evidence) -> bool:
    """Whether the landmarks could not count the aperture's peaks: the digits were lost,
    within the movement's own bounds, long enough to hide a closing and re-opening (the
    scored span's gap, :attr:`Evidence.aperture_gap`, can be shorter)."""
    o = e.observed
    return o is not None and o.aperture_peaks is None and "aperture_peaks" in o.flags


def _unseen(e: Evidence, r: VerdictRules, base: str | None) -> str | None:
    """Why the movement was not seen well enough to judge, if it was not."""
    # a closing and re-opening seen stands, whatever a loss elsewhere may hide
    seen_twice = e.observed is not None and (e.observed.aperture_peaks or 0) >= 2
    if e.scored_share < r.min_scored or not seen_twice and (
            _peaks_hidden(e) or r.landmarks.hides_a_reopening(e.aperture_gap,
                                                              _movement_time(e))):
        return "digits-unseen"
    if e.observed is not None and (e.observed.movements or 1) > 1:
        return "several-movements"
    return None


#: The rules in the order they are tried: (name, verdict, fires(evidence, rules, base)),
#: ``base`` being the familiarity's verdict (None without a calibration: then only the
#: rules about the data are tried). The first that fires gives the verdict; a rule that
#: fires with a string names the verdict's detail.
RULE_TABLE: tuple[tuple[str, str, Callable[[Evidence, VerdictRules, str | None],
                                           bool | str | None]], ...] = (
    # a whole-hand grasp: out of the verdict's depth
    ("not-a-precision-grip", "unfamiliar",
     lambda e, r, base: e.rest_aperture > r.precision_grip_aperture),
    # opening late or twice, seen in the field's landmarks (a start of the opening that
    # was not seen is no landmark), even where the models find it familiar, and even in
    # a movement cut short after it
    ("grip-departs", "abnormal",
     lambda e, r, base: base in ("normal", "abnormal") and e.observed is not None
     and grip_departs(e.observed, r)),
    # the digits unseen through the opening (lost long enough to hide an opening, or
    # too rarely seen to score), or more than one movement
    ("insufficient-data", "unfamiliar", _unseen),
    # the clip ends before the hand arrives: its transport never slowed by `arrival`
    ("incomplete", "unfamiliar", lambda e, r, base: e.slowed < r.arrival and "incomplete"),
    # even the transport is like no reach model's own
    ("not-a-human-reach", "unfamiliar",
     lambda e, r, base: e.transport_familiarity < r.unfamiliar_threshold),
    # unfamiliar where the grip shows no departure of its own and the transport alone
    # fails the test the movement failed: the misfit is the transport's, and the
    # abnormal grasps the verdict knows (a late or a second opening, thesis ch. 5) keep a
    # reach's transport
    ("transport-departs", "unfamiliar",
     lambda e, r, base: base == "abnormal"
     and e.transport_familiarity < r.familiarity_threshold),
    ("familiarity", "", lambda e, r, base: base is not None),
)
#: The rules' names (:attr:`Verdict.rule`), in the order they are tried.
VERDICT_RULES = tuple(name for name, _, _ in RULE_TABLE)
#: The rules that read the movement's end: a movement still being seen (``judge(...,
#: ongoing=True)``) has not ended short.
AT_END = ("incomplete",)
#: Why the data cannot carry a verdict (the ``verdict_detail`` of an ``unfamiliar`` one).
REASONS = ("digits-unseen", "several-movements", "incomplete")


def judge(evidence: Evidence, rules: VerdictRules | None = None, *,
          ongoing: bool = False) -> Verdict:
    """The verdict: the best model by log-likelihood, then the first rule of
    :data:`RULE_TABLE` that fires.

    Parameters
    ----------
    evidence : Evidence
    rules : VerdictRules, optional
    ongoing : bool
        The movement is still being seen (a stream's rows so far): the rules
        of :data:`AT_END` do not fire, so the verdict is the one the
        movement gets if it ends as it goes (what
        :class:`~perception.online.SettleRule` settles).
    """
    if not isinstance(evidence, Evidence):  # not an AttributeError at its first use
        raise TypeError(f"expected Evidence, got {type(evidence).__name__}")
    if rules is not None and not isinstance(rules, VerdictRules):
        raise TypeError(f"expected VerdictRules, got {type(rules).__name__}")
    rules = VerdictRules() if rules is None else rules
    ll = np.asarray(evidence.log_likelihood, dtype=float)
    best = int(np.argmax(ll))
    margin = float(ll[best] - np.max(np.delete(ll, best))) if ll.size > 1 else math.nan
    fam = float(evidence.familiarity[best])
    base = _familiar(evidence, rules, best)
    for name, verdict, fires in RULE_TABLE:
        if name not in ("not-a-precision-grip", "insufficient-data") and base is None:
            continue  # no calibration: only the rules about the data
        if ongoing and name in AT_END:
            continue
        why = fires(evidence, rules, base)
        if why:
            verdict = verdict or base
            detail = why if isinstance(why, str) else None
            if verdict == "abnormal" and evidence.observed is not None:
                detail = verdict_detail(evidence.observed, evidence.reference, rules)
            return Verdict(verdict, best, fam, margin, name, detail)
    return Verdict(None, best, fam, margin)


def _pc(share: float) -> str:
    """A share of the movement as the reasons print it: ``62 %``."""
    return f"{share * 100:.0f} %"


def _fam(x: float) -> str:
    """A familiarity with the digits that tell it from its threshold (0.02, 0.004, 3e-05)."""
    return f"{x:.2f}" if x >= 0.01 else f"{x:.1g}"


def _opening(o: Landmarks, rules: VerdictRules) -> str:
    """When the grip starts to open, against ``late_opening``."""
    if not math.isfinite(o.opening_time):
        return "the grip's start to open was not seen"
    side = "after" if o.opening_time > rules.late_opening else "before"
    return (f"the grip starts to open at {_pc(o.opening_time)} of the movement, {side} the "
            f"{_pc(rules.late_opening)} threshold (late_opening)")


def _peaks(o: Landmarks) -> str:
    """The aperture's peaks: a grasp opens once."""
    if o.aperture_peaks is None:
        return "the aperture's peaks not counted (the digits were unseen too long)"
    if o.aperture_peaks >= 2:
        return f"{o.aperture_peaks} aperture peaks (a grasp opens once)"
    return f"{o.aperture_peaks} aperture peak"


def _mga(o: Landmarks, ref: Landmarks | None, rules: VerdictRules) -> str:
    """When the MGA comes, against ``late_mga`` (and the reference model's own)."""
    if not math.isfinite(o.mga_time):
        return "the MGA was not seen"
    side = "after" if o.mga_time > rules.late_mga else "before"
    text = (f"the MGA comes at {_pc(o.mga_time)} of the movement, {side} the "
            f"{_pc(rules.late_mga)} threshold (late_mga)")
    if ref is not None and math.isfinite(ref.mga_time):
        text += f", the reference model's at {_pc(ref.mga_time)}"
    return text


def _no_opening(o: Landmarks, ref: Landmarks, rules: VerdictRules) -> str:
    """How far the grip opens against ``no_opening`` of the reference model's opening."""
    return (f"the grip opens {o.opening * 1000:.0f} mm beyond its rest, under "
            f"{_pc(rules.no_opening)} of the reference model's {ref.opening * 1000:.0f} mm "
            "(no_opening)")


def _departure(detail: str | None, e: Evidence, rules: VerdictRules) -> str:
    """The kind of an abnormal grasp with the landmark that made it, against its threshold."""
    o, ref = e.observed, e.reference
    if o is None or detail is None:
        return ""
    if detail == "no-opening" and ref is not None:
        return f"no-opening: {_no_opening(o, ref, rules)}"
    if detail == "re-opening":
        return f"re-opening: {_peaks(o)}"
    if detail == "delayed-opening":
        late = math.isfinite(o.opening_time) and o.opening_time > rules.late_opening
        return f"delayed-opening: {_opening(o, rules) if late else _mga(o, ref, rules)}"
    # nothing in the landmarks departs: say what they are, so that a reader sees it
    return (f"no landmark departs: {_opening(o, rules)}, {_peaks(o)}, "
            f"{_mga(o, ref, rules)}")


def _familiarity(e: Evidence, rules: VerdictRules, best: int, names: Sequence[str]) -> str:
    """The best model's familiarity against the threshold, and the model nearest to passing."""
    fam, t = float(e.familiarity[best]), rules.familiarity_threshold
    sign = "<" if fam < t else ">="
    text = (f"best model {names[best]} familiarity {_fam(fam)} {sign} {_fam(t)} threshold "
            "(familiarity_threshold)")
    others = [(float(f), i) for i, f in enumerate(e.familiarity)
              if i != best and math.isfinite(f)]
    if fam < t and others:
        near, i = max(others)
        ll = np.asarray(e.log_likelihood, dtype=float)
        if near >= t:  # familiar, but a worse fit than the best: it does not decide
            text += (f"; {names[i]} would pass at {_fam(near)} but fits worse "
                     f"(log-likelihood {ll[best] - ll[i]:.1f} lower)")
        else:
            text += f"; the nearest to passing: {names[i]} at {_fam(near)}"
    return text


def reason(verdict: Verdict, evidence: Evidence, rules: VerdictRules | None = None,
           names: Sequence[str] | None = None, lost: str | None = None) -> str:
    """Why ``verdict`` was given, in words, with each measured value against its threshold.

    The rule that fired (:attr:`Verdict.rule`) with what it read in
    ``evidence``: the landmark that made an abnormal grasp's kind (``"delayed-opening:
    the grip starts to open at 62 % of the movement, after the 55 % threshold
    (late_opening)"``), the best model's familiarity against
    ``familiarity_threshold`` and the model nearest to passing, the digits'
    gap, the transport's slowing or familiarity, the rest aperture. Every
    verdict gets one, ``normal`` and ``reach`` too; each threshold is named
    by its :class:`VerdictRules` field.

    Parameters
    ----------
    verdict : Verdict
        :func:`judge`'s, of ``evidence`` under ``rules``.
    evidence : Evidence
    rules : VerdictRules, optional
    names : sequence of str, optional
        The models' names, in the order of ``evidence.kinds`` (default:
        ``model 1``, ``model 2``, ...).
    lost : str, optional
        What was lost and where, in words (the observation's: "the thumb was
        lost 0.48 s at 2-34 % of the movement"), for a movement whose gap
        leaves too little to judge; default: the evidence's longest gap.
    """
    rules = VerdictRules() if rules is None else rules
    e, v = evidence, verdict
    names = list(names) if names is not None else [f"model {i + 1}"
                                                   for i in range(len(e.kinds))]
    o, rule = e.observed, v.rule
    if rule == "not-a-precision-grip":
        return (f"not a precision grip: the digits start {e.rest_aperture * 100:.0f} cm "
                f"apart, over the {rules.precision_grip_aperture * 100:.0f} cm limit "
                "(precision_grip_aperture; the verdict knows grasps whose digits start closed)")
    if rule == "insufficient-data" and v.detail == "several-movements" and o is not None:
        return f"insufficient data: {o.movements} movements in the clip (the verdict judges one)"
    if rule == "insufficient-data" and e.scored_share < rules.min_scored:
        return (f"insufficient data: the digits are seen in two frames running on "
                f"{_pc(e.scored_share)} of the movement's steps, under the "
                f"{_pc(rules.min_scored)} a verdict needs (min_scored)")
    if rule == "insufficient-data":
        lp = rules.landmarks
        lost = lost or (o.flags["aperture_peaks"] if _peaks_hidden(e) else
                        f"the aperture was lost {e.aperture_gap:.2f} s during the movement")
        return (f"insufficient data: {lost} (a gap over {lp.max_gap:.2f} s and "
                f"{_pc(lp.max_gap_share)} of the movement may hide a second opening: "
                "max_gap, max_gap_share)")
    if rule == "incomplete":
        return (f"incomplete: the clip ends before the hand arrives: its transport slowed "
                f"by {_pc(e.slowed)} of its peak speed, under the {_pc(rules.arrival)} "
                "of an arrival (arrival)")
    if rule == "not-a-human-reach":
        return (f"not a human reach: its transport's familiarity to the best reach model "
                f"{_fam(e.transport_familiarity)} < {_fam(rules.unfamiliar_threshold)} "
                "threshold (unfamiliar_threshold)")
    if rule == "transport-departs":
        return (f"the transport departs, not the grip: the transport's familiarity to the "
                f"best reach model {_fam(e.transport_familiarity)} < "
                f"{_fam(rules.familiarity_threshold)} threshold (familiarity_threshold), as "
                f"the movement's (best model {names[v.best]} at {_fam(v.familiarity)}), "
                "and no landmark of the grip departs (an abnormal grasp keeps a reach's "
                "transport)")
    if rule is None:
        return (f"no verdict: the best model {names[v.best]} has no calibration (no "
                "familiarity to judge by)")
    fam = _familiarity(e, rules, v.best, names)
    departs = _departure(v.detail, e, rules)
    if rule == "grip-departs":
        if v.detail == "no-opening" and o is not None:  # the kind, then why the rule fired
            departs += "; " + (_peaks(o) if (o.aperture_peaks or 0) >= 2
                               else _opening(o, rules))
        return f"{departs}; {fam}"
    if v.verdict == "abnormal":
        return "; ".join(x for x in (fam, departs) if x)
    if v.verdict == "normal" and o is not None:  # the grip's landmarks, each within its rule
        return f"{fam}; {_opening(o, rules)}, {_peaks(o)}"
    return fam

"""The hand's structure: which candidate blobs together look like a hand.

Colour, size and shape leave a few candidates per hand marker
(:mod:`perception.tracking.candidates`); the hand decides among them. At
rest (the clip's first frames) the thumb and finger markers lie within
``digit_gap`` of each other, both within ``hand_span`` of the wrist band
(and at least ``min_band_distance`` from it), and the band lies across the
forearm: its long axis roughly perpendicular to the line from the band to
the digits. Later (re-acquisition while the hand moves) only the span is
required. Markers already tracked take part as fixed anchors.

Every combination of one candidate per marker is scored (:func:`hand_cost`,
plus how far each candidate's colour lies from its marker's own);
the cheapest plausible one wins (the weights and limits are
:class:`~perception.tracking.params.TrackerParams` fields). Where another
plausible combination costs less than ``ambiguity_margin`` more and puts a
marker on a different blob, that marker is **ambiguous**: the tracker
reports it so, and does not guess.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from perception.tracking.candidates import Candidate
from perception.tracking.params import TrackerParams

__all__ = ["HandChoice", "choose_hand", "hand_cost"]


@dataclass(frozen=True)
class HandChoice:
    """The outcome of choosing hand markers.

    Attributes
    ----------
    chosen : dict of str to Candidate
        Markers placed without doubt.
    ambiguous : dict of str to list of Candidate
        Markers with more than one plausible blob (the rivals, best first).
    cost : float
        Cost of the best placement (inf: none).
    """

    chosen: dict[str, Candidate] = field(default_factory=dict)
    ambiguous: dict[str, list[Candidate]] = field(default_factory=dict)
    cost: float = math.inf

    @property
    def placed(self) -> int:
        """Markers placed, with or without doubt."""
        return len(self.chosen) + len(self.ambiguous)


def hand_cost(points: Mapping[str, Sequence[float]], band_axis: Sequence[float] | None,
              px_per_m: float, params: TrackerParams, *, at_rest: bool) -> float | None:
    """Cost of one placement of the hand markers; None when it is not a hand.

    Parameters
    ----------
    points : mapping of str to (float, float)
        Positions (px) of the placed hand markers among ``thumb``, ``finger``,
        ``wrist`` (any may be absent).
    band_axis : (float, float), optional
        Unit long axis of the wrist band's blob (None: not known).
    px_per_m : float
        Image scale, px/m.
    params : TrackerParams
        ``digit_gap``, ``hand_span``, ``min_band_distance``, ``typical_reach``
        and ``max_band_cos``.
    at_rest : bool
        The clip's first frames: digits close together, band across the forearm.

    Returns
    -------
    float or None
        0 for a textbook hand; larger the less it looks like one.
    """
    cost = 0.0
    digits = [points[n] for n in ("thumb", "finger") if n in points]
    if len(digits) == 2:
        gap = math.dist(*digits) / px_per_m
        limit = params.digit_gap if at_rest else params.hand_span
        if gap > limit:
            return None
        cost += gap / limit
    wrist = points.get("wrist")
    if wrist is None or not digits:
        return cost
    for d in digits:
        reach = math.dist(d, wrist) / px_per_m
        if not params.min_band_distance <= reach <= params.hand_span:
            return None
        cost += abs(reach - params.typical_reach) / params.typical_reach / len(digits)
    if at_rest and band_axis is not None:
        mx = sum(d[0] for d in digits) / len(digits) - wrist[0]
        my = sum(d[1] for d in digits) / len(digits) - wrist[1]
        norm = math.hypot(mx, my)
        cos = abs(mx * band_axis[0] + my * band_axis[1]) / norm if norm > 0 else 1.0
        if cos > params.max_band_cos:
            return None
        cost += cos
    return cost


def choose_hand(candidates: Mapping[str, Sequence[Candidate]],
                anchors: Mapping[str, Sequence[float]], px_per_m: float,
                params: TrackerParams, *, at_rest: bool,
                separation_px: float | None = None) -> HandChoice:
    """One candidate per hand marker: the plausible combination that looks most like a hand.

    Parameters
    ----------
    candidates : mapping of str to sequence of Candidate
        Per marker to place, its surviving candidates (empty: not placed).
    anchors : mapping of str to (float, float)
        Positions (px) of hand markers already tracked.
    px_per_m : float
        Image scale, px/m.
    params : TrackerParams
        The hand's limits, ``colour_weight`` and ``ambiguity_margin``.
    at_rest : bool
        See :func:`hand_cost`.
    separation_px : float, optional
        Rival blobs closer than this (px) are the same blob (default
        ``params.rival_separation_px``).

    Returns
    -------
    HandChoice
        Markers with no plausible combination are in neither field.
    """
    names = [n for n, cands in candidates.items() if cands]
    if not names:
        return HandChoice()
    if separation_px is None:
        separation_px = params.rival_separation_px
    scored = []
    for combo in itertools.product(*(range(len(candidates[n])) for n in names)):
        picked = {n: candidates[n][k] for n, k in zip(names, combo)}
        points = {**anchors, **{n: c.centre for n, c in picked.items()}}
        axis = picked["wrist"].axis if "wrist" in picked else None
        cost = hand_cost(points, axis, px_per_m, params, at_rest=at_rest)
        if cost is not None:
            cost += params.colour_weight * sum(1 - c.purity for c in picked.values())
            scored.append((cost, picked))
    if not scored:
        # No combination of all: the most markers that do make a hand (one of
        # them may be hidden, or only something else of its colour in view).
        if len(names) == 1 or not anchors and len(names) == 2:
            return HandChoice()
        subsets = [choose_hand({n: candidates[n] for n in names if n != drop}, anchors,
                               px_per_m, params, at_rest=at_rest, separation_px=separation_px)
                   for drop in names]
        return min(subsets, key=lambda c: (-c.placed, c.cost))
    scored.sort(key=lambda s: s[0])
    best_cost, best = scored[0]
    close = [p for c, p in scored if c <= best_cost + params.ambiguity_margin]
    chosen, ambiguous = {}, {}
    for n in names:
        rivals = [best[n]]
        for picked in close[1:]:
            if all(math.dist(picked[n].centre, r.centre) > separation_px for r in rivals):
                rivals.append(picked[n])
        if len(rivals) == 1:
            chosen[n] = best[n]
        else:
            ambiguous[n] = rivals
    return HandChoice(chosen, ambiguous, best_cost)

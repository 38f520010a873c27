"""Reaches in a 3D recording, each brought into the movement's own plane as tracks.

A motion-capture trial holds more than the reach: rest, the reach to the
object, the grasp, often the object's transport, a lift or a drink, the
return, and in a long session many of each. :func:`trial_reaches` finds
every reach to grasp in one and says of every trial that gives none, and of
every reach it cannot score, why (:class:`Unscored`). docs/reaches.md
describes the rules; in short:

* **movements** (:func:`find_movements`): every local peak of the transport
  point's speed (the wrist markers' mean where a wrist is mapped, else the
  grip midpoint) of at least :attr:`ReachParams.min_speed`, bounded by the
  field's rule around its own peak (:func:`perception.landmarks.movement_bounds`,
  5 % of that peak: no movement's bound depends on a faster one elsewhere).
  Where two movements follow each other without the speed falling to the
  bound, they part at the speed minimum between them; a movement whose path
  turns by :attr:`ReachParams.turn` or more at a speed minimum, with
  :attr:`ReachParams.min_travel` on each side (a reach then the object's
  transport or a lift; a withdrawal then the next reach), is two. Each
  bound says which rule set it (:attr:`Reach.bound`).
* **reaches** (:func:`classify_movements`): from the transport alone, not
  from the grip (a whole-hand grasp barely opens it, a late or slight
  opening is still a grasp). With object markers, a movement that ends
  :attr:`ReachParams.approach` of its distance nearer the object is a reach, and it ends
  where the object first moves if that comes before the hand stops.
  Without them, a movement away from where the hand rested is a reach;
  what follows it (transport, lift, drink, release) is not, until the hand
  has come back toward where the reach began.

:func:`reach_tracks` turns one reach into the tracks the recognition reads:

* **the plane**: the transport path from onset to end is fitted by its two
  principal directions (SVD); the model's +y is the start-to-end direction
  within the plane and +x the one across it. How far the path leaves the
  plane (RMS and largest, m) goes into the report.
* **the grip**: the aperture is the 3D thumb-index distance; the digits are
  placed across the approach at that aperture, the finger on the model's +x
  side (a projection would hide a grip that lies out of the plane, as it
  does when a lab's participants grasp along the line of sight).
* **the wrist**: a point :attr:`ReachParams.wrist_behind` behind the grip midpoint
  along the approach, the models' own hand (a lab's wrist or hand markers
  carry the transport landmarks, in 3D, not the models' tracks).
* **the object**: the mean of its markers, a given position, or else where
  the grip midpoint comes to rest at the reach's end (where the hand closes
  on it); its size as given, or else the aperture there less the aperture
  at rest (what the recognition's grip aperture reads at contact).
* **rest**: a reach with less than :attr:`ReachParams.min_rest` of stillness before its
  onset (a trial that starts late in its rest, or in motion) is given that
  much rest by holding its first clean sample, with a note; a reach that
  ends where the hand goes on (the object's first motion, the speed minimum
  before a transport or a lift) ends there, its last sample held as long.

Positions are written in metres in the plane, y along the approach
(:attr:`~perception.io.tracks.Tracks.units` ``"m"``): every later stage
reads them as a clip's, with no image scale to find.

The data are :mod:`perception.reach_data`'s, the movement rules
:mod:`perception.movements`' and the plane :mod:`perception.reach_plane`'s;
every name is importable from here.
"""

from __future__ import annotations

import math

import numpy as np

from perception.boundary import expect
from perception.cleaning import clean_path
from perception.errors import InputError
from perception.movements import (
    classify_movements,
    find_movements,
    find_reaches,
    movements_of,
)
from perception.reach_data import (
    MIN_SAMPLES,
    MarkerMap,
    Movement,
    Reach,
    ReachParams,
    Unscored,
    digit_number,
    ever_seen,
)
from perception.reach_plane import PlaneFit, ReachTracks, fit_plane, reach_tracks

__all__ = ["MIN_SAMPLES", "MarkerMap", "Movement", "PlaneFit", "Reach", "ReachParams",
           "ReachTracks", "Unscored", "classify_movements", "find_movements", "find_reaches",
           "fit_plane", "reach_tracks", "recording_reaches", "trial_reaches"]


def _mean_marker(markers, names, time, params, notes) -> np.ndarray | None:
    if not names:
        return None
    paths = []
    for m in names:
        p, rep = clean_path(time, markers[m], params.cleaning)
        if (line := rep.describe(m)) is not None:
            notes.append(line)
        paths.append(p)
    if len(paths) == 1:
        return paths[0]
    stack = np.stack(paths)
    seen = np.isfinite(stack)
    n = seen.sum(axis=0)
    # the mean of the markers seen; NaN where none is (without numpy's empty-slice warning)
    return np.where(n > 0, np.where(seen, stack, 0.0).sum(axis=0) / np.maximum(n, 1), np.nan)



def _lost_throughout(trial, markers: MarkerMap) -> str | None:
    """The role's markers none of whose samples is seen, named (None if each role is seen)."""
    for names in ((markers.finger,), (markers.thumb,), markers.wrist):
        if names and not any(ever_seen(trial.markers[m]) for m in names):
            return ", ".join(names)
    return None


def trial_reaches(trial, markers: MarkerMap | None = None,
                  params: ReachParams | None = None) -> tuple[list[Reach], list[Unscored]]:
    """Every reach to grasp of one trial, and every trial or reach that gives none, and why.

    Never refuses a trial for what it holds: a trial without a reach gives
    one :class:`Unscored` (``no reach``: the hand never moved, or none of its
    movements is a reach, each said; ``too short``; ``marker lost``), and a
    reach that cannot be scored gives one (``starts in motion``, ``ends in
    motion``, ``too short``, ``marker lost``). What follows a reach (the
    object's transport, a lift, the release, the return) is part of the
    trial, not a reach, and is not listed.

    Parameters
    ----------
    trial : MocapTrial
        Its ``time`` (s), ``markers`` (name -> (N, 3) m), ``name`` and ``source``.
    markers : MarkerMap, optional
        Default: :meth:`MarkerMap.guess` from the recording's names.
    params : ReachParams, optional

    Returns
    -------
    list of Reach, list of Unscored

    Raises
    ------
    InputError
        Only for a mapping that names a marker the recording lacks (a mistake
        that holds for every trial of the file).
    """
    expect(markers, MarkerMap, "trial_reaches(markers=)", optional=True)
    expect(params, ReachParams, "trial_reaches(params=)", optional=True)
    params = ReachParams() if params is None else params
    notes = list(getattr(trial, "notes", ()))
    if markers is None:
        markers = MarkerMap.guess(trial.markers)
        # a marker the names suggest but never seen is passed over, said
        used = {m for m, _ in markers.roles()}
        notes += [f"marker {m!r} is never seen: not taken as the {role}"
                  for m, role in MarkerMap.guess(list(trial.markers)).roles()
                  if m not in used and not ever_seen(trial.markers[m])]
        # a digit told by its number, not its name, is said (d1 the thumb, d2 the index)
        notes += [f"marker {m!r} taken as the {role} (digit {digit_number(m)})"
                  for m, role in markers.roles() if role in ("thumb", "finger")
                  and digit_number(m) is not None]
    markers = markers.matched(trial.markers)
    markers.check(trial.markers, trial.source)
    source = str(trial.source)
    time = np.asarray(trial.time, dtype=float)

    # the trial's design and number go with each of its entries (perception.factors)
    labels = {"factors": dict(getattr(trial, "factors", {}) or {}),
              "trial_number": str(getattr(trial, "trial_number", "") or "")}

    def unscored(status, reason, name=trial.name, onset=None, end=None, number=None):
        return Unscored(name, source, status, reason,
                        math.nan if onset is None else float(time[onset]),
                        math.nan if end is None else float(time[end]),
                        reach_number=number, **labels)

    if len(time) < MIN_SAMPLES:
        return [], [unscored("too short", f"too short: {len(time)} samples")]
    if (lost := _lost_throughout(trial, markers)) is not None:
        return [], [unscored("marker lost", f"marker lost throughout: {lost}")]
    finger = _mean_marker(trial.markers, (markers.finger,), time, params, notes)
    thumb = _mean_marker(trial.markers, (markers.thumb,), time, params, notes)
    wrist = _mean_marker(trial.markers, markers.wrist, time, params, notes)
    obj = _mean_marker(trial.markers, markers.object, time, params, notes)
    if obj is not None and not np.isfinite(obj).all(axis=1).any():
        notes.append(f"object markers lost throughout ({', '.join(markers.object)}): "
                     "the object is where the grip closes")
        obj = None
    mid = 0.5 * (finger + thumb)
    transport = mid if wrist is None else wrist  # the field's transport marker
    if not np.isfinite(transport).all(axis=1).any():
        what = ", ".join(markers.wrist) if wrist is not None else \
            f"{markers.thumb} and {markers.finger} together"
        return [], [unscored("marker lost", f"marker lost throughout: {what}")]
    aperture = np.linalg.norm(finger - thumb, axis=1)
    moves = movements_of(time, transport, params, aperture, obj)
    candidates = [m for m in moves if m.kind == "reach"]
    if not candidates:
        if not moves:
            return [], [unscored("no reach", "no reach: the hand never moved (no movement of "
                                 f"{params.min_travel * 1000:.0f} mm or more)")]
        said = "; ".join(f"{_when(time, m)} {m.reason}" for m in moves)
        return [], [unscored("no reach", f"no reach: {len(moves)} movement"
                             f"{'s' if len(moves) > 1 else ''}, none a reach to grasp ({said})")]
    dt = float(np.median(np.diff(time)))
    reaches, skipped = [], []
    for k, m in enumerate(candidates):
        name = trial.name if len(candidates) == 1 else f"{trial.name}-reach{k + 1}"
        if m.onset is None:
            skipped.append(unscored("starts in motion", "starts in motion: the recording "
                                    "begins during the reach", name, None, m.end, k + 1))
            continue
        if m.end is None:
            skipped.append(unscored("ends in motion", "ends in motion: the recording stops "
                                    "before the hand does", name, m.onset, None, k + 1))
            continue
        if m.end - m.onset + 1 < MIN_SAMPLES:
            skipped.append(unscored("too short", f"too short: {m.end - m.onset + 1} samples",
                                    name, m.onset, m.end, k + 1))
            continue
        gone = [n for n, p in ((markers.finger, finger), (markers.thumb, thumb))
                if not np.isfinite(p[m.onset:m.end + 1]).all(axis=1).any()]
        if gone:
            skipped.append(unscored("marker lost", f"marker lost during the reach: "
                                    f"{', '.join(gone)}", name, m.onset, m.end, k + 1))
            continue
        i = moves.index(m)
        prev_end = moves[i - 1].end if i and moves[i - 1].end is not None else 0
        nxt = moves[i + 1].onset if i + 1 < len(moves) and moves[i + 1].onset is not None \
            else len(time) - 1
        lo = max(prev_end, m.onset - int(round(2 * params.min_rest / dt)))
        hi = max(m.end, min(nxt, m.end + int(round(params.tail / dt)), len(time) - 1))
        rows = slice(lo, hi + 1)
        obj_at = None
        if params.object_position is not None:
            obj_at = np.asarray(params.object_position, dtype=float)
        elif obj is not None:
            seen = obj[m.onset:m.end + 1]
            seen = seen[np.isfinite(seen).all(axis=1)]
            obj_at = np.median(seen, axis=0) if len(seen) else None
        follows = []
        for o in moves[i + 1:]:
            if o.kind != "after":
                break
            follows.append(f"{_when(time, o)} {o.reason}")
        extra = [f"not part of the reach: {'; '.join(follows)}"] if follows else []
        reaches.append(Reach(
            name=name, source=source, time=time[rows], transport=transport[rows],
            finger=finger[rows], thumb=thumb[rows],
            wrist=None if wrist is None else wrist[rows], object=obj_at,
            onset=m.onset - lo, end=m.end - lo, notes=tuple(notes + extra),
            onset_bound=m.onset_bound, end_bound=m.end_bound, reach_number=k + 1, **labels))
    return reaches, skipped


def _when(time: np.ndarray, m: Movement) -> str:
    a = "start" if m.onset is None else f"{time[m.onset]:.2f}"
    b = "end" if m.end is None else f"{time[m.end]:.2f}"
    return f"{a}-{b} s:"


def recording_reaches(trial, markers: MarkerMap | None = None,
                      params: ReachParams | None = None) -> list[Reach]:
    """Every reach to grasp in a recording (a :class:`~perception.io.mocap.MocapTrial`).

    :func:`trial_reaches`' reaches; where there are none, its reason is raised.

    Parameters
    ----------
    trial : MocapTrial
        Its ``time`` (s), ``markers`` (name -> (N, 3) m), ``name`` and ``source``.
    markers : MarkerMap, optional
        Default: :meth:`MarkerMap.guess` from the recording's names.
    params : ReachParams, optional

    Raises
    ------
    InputError
        A mapped marker is missing, or no reach is found.
    """
    reaches, unscored = trial_reaches(trial, markers, params)
    if not reaches:
        reason = unscored[0].reason if unscored else "no reach to grasp found"
        raise InputError(f"no reach to grasp found ({reason})", trial.source)
    return reaches



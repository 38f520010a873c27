"""The movement's shape: a demonstration brought to the repertoire's own scale.

A person may reach slower or faster, farther or nearer, and be filmed at
another frame rate and scale than the repertoire's models were planned and
calibrated for — and still grasp normally. The verdict asks whether the
*coordination* is one of the models' own (does the grip follow the
transport as the model's does?), so before it is judged a demonstration is
brought to the repertoire's reference scale (:func:`canonical`):

* **time**: a movement time (:func:`movement_time`) outside the range of
  the repertoire's grasp models is scaled to the nearest end of that range
  (a 0.6 s grasp to 0.8 s, a 1.5 s one to 1.2 s: within the range the
  models of several durations already judge it as it is), then the
  movement is resampled at the reference frame period. Not every movement
  is scaled to one duration: the model's own 0.6 s grasp, stretched to
  1 s, fits its 1 s grasp worse than a 1 s person's does — the muscles'
  lag does not scale with speed;
* **transport**: the wrist's path scaled about its goal (``wrist_offset``
  short of the object centre, where the models' wrists stop) so that it
  starts at the reference distance; the digits keep their places relative
  to the wrist, so the grip is not rescaled;
* **hand**: the digit tips' rest position ahead of the wrist moved to the
  reference hand's.

The grip aperture and its timing relative to the transport — what tells a
normal grasp from a delayed or an open-close-open one — are left as they
were. The verdict (:mod:`perception.recognition.verdict`) is then read off
the repertoire's models at the reference scene, whose calibrations were
made there.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from minvar.grasp_task import GraspTask
from perception.errors import InputError
from perception.landmarks import movement_time
from perception.observation import Observation
from perception.recognition.models import SceneSpec
from perception.recognition.rules import VerdictRules
from perception.resume import Kept
from perception.rowwise import finite_rows

__all__ = ["WRIST_GOAL_OFFSET", "Normalisation", "canonical", "closed_hand", "is_mirrored",
           "opens", "rest_and_opening"]

#: Where the models' wrists stop by default: this far short of the object centre, m
#: (the grasp task's default ``wrist_offset``; a repertoire's own:
#: :meth:`~perception.recognition.repertoire.Repertoire.wrist_offset`).
WRIST_GOAL_OFFSET: float = GraspTask.wrist_offset


@dataclass(frozen=True)
class Normalisation:
    """How a demonstration was brought to the reference scale.

    Attributes
    ----------
    movement_time : float
        Its estimated movement time, s.
    time_scale : float
        Its times were multiplied by this (> 1: it was faster than the
        repertoire's fastest model; 1 within the repertoire's range).
    distance_scale : float
        Reference transport / its transport.
    wrist_offset : float
        Where the models' wrists stop short of the object centre, m: the goal
        the transport was scaled about.
    """

    movement_time: float
    time_scale: float
    distance_scale: float
    wrist_offset: float = WRIST_GOAL_OFFSET

    def to_dict(self) -> dict:
        """JSON-able fields."""
        return dataclasses.asdict(self)


def _resample(t_new: np.ndarray, t: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """``xy`` (N, 2) at ``t_new``, linearly; NaN where either neighbour is lost."""
    out = np.empty((len(t_new), 2))
    filled = np.nan_to_num(xy)  # both columns at once: 8 us a call, six calls a row
    for k in range(2):
        out[:, k] = np.interp(t_new, t, filled[:, k])
    lost = ~finite_rows(xy)
    i = np.clip(np.searchsorted(t, t_new), 1, len(t) - 1)
    gone = lost[i] | lost[i - 1]
    out[gone] = np.nan
    return out


def canonical(obs: Observation, scene: SceneSpec, durations: tuple[float, float],
              rules: VerdictRules | None = None, wrist_offset: float = WRIST_GOAL_OFFSET
              ) -> tuple[Observation, Normalisation]:
    """``obs`` brought to ``scene`` and the range of ``durations`` (see the module docstring).

    Parameters
    ----------
    obs : Observation
        The demonstration, in its own scene.
    scene : SceneSpec
        The reference scene: its distance, hand (``tip_start``) and frame period.
    durations : (float, float)
        The shortest and longest reference movement time, s.
    rules : VerdictRules, optional
        Its ``span_fraction`` (the movement time) and ``min_transport``.
    wrist_offset : float
        Where the reference models' wrists stop short of the object centre, m
        (:meth:`~perception.recognition.repertoire.Repertoire.wrist_offset`).

    Returns
    -------
    Observation
        The demonstration at the reference scale (``clip`` kept).
    Normalisation
        What was done.

    Raises
    ------
    InputError
        Too little of the movement is seen to measure its time, or the wrist
        travels less than ``rules.min_transport``.
    """
    rules = VerdictRules() if rules is None else rules
    # a stream at rest brings the same movement again at every row (only the rows after it
    # grow): what it became is kept (the observation's other fields are the new one's)
    key = (scene, durations, rules)  # the whole rules: a field read later is keyed too
    inputs = (obs.time, obs.wrist, obs.finger, obs.thumb, obs.frame,
              np.array([*np.asarray(obs.hand_offset, dtype=float), obs.start_distance,
                        obs.noise, wrist_offset]))
    kept = _CANONICAL.longest(key, inputs, first=lambda s: len(s[0]) == len(obs.time))
    if kept is None:
        arrays, norm = _canonical(obs, scene, durations, rules, wrist_offset)
        _CANONICAL.keep(key, inputs, (arrays, norm))
    else:
        arrays, norm = kept[1]
    # copies: each result's arrays its own, as they were when made afresh
    return dataclasses.replace(obs, **{k: np.copy(v) for k, v in arrays.items()}, raw={},
                               dt=scene.frame_period, start_distance=scene.distance,
                               noise=obs.noise * norm.distance_scale), norm


#: Movements brought to the reference scale in this thread (:func:`canonical`): the
#: verdict's, kept for the rows of a stream at rest.
_CANONICAL = Kept(2)


def _canonical(obs: Observation, scene: SceneSpec, durations: tuple[float, float],
               rules: VerdictRules, wrist_offset: float) -> tuple[dict, Normalisation]:
    """:func:`canonical`'s new arrays (time, frames, paths, hand offset) and what was done."""
    mt = movement_time(obs, rules.span_fraction)
    if not (np.isfinite(mt) and mt > 0):
        raise InputError("the wrist is seen too little to measure the movement time",
                         obs.clip, field="wrist")
    alpha = float(np.clip(mt, *durations)) / mt
    transport = obs.start_distance - wrist_offset
    if transport < rules.min_transport:
        raise InputError(f"starts {obs.start_distance * 1000:.0f} mm from the object: too near "
                         "to judge a reach", obs.clip, field="wrist")
    s = (scene.distance - wrist_offset) / transport
    goal = np.array([0.0, -wrist_offset])
    tip = np.array([0.0, scene.tip_start]) - np.asarray(obs.hand_offset, dtype=float)
    wrist = goal + (obs.wrist - goal) * s
    finger = obs.finger - obs.wrist + wrist + tip
    thumb = obs.thumb - obs.wrist + wrist + tip
    t_scaled = obs.time * alpha
    step = scene.frame_period
    t_new = np.arange(np.ceil(t_scaled[0] / step), np.floor(t_scaled[-1] / step) + 1) * step
    frames = np.interp(t_new, t_scaled, obs.frame.astype(float)).round().astype(int)
    arrays = {"time": t_new, "frame": frames, "wrist": _resample(t_new, t_scaled, wrist),
              "finger": _resample(t_new, t_scaled, finger),
              "thumb": _resample(t_new, t_scaled, thumb),
              "hand_offset": np.asarray(obs.hand_offset, dtype=float) + tip}
    return arrays, Normalisation(float(mt), float(alpha), float(s), float(wrist_offset))


def closed_hand(obs: Observation) -> Observation:
    """``obs`` with the digits kept closed at their rest place ahead of the wrist.

    The transport alone, as a reach-only model makes it: scored against the
    reach models, it says whether the wrist moves like a human reach
    whatever the grip does (the verdict ``unfamiliar`` when it does not).

    Parameters
    ----------
    obs : Observation
        A demonstration (at the reference scale).
    """
    tips = obs.wrist + np.asarray(obs.hand_offset, dtype=float)
    return dataclasses.replace(obs, finger=tips.copy(), thumb=tips.copy())


def is_mirrored(obs: Observation, rules: VerdictRules | None = None) -> bool:
    """Whether the finger opens on the model's -x side: a mirrored scene.

    The models put the finger at +x of the approach (a right hand filmed
    from its thumb's side, or a left hand from the other side, is the
    mirror image). Read over the frames where the grip is open by at least
    ``rules.mirror_opening``: mirrored if in more than ``mirror_majority``
    of them the finger is on -x. A movement that never opens (a reach) is
    never mirrored.

    Parameters
    ----------
    obs : Observation
        The demonstration.
    rules : VerdictRules, optional
    """
    rules = VerdictRules() if rules is None else rules
    opening = obs.finger - obs.thumb
    wide = np.linalg.norm(opening, axis=1) >= rules.mirror_opening
    return bool(wide.any() and np.mean(opening[wide, 0] < 0) > rules.mirror_majority)


def opens(obs: Observation, rules: VerdictRules | None = None) -> bool:
    """Whether the grip opens as a grasp of the object must: a grasp, not a reach.

    The observed aperture must exceed its rest value (the first
    ``rules.grasp_rest_frames`` seen frames) by ``rules.grasp_opening`` ×
    the object's diameter at some frame. The
    verdict is then judged against the repertoire's grasp models, otherwise
    against its reach models: whether the hand opens is what tells the two
    kinds apart, and the one-step likelihood weighs it weakly (a grasp
    model's predicted opening is uncertain, its signal-dependent noise large).

    Parameters
    ----------
    obs : Observation
        The demonstration.
    rules : VerdictRules, optional
    """
    rules = VerdictRules() if rules is None else rules
    _, opening = rest_and_opening(obs.g[np.isfinite(obs.g)], rules)
    return bool(opening >= rules.grasp_opening * obs.object_diameter)


def rest_and_opening(g: np.ndarray, rules: VerdictRules | None = None) -> tuple[float, float]:
    """The grip's rest aperture (the mean of its first ``rules.grasp_rest_frames`` samples)
    and how far it opened beyond it, m (NaN, 0 without a sample).

    Parameters
    ----------
    g : (N,) array
        The aperture where it was seen, m (the offline verdict's and the online one's).
    rules : VerdictRules, optional
    """
    rules = VerdictRules() if rules is None else rules
    if not len(g):
        return float("nan"), 0.0
    rest = float(np.mean(g[:rules.grasp_rest_frames]))
    return rest, float(np.max(g) - rest)

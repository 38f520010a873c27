"""What a verdict is judged on, built in one place for every path.

A clip's recognition (:func:`perception.pipeline.recognize_tracks`) scores
the movement once, at the repertoire's reference scale, against every model;
the verdict then judges the models of the kind the grip shows
(:func:`judged_models`), the movement's own landmarks against the reference
grasp model's (:func:`clip_landmarks`), and the gaps and the end of the
movement (:func:`movement_evidence`). :func:`perception.recognition.rules.judge`
is called once on the :class:`~perception.recognition.rules.Evidence` built
here.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from perception.landmarks import Landmarks, longest_gap, model_landmarks, observed_landmarks
from perception.recognition.rules import Evidence, VerdictRules, peak_and_least, slowed, speeds
from perception.resume import Kept

if TYPE_CHECKING:
    from perception.observation import Observation
    from perception.recognition.models import MotorModel

__all__ = ["clip_landmarks", "grip_course", "judged_models", "marker_aperture",
           "model_own_landmarks", "movement_evidence", "reference_model", "wrist_progress"]


def judged_models(kinds: Sequence[str], kind: str) -> tuple[int, ...]:
    """Indices of the models of ``kind`` (every model where there is none of it).

    Parameters
    ----------
    kinds : sequence of str
        Each model's kind.
    kind : str
        ``grasp`` where the grip opens as a grasp's must, else ``reach``
        (:func:`perception.recognition.shape.opens`).
    """
    every = tuple(range(len(kinds)))
    return tuple(i for i in every if kinds[i] == kind) or every


def reference_model(names: Sequence[str], kinds: Sequence[str],
                    log_likelihood: np.ndarray) -> str | None:
    """The grasp model with the highest final log-likelihood (None without a grasp model).

    Parameters
    ----------
    names, kinds : sequence of str
    log_likelihood : (M,) array
        Each model's final log-likelihood.
    """
    grasp = [i for i, k in enumerate(kinds) if k == "grasp"]
    if not grasp:
        return None
    return names[grasp[int(np.argmax(np.asarray(log_likelihood)[grasp]))]]


def model_own_landmarks(model: MotorModel, rules: VerdictRules) -> Landmarks:
    """The landmarks of a model's own noise-free movement.

    Its movement from its planned start, run until half its planned duration
    past its end, bounded by ``rules.landmarks`` as a clip's are. Measured
    once per model and landmark definition (a stream judged frame by frame
    asks at every frame; a model is never changed after it is planned).
    """
    from perception.recognition.rollout import rollout

    key = (id(model), rules.landmarks)
    hit = _OWN.get(key)
    if hit is not None and hit[0] is model:
        return hit[1]
    run = rollout([model], int(np.ceil(1.5 * model.duration / model.dt)) + 1)
    own = model_landmarks(run.time, run.wrist[0, 0], run.finger[0, 0], run.thumb[0, 0],
                          rules.landmarks)
    if len(_OWN) >= 64:  # a repertoire's models a few times over
        _OWN.pop(next(iter(_OWN)))
    _OWN[key] = (model, own)
    return own


#: :func:`model_own_landmarks`' measured so far: (model id, landmark params) -> (model, landmarks).
_OWN: dict[tuple, tuple] = {}


def clip_landmarks(observation: Observation, models: Sequence[MotorModel],
                   log_likelihood: np.ndarray, rules: VerdictRules,
                   measured: Landmarks | None = None
                   ) -> tuple[Landmarks, Landmarks | None]:
    """The movement's landmarks and the reference grasp model's own.

    Parameters
    ----------
    observation : Observation
        The movement at its own scale (the landmarks' units are the clip's).
    models : sequence of MotorModel
        The models scored.
    log_likelihood : (M,) array
        Their final log-likelihoods (:func:`reference_model`).
    rules : VerdictRules
        Its ``landmarks`` bound them.
    measured : Landmarks, optional
        The movement's landmarks measured on better data than the observation
        holds (a 3D recording's speed and aperture); else measured on it.
    """
    names = [m.name for m in models]
    ref = reference_model(names, [m.kind for m in models], log_likelihood)
    observed = (measured if measured is not None
                else observed_landmarks(observation, rules.landmarks))
    own = model_own_landmarks(models[names.index(ref)], rules) if ref is not None else None
    return observed, own


def marker_aperture(obs: Observation) -> np.ndarray:
    """The digit markers' own aperture, m, NaN where one is lost (the filtered aperture
    coasts through a gap).

    Parameters
    ----------
    obs : Observation
        The movement (its ``raw`` positions, else its filtered ``g``).
    """
    raw = obs.raw or {}
    if "finger" in raw and "thumb" in raw:
        return np.linalg.norm(raw["finger"] - raw["thumb"], axis=1)
    return obs.g


def wrist_progress(obs: Observation, wrist_offset: float) -> np.ndarray:
    """(N,) the wrist's displacement from where the movement started, as a share of its way
    to the models' goal (``start distance - wrist_offset``); not clipped.

    Parameters
    ----------
    obs : Observation
        The movement at its own scale.
    wrist_offset : float
        Where the models' wrists stop short of the object centre, m.
    """
    return np.linalg.norm(obs.wrist - obs.wrist[0], axis=1) / (obs.start_distance - wrist_offset)


def grip_course(observation: Observation, rules: VerdictRules,
                wrist_offset: float) -> dict[str, float | bool]:
    """The grip's course in the movement so far, read from the digit markers' own aperture
    (:func:`marker_aperture`, seen samples) and the wrist's way to the models' goal
    (:func:`wrist_progress`): what :class:`~perception.recognition.rules.Evidence` holds
    as ``opening_progress``, ``opening``, ``closing``, ``progress`` and ``reopened``.

    Each is known while the movement is under way, before the end that the landmarks
    need (the online settle rule reads them; the verdict does not). The grip *opened as
    a grasp's must* where its aperture exceeded its rest
    (:func:`~perception.recognition.shape.rest_and_opening`) by ``rules.grasp_opening``
    × the object's diameter.

    * ``opening_progress``: the wrist's progress where the aperture first exceeded its
      rest by ``rules.landmarks.opening_level`` of its opening, as the landmark
      ``opening_time`` reads it (NaN where it has not opened as a grasp's must);
    * ``opening``: how far it opened beyond its rest, m;
    * ``closing``: share of that opening closed since its maximum;
    * ``progress``: the largest share of the wrist's way covered, 0..1;
    * ``reopened``: it opened as a grasp's must, then closed and opened again, each by
      ``rules.landmarks.peak_prominence`` of its opening so far.

    Parameters
    ----------
    observation : Observation
        The movement at its own scale.
    rules : VerdictRules
    wrist_offset : float
        Where the models' wrists stop short of the object centre, m.
    """
    from perception.recognition.shape import rest_and_opening

    obs = observation
    g = marker_aperture(obs)
    rows = np.flatnonzero(np.isfinite(g))
    g = g[rows]
    moved = wrist_progress(obs, wrist_offset)
    rest, opening = rest_and_opening(g, rules)
    course = {"opening_progress": float("nan"), "opening": opening,
              "closing": float(g.max() - g[-1]) / opening if opening > 0 and g.size else 0.0,
              "progress": float(np.clip(np.nanmax(moved, initial=0.0), 0.0, 1.0)),
              "reopened": False}
    if len(g) < 3:
        return course
    if opening >= rules.grasp_opening * obs.object_diameter:
        k = rows[int(np.argmax(g > rest + rules.landmarks.opening_level * opening))]
        course["opening_progress"] = float(np.clip(moved[k], 0.0, 1.0))
    above = np.flatnonzero(g > rest + rules.grasp_opening * obs.object_diameter)
    if above.size:
        after = g[above[0]:]
        dip = np.maximum.accumulate(after) - after
        k = int(np.argmax(dip))
        need = rules.landmarks.peak_prominence * (float(after.max()) - rest)
        course["reopened"] = bool(dip[k] >= need and float(after[k:].max() - after[k]) >= need)
    return course


def movement_evidence(observation: Observation, kinds: Sequence[str],
                      log_likelihood: np.ndarray, familiarity: np.ndarray,
                      landmarks: tuple[Landmarks, Landmarks | None] | None = None,
                      transport_familiarity: float = float("nan"),
                      scored_share: float = 1.0,
                      grip: dict | None = None) -> Evidence:
    """The :class:`~perception.recognition.rules.Evidence` of a movement.

    Parameters
    ----------
    observation : Observation
        The movement at its own scale: its rest aperture, the longest stretch
        its digits went unseen (the markers' own aperture: the filtered one
        coasts through a gap) and how far its transport slowed.
    kinds : sequence of str
        The judged models' kinds.
    log_likelihood, familiarity : (M,) arrays
        The judged models' final log-likelihood and familiarity.
    landmarks : (Landmarks, Landmarks or None), optional
        :func:`clip_landmarks`' (None: scores alone, as a lone engine pass).
    transport_familiarity : float
        The transport's alone to the best reach model (NaN: not measured).
    scored_share : float
        Share of the movement's steps scored.
    grip : dict, optional
        :func:`grip_course`'s (None: not measured).
    """
    if landmarks is None:
        return Evidence(list(kinds), np.asarray(log_likelihood), np.asarray(familiarity))
    obs = observation
    return Evidence(list(kinds), np.asarray(log_likelihood), np.asarray(familiarity),
                    transport_familiarity=float(transport_familiarity),
                    rest_aperture=obs.marker_separation, observed=landmarks[0],
                    reference=landmarks[1],
                    aperture_gap=longest_gap(obs.time, marker_aperture(obs)),
                    slowed=_arrival(obs), scored_share=float(scored_share), **(grip or {}))


def _arrival(obs) -> float:
    """How far the transport slowed from its peak in the scored movement, read to the
    clip's last sample: the end rule closes the movement early under noisy tracking
    (its speed floor rises with the noise), and a clip that goes on with the hand at
    rest is not cut before the hand arrives.

    :func:`~perception.recognition.rules.slowed` of those rows, resumed where they
    begin with the rows measured last in this thread with the same movement, its
    peak among them: the slowest speed since is the least of the kept one and the
    new rows' (a minimum is exact in any order), not every row's again.
    """
    if obs.clip_wrist is None or obs.clip_time is None or not len(obs.time):
        return slowed(obs.time, obs.wrist)
    start = int(np.searchsorted(obs.clip_time, obs.time[0]))
    time, wrist, movement = obs.clip_time[start:], obs.clip_wrist[start:], len(obs.time)
    kept = _ARRIVAL.longest(movement, (time, wrist))
    if kept is None:
        peak_least = peak_and_least(time, wrist, movement)
        if peak_least is None:
            return 0.0  # slowed's: no peak to slow from
        peak, least = peak_least
    else:
        (peak, least), n = kept[1], len(kept[0][0])
        new = speeds(time[n - 1:], wrist[n - 1:])
        new = new[np.isfinite(new)]
        if len(new):
            least = min(least, new.min())
    if movement <= len(time):  # its peak among these rows: a longer series resumes it
        _ARRIVAL.keep(movement, (time, wrist), (peak, least), kept)
    return float(1.0 - least / peak)


#: The last arrival measured in this thread: the movement's length, its rows, and their
#: peak speed and slowest speed since (:func:`_arrival`).
_ARRIVAL = Kept(1)

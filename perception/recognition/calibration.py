"""Calibrating familiarity: each model scores its own demonstrations.

For every model, :func:`calibrate` makes ``CalibrationParams.demonstrations``
demonstrations of the model's own movement (:func:`~perception.recognition.rollout.rollout`
from its stored gains, with command noise) varied the way one person's
grasps vary (movement time, the grip's timing against the transport, the
size of the opening, a bowed path), puts them through a camera with tracking
noise, observes them like a clip (:func:`~perception.observation.observe`:
smoothing, onset, end; the onset by the onset profile unscaled, as before
its time scale was fitted to a clip's start: fitted, a demonstration whose
clock runs ahead early (``transport_skew``) moves its onset, and every
calibration widened) and scores each against the model
(:func:`~perception.recognition.engine.recognize`). The misfits are the
model's :class:`~perception.recognition.verdict.Calibration`. It is done once
per repertoire (``Repertoire.build``, or on loading a file that lacks it)
and stored in the repertoire file.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from perception.geometry import SimilarityTransform
from perception.io.tracks import Status, Tracks
from perception.observation import ObserveParams, observe
from perception.recognition.engine import recognize
from perception.recognition.models import MotorModel
from perception.recognition.rollout import Rollout, rollout
from perception.recognition.verdict import Calibration, CalibrationParams, misfit

__all__ = ["calibrate", "own_demonstration"]

_MARKERS = ("thumb", "finger", "wrist", "object")


def _bump(tau: np.ndarray) -> np.ndarray:
    """0 at the start and end of the movement, 1 in its middle."""
    return np.sin(np.pi * np.clip(tau, 0.0, 1.0))


def _skewed(tau: np.ndarray, skew: float) -> np.ndarray:
    """A monotone warp of the movement's clock, 0 -> 0 and 1 -> 1: ``skew`` > 0 runs
    ahead early (the speed peaks earlier, a longer deceleration), < 0 behind."""
    tau = np.clip(tau, 0.0, 1.0)
    return tau + skew * np.sin(np.pi * tau) / np.pi


def _interp(t: np.ndarray, ref: np.ndarray, xy: np.ndarray) -> np.ndarray:
    return np.stack([np.interp(t, ref, xy[:, 0]), np.interp(t, ref, xy[:, 1])], axis=1)


def own_demonstration(model: MotorModel, run: Rollout, index: int, params: CalibrationParams,
                      rng: np.random.Generator) -> Tracks:
    """One of the model's own demonstrations as tracks (px), varied and noisy.

    Parameters
    ----------
    model : MotorModel
        The model (its scene gives the frame rate and the object).
    run : Rollout
        Executions of this model alone (``run.wrist`` is (1, trials, S+1, 2)).
    index : int
        Which execution.
    params : CalibrationParams
        The variability and the camera.
    rng : numpy.random.Generator
        Source of the variations and the tracking noise.
    """
    p, D = params, model.duration
    period = model.scene.frame_period
    k = 1 + rng.uniform(-p.time_scale, p.time_scale)
    shift, scale = rng.uniform(-p.grip_shift, p.grip_shift), rng.uniform(-p.aperture_scale,
                                                                          p.aperture_scale)
    bow = rng.uniform(-p.path_bow, p.path_bow)
    skew = rng.uniform(0.0, p.transport_skew)
    noise_px = p.noise_px * rng.uniform(1 - p.noise_spread, 1 + p.noise_spread)
    t = np.arange(int(round((2 * p.rest + k * D) / period)) + 1) * period
    tau = (t - p.rest) / (k * D)
    tm = np.clip(_skewed(tau, skew) * D, 0.0, run.time[-1])
    tg = np.clip(tm + shift * D * _bump(tau), 0.0, run.time[-1])  # the grip's own clock
    wrist = _interp(tm, run.time, run.wrist[0, index])
    finger = _interp(tg, run.time, run.finger[0, index] - run.wrist[0, index])
    thumb = _interp(tg, run.time, run.thumb[0, index] - run.wrist[0, index])
    mid, half = 0.5 * (finger + thumb), 0.5 * (finger - thumb) * (1 + scale * _bump(tau))[:, None]
    lateral = np.stack([bow * _bump(tau), np.zeros_like(tau)], axis=1)
    wrist = wrist + lateral
    across = np.array([p.marker_offset, 0.0])
    world = {"wrist": wrist, "finger": wrist + mid + half + across,
             "thumb": wrist + mid - half - across, "object": np.zeros_like(wrist)}
    camera = SimilarityTransform((320.0, 144.0), p.px_per_m, math.pi / 2)
    pos = np.stack([camera.to_pixels(world[m]) for m in _MARKERS], axis=1)
    pos = pos + noise_px * rng.standard_normal(pos.shape)
    diameter = [model.scene.object_size * p.px_per_m if m == "object" else math.nan
                for m in _MARKERS]
    return Tracks(frame=np.arange(len(t)), time=t, markers=_MARKERS, position=pos,
                  likelihood=np.ones(pos.shape[:2], np.float32),
                  status=np.full(pos.shape[:2], Status.TRACKED, np.int8),
                  tracker={"method": "calibration", "diameter_px": diameter})


def _calibrate_one(model: MotorModel, params: CalibrationParams, seed: list[int]
                   ) -> Calibration:
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    steps = int(np.ceil((1 + params.time_scale + params.grip_shift) * model.duration
                        / model.dt)) + 2
    cv = params.execution_cv
    run = rollout([model], steps, trials=params.demonstrations, cv=cv, rng=rng)
    values = []
    # the onset profile unscaled: a time scale fitted to the demonstrations' start moved
    # the onset of those whose clock runs ahead early, and widened every calibration
    # (docs/recognition.md §1)
    own = ObserveParams(onset_scale_range=None)
    for j in range(params.demonstrations):
        obs = observe(own_demonstration(model, run, j, params, rng), own,
                      clip=f"{model.name}-own")
        rec = recognize(obs, [model])
        values.append(misfit(rec.mahalanobis, rec.scored)[0])
    return Calibration(np.array(values), model.scene.frame_period, params)


def calibrate(models: Sequence[MotorModel], params: CalibrationParams | None = None
              ) -> list[Calibration]:
    """The calibration of each model from its own demonstrations.

    Parameters
    ----------
    models : sequence of MotorModel
        The models (each calibrated on its own; the same model in the same
        scene always gets the same calibration).
    params : CalibrationParams, optional
        The demonstrations' number and variability.
    """
    params = CalibrationParams() if params is None else params
    # each model's draws depend on its name and the seed only: adding a model
    # to a repertoire leaves the others' calibrations as they were
    return [_calibrate_one(m, params, _stream(params.seed, m.name)) for m in models]


def _stream(seed: int, name: str) -> list[int]:
    return [seed, *name.encode()]

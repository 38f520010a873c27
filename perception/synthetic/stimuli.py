"""The stimuli of thesis 5.4.1 (after Gangitano et al. 2004), from the grasp model.

All are derived from the minimum variance grasp model of :mod:`minvar.grasp`,
differing only in the grip channel's via-points:

``normal``
    The thesis's grasp: one via-point per digit 1 cm outside the object,
    level with the targets, at 70 % of the movement.
``delayed``
    The digits stay nearly closed through the first half and open late: the
    maximal aperture comes markedly late (about 85-90 % of the movement).
``open-close-open``
    The digits open as for a normal grasp, are closed at the normal grasp's
    expected maximal aperture (its via-point's time, 70 % of the movement;
    thesis line 1081), and re-open before closing on the object.
``reach``
    Not a Gangitano stimulus: the transport alone, digits kept closed (for
    checking that reach-only movements are told from grasps).
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from minvar import GraspTask, GripVia, shoulder_for, simulate_grasp
from perception.geometry import DEFAULT_OBJECT_DIAMETER, DEFAULT_TIP_START
from perception.limits import MAX_REST_S
from perception.validation import declared

__all__ = ["CONDITIONS", "StimulusParams", "stimulus_task", "stimulus_paths"]

CONDITIONS = ("normal", "delayed", "open-close-open", "reach")

@declared
class StimulusParams:
    """One demonstration's movement.

    Parameters
    ----------
    condition : str
        ``normal``, ``delayed``, ``open-close-open`` or ``reach``.
    object_size : float
        Object diameter, m (thesis chapter 5: a 100 mm ball).
    distance : float
        Wrist start to object centre, m.
    duration : float
        Movement time, s.
    execution_cv : float
        Coefficient of variation of the demonstrator's motor noise.
    rest_before, rest_after : float
        Still periods around the movement, s (trimmed before recognition).
    marker_offset : float
        How far each digit's marker sits outside its tip, across the grip, m:
        the model's tips touch at the start, real markers sit side by side.
    """

    condition: Literal[CONDITIONS] = "normal"
    object_size: Annotated[float, Field(gt=0, le=0.5)] = DEFAULT_OBJECT_DIAMETER
    distance: Annotated[float, Field(gt=0, le=2)] = 0.25
    duration: Annotated[float, Field(gt=0, le=10)] = 1.0
    execution_cv: Annotated[float, Field(ge=0, le=1)] = 0.03
    rest_before: Annotated[float, Field(ge=0, le=MAX_REST_S)] = 0.3
    rest_after: Annotated[float, Field(ge=0, le=MAX_REST_S)] = 0.3
    marker_offset: Annotated[float, Field(ge=0, le=0.1)] = 0.0065


def stimulus_task(p: StimulusParams) -> GraspTask:
    """The :class:`minvar.GraspTask` that produces stimulus ``p``.

    Parameters
    ----------
    p : StimulusParams
        The demonstration.
    """
    radius = p.object_size / 2
    common = dict(object_size=p.object_size, distance=p.distance, duration=p.duration,
                  execution_cv=p.execution_cv, tip_start=DEFAULT_TIP_START,
                  shoulder_offset=shoulder_for(p.distance))
    if p.condition == "normal":
        return GraspTask(**common)
    if p.condition == "reach":
        return GraspTask(reach_only=True, **common)
    if p.condition == "delayed":
        # two closed via-points: one soft via-point alone lets the tips drift open early
        vias = (GripVia(0.003, 0.0, 0.30), GripVia(0.003, 0.0, 0.55),
                GripVia(radius + 0.02, 0.0, 0.88))
    else:  # open-close-open
        # closed at the normal grasp's expected maximum aperture (thesis line 1081: "an
        # unexpected finger closure at the point of expected maximum finger aperture"),
        # the normal via-point's time; opening as normal does until then, re-opening after
        closed_at = GraspTask().viapoint_time
        vias = (GripVia(radius + 0.012, 0.0, closed_at - 0.22),
                GripVia(0.3 * radius, 0.0, closed_at), GripVia(radius + 0.015, 0.0, 0.88))
    return GraspTask(grip_via=vias, **common)


def stimulus_paths(p: StimulusParams, fps: float, *, seed) -> tuple[np.ndarray, dict]:
    """World-frame marker paths of one noisy demonstration, sampled at frame times.

    Parameters
    ----------
    p : StimulusParams
        The demonstration.
    fps : float
        Frame rate, frames/s.
    seed : int or numpy.random.Generator
        Motor noise of this repetition.

    Returns
    -------
    time : (F,) array
        Frame times, s.
    paths : dict of (F, 2) arrays
        ``wrist``, ``finger``, ``thumb`` marker positions, m (object centre at
        the origin); the digit markers sit ``p.marker_offset`` outside the tips.
    """
    res = simulate_grasp(stimulus_task(p), trials=1, seed=seed)
    t_model = res.time
    n = int(round((p.rest_before + p.duration + p.rest_after) * fps)) + 1
    t = np.arange(n) / fps
    # the model's time runs from the onset; before it the hand rests, after it it holds
    tm = np.clip(t - p.rest_before, 0.0, t_model[-1])
    paths = {}
    for name in ("wrist", "finger", "thumb"):
        xy = getattr(res, name)[0]
        paths[name] = np.stack([np.interp(tm, t_model, v) for v in xy.T], axis=1)
    # the hand frame is not rotated: across the grip is the world x axis
    paths["finger"][:, 0] += p.marker_offset
    paths["thumb"][:, 0] -= p.marker_offset
    return t, paths

"""Recipes: sets of synthetic grasp clips rendered from the minimum variance model.

A *recipe* (TOML, docs/recipes.md) says how many clips of each stimulus
condition (:mod:`perception.synthetic.stimuli`) to render, the scene, the
demonstrator's variability and the camera/rendering style. Every clip gets
its ground truth beside it (``<clip>.truth.h5``) with its condition and
parameters, and the set gets a ``manifest.csv``.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from perception.errors import InputError
from perception.io.atomic import write_csv
from perception.io.config import Spec, check_keys, check_table, read_toml, sub_table
from perception.io.video import CODECS
from perception.limits import MAX_CLIPS
from perception.synthetic.footage import load_background
from perception.synthetic.render import render_clip, render_rows
from perception.synthetic.scene import (
    DISTRACTOR_LIMITS,
    OCCLUSION_LIMITS,
    RENDER_LIMITS,
    Camera,
    Distractor,
    Occlusion,
    RenderStyle,
    Scene,
)
from perception.synthetic.stimuli import (
    CONDITIONS,
    SCENE_LIMITS,
    StimulusParams,
    stimulus_paths,
    stimulus_task,
)
from perception.tracking.markers import MARKER_NAMES

__all__ = ["Recipe", "load_recipe", "render_style", "clip_plans", "synthesize"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Recipe:
    """How to render a set of clips (parsed from a TOML recipe).

    Parameters
    ----------
    name : str
        Recipe name (file stem).
    counts : dict
        Clips per condition.
    stimulus : StimulusParams
        The nominal movement (its condition is replaced per clip).
    duration_sd, distance_sd : float
        Demonstrator variability between clips (SD, s and m).
    camera_angle_deg : (float, float)
        Range of camera rotations, degrees, drawn uniformly per clip.
    style : dict
        :class:`perception.synthetic.render.RenderStyle` fields (fps, width, height, codec,
        hand, noise_sd, blur_sigma, lighting, ...).
    """

    name: str
    counts: dict
    stimulus: StimulusParams = field(default_factory=StimulusParams)
    duration_sd: float = 0.0
    distance_sd: float = 0.0
    camera_angle_deg: tuple[float, float] = (0.0, 0.0)
    style: dict = field(default_factory=dict)

    @property
    def n_clips(self) -> int:
        """Total number of clips."""
        return int(sum(self.counts.values()))


#: The tables of a recipe file.
RECIPE_TABLES = ("conditions", "scene", "variation", "render")


#: Type and range of each ``[variation]`` value.
VARIATION_LIMITS: dict[str, Spec] = {
    "duration_sd": Spec(float, 0, 10, note="s"),
    "distance_sd": Spec(float, 0, 1, note="m"),
    "camera_angle_deg": Spec(float, -180, 180, size=2, note="degrees, [low, high]"),
}
#: Of each ``[conditions]`` value (clips of that condition).
CONDITION_LIMITS: dict[str, Spec] = {
    c: Spec(int, 0, MAX_CLIPS, note=f"at most {MAX_CLIPS} clips per recipe") for c in CONDITIONS}
#: Of each ``[[render.occlusions]]`` value: an occlusion hides one of the markers.
_OCCLUSION_TABLE = {**OCCLUSION_LIMITS, "marker": Spec(str, choices=MARKER_NAMES)}
#: A distractor's, and a sleeve's, colour names a marker.
_DISTRACTOR_TABLE = {**DISTRACTOR_LIMITS, "colour": Spec("colour", choices=MARKER_NAMES)}
_RENDER_TABLE = {**RENDER_LIMITS, "sleeve": Spec("colour", choices=MARKER_NAMES)}
_REQUIRED = {"distractors": ("colour", "start"), "occlusions": ("marker", "start", "stop")}


def load_recipe(path: str | os.PathLike) -> Recipe:
    """Read a recipe TOML file.

    Every value is checked for its type and range before anything is built
    (:data:`CONDITION_LIMITS`, :data:`VARIATION_LIMITS`,
    :data:`perception.synthetic.stimuli.SCENE_LIMITS`,
    :data:`perception.synthetic.scene.RENDER_LIMITS`, ...).

    Parameters
    ----------
    path : str or os.PathLike
        The recipe.

    Raises
    ------
    InputError
        If the file is missing, not a regular file, not TOML, or has unknown
        or bad fields; the message names the file and the field.
    """
    path = Path(path)
    cfg = read_toml(path, "recipe")
    try:
        check_keys(cfg, RECIPE_TABLES, "the top level", path)
        tables = {name: sub_table(cfg, name, f"[{name}]", path) for name in RECIPE_TABLES}
        check_table(tables["conditions"], CONDITION_LIMITS, "[conditions]", path)
        counts = {str(k): int(v) for k, v in tables["conditions"].items()}
        if not 0 < sum(counts.values()) <= MAX_CLIPS:
            raise InputError(f"expected at least 1 and at most {MAX_CLIPS} clips in all, got "
                             f"{sum(counts.values())}", path, field="[conditions]")
        check_table(tables["scene"], SCENE_LIMITS, "[scene]", path)
        check_table(tables["variation"], VARIATION_LIMITS, "[variation]", path)
        stim = StimulusParams(**tables["scene"])
        var = tables["variation"]
        angle = tuple(float(a) for a in var.get("camera_angle_deg", (0.0, 0.0)))
        recipe = Recipe(name=path.stem, counts=counts, stimulus=stim,
                        duration_sd=float(var.get("duration_sd", 0.0)),
                        distance_sd=float(var.get("distance_sd", 0.0)),
                        camera_angle_deg=angle, style=dict(tables["render"]))
        render_style(recipe.style, path)  # validate now, not after rendering half the set
        clip_plans(recipe, seed=0)  # every clip's movement must be plannable
    except InputError as exc:
        if exc.path is None:
            raise InputError(exc.problem, path, field=exc.field) from None
        raise
    except (TypeError, ValueError, KeyError) as exc:
        raise InputError(f"bad recipe: {exc}", path) from None
    return recipe


def render_style(table: Mapping[str, Any], path: str | os.PathLike | None = None) -> RenderStyle:
    """A :class:`~perception.synthetic.render.RenderStyle` from a recipe's ``[render]`` table.

    Parameters
    ----------
    table : mapping
        RenderStyle fields; ``distractors`` and ``occlusions`` as lists of tables
        (``{colour, start, end, diameter, frames, shape, aspect, angle_deg}``,
        ``{marker, start, stop}``); ``background = "photo:NAME"`` or
        ``"video:PATH"``. An unknown key is refused, naming the nearest valid
        one; every value is checked against :data:`RENDER_LIMITS` (and
        :data:`DISTRACTOR_LIMITS`, :data:`OCCLUSION_LIMITS`).
    path : str or os.PathLike, optional
        The recipe, for messages.

    Raises
    ------
    InputError
        A bad key or value, naming the field (``[render] fps``).
    """
    check_table(table, _RENDER_TABLE, "[render]", path)
    fields = dict(table)
    for key, limits, cls in (("distractors", _DISTRACTOR_TABLE, Distractor),
                             ("occlusions", _OCCLUSION_TABLE, Occlusion)):
        if key not in fields:
            continue
        items = fields[key]
        if not isinstance(items, list | tuple) or not all(isinstance(i, Mapping) for i in items):
            raise InputError(f"expected a list of tables ([[render.{key}]]), got "
                             f"{items!r}"[:120], path, field=f"[render] {key}")
        built = []
        for i, item in enumerate(items):
            where = f"[[render.{key}]] #{i + 1}"
            check_table(item, limits, where, path)
            missing = [k for k in _REQUIRED[key] if k not in item]
            if missing:
                raise InputError(f"missing; give {', '.join(_REQUIRED[key])}", path,
                                 field=f"{where} {missing[0]}")
            try:
                built.append(cls(**item))
            except InputError as exc:  # between fields: frames = [first, stop]
                name = (exc.field or "").rpartition(".")[2]
                raise InputError(exc.problem, path, field=f"{where} {name}") from None
        fields[key] = tuple(built)
    try:
        style = RenderStyle(**fields)
    except InputError as exc:  # between fields: exposure within a frame period
        name = (exc.field or "").rpartition(".")[2]
        raise InputError(exc.problem, path, field=f"[render] {name}") from None
    if style.background:  # a missing photograph or package: refused before rendering
        next(load_background(style.background, 16, 16))
    return style


def clip_plans(recipe: Recipe, seed: int) -> list[tuple]:
    """Each clip's name, condition, movement, camera angle and random generator.

    Clip *i* of a condition draws from its own stream, keyed by (seed,
    condition, i): adding clips, or clips of other conditions, leaves it as it is.

    Parameters
    ----------
    recipe : Recipe
        What to render.
    seed : int
        Master seed.

    Raises
    ------
    InputError
        If a clip's drawn movement is impossible (e.g. a negative duration).
    """
    plans = []
    base = recipe.stimulus
    for c, cond in enumerate(CONDITIONS):
        for i in range(recipe.counts.get(cond, 0)):
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(c, i)))
            clip = f"{cond}-{i + 1:02d}"
            try:
                params = dataclasses.replace(
                    base, condition=cond,
                    duration=float(base.duration + recipe.duration_sd * rng.standard_normal()),
                    distance=float(base.distance + recipe.distance_sd * rng.standard_normal()))
                stimulus_task(params)
            except ValueError as exc:  # too large a variation: a negative duration
                varied = recipe.duration_sd > 0 or recipe.distance_sd > 0
                raise InputError(f"clip {clip} (seed {seed}) draws an impossible movement: "
                                 f"{exc}", field="[variation]" if varied else "[scene]") \
                    from None
            plans.append((clip, cond, params, float(rng.uniform(*recipe.camera_angle_deg)), rng))
    return plans


def synthesize(recipe: Recipe, out: str | os.PathLike, *, seed: int = 0,
               progress: bool = False, jobs: int = 1) -> pd.DataFrame:
    """Render every clip of a recipe into ``out`` and write ``manifest.csv``.

    Parameters
    ----------
    recipe : Recipe
        What to render.
    out : str or os.PathLike
        Output folder.
    seed : int
        Master seed; each clip draws from its own stream (:func:`clip_plans`),
        so a clip does not change when other clips are added.
    progress : bool
        Show a progress bar.
    jobs : int
        Worker processes rendering clips, one OpenCV thread each (1: in this
        process). Each clip comes from its own stream, so the clips do not
        depend on ``jobs``.

    Returns
    -------
    pandas.DataFrame
        The manifest: clip, condition, seed, video, truth, parameters (JSON).
    """
    from tqdm import tqdm

    if int(jobs) < 1:
        raise InputError(f"expected at least 1, got {jobs}", field="--jobs")
    render_style(recipe.style)
    plans = clip_plans(recipe, seed)  # all of them first: a bad draw renders nothing
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    work = [(recipe, out, plan) for plan in plans]
    bar = tqdm(total=len(plans), desc=f"synth {recipe.name}", unit="clip", disable=not progress)
    with bar:
        rows = render_rows(_render_one, work, int(jobs), bar)
    manifest = pd.DataFrame(rows)
    write_csv(out / "manifest.csv", manifest)
    return manifest


def _render_one(work: tuple) -> dict:
    """Render one clip of :func:`clip_plans`; its manifest row."""
    recipe, out, (clip, cond, params, angle, rng) = work
    style = render_style(recipe.style)
    t, paths = stimulus_paths(params, style.fps, seed=rng)
    scene = Scene(wrist=paths["wrist"], finger=paths["finger"], thumb=paths["thumb"],
                  object_diameter=params.object_size)
    camera = Camera.for_frame(style.width, style.height, angle_deg=angle)
    clip_seed = int(rng.integers(2**31))
    meta = {**dataclasses.asdict(params), "camera_angle_deg": angle, "recipe": recipe.name}
    result = render_clip(scene, camera, style, out / f"{clip}{_suffix(style)}",
                         seed=clip_seed, label=cond, params=meta)
    log.info("rendered %s (%d frames)", clip, result.n_frames)
    return {"clip": clip, "condition": cond, "seed": clip_seed,
            "video": result.video.name, "truth": result.truth.name,
            "parameters": json.dumps(meta)}


def _suffix(style: RenderStyle) -> str:
    """File extension for the style's codec (the inverse of :data:`video.CODECS`)."""
    by_codec = {codec.lower(): ext for ext, codec in CODECS.items()}
    return by_codec.get((style.codec or CODECS[".mp4"]).lower(), ".mp4")

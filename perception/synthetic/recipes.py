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
from dataclasses import field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pandas as pd
from pydantic import Field

from perception.errors import InputError
from perception.io.atomic import write_csv
from perception.io.config import check_keys, from_table, read_toml, sub_table
from perception.io.video import CODECS
from perception.limits import MAX_CLIPS
from perception.synthetic.footage import load_background
from perception.synthetic.render import render_clip, render_rows
from perception.synthetic.scene import Camera, Distractor, Occlusion, RenderStyle, Scene
from perception.synthetic.stimuli import CONDITIONS, StimulusParams, stimulus_paths, stimulus_task
from perception.validation import Int, Tuple, declared

__all__ = ["Recipe", "load_recipe", "render_style", "clip_plans", "synthesize"]

log = logging.getLogger(__name__)


_Degrees = Annotated[float, Field(ge=-180, le=180)]


@declared
class Recipe:
    """How to render a set of clips (parsed from a TOML recipe).

    Parameters
    ----------
    name : str
        Recipe name (file stem).
    counts : dict
        Clips per condition (a recipe's ``[conditions]``).
    stimulus : StimulusParams
        The nominal movement (its condition is replaced per clip).
    duration_sd, distance_sd : float
        Demonstrator variability between clips (SD, s and m; ``[variation]``).
    camera_angle_deg : (float, float)
        Range of camera rotations, degrees, drawn uniformly per clip
        (``[variation]``).
    style : dict
        :class:`perception.synthetic.render.RenderStyle` fields (fps, width, height, codec,
        hand, noise_sd, blur_sigma, lighting, ...).
    """

    name: str
    counts: Annotated[dict[Literal[CONDITIONS], Annotated[Int, Field(ge=0, le=MAX_CLIPS)]],
                      Field(description=f"clips; at most {MAX_CLIPS} clips per recipe")]
    stimulus: StimulusParams = field(default_factory=StimulusParams)
    duration_sd: Annotated[float, Field(ge=0, le=10)] = 0.0
    distance_sd: Annotated[float, Field(ge=0, le=1)] = 0.0
    camera_angle_deg: Annotated[tuple[_Degrees, _Degrees], Tuple] = (0.0, 0.0)
    style: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not 0 < sum(self.counts.values()) <= MAX_CLIPS:
            raise InputError(f"expected at least 1 and at most {MAX_CLIPS} clips in all, got "
                             f"{sum(self.counts.values())}", location=("Recipe", "counts"))

    @property
    def n_clips(self) -> int:
        """Total number of clips."""
        return int(sum(self.counts.values()))


#: The tables of a recipe file.
RECIPE_TABLES = ("conditions", "scene", "variation", "render")


_VARIATION = ("duration_sd", "distance_sd", "camera_angle_deg")


def load_recipe(path: str | os.PathLike) -> Recipe:
    """Read a recipe TOML file.

    Every value is checked for the type and range its class declares
    (:class:`Recipe`, :class:`StimulusParams`, :class:`RenderStyle`, ...)
    before anything is built.

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
        check_keys(tables["conditions"], CONDITIONS, "[conditions]", path)
        check_keys(tables["variation"], _VARIATION, "[variation]", path)
        stim = from_table(StimulusParams, tables["scene"], "[scene]", path, condition="normal")
        try:
            recipe = Recipe(name=path.stem, counts=dict(tables["conditions"]), stimulus=stim,
                            style=dict(tables["render"]), **tables["variation"])
        except InputError as exc:  # ("Recipe", "counts", "normal"): [conditions] normal
            where = ["[variation]" if exc.location[1:2] != ("counts",) else "[conditions]"]
            raise InputError(exc.problem, path, field=" ".join(where + [
                k for k in exc.location[1:] if k != "counts"])) from None
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
        one; every value is checked against the ranges :class:`RenderStyle`,
        :class:`Distractor` and :class:`Occlusion` declare.
    path : str or os.PathLike, optional
        The recipe, for messages.

    Raises
    ------
    InputError
        A bad key or value, naming the field (``[render] fps``).
    """
    fields = dict(sub_table(table, None, "[render]", path))
    for key, cls in (("distractors", Distractor), ("occlusions", Occlusion)):
        items = fields.get(key, ())
        if not isinstance(items, list | tuple) or not all(isinstance(i, Mapping) for i in items):
            raise InputError(f"expected a list of tables ([[render.{key}]]), got "
                             f"{items!r}"[:120], path, field=f"[render] {key}")
        fields[key] = tuple(from_table(cls, item, f"[[render.{key}]] #{i + 1}", path)
                            for i, item in enumerate(items))
    style = from_table(RenderStyle, fields, "[render]", path)
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
        raise InputError(f"expected at least 1, got {jobs}", field="jobs")
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

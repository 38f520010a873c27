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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from perception.errors import InputError
from perception.io.atomic import write_csv
from perception.io.video import CODECS
from perception.limits import MAX_CLIPS
from perception.synthetic.footage import load_background
from perception.synthetic.render import render_clip
from perception.synthetic.scene import Camera, Distractor, Occlusion, RenderStyle, Scene
from perception.synthetic.stimuli import CONDITIONS, StimulusParams, stimulus_paths, stimulus_task

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


def load_recipe(path: str | os.PathLike) -> Recipe:
    """Read a recipe TOML file.

    Parameters
    ----------
    path : str or os.PathLike
        The recipe.

    Raises
    ------
    InputError
        If the file is missing, not TOML, or has unknown or bad fields.
    """
    from perception.io.config import check_keys, read_toml

    path = Path(path)
    cfg = read_toml(path, "recipe")
    try:
        check_keys(cfg, RECIPE_TABLES, "the top level")
        for name in RECIPE_TABLES:
            if not isinstance(cfg.get(name, {}), dict):
                raise ValueError(f"[{name}] must be a table")
        check_keys(cfg.get("scene", {}),
                   [f.name for f in dataclasses.fields(StimulusParams) if f.name != "condition"],
                   "[scene]")
        table = cfg.get("conditions", {})
        if not isinstance(table, dict):
            raise ValueError("[conditions] must be a table of clip counts, e.g. normal = 2")
        bad = set(table) - set(CONDITIONS)
        if bad:
            raise ValueError(f"[conditions]: unknown {sorted(bad)} (expected {CONDITIONS})")
        if not all(isinstance(v, int) and not isinstance(v, bool) and v >= 0
                   for v in table.values()) or sum(table.values()) == 0:
            raise ValueError("[conditions]: give a whole, non-negative clip count per "
                             "condition, and at least one clip")
        counts = {str(k): int(v) for k, v in table.items()}
        if sum(counts.values()) > MAX_CLIPS:
            raise ValueError(f"[conditions]: at most {MAX_CLIPS} clips per recipe, got "
                             f"{sum(counts.values())}")
        stim = StimulusParams(**cfg.get("scene", {}))
        var = dict(cfg.get("variation", {}))
        angle = tuple(float(a) for a in var.pop("camera_angle_deg", (0.0, 0.0)))
        if len(angle) != 2:
            raise ValueError("[variation] camera_angle_deg: expected [low, high]")
        recipe = Recipe(name=path.stem, counts=counts, stimulus=stim,
                        duration_sd=float(var.pop("duration_sd", 0.0)),
                        distance_sd=float(var.pop("distance_sd", 0.0)),
                        camera_angle_deg=angle, style=dict(cfg.get("render", {})))
        if var:
            raise ValueError(f"[variation]: unknown fields {sorted(var)}")
        if not (recipe.duration_sd >= 0 and recipe.distance_sd >= 0):
            raise ValueError("[variation]: duration_sd and distance_sd must be >= 0")
        render_style(recipe.style)  # validate now, not after rendering half the set
        clip_plans(recipe, seed=0)  # every clip's movement must be plannable
    except (TypeError, ValueError, KeyError) as exc:
        raise InputError(f"bad recipe: {exc}", path) from None
    return recipe


def _refuse_unknown(table: dict, valid, where: str) -> None:
    """Refuse a key that is not in ``valid``, naming the nearest valid one."""
    import difflib

    for key in table:
        if key not in valid:
            near = difflib.get_close_matches(str(key), list(valid), n=1)
            hint = f"did you mean {near[0]!r}?" if near else f"expected one of {sorted(valid)}"
            raise ValueError(f"{where}: unknown key {key!r} ({hint})")


def render_style(table: dict) -> RenderStyle:
    """A :class:`~perception.synthetic.render.RenderStyle` from a recipe's ``[render]`` table.

    Parameters
    ----------
    table : dict
        RenderStyle fields; ``distractors`` and ``occlusions`` as lists of tables
        (``{colour, start, end, diameter, frames, shape, aspect, angle_deg}``,
        ``{marker, start, stop}``); ``background = "photo:NAME"`` or
        ``"video:PATH"``. An unknown key is refused, naming the nearest valid one.
    """
    fields = dict(table)
    _refuse_unknown(fields, {f.name for f in dataclasses.fields(RenderStyle)}, "[render]")

    def tup(v):
        return None if v is None else tuple(v)

    if "distractors" in fields:
        valid = {f.name for f in dataclasses.fields(Distractor)}
        for d in fields["distractors"]:
            _refuse_unknown(d, valid, "[[render.distractors]]")
        fields["distractors"] = tuple(
            Distractor(colour=d["colour"] if isinstance(d["colour"], str) else tuple(d["colour"]),
                       start=tuple(d["start"]), end=tup(d.get("end")),
                       diameter=float(d.get("diameter", 0.02)), frames=tup(d.get("frames")),
                       shape=str(d.get("shape", "disc")), aspect=float(d.get("aspect", 1.0)),
                       angle_deg=float(d.get("angle_deg", 0.0)))
            for d in fields["distractors"])
    if "occlusions" in fields:
        for o in fields["occlusions"]:
            _refuse_unknown(o, {"marker", "start", "stop"}, "[[render.occlusions]]")
        fields["occlusions"] = tuple(Occlusion(**o) for o in fields["occlusions"])
    if "band_size" in fields:
        fields["band_size"] = tuple(fields["band_size"])
    style = RenderStyle(**fields)
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
    ValueError
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
            except ValueError as exc:
                raise ValueError(f"clip {clip} (seed {seed}): {exc}") from None
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
        Processes rendering clips (this one and ``jobs - 1`` spawned workers,
        one BLAS/OpenCV thread each). Each clip comes from its own stream, so
        the clips do not depend on ``jobs``.

    Returns
    -------
    pandas.DataFrame
        The manifest: clip, condition, seed, video, truth, parameters (JSON).
    """
    from tqdm import tqdm

    if int(jobs) < 1:
        raise ValueError(f"--jobs: expected at least 1, got {jobs}")
    render_style(recipe.style)
    plans = clip_plans(recipe, seed)  # all of them first: a bad draw renders nothing
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    work = [(recipe, out, plan) for plan in plans]
    bar = tqdm(total=len(plans), desc=f"synth {recipe.name}", unit="clip", disable=not progress)
    with bar:
        rows = _render_all(work, int(jobs), bar)
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


class _Render:
    """:func:`_render_one` of item ``(index, work)`` as a :mod:`perception.workers` job."""

    def run(self, item: tuple[int, tuple], shared: None) -> tuple[int, dict]:
        return item[0], _render_one(item[1])


def _render_all(work: list, jobs: int, bar) -> list[dict]:
    """:func:`_render_one` of every item, in this process and ``jobs - 1`` spawned workers
    (one BLAS/OpenCV thread each)."""
    from perception.workers import run_shared

    rows: list[dict | None] = [None] * len(work)
    for i, row in run_shared(list(enumerate(work)), _Render(), jobs):
        rows[i] = row
        bar.update()
    return rows


def _suffix(style: RenderStyle) -> str:
    """File extension for the style's codec (the inverse of :data:`video.CODECS`)."""
    by_codec = {codec.lower(): ext for ext, codec in CODECS.items()}
    return by_codec.get((style.codec or CODECS[".mp4"]).lower(), ".mp4")

"""The reference docs (``docs/``) keep up with the code.

Every dataset, group and attribute a tracks or repertoire file holds, every
field of the parameter classes, every status code, report key and command
option must be named in the matching document, in code spans. Modules are
imported lazily from a list of candidate homes, so the test follows code
that moves between modules.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import re
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

#: The public facade first (``perception.api``, also importable from ``perception``).
_FACADE = ("perception.api", "perception")

#: Where each name may live after the facade: today's module first, then the
#: homes planned or used by other layouts. The test follows code that moves.
HOMES = {
    "Tracks": ("perception.io.tracks", "perception.tracks"),
    "TracksWriter": ("perception.io.tracks", "perception.tracks"),
    "Status": ("perception.io.tracks", "perception.tracks"),
    "TrackerParams": ("perception.tracking.tracker", "perception.tracking.params",
                      "perception.tracking", "perception.tracker"),
    "track_video": ("perception.tracking.video_tracks", "perception.tracking.tracker",
                    "perception.tracking", "perception.tracker"),
    "MarkerColour": ("perception.tracking.markers", "perception.tracking", "perception.markers"),
    "Scene": ("perception.synthetic.render", "perception.synthetic.scene",
              "perception.synthetic", "perception.render"),
    "Camera": ("perception.synthetic.render", "perception.synthetic.scene",
               "perception.synthetic", "perception.render"),
    "RenderStyle": ("perception.synthetic.render", "perception.synthetic.scene",
                    "perception.synthetic", "perception.render"),
    "Distractor": ("perception.synthetic.render", "perception.synthetic.scene",
                   "perception.synthetic", "perception.render"),
    "Occlusion": ("perception.synthetic.render", "perception.synthetic.scene",
                  "perception.synthetic", "perception.render"),
    "render_clip": ("perception.synthetic.render", "perception.synthetic", "perception.render"),
    "StimulusParams": ("perception.synthetic.recipes", "perception.synthetic.stimuli",
                       "perception.synthetic", "perception.recipes"),
    "ObserveParams": ("perception.observe",),
    "observe": ("perception.observe",),
    "HammerParams": ("perception.recognition.engine", "perception.recognition",
                     "perception.hammer"),
    "recognize": ("perception.recognition.engine", "perception.recognition",
                  "perception.hammer"),
    "Repertoire": ("perception.recognition.repertoire", "perception.recognition",
                   "perception.io.repertoire", "perception.repertoire"),
    "ModelSpec": ("perception.recognition.repertoire", "perception.recognition.models",
                  "perception.recognition", "perception.io.repertoire", "perception.repertoire"),
    "SceneSpec": ("perception.recognition.repertoire", "perception.recognition.models",
                  "perception.recognition", "perception.io.repertoire", "perception.repertoire"),
    "clip_outputs": ("perception.report", "perception.report.clip"),
    "CalibrationParams": ("perception.recognition.verdict", "perception.recognition"),
    "IndependentParams": ("perception.synthetic.independent",),
    "FIGURES": ("perception.report.batch",),
    "summary_table": ("perception.batch",),
    "condition_statistics": ("perception.report.conditions", "perception.report"),
    "condition_profiles": ("perception.report.conditions", "perception.report"),
    "build_parser": ("hammer_mv.cli",),
}


@cache
def find(name: str):
    """The object ``name`` from the first candidate module that has it."""
    tried = []
    for module in (*_FACADE, *HOMES[name]):
        try:
            mod = importlib.import_module(module)
        except ImportError as exc:  # absent here, or part of another layout
            tried.append(f"{module} ({exc})")
            continue
        obj = getattr(mod, name, None)
        if obj is not None and not inspect.ismodule(obj):  # perception.observe is both
            return obj
        tried.append(f"{module} (no {name})")
    pytest.fail(f"{name} found nowhere: add its new home to HOMES; tried {tried}")


# -- the docs' code spans ----------------------------------------------------
_FENCE = re.compile(r"^```.*?^```", re.S | re.M)
_SPAN = re.compile(r"`([^`\n]+)`")


@cache
def doc(name: str) -> str:
    path = DOCS / name
    assert path.is_file(), f"docs/{name} is missing"
    return path.read_text(encoding="utf-8")


@cache
def spans(name: str) -> tuple[str, ...]:
    """Inline code spans of a document (fenced blocks excluded)."""
    return tuple(_SPAN.findall(_FENCE.sub("", doc(name))))


@cache
def all_spans() -> tuple[str, ...]:
    return tuple(s for p in sorted(DOCS.glob("*.md")) for s in spans(p.name))


def documented(term: str, where: tuple[str, ...]) -> bool:
    """Whether ``term`` appears as a whole name (``/`` may join it) in a code span."""
    pattern = re.compile(rf"(?<![\w-]){re.escape(term)}(?![\w-])")
    return any(pattern.search(s) for s in where)


def missing(terms, where: tuple[str, ...]) -> list[str]:
    return sorted({t for t in terms if not documented(t, where)})


# -- fixtures: a tiny rendered, tracked clip; a one-model repertoire ------------
@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    Scene, Camera, RenderStyle = find("Scene"), find("Camera"), find("RenderStyle")
    out = tmp_path_factory.mktemp("clip")
    style = RenderStyle(fps=30.0, width=480, height=360, texture=False)
    scene = Scene.reach_to_grasp(30, 30.0, start=(0.0, -0.25), onset=0.3, duration=0.6)
    result = find("render_clip")(scene, Camera.for_frame(480, 360), style, out / "c.avi",
                                 seed=1, label="normal", params={"duration": 0.6})
    tracks = find("track_video")(result.video, out / "c.tracks.h5")
    return {"truth": Path(result.truth), "tracks": Path(tracks)}


@pytest.fixture(scope="module")
def repertoire(tmp_path_factory):
    rep = find("Repertoire").build([find("ModelSpec")("grasp-1.0s", "grasp", {"duration": 1.0})])
    path = tmp_path_factory.mktemp("rep") / "rep.h5"
    rep.save(path)
    return rep, path


def _walk(path: Path, rename: dict[str, str] | None = None):
    """Paths of every group and dataset, and every attribute key, of an HDF5 file."""
    import h5py

    rename = rename or {}
    names, attrs = [], set()
    with h5py.File(path, "r") as f:
        attrs.update(f.attrs)

        def visit(name, obj):
            parts = [rename.get(p, p) for p in name.split("/")]
            names.append("/".join(parts))
            attrs.update(obj.attrs)

        f.visititems(visit)
    return names, attrs


# -- tracks-format.md ----------------------------------------------------------
def test_every_tracks_file_name_and_attribute_is_documented(clip):
    where = spans("tracks-format.md")
    for kind in ("tracks", "truth"):
        names, attrs = _walk(clip[kind])
        assert missing(names, where) == [], f"{kind} file: undocumented groups/datasets"
        assert missing(attrs, where) == [], f"{kind} file: undocumented attributes"


def test_status_codes_are_documented_with_their_numbers():
    text = doc("tracks-format.md")
    for status in find("Status"):
        row = rf"^\|\s*`?{int(status)}`?\s*\|\s*`?{status.name.lower()}`?\s*\|"
        assert re.search(row, text, re.M), f"no table row '| {int(status)} | " \
                                           f"{status.name.lower()} |' in tracks-format.md"


def test_tracker_params_and_export_columns_are_documented(clip):
    where = spans("tracks-format.md")
    fields = [f.name for f in dataclasses.fields(find("TrackerParams"))]
    assert missing(fields, where) == []
    tracks = find("Tracks").load(clip["tracks"])
    columns = set(tracks.to_trackpy().columns)
    for c in tracks.to_pandas().columns:
        for m in tracks.markers:
            c = c.replace(f"{m}_", "<marker>_") if c.startswith(f"{m}_") else c
        columns.add(c)
    assert missing(columns, where) == []
    assert documented("scorer", where) and documented("bodyparts", where)


# -- repertoire-format.md ------------------------------------------------------
def test_every_repertoire_name_and_attribute_is_documented(repertoire):
    rep, path = repertoire
    names, attrs = _walk(path, {m.name: "<name>" for m in rep})
    where = spans("repertoire-format.md")
    components = {p for n in names for p in n.split("/")}
    assert missing(components, where) == [], "undocumented groups/datasets"
    assert missing({n for n in names if n.count("/") <= 1}, where) == []
    assert missing(attrs, where) == [], "undocumented attributes"


def test_repertoire_config_keys_are_documented():
    where = spans("repertoire-format.md")
    scene = [f.name for f in dataclasses.fields(find("SceneSpec"))]
    assert missing(scene, where) == []
    import minvar

    scene_set = {"object_size", "distance", "tip_start", "reach_only", "plant"}
    task = [f.name for f in dataclasses.fields(minvar.GraspTask) if f.name not in scene_set]
    assert missing(task + ["name", "kind", "durations", "half_aperture", "height", "fraction"],
                   where) == []


# -- the other documents' parameter classes ----------------------------------------
@pytest.mark.parametrize(
    "name, document",
    [
        ("ObserveParams", "recognition.md"),
        ("HammerParams", "recognition.md"),
        ("CalibrationParams", "recognition.md"),
        ("CalibrationParams", "repertoire-format.md"),
        ("IndependentParams", "recognition.md"),
        ("StimulusParams", "recipes.md"),
        ("RenderStyle", "recipes.md"),
        ("Distractor", "recipes.md"),
        ("Occlusion", "recipes.md"),
        ("MarkerColour", "markers.md"),
    ],
)
def test_every_field_is_documented(name, document):
    fields = [f.name for f in dataclasses.fields(find(name))]
    assert missing(fields, spans(document)) == [], f"{name} fields missing from docs/{document}"


def test_model_parameters_are_documented():
    import minvar

    where = spans("model.md")
    for cls in (minvar.PointMassPlant, minvar.ReachTask, minvar.GraspTask, minvar.LQGProblem,
                minvar.LQGSolution):
        fields = [f.name for f in dataclasses.fields(cls)]
        assert missing(fields, where) == [], cls.__name__


# -- recognition.md: report keys and columns -----------------------------------------
def test_recognition_outputs_are_documented(clip, repertoire):
    rep, _ = repertoire
    tracks = find("Tracks").load(clip["tracks"])
    rec = find("recognize")(find("observe")(tracks, clip="c"), rep)
    where = spans("recognition.md")
    report = rec.to_dict()
    assert missing(report, where) == []
    assert missing(report["models"][0], where) == []
    assert missing(rec.to_pandas().columns, where) == []
    assert missing(["fingerprint", "condition", "input"], where) == []
    outputs = find("clip_outputs")(Path("."), "<clip>").values()
    assert missing([p.name for p in outputs], where) == []
    batch = ["summary.csv", "statistics.csv", "condition_profiles.csv",
             "condition_profiles.png", "report.html", "batch.json", "conf_<model>", "reused",
             "status", "error", "rule", "clips", "ok", "failed", "settings", "repertoire",
             "p_value", "mean_difference", "statistic", "phase", "mean", "sd",
             "aperture_profiles.csv"]
    assert missing(batch, where) == []
    assert missing([name for name, _, _ in find("FIGURES")], where) == []


def test_batch_tables_are_documented(clip, repertoire):
    """Every column summary.csv, statistics.csv and condition_profiles.csv can have."""
    import numpy as np

    from perception.batch import ClipResult
    from perception.report import ClipSummary

    rep, _ = repertoire
    rec = find("recognize")(find("observe")(find("Tracks").load(clip["tracks"]), clip="c"), rep)
    summary = ClipSummary.from_recognition(rec)
    results = [ClipResult(f"c{i}", cond, "ok", summary=summary)
               for i, cond in enumerate(["normal", "normal", "delayed", "delayed"])]
    table = find("summary_table")(results)
    where = spans("recognition.md")
    columns = [c for c in table.columns if not c.startswith("conf_")]
    assert missing(columns, where) == []
    table[f"conf_{rec.names[0]}"] = np.arange(len(table), dtype=float)
    stats = find("condition_statistics")(table, rec.names[0])
    assert missing(stats.columns, where) == []
    profiles = find("condition_profiles")([summary], ["normal"], rec.names[0])
    assert missing(profiles.columns, where) == []


# -- command options -------------------------------------------------------------
def _options(parser):
    """Every option of a parser and its subcommands: one tuple of spellings each."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                yield from _options(sub)
        elif action.option_strings and not isinstance(action, argparse._HelpAction):
            yield tuple(action.option_strings)


@pytest.mark.parametrize("command", ["track", "tracks", "repertoire", "recognize", "batch",
                                     "synth"])
def test_every_option_of_the_perception_commands_is_documented(command):
    import argparse

    parser = find("build_parser")()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    undocumented = [opts for opts in _options(sub.choices[command])
                    if not any(documented(o, all_spans()) for o in opts)]
    assert undocumented == [], f"hammer-mv {command}: options missing from docs/"


# -- links and shipped recipes ---------------------------------------------------------
def test_links_between_docs_resolve():
    for path in [*DOCS.glob("*.md"), ROOT / "datasets" / "README.md"]:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", path.read_text()):
            if "://" not in target:
                assert (path.parent / target).exists(), f"{path.name}: broken link {target}"


def test_every_shipped_recipe_is_listed():
    for recipe in sorted((ROOT / "datasets").glob("*.toml")):
        assert documented(recipe.name, spans("recipes.md")), recipe.name
        assert f"`{recipe.name}`" in (ROOT / "datasets" / "README.md").read_text()

"""Chapter 5's clips: rendered by two generators, tracked and recognised in batches."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pandas as pd

from perception.batch import discover, run_batch
from perception.recognition.repertoire import Repertoire
from perception.synthetic.independent import render_independent_set
from perception.synthetic.recipes import load_recipe, render_style, synthesize
from tools.thesis.ch5_fixed import CONDITIONS

ROOT = Path(__file__).resolve().parents[2]

GENERATORS = ("independent", "thesis")
EXPECTED = {"normal": "normal", "delayed": "abnormal", "open-close-open": "abnormal",
            "reach": "reach"}
RECIPE = ROOT / "datasets" / "gangitano.toml"


@dataclasses.dataclass(frozen=True)
class Batch:
    """One generator's batch: its summary, each clip's JSON, the clips' folder."""

    name: str
    summary: pd.DataFrame
    clips: dict
    folder: Path
    #: (w_r, w_g) the clips were scored with, and the ratio that balances the two terms
    weights: tuple[float, float] = (1.0, 2.0)
    balanced: float = float("nan")

    @property
    def reference(self) -> str:
        return str(self.summary["reference_model"].dropna().iloc[0])

    def by_condition(self, condition: str) -> list[dict]:
        names = self.summary.loc[(self.summary["condition"] == condition)
                                 & (self.summary["status"] == "ok"), "clip"]
        return [self.clips[c] for c in names]

    def final(self, condition: str) -> np.ndarray:
        ok = self.summary[(self.summary["condition"] == condition)
                          & (self.summary["status"] == "ok")]
        return ok["reference_confidence"].to_numpy(float)


def render_sets(out: Path, clips: int, seed: int) -> dict[str, Path]:
    """Render both generators' clips in the gangitano recipe's style; return their folders."""
    recipe = load_recipe(RECIPE)
    counts = {c: clips for c in CONDITIONS}
    folders = {g: out / g / "clips" for g in GENERATORS}
    render_independent_set(folders["independent"], counts, seed=seed,
                           style=render_style(recipe.style),
                           camera_angle_deg=recipe.camera_angle_deg)
    synthesize(dataclasses.replace(recipe, counts=counts), folders["thesis"], seed=seed)
    return folders


def run_batches(folders: dict[str, Path], rep: Repertoire, jobs: int) -> dict[str, Batch]:
    """Track, recognise and report every generator's clips."""
    batches = {}
    for name, folder in folders.items():
        report = folder.parent / "report"
        summary = run_batch(discover(folder / "manifest.csv"), report, rep, jobs=jobs,
                            quiet=True)
        clips = {c: json.loads((report / f"{c}.recognition.json").read_text())
                 for c in summary.loc[summary["status"] == "ok", "clip"]}
        batches[name] = Batch(name, summary, clips, folder)
    return batches


# -- the thesis rule, read on the reference grasp model (Fig. 5.8) -------------------
def series(d: dict, model: str) -> dict[str, np.ndarray]:
    """One clip's confidence (C), its transport and grip terms, time, phase and aperture."""
    c = np.asarray(d["confidence"][model], dtype=float)
    tr = np.asarray(d["transport_confidence"][model], dtype=float)
    t = np.asarray(d["time"], dtype=float)
    g = np.array([np.nan if v is None else v for v in d["aperture"]], dtype=float)
    return {"C": c, "transport": tr, "grip": c - tr, "time": t, "phase": t / t[-1], "g": g}




def mean_se(x) -> tuple[float, float]:
    """Mean and standard error."""
    x = np.asarray(x, dtype=float)
    return float(x.mean()), float(x.std(ddof=1) / np.sqrt(len(x))) if len(x) > 1 else np.nan


def at_phase(b: Batch, cond: str, phase: float, key: str = "C") -> np.ndarray:
    """Each ``cond`` clip's ``key`` series at ``phase`` of its movement."""
    return np.array([np.interp(phase, series(d, b.reference)["phase"],
                               series(d, b.reference)[key]) for d in b.by_condition(cond)])



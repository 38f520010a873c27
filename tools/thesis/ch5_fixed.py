"""Chapter 5's rows that no reading of the confidence rule enters.

The verdict and the likelihood rule (our own checks), the aperture profiles
(Fig. 5.4(d)) and the reference model's own movement against the clips
(Figs. 5.5-5.7). Part of :mod:`tools.thesis.ch5`, which gives each function a
:class:`~tools.thesis.ch5_batch.Batch` (one generator's clips, their summary and
recognition reports).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from perception.io.atomic import write_csv
from tools.thesis.claims import Measured
from tools.thesis.common import save

if TYPE_CHECKING:
    from tools.thesis.ch5_batch import Batch

CONDITIONS = ("normal", "delayed", "open-close-open", "reach")
ABNORMAL = ("delayed", "open-close-open")


def _auc(pos: np.ndarray, neg: np.ndarray) -> float:
    """Area under the ROC curve: P(a positive scores above a negative), ties half."""
    if not (len(pos) and len(neg)):
        return float("nan")
    diff = pos[:, None] - neg[None, :]
    return float(np.mean(diff > 0) + 0.5 * np.mean(diff == 0))


def verdicts(b: Batch, out: Path) -> list[tuple[str, Measured]]:
    """Accuracy per class, the confusion table and ROC AUC of familiarity."""
    s = b.summary[b.summary["status"] == "ok"]
    table = pd.crosstab(s["condition"], s["verdict"]).reindex(CONDITIONS).fillna(0).astype(int)
    write_csv(out / f"verdict_{b.name}.csv", table.reset_index())
    rows = []
    for cls, conds in (("normal", ["normal"]), ("abnormal", list(ABNORMAL)), ("reach", ["reach"])):
        group = s[s["condition"].isin(conds)]
        right = (group["verdict"] == cls).mean() if len(group) else float("nan")
        rows.append((f"verdict-{cls}", Measured(f"{100 * right:.0f} % of {len(group)}",
        {"right": right},
        note="confusion table (rows: condition, columns: verdict): "
            + "; ".join(f"{c}: " + ", ".join(f"{v} {n}" for v, n in table.loc[c].items() if n)
                        for c in table.index) + ".")))
    grasp = s[s["condition"].isin(["normal", *ABNORMAL])]
    fam = grasp["familiarity"].to_numpy(float)
    auc = _auc(fam[grasp["condition"].to_numpy() == "normal"],
               fam[grasp["condition"].to_numpy() != "normal"])
    rows.append(("auc", Measured(f"AUC {auc:.3f}",
        {"auc": auc},
        note="familiarity of the best model, normal clips against delayed and "
                      "open-close-open ones; agreement: AUC >= 0.95.")))
    return rows


def likelihood(b: Batch) -> tuple[str, Measured]:
    """How far apart normal and abnormal grasps lie in log-likelihood."""
    def best_grasp_ll(d):
        return max(m["final_log_likelihood"] for m in d["models"] if m["kind"] == "grasp")

    normal = np.array([best_grasp_ll(d) for d in b.by_condition("normal")])
    other = np.array([best_grasp_ll(d) for c in ABNORMAL for d in b.by_condition(c)])
    gap = float(normal.min() - other.max()) if len(normal) and len(other) else float("nan")
    return ("likelihood", Measured(f"lowest normal minus highest abnormal: {gap:.0f}",
        {"gap": gap},
        note=f"medians: normal {np.median(normal):.0f}, abnormal {np.median(other):.0f}."))


def apertures(b: Batch, model: pd.DataFrame | None = None) -> list[tuple[str, Measured]]:
    """Fig. 5.4(d): normal's aperture like the model's; more variable for the other stimuli.

    ``model``: the reference model's own aperture profile (phase, mean;
    :func:`perception.report.conditions.model_aperture`), by default the batch
    report's (the repertoire the batch ran with).
    """
    prof = pd.read_csv(b.folder.parent / "report" / "aperture_profiles.csv")
    by = {c: g for c, g in prof.groupby("condition")}
    model = by.get(f"model:{b.reference}") if model is None else model.reset_index(drop=True)
    normal = by["normal"]
    i, j = int(normal["mean"].idxmax()), int(model["mean"].idxmax())
    mga_obs, mga_model = normal.loc[i, "mean"], model.loc[j, "mean"]
    t_obs, t_model = normal.loc[i, "phase"], model.loc[j, "phase"]
    sd = {c: (float(by[c]["sd"].mean()), float(by[c]["sd"].max())) for c in ("normal", *ABNORMAL)
          if c in by}
    return [
        ("aperture", Measured(f"maximum {100 * mga_obs:.1f} cm at {100 * t_obs:.0f} % "
              f"(model {b.reference}: {100 * mga_model:.1f} cm at {100 * t_model:.0f} %)",
        {"mga_gap_m": abs(mga_obs - mga_model), "time_gap": abs(t_obs - t_model)},
        note="agreement: maximum aperture within 2 cm and 10 % of the movement.")),
        ("aperture-sd", Measured(
            "largest SD " + ", ".join(f"{c} {100 * v[1]:.2f} cm" for c, v in sd.items())
              + "; mean SD " + ", ".join(f"{c} {100 * v[0]:.2f} cm" for c, v in sd.items()),
        {"abnormal_above_normal": all(sd[c][1] > sd["normal"][1] for c in ABNORMAL if c in sd)},
        note="SD across clips over normalised movement time; agreement judged on the largest "
              "(the widest band of the figure). A delayed grasp's closed digits vary little for "
              "half the movement, so its mean SD can be below normal's. A check of our stimuli, "
              "not of the model: line 1109 describes the human demonstrator's recordings, and "
              "here the spread is the stimulus generator's.")),
    ]


def prediction(b: Batch, recs: dict, inside: str) -> tuple[str, Measured]:
    """Figs. 5.5-5.7: the normal model's own movement is close to normal grasps only."""
    err = {}
    for cond in ("normal", *ABNORMAL):
        values = []
        for d in b.by_condition(cond):
            rec = recs[d["clip"]]
            own = rec.nominal(b.reference)
            g_own = np.linalg.norm(own["finger"] - own["thumb"], axis=1)
            values.append(np.nanmean(np.abs(rec.scored_movement.g - g_own)))
        err[cond] = float(np.median(values))
    return ("prediction", Measured(
        "median |observed - model| aperture " + ", ".join(f"{c} {100 * v:.1f} cm"
                                                          for c, v in err.items()),
        {"abnormal_beyond_1_5_normal": all(err[c] > 1.5 * err["normal"] for c in ABNORMAL)},
        note=f"model: {b.reference}, the reference normal model, as the thesis draws it (figures "
        f"fig5_5-5_7_*_{b.name}.png): its noise-free movement from the clip's onset; "
        "agreement: abnormal > 1.5 x normal. Clips whose observed digit paths enter the "
        f"object by more than 1 cm: {inside} (the stimulus generator's, not the figure's)."))


def prediction_figures(b: Batch, recs: dict, out: Path) -> str:
    """Figs. 5.5-5.7: one clip per stimulus against the reference (normal) model's own
    movement, the object drawn; returns a note on digit paths inside the object."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle

    inside = []
    for number, cond in zip((5, 6, 7), ("normal", *ABNORMAL)):
        names = [d["clip"] for d in b.by_condition(cond)]
        if not names:
            continue
        rec = recs[names[0]]
        own = rec.nominal(b.reference)
        obs = rec.scored_movement  # the scale the model was scored (and drawn) at
        radius = obs.object_diameter / 2
        fig = Figure(figsize=(5, 5))
        ax = fig.add_subplot()
        for key, style in (("finger", ":"), ("thumb", "--")):
            ax.plot(*getattr(obs, key).T, "k" + style, label=f"observed {key}")
            ax.plot(*own[key].T, "r" + style, label=f"{b.reference} {key}")
        ax.add_patch(Circle((0, 0), radius, fill=False, color="0.4"))
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(f"Fig. 5.{number}: {cond} against the normal model ({b.reference})")
        ax.legend(fontsize=7)
        save(out, f"fig5_{number}_{cond.replace('-', '_')}_{b.name}", fig)
        for d in b.by_condition(cond):
            o = recs[d["clip"]].scored_movement
            depth = min(np.nanmin(np.linalg.norm(getattr(o, k), axis=1)) for k in
                        ("finger", "thumb"))
            inside.append((cond, d["clip"], depth < radius - 0.01))  # 1 cm through the surface
    n_in = {c: sum(x for cc, _, x in inside if cc == c) for c in ("normal", *ABNORMAL)}
    return ", ".join(f"{c}: {k} of {len(b.by_condition(c))}" for c, k in n_in.items())


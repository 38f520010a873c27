"""How chapter 4's verdicts depend on what the thesis leaves open.

The rules of :mod:`tools.thesis.ch4_rules` judge both the claims and the
sensitivity tables here: every verdict that rests on geometry the thesis does not
give (``tip_start``, the reading of its "20 cm"), recomputed from exact moments
over the range the thesis allows, so a dependent row is reported as conditional
with the range where it holds rather than at a value chosen after seeing the
verdicts.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from minvar.grasp import GraspTask, plan_grasp
from minvar.grasp_experiments import GraspExperiment
from minvar.grasp_stats import end_distance, grasp_moments
from tools.thesis.ch4_rules import SD_ERROR_500, UM, cm, level_is_best, pct, u_minimum
from tools.thesis.records import CONDITIONAL, sensitivity

#: tip_start values tabulated: from just ahead of the wrist to on the target line.
TIP_STARTS = (0.01, 0.02, 0.03, 0.04, 0.06)
#: Settings each tip_start is checked on (a coarser grid than the sweeps').
SENS_HEIGHTS = (-0.005, 0.0, 0.005)
SENS_TIMES = (0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8)
SENS_SIZES = (0.0, 0.08)


def _geometry_moments(base: GraspTask) -> dict:
    """Exact moments of the sensitivity settings of one geometry, by (parameter, value)."""
    tasks = {("viapoint_height", h): replace(base, viapoint_height=h) for h in SENS_HEIGHTS}
    tasks.update({("viapoint_time", f): replace(base, viapoint_time=f) for f in SENS_TIMES})
    tasks.update({("object_size", x): replace(base, object_size=x) for x in SENS_SIZES})
    exact = {}
    for task in tasks.values():
        if task not in exact:  # the base recurs: plan it once
            exact[task] = grasp_moments(plan_grasp(task))
    return {key: (task, exact[task]) for key, task in tasks.items()}


def _verdict_cells(moments: dict) -> list[str]:
    """Height verdict, via-time minimum, MGA-time range and slope for one geometry."""
    def dist(key):
        task, m = moments[key]
        return end_distance(m, "finger", task.finger_target)

    def sd(key):
        return float(np.sqrt(np.trace(moments[key][1].finger_cov[-1])))

    d = [dist(("viapoint_height", h)) for h in SENS_HEIGHTS]
    sds = np.array([sd(("viapoint_time", f)) for f in SENS_TIMES])
    t_min, _ = u_minimum(SENS_TIMES, sds)
    times = np.asarray(SENS_TIMES)
    rise = sds[times < 0.7 - 1e-9] / sds[np.argmin(np.abs(times - 0.7))] - 1
    rises = bool(np.all(rise > 0) and rise.max() > 2 * SD_ERROR_500)
    mga = {x: moments[("object_size", x)][1] for x in SENS_SIZES}
    times = [m.relative_time[np.argmax(m.aperture_mean)] for m in mga.values()]
    slope = (mga[0.08].aperture_mean.max() - mga[0.0].aperture_mean.max()) / 0.08
    best = SENS_HEIGHTS[int(np.argmin(d))]
    return [
        f"{'yes' if level_is_best(SENS_HEIGHTS, d) else '**no**'} (lowest at {cm(best)})",
        f"lowest at {pct(t_min)}; {100 * rise.min():+.1f} to {100 * rise.max():+.1f} % below "
        f"70 %" + ("" if rises else " (**no rise**)"),
        f"{pct(min(times))}-{pct(max(times))}"
        + ("" if min(times) >= 0.6 - 1e-9 and max(times) <= 0.8 + 1e-9 else " (**outside**)"),
        f"{slope:.3f}",
    ]


def _from_experiments(done: dict[str, GraspExperiment]) -> dict:
    """The sensitivity settings of the default geometry, from the sweeps' own moments."""
    sweeps = {"viapoint_height": ("viapoint-height", SENS_HEIGHTS),
              "viapoint_time": ("viapoint-time", SENS_TIMES),
              "object_size": ("object-size", SENS_SIZES)}
    out = {}
    for parameter, (name, values) in sweeps.items():
        e = done[name]
        for v in values:
            i = int(np.argmin(np.abs(e.values - v)))
            if abs(e.values[i] - v) > 1e-9:
                raise ValueError(f"{name} has no setting {v}")
            out[(parameter, v)] = (replace(e.base, **{parameter: v}), e.moments[i])
    return out


def tip_start_table(base: GraspTask, done: dict[str, GraspExperiment],
                    at: str = "") -> tuple[dict, dict]:
    """The tip_start table, and the default geometry's moments (reused for travel).

    ``at``: words after "tip_start" in the title naming the settings (``base``'s cost
    weights and model form) when they are not ours; each column's verdicts come from
    the table at that column's settings (:func:`mark_conditional`)."""
    rows, used = [], _from_experiments(done)
    for ts in TIP_STARTS:
        mine = abs(ts - base.tip_start) < 1e-12
        moments = used if mine else _geometry_moments(replace(base, tip_start=ts))
        mark = " (used)" if mine else (
            " (on the target line)" if abs(ts - base.wrist_offset) < 1e-12 else "")
        rows.append([f"{cm(ts)}{mark}", *_verdict_cells(moments)])
    table = sensitivity(
        f"tip_start{at}, where the closed digit tips start ahead of the wrist",
        "not given; Fig. 4.4(a) (line 814) has the digits reach the level of the targets "
        "during the movement, so they start below it (0 < tip_start < wrist_offset = 6 cm)",
        f"We use {cm(base.tip_start)}. Exact moments; via-point heights "
        f"{', '.join(cm(h) for h in SENS_HEIGHTS)}, times {pct(SENS_TIMES[0])}-"
        f"{pct(SENS_TIMES[-1])} in 5 % steps, sizes 0 and 8 cm (the MGA time rises with size, "
        "so these bound it; the slope is theirs). The wrist travels "
        f"{cm(base.transport_distance)}.",
        ["tip_start", "digit distance lowest at level (Fig. 4.3a,b)",
         "SD at 50-65 % against 70 %, rising beyond 6.3 % (Fig. 4.5c,d; line 834)",
         "MGA time, sizes 0-8 cm (Fig. 4.10b)",
         "MGA slope (Fig. 4.10a)"], rows)
    return table, used


def mark_conditional(claims: list[dict], dependent: dict[str, int], ours: dict,
                     theirs: dict) -> None:
    """Rows that depend on tip_start: say where they hold across the thesis's 0-6 cm, in
    each column from the tip_start table at that column's settings (``ours``, ``theirs``:
    :func:`tip_start_table`; ``dependent``: claim id -> the table's column). A column
    is ``conditional`` only where the verdict flips within the range; where it holds at
    every tip_start or at none, the range is reported beside the verdict."""
    for c in claims:
        col = dependent.get(c["id"])
        if col is None:
            continue
        for key, table, whose in (("at_thesis", theirs, "the thesis's model and weights"),
                                  ("verdict", ours, "our weights")):
            holds = [r[0].split(" ")[0] + " cm" for r in table["rows"] if "**" not in r[col]]
            fails = [r[0].split(" ")[0] + " cm" for r in table["rows"] if "**" in r[col]]
            where = (f"holds at {', '.join(holds) or 'none'}, fails at "
                     f"{', '.join(fails) or 'none'} ({whose})")
            flips = bool(holds and fails)  # the verdict turns on a choice the thesis leaves
            if key == "at_thesis":
                c[key] = (f"conditional on tip_start (not given; 0-6 cm): {where}. {c[key]}"
                          if flips else f"{c[key]}; over tip_start 1-6 cm it {where}")
            elif flips:
                c["why"] = (f"{c['why']} Conditional on tip_start: {where}; at our 2 cm it "
                            f"is '{c['verdict']}'.").strip()
                c["verdict"], c["agrees"] = CONDITIONAL, False


def travel_table(base: GraspTask, used: dict) -> dict:
    """The digit end-point verdicts for the three readings of the thesis's "20 cm"."""
    readings = (
        (0.20, "object centre 20 cm from the wrist's start (lines 770, 915, read literally)"),
        (0.20 + base.tip_start, "object centre 20 cm from the closed tips"),
        (0.20 + base.wrist_offset, "the wrist moves 20 cm (line 953, 'distance to be moved'; "
         "used)"),
    )
    rows = []
    for distance, what in readings:
        wrist = grasp_moments(plan_grasp(replace(base, distance=distance)))
        moved = {k: (replace(t, distance=distance), m.with_transport(wrist))
                 for k, (t, m) in used.items()}
        cells = _verdict_cells(moved)
        rows.append([f"{cm(distance - base.wrist_offset)}: {what}", cells[0], cells[1],
                     f"{float(np.sqrt(np.trace(wrist.wrist_cov[-1]))) * UM:.1f} µm"])
    return sensitivity(
        "transport distance, how far the wrist travels in the standard grasp",
        "'a disk located 20cm directly in front of the starting position of the arm and "
        "hand' (line 770; 'in front of the hand', line 915) and 'the distance to be moved' "
        "(line 953)",
        "Only the wrist's moments change (the grip is planned in the hand frame), so the "
        "digit end-point verdicts are recomputed exactly from the grip's moments and each "
        "transport's; the MGA does not depend on it.",
        ["wrist travel", "digit distance lowest at level", "SD at 50-65 % against 70 %",
         "wrist end-point SD"], rows)



"""Every lab's recordings and both generators, read as a user would: trials in, results out.

For each source this reports how many trials went in, how many reaches
were scored and how many trials or movements were not (with their
reasons), the verdicts on the real (or generated) grasps and on the
abnormal variants built from them (:mod:`perception.synthetic.variants`,
written back into the recording and found again, so that a variant the
reach finder drops is counted, not silently missed), and the landmarks
against an independent segmentation:

* ``optotrak`` — the shared Optotrak table (60 trials, 85 Hz): even trials
  are ``dev`` (the rules were chosen on them), odd ones ``heldout``; read as
  written (``--rate 85``); ``optotrak-clock``: again as the table a lab
  writes whose ``time`` column holds the steps between samples and whose
  clock is ``globalTime`` in ms (``--time-column globalTime``);
* ``rtmocap`` — the RTMocap pick-and-place trials (15, 200 Hz, headerless,
  ``--columns``): the reach must end where the hand stops at the object,
  within 0.1 s of the object's first motion;
* ``qualisys`` — the Qualisys cushion session (back-to-back whole-hand
  grasps): every approach to the object found or listed;
* ``independent`` — grasps built from published kinematics without the
  minimum variance model (:mod:`perception.synthetic.independent`), never
  tuned on, as 3D recordings: single reaches at 100 Hz, pick-and-place trials
  with an object marker at 200 Hz, drinking trials (normal and whole-hand
  grasps) and a session of 12 grasps with returns at 120 Hz, each written as
  a lab writes it (Vicon Nexus CSV; pick-and-place as RTMocap's headerless
  tables) and read back through the readers;
* ``minvar`` — the same tasks with the model's own grasps
  (:mod:`perception.synthetic.stimuli`).

The independent segmentation is the field's definition written out plainly
(:func:`reference_landmarks`: a 10 Hz zero-lag Butterworth filter, onset
and end where the transport's 3D speed crosses 5 % of its peak around the
reach, MGA the largest 3D tip-to-tip distance between them); for the
generated tasks it runs on the noise-free paths up to the grasp::

    python tools/evaluate_labs.py -o out/eval-labs [--only optotrak rtmocap ...]

Writes ``OUT/evaluation.md`` and ``OUT/evaluation.json`` and prints the table.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time as _time
from pathlib import Path

import numpy as np
from scipy.ndimage import median_filter
from scipy.signal import butter, filtfilt

from perception.errors import HammerMVError
from perception.io.atomic import write_text
from perception.io.mocap import MocapTrial, read_mocap
from perception.reaches import MarkerMap, trial_reaches
from perception.recognition.repertoire import Repertoire
from perception.recordings import MocapImport, recognize_reach
from perception.synthetic.variants import late_opening, reopening

REALDATA = Path(__file__).resolve().parents[1].parent / "shared" / "realdata"
RIGHT = {"normal": ("normal", None), "late": ("abnormal", "delayed-opening"),
         "reopen": ("abnormal", "re-opening")}
RTMOCAP_COLUMNS = ("object", "thumb", "index", "hand", "wristA", "wristB")


# -- the field's definitions, written out independently --------------------------------
def reference_landmarks(time, transport, aperture, around: float | None = None) -> dict:
    """Onset, end, movement time (s) and MGA (m) by the field's definitions, plainly.

    Lost samples are filled linearly and spikes taken out by a 0.1 s running
    median (as a lab cleans a table before filtering);
    the movement is the first whose speed peaks above a third of the
    fastest (a trial's reach comes before its return), or the one around the
    fastest sample after ``around``, s, when given.
    """
    from scipy.signal import find_peaks

    t = np.asarray(time, dtype=float)
    ok = np.isfinite(transport).all(axis=1) & np.isfinite(aperture)
    tr = np.stack([np.interp(t, t[ok], transport[ok, k]) for k in range(3)], axis=1)
    g = np.interp(t, t[ok], aperture[ok])
    rate = 1 / np.median(np.diff(t))
    k = 2 * int(0.05 * rate) + 1
    tr = median_filter(tr, size=(k, 1), mode="mirror")
    g = median_filter(g, size=k, mode="mirror")
    b, a = butter(2, min(10 / (0.5 * rate), 0.99))
    tr, g = filtfilt(b, a, tr, axis=0), filtfilt(b, a, g)
    v = np.linalg.norm(np.gradient(tr, t, axis=0), axis=1)
    if around is None:
        peaks = find_peaks(v, height=np.max(v) / 3)[0]
        p = int(peaks[0]) if len(peaks) else int(np.argmax(v))
    else:
        lo = int(np.searchsorted(t, around))
        p = lo + int(np.argmax(v[lo:]))
    below = v < 0.05 * v[p]
    on = p - int(np.argmax(below[p::-1])) + 1
    end = p + int(np.argmax(below[p:])) - 1
    return {"onset": float(t[on]), "end": float(t[end]), "mt": float(t[end] - t[on]),
            "mga": float(np.max(g[on:end + 1]))}


def _first_motion(time, path, since: float, rest: float = 0.003) -> float:
    """When an object marker first leaves where it rested, s (NaN if it never does)."""
    ok = np.isfinite(path).all(axis=1)
    before = ok & (time <= since)
    home = np.median(path[before if before.any() else ok][:20], axis=0)
    moved = ok & (time > since) & (np.linalg.norm(path - home, axis=1) > rest)
    return float(time[np.argmax(moved)]) if moved.any() else math.nan


# -- scoring one recording --------------------------------------------------------------
def score_trials(trials, options: MocapImport, rep, *, variants: bool) -> dict:
    """Trials in; every reach scored (and its variants, written back and found again)."""
    out = {"trials": len(trials), "reaches": [], "unscored": []}
    for trial in trials:
        reaches, unscored = trial_reaches(trial, options.markers, options.reaches)
        out["unscored"] += [{"name": u.name, "status": u.status, "reason": u.reason}
                            for u in unscored]
        for reach in reaches:
            row = {"name": reach.name, "trial": trial.name}
            row.update(_verdict(reach, rep, options))
            if variants:
                for kind, make in (("late", late_opening), ("reopen", reopening)):
                    row[kind] = _variant(trial, reach, make, kind, options, rep)
            out["reaches"].append(row)
    return out


def _verdict(reach, rep, options) -> dict:
    try:
        rec, _ = recognize_reach(reach, rep, None, options)
    except HammerMVError as exc:
        return {"verdict": "refused", "detail": None, "reason": exc.problem}
    except (IndexError, ValueError) as exc:  # a bug: counted and named, the run goes on
        return {"verdict": "crash", "detail": None, "reason": f"{type(exc).__name__}: {exc}"}
    lm = rec.measured if getattr(rec, "measured", None) is not None else rec.landmarks[0]
    return {"verdict": rec.verdict, "detail": rec.verdict_detail, "reason": rec.verdict_reason,
            "familiarity": rec.decision.familiarity, "mt": lm.movement_time, "mga": lm.mga,
            "onset": float(reach.time[reach.onset]), "end": float(reach.time[reach.end])}


def _variant(trial, reach, make, kind, options, rep) -> dict:
    """The variant written into the trial's own recording, then found and scored again."""
    try:
        v = make(reach)
    except ValueError as exc:
        return {"verdict": "not made", "detail": None, "reason": str(exc)}
    first = int(np.searchsorted(trial.time, reach.time[0]))
    rows = slice(first, first + len(reach.time))
    mm = dict(trial.markers)
    mm[options.markers.thumb] = mm[options.markers.thumb].copy()
    mm[options.markers.finger] = mm[options.markers.finger].copy()
    mm[options.markers.thumb][rows] = v.thumb
    mm[options.markers.finger][rows] = v.finger
    changed = MocapTrial(trial.name + f"-{kind}", trial.source, trial.time, mm, trial.rate,
                         trial.units)
    found, unscored = trial_reaches(changed, options.markers, options.reaches)
    mine = [r for r in found if abs(r.time[r.onset] - reach.time[reach.onset]) < 0.2]
    if not mine:
        why = "; ".join(u.reason for u in unscored) or "another movement was found"
        return {"verdict": "dropped", "detail": None, "reason": why}
    return _verdict(mine[0], rep, options)


# -- the sources ------------------------------------------------------------------------
def optotrak(rep, which: str, clock: bool = False) -> dict:
    """The Optotrak trials; ``clock``: rewritten as a table whose ``time`` column holds the
    steps between samples and whose clock is ``globalTime`` (ms), read by naming it."""
    path = REALDATA / "optotrak-grasps" / "trials.tsv"
    options = MocapImport(markers=MarkerMap(thumb="thumb", finger="index"), rate=85.0)
    if clock:
        import tempfile

        import pandas as pd

        table = pd.read_csv(path, sep="\t")
        step = 1000 / 85 + np.random.default_rng(0).normal(0, 0.05, len(table))
        table.insert(1, "time", np.round(step, 3))
        table.insert(2, "globalTime", np.round(np.cumsum(step), 3))
        with tempfile.TemporaryDirectory() as tmp:
            written = Path(tmp) / "trials-globaltime.csv"
            table.to_csv(written, index=False)
            trials = read_mocap(written, time_column="globalTime")
    else:
        trials = read_mocap(path, rate=85.0)
    trials = trials[0 if which == "dev" else 1::2]
    res = score_trials(trials, options, rep, variants=True)
    for row, trial in zip(res["reaches"], trials):
        ref = reference_landmarks(trial.time, 0.5 * (trial.markers["thumb"]
                                                     + trial.markers["index"]),
                                  np.linalg.norm(trial.markers["thumb"]
                                                 - trial.markers["index"], axis=1))
        row["ref_mt"], row["ref_mga"] = ref["mt"], ref["mga"]
    return res


def rtmocap(rep) -> dict:
    folder = REALDATA / "rtmocap-pick-and-place"
    options = MocapImport(markers=MarkerMap(thumb="thumb", finger="index",
                                            wrist=("wristA", "wristB"), object=("object",)),
                          rate=200.0)
    trials = []
    for f in sorted(folder.glob("Raw_data_*.txt")):
        try:
            trials += read_mocap(f, rate=200.0, columns=RTMOCAP_COLUMNS)
        except TypeError:  # a reader without columns=: read the layout here
            d = np.loadtxt(f) / 1000
            trials.append(MocapTrial(f.stem, str(f), np.arange(len(d)) / 200.0,
                                     {n: d[:, 3 * k:3 * k + 3] for k, n in
                                      enumerate(RTMOCAP_COLUMNS)}, 200.0, "mm"))
    res = score_trials(trials, options, rep, variants=False)
    by_trial = {t.name: t for t in trials}
    for row in res["reaches"]:
        trial = by_trial[row["trial"]]
        if "onset" in row:
            row["object_moves"] = _first_motion(trial.time, trial.markers["object"],
                                                row["onset"])
    return res


def qualisys(rep) -> dict:
    path = REALDATA / "qualisys-pick-and-place" / "recording.tsv"
    trials = read_mocap(path)
    options = MocapImport(markers=MarkerMap.guess(trials[0].markers))
    res = score_trials(trials, options, rep, variants=False)
    for row in res["reaches"]:  # whole-hand grasps of a cushion: not a precision grip
        row["condition"] = "whole-hand"
    # approaches, counted plainly: the hand's distance to the pillow dips below 40 %
    # of its range, once per dip
    trial = trials[0]
    hand = np.nanmean(np.stack([trial.markers[m] for m in options.markers.wrist]), axis=0)
    obj = np.nanmean(np.stack([trial.markers[m] for m in options.markers.object]), axis=0)
    d = np.linalg.norm(hand - obj, axis=1)
    ok = np.isfinite(d)
    d = np.interp(trial.time, trial.time[ok], d[ok])
    near = d < np.percentile(d, 5) + 0.4 * (np.percentile(d, 95) - np.percentile(d, 5))
    res["approaches"] = int(np.sum(np.diff(near.astype(int)) == 1) + near[0])
    return res


def generated(rep, generator: str, seed: int = 7000) -> dict:
    """Single reaches of each condition, pick-and-place trials and a 12-grasp session."""
    import tempfile

    from mocap_tasks import (
        VERDICT,
        drinking,
        pick_and_place,
        session,
        single_reach,
        write_headerless,
        write_vicon,
    )

    made = [single_reach(generator, c, seed + 10 * k + i)
            for k, c in enumerate(VERDICT) for i in range(8)]
    made += [pick_and_place(generator, "normal", seed + 100 + i) for i in range(5)]
    made += [drinking(generator, c, seed + 150 + i)
             for i, c in enumerate(["normal"] * 3 + ["whole-hand"] * 3)]
    made.append(session(generator, ["normal"] * 12, seed + 200))
    out = {"trials": len(made), "reaches": [], "unscored": [], "conditions": {}}
    with tempfile.TemporaryDirectory() as tmp:  # read as written: through the files' readers
        for g in made:
            path = Path(tmp) / f"{g.trial.name}.csv"
            if "-pnp-" in g.trial.name:  # as RTMocap writes them
                path = path.with_suffix(".txt")
                columns = write_headerless(g.trial, path)
                (trial,) = read_mocap(path, rate=g.trial.rate, columns=columns)
            else:
                write_vicon(g.trial, path)
                (trial,) = read_mocap(path)
            g.trial = trial
            _score_generated(g, rep, out)
    return out


def _score_generated(g, rep, out: dict) -> None:
    """One generated recording's reaches, matched to the truth by their onsets."""
    names = g.trial.markers
    options = MocapImport(markers=MarkerMap(
        thumb="thumb", finger="index", wrist=("hand",),
        object=("object",) if "object" in names else ()))
    res = score_trials([g.trial], options, rep, variants=False)
    out["unscored"] += res["unscored"]
    for truth in g.truth:
        mine = [r for r in res["reaches"]
                if "onset" in r and abs(r["onset"] - truth["onset"]) < 0.3]
        if not mine:
            out["reaches"].append({"name": f"{g.trial.name}@{truth['onset']:.1f}s",
                                   "condition": truth["condition"], "verdict": "dropped",
                                   "detail": None, "reason": "no reach found here"})
            continue
        row = dict(mine[0], condition=truth["condition"], ref_mt=truth["mt"],
                   ref_mga=truth["mga"])
        out["reaches"].append(row)
    extra = len(res["reaches"]) - sum(1 for t in g.truth for r in res["reaches"]
                                      if "onset" in r and abs(r["onset"] - t["onset"]) < 0.3)
    if extra > 0:
        out["unscored"].append({"name": g.trial.name, "status": "extra",
                                "reason": f"{extra} reach(es) found where none was made"})


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sys.path.insert(0, str(Path(__file__).parent))  # tools/mocap_tasks.py
    p.add_argument("--only", nargs="+", default=None,
                   choices=("optotrak", "optotrak-clock", "rtmocap", "qualisys", "independent",
                            "minvar"))
    p.add_argument("--set", choices=("dev", "heldout"), default="heldout",
                   help="which Optotrak trials (default: heldout)")
    p.add_argument("-o", "--output", type=Path, required=True)
    args = p.parse_args(argv)
    rep = Repertoire.default()
    runs = {"optotrak": lambda: optotrak(rep, args.set),
            "optotrak-clock": lambda: optotrak(rep, args.set, clock=True),
            "rtmocap": lambda: rtmocap(rep),
            "qualisys": lambda: qualisys(rep),
            "independent": lambda: generated(rep, "independent"),
            "minvar": lambda: generated(rep, "minvar")}
    res = {}
    for name, run in runs.items():
        if args.only and name not in args.only:
            continue
        start = _time.perf_counter()
        res[name] = run()
        res[name]["seconds"] = round(_time.perf_counter() - start, 1)
    md = markdown(res)
    args.output.mkdir(parents=True, exist_ok=True)
    write_text(args.output / "evaluation.md", md)
    write_text(args.output / "evaluation.json", json.dumps(res, indent=1, default=str) + "\n")
    print(md)
    return 0


def summary(res: dict) -> dict:
    """Counts and medians of one source's result."""
    rows = res["reaches"]
    out = {"trials": res["trials"], "scored": len(rows), "unscored": len(res["unscored"])}
    if any("condition" in r for r in rows):
        from mocap_tasks import VERDICT

        out["conditions"] = {}
        for cond, (verdict, detail) in VERDICT.items():
            got = [r for r in rows if r.get("condition") == cond]
            if got:
                out["conditions"][cond] = {
                    "n": len(got), "right": sum(g["verdict"] == verdict and (
                        detail is None or g["detail"] == detail) for g in got),
                    "abnormal": sum(g["verdict"] == "abnormal" for g in got),
                    "verdicts": _count(g["verdict"] for g in got)}
        rows_normal = [r for r in rows if r.get("condition") == "normal"]
    else:
        rows_normal = rows
    for kind, (verdict, detail) in RIGHT.items():
        got = [r if kind == "normal" else r.get(kind) for r in rows_normal]
        got = [g for g in got if g is not None]
        if not got:
            continue
        out[kind] = {"n": len(got),
                     "right": sum(g["verdict"] == verdict and (detail is None or
                                                               g["detail"] == detail)
                                  for g in got),
                     "abnormal": sum(g["verdict"] == "abnormal" for g in got),
                     "dropped": sum(g["verdict"] in ("dropped", "refused") for g in got),
                     "verdicts": _count(g["verdict"] for g in got)}
    pairs = [(r["mt"], r["ref_mt"], r["mga"], r["ref_mga"]) for r in rows
             if "ref_mt" in r and "mt" in r]
    if pairs:
        a = np.array(pairs, dtype=float)
        out["mt_median_error_s"] = float(np.nanmedian(np.abs(a[:, 0] - a[:, 1])))
        out["mga_median_error_mm"] = float(np.nanmedian(np.abs(a[:, 2] - a[:, 3])) * 1000)
    ends = [r["end"] - r["object_moves"] for r in rows if "object_moves" in r]
    if ends:
        out["end_minus_object_motion_s"] = {"median": float(np.nanmedian(ends)),
                                            "max_abs": float(np.nanmax(np.abs(ends)))}
    if "approaches" in res:
        out["approaches"] = res["approaches"]
    return out


def _count(values) -> dict:
    c: dict = {}
    for v in values:
        c[v] = c.get(v, 0) + 1
    return c


def markdown(res: dict) -> str:
    lines = ["| source | trials | scored | not scored | normal right | late abnormal "
             "(kind) | re-opening abnormal (kind) | MT err (s) | MGA err (mm) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, r in res.items():
        s = summary(r)
        r["summary"] = s

        def cell(kind, s=s):
            k = s.get(kind)
            return "–" if k is None else f"{k['abnormal']} ({k['right']}) / {k['n']}"
        n = s.get("normal", {"right": 0, "n": 0})
        lines.append(f"| {name} | {s['trials']} | {s['scored']} | {s['unscored']} | "
                     f"{n['right']} / {n['n']} | {cell('late')} | {cell('reopen')} | "
                     f"{s.get('mt_median_error_s', math.nan):.3f} | "
                     f"{s.get('mga_median_error_mm', math.nan):.1f} |")
    for name, r in res.items():
        s = r["summary"]
        if "end_minus_object_motion_s" in s:
            e = s["end_minus_object_motion_s"]
            lines.append(f"\n{name}: the reach's end minus the object's first motion: median "
                         f"{e['median']:+.3f} s, largest {e['max_abs']:.3f} s")
        for cond, c in s.get("conditions", {}).items():
            lines.append(f"\n{name} {cond}: {c['right']} / {c['n']} right ({c['verdicts']})")
        if "approaches" in s:
            lines.append(f"\n{name}: {s['approaches']} approaches to the object counted plainly")
        for u in r["unscored"]:
            lines.append(f"- {name} {u['name']}: not scored ({u['status']}): {u['reason']}")
        for row in r["reaches"]:
            for kind in RIGHT:
                g = row if kind == "normal" else row.get(kind)
                want = RIGHT[kind]
                if "condition" in row:
                    from mocap_tasks import VERDICT
                    want = VERDICT[row["condition"]]
                    if kind != "normal":
                        continue
                if g is not None and (g["verdict"], g["detail"]) != want:
                    lines.append(f"- {name} {row['name']} ({kind}): {g['verdict']} "
                                 f"{g['detail'] or ''} — {g['reason'] or ''}")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())

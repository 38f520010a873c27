"""Evaluate the verdict and the landmarks on real motion-capture grasps, dev and held-out apart.

Reads a recording of real healthy grasps (one reach per trial: a lab's
table with a trial column, a C3D or a Qualisys file), splits its trials by
their order into ``dev`` (even: the trials that rules and thresholds were
chosen on) and ``heldout`` (odd: never used to choose anything), and for
each trial of the chosen set scores

* the real grasp (right: ``normal``);
* its late-opening variant and its re-opening variant
  (:mod:`perception.synthetic.variants`: the real transport kept, the grip
  changed; right: ``abnormal`` with ``delayed-opening`` and ``re-opening``);

and checks the landmarks against the field's definitions written out
independently here (a 10 Hz zero-lag Butterworth filter, onset and end
where the grip midpoint's 3D speed crosses 5 % of its peak, MGA the
largest 3D tip-to-tip distance between them)::

    python tools/evaluate_real.py TRIALS.tsv --rate 85 --markers thumb=thumb finger=index \\
        --set heldout -o out/eval-real/heldout

Writes ``OUT/evaluation.md`` and ``OUT/evaluation.json`` and prints the table.
A normal grasp called ``abnormal`` with familiarity < 0.01, or a variant
called ``normal`` with familiarity > 0.5, is *confidently wrong*.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time as _time
from pathlib import Path

import numpy as np
from scipy.signal import butter, filtfilt
from scipy.stats import pearsonr

from perception.errors import HammerMVError
from perception.io.atomic import write_text
from perception.reaches import MarkerMap
from perception.recognition.repertoire import Repertoire
from perception.recordings import MocapImport, read_reaches, recognize_reach
from perception.synthetic.variants import late_opening, reopening

RIGHT = {"normal": ("normal", None), "late": ("abnormal", "delayed-opening"),
         "reopen": ("abnormal", "re-opening")}


def independent_landmarks(reach) -> tuple[float, float]:
    """Movement time (s) and MGA time (share) by the field's definitions, written out plainly."""
    t = reach.time
    ok = np.isfinite(reach.finger).all(axis=1) & np.isfinite(reach.thumb).all(axis=1)
    # lost samples filled linearly, as a lab fills gaps before filtering
    f, th = ([np.interp(t, t[ok], p[ok, k]) for k in range(3)] for p in (reach.finger,
                                                                          reach.thumb))
    f, th = np.stack(f, axis=1), np.stack(th, axis=1)
    rate = 1 / np.median(np.diff(t))
    b, a = butter(2, 10 / (0.5 * rate))
    mid = filtfilt(b, a, 0.5 * (f + th), axis=0)
    g = filtfilt(b, a, np.linalg.norm(f - th, axis=1))
    v = np.linalg.norm(np.gradient(mid, t, axis=0), axis=1)
    p = int(np.argmax(v))
    below = v < 0.05 * v[p]
    on = p - int(np.argmax(below[p::-1])) + 1
    end = p + int(np.argmax(below[p:])) - 1
    j = on + int(np.argmax(g[on:end + 1]))
    return float(t[end] - t[on]), float((t[j] - t[on]) / (t[end] - t[on]))


def evaluate(path: Path, options: MocapImport, which: str) -> dict:
    reaches = read_reaches(path, options)
    chosen = reaches[0 if which == "dev" else 1::2]
    rep = Repertoire.default()
    rows = []
    for reach in chosen:
        for kind, make in (("normal", lambda r: r), ("late", late_opening),
                           ("reopen", reopening)):
            try:
                rec, _ = recognize_reach(make(reach), rep, None, options)
                row = {"trial": reach.name, "kind": kind, "verdict": rec.verdict,
                       "detail": rec.verdict_detail, "familiarity": rec.decision.familiarity,
                       "reason": rec.verdict_reason}
                if kind == "normal":
                    lm = rec.landmarks[0]
                    mt, mga_share = independent_landmarks(reach)
                    row.update(mt=lm.movement_time, mt_truth=mt, mga_time=lm.mga_time,
                               mga_time_truth=mga_share)
            except (HammerMVError, ValueError) as exc:
                row = {"trial": reach.name, "kind": kind, "verdict": "refused",
                       "detail": None, "familiarity": math.nan, "reason": str(exc)}
            rows.append(row)
    return summarise(rows, which, path)


def summarise(rows: list[dict], which: str, path: Path) -> dict:
    out = {"set": which, "input": path.name, "trials": len(rows) // 3, "by_kind": {}}
    for kind, (verdict, detail) in RIGHT.items():
        mine = [r for r in rows if r["kind"] == kind]
        right = [r for r in mine if r["verdict"] == verdict
                 and (detail is None or r["detail"] == detail)]
        abnormal = [r for r in mine if r["verdict"] == "abnormal"]
        wrong = [r for r in mine
                 if (kind == "normal" and r["verdict"] == "abnormal" and r["familiarity"] < 0.01)
                 or (kind != "normal" and r["verdict"] == "normal" and r["familiarity"] > 0.5)]
        counts: dict[str, int] = {}
        for r in mine:
            counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
        out["by_kind"][kind] = {"n": len(mine), "right": len(right), "abnormal": len(abnormal),
                                "confidently_wrong": len(wrong), "verdicts": counts}
    normal = [r for r in rows if r["kind"] == "normal" and "mt" in r
              and math.isfinite(r["mt"])]
    if len(normal) >= 3:
        mt = np.array([[r["mt"], r["mt_truth"]] for r in normal])
        mga = np.array([abs(r["mga_time"] - r["mga_time_truth"]) for r in normal])
        out["landmarks"] = {"movement_time_r": float(pearsonr(mt[:, 0], mt[:, 1])[0]),
                            "movement_time_median_error_s": float(np.median(np.abs(
                                mt[:, 0] - mt[:, 1]))),
                            "mga_time_max_error": float(mga.max()),
                            "mga_time_median_error": float(np.median(mga))}
    if which == "dev":  # the set to look at: name what it got wrong
        out["wrong"] = [{k: r[k] for k in ("trial", "kind", "verdict", "detail", "reason")}
                        for r in rows if (r["verdict"], r["detail"]) != RIGHT[r["kind"]]]
    return out


def markdown(res: dict) -> str:
    lines = [f"## Real grasps: `{res['input']}`, {res['set']} trials ({res['trials']})", "",
             "| grasps | right | abnormal | confidently wrong | verdicts |",
             "|---|---|---|---|---|"]
    names = {"normal": "real, normal", "late": "opening moved late",
             "reopen": "closing and re-opening inserted"}
    for kind, b in res["by_kind"].items():
        verdicts = ", ".join(f"{k} {v}" for k, v in sorted(b["verdicts"].items()))
        lines.append(f"| {names[kind]} | {b['right']} / {b['n']} | {b['abnormal']} | "
                     f"{b['confidently_wrong']} | {verdicts} |")
    if "landmarks" in res:
        lm = res["landmarks"]
        lines += ["", f"Landmarks against the field's definitions computed independently: "
                      f"movement time r = {lm['movement_time_r']:.3f} (median error "
                      f"{lm['movement_time_median_error_s'] * 1000:.0f} ms), MGA time within "
                      f"{lm['mga_time_max_error']:.3f} of the movement (median "
                      f"{lm['mga_time_median_error']:.3f})."]
    for w in res.get("wrong", []):
        lines.append(f"- {w['trial']} ({w['kind']}): {w['verdict']} {w['detail'] or ''} — "
                     f"{w['reason'] or ''}")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("input", type=Path)
    p.add_argument("--rate", type=float, default=None)
    p.add_argument("--markers", nargs="+", default=None, metavar="ROLE=NAME")
    p.add_argument("--set", choices=("dev", "heldout"), default="dev")
    p.add_argument("-o", "--output", type=Path, required=True)
    args = p.parse_args(argv)
    from hammer_mv.cli.options import mocap_import

    args.units = args.trial_column = args.object_size = None
    options = mocap_import(args)
    if options.markers is None:
        options = MocapImport(markers=MarkerMap("thumb", "index"), rate=args.rate)
    start = _time.perf_counter()
    res = evaluate(args.input, options, args.set)
    res["seconds"] = round(_time.perf_counter() - start, 1)
    md = markdown(res) + f"\n{res['trials']} trials x 3 scored in {res['seconds']} s.\n"
    args.output.mkdir(parents=True, exist_ok=True)
    write_text(args.output / "evaluation.md", md)
    write_text(args.output / "evaluation.json", json.dumps(res, indent=1, default=str) + "\n")
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())

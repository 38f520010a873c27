"""Evaluate the verdict where it was not tuned: a healthy-adult population, from video.

Renders a population of the independent generator (movements built from
published human kinematics, not by the minimum variance model;
:func:`perception.synthetic.population.render_population_set`, ranges in
:data:`~perception.synthetic.population.POPULATION_RANGES`), tracks and
recognises it from video with ``hammer-mv batch`` (the default repertoire),
and reports how often the verdict is right::

    python tools/evaluate_verdict.py --set heldout -o out/eval/heldout
    python tools/evaluate_verdict.py --set dev -o out/eval/dev --jobs 2

``--generator sigma-lognormal`` evaluates on the second generator instead
(:mod:`perception.synthetic.sigma_lognormal`: lognormal speed strokes, grip
pulses, marker noise and dropouts; used only to evaluate, never to tune), with
the same set names and seeds; ``--source tracks`` recognises in-memory tracks
of the same movements (no video, no tracker: seconds instead of minutes)::

    python tools/evaluate_verdict.py --generator sigma-lognormal --set heldout -o out/eval/sl
    python tools/evaluate_verdict.py --generator sigma-lognormal --source tracks \
        --set fast-heldout -o out/eval/sl-fast-tracks

Two populations, disjoint by seed (clip *k* of a set draws everything from
``numpy.random.default_rng(first_seed + k)``):

* ``dev`` — seeds 1000, 1001, …: for looking at clips and choosing parameters;
* ``heldout`` — seeds 9000, 9001, …: never used to choose a parameter; its
  report gives aggregates only (no list of the clips it got wrong).

and two of fast grasps, beyond the population's 0.65 s (movement times of
0.45-0.65 s, :data:`FAST_DURATION`; everything else as the population):
``fast-dev`` (seeds 20000, …) and ``fast-heldout`` (seeds 29000, …).

Writes ``OUT/clips/`` (clips, ground truth, ``manifest.csv`` with the drawn
parameters), ``OUT/report/`` (the batch report), ``OUT/evaluation.md``
(markdown tables) and ``OUT/evaluation.json``, and prints the tables:

* the confusion table, condition × verdict (``normal``, ``abnormal``,
  ``reach``, ``unfamiliar``, ``failed/refused``: a clip that failed or got no
  verdict);
* per condition the share right (normal → ``normal``, reach → ``reach``,
  delayed and open-close-open → ``abnormal``);
* the *confidently wrong* verdicts: a normal grasp or a reach called
  ``abnormal`` with familiarity < 0.01, or a delayed or open-close-open grasp
  called ``normal`` or ``reach`` with familiarity > 0.5;
* the ROC AUC of the familiarity separating normal grasps from delayed and
  open-close-open ones (Mann-Whitney U / (n1 n2); a clip without a
  familiarity counts as 0);
* all of it by movement-time band (< 0.8 s, 0.8–1.2 s, > 1.2 s) and by frame
  rate.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

#: The first seed of each population; clip k of a set uses ``first_seed + k``.
SETS: dict[str, int] = {"dev": 1000, "heldout": 9000, "fast-dev": 20000, "fast-heldout": 29000}
#: Most clips in one set: no set's seeds reach the next one's.
MAX_CLIPS = SETS["heldout"] - SETS["dev"]
#: Movement times of the fast sets, s: people asked to be quick (the population's
#: shortest is 0.65 s).
FAST_DURATION = (0.45, 0.65)
#: The sets held out: their reports list no clips.
HELD_OUT = ("heldout", "fast-heldout")
#: Clips per condition by default (at least 60 in all).
DEFAULT_COUNTS: dict[str, int] = {"normal": 30, "delayed": 10, "open-close-open": 10, "reach": 10}
QUICK_COUNTS: dict[str, int] = {"normal": 1, "delayed": 1, "open-close-open": 1, "reach": 1}
CONDITIONS = tuple(DEFAULT_COUNTS)
#: The verdict each condition should get.
EXPECTED: dict[str, str] = {"normal": "normal", "delayed": "abnormal",
                            "open-close-open": "abnormal", "reach": "reach"}
FAILED = "failed/refused"
#: The generators a set can be drawn from (docs/generators.md).
GENERATORS = ("independent", "sigma-lognormal")
#: Where the verdict is computed from: rendered video through ``hammer-mv batch``, or
#: in-memory tracks of the same movements.
SOURCES = ("video", "tracks")
#: Columns of the confusion table (any other verdict met is appended).
VERDICTS = ("normal", "abnormal", "reach", "unfamiliar", FAILED)
#: Confidently wrong: a familiar-movement clip called abnormal below LOW, an
#: abnormal grasp called normal or reach above HIGH.
LOW, HIGH = 0.01, 0.5
#: Movement-time bands, s: (label, low, high).
BANDS = (("MT < 0.8 s", 0.0, 0.8), ("MT 0.8–1.2 s", 0.8, 1.2), ("MT > 1.2 s", 1.2, math.inf))


def set_seeds(name: str, n: int) -> range:
    """The seeds of the ``n`` clips of set ``name``."""
    if not 0 < n <= MAX_CLIPS:
        raise ValueError(f"a set holds 1 to {MAX_CLIPS} clips, got {n}")
    return range(SETS[name], SETS[name] + n)


def parse_counts(text: str) -> dict[str, int]:
    """``normal=30,delayed=10`` → clips per condition (conditions not named: 0)."""
    counts = dict.fromkeys(CONDITIONS, 0)
    for part in filter(None, (p.strip() for p in text.split(","))):
        name, sep, value = part.partition("=")
        if not sep or name.strip() not in counts:
            raise argparse.ArgumentTypeError(
                f"expected CONDITION=N with CONDITION one of {', '.join(CONDITIONS)}, got {part!r}")
        try:
            counts[name.strip()] = int(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number in {part!r}") from None
        if counts[name.strip()] < 0:
            raise argparse.ArgumentTypeError(f"expected a count >= 0 in {part!r}")
    if sum(counts.values()) == 0:
        raise argparse.ArgumentTypeError("expected at least one clip")
    return counts


# -- metrics ---------------------------------------------------------------------

def clip_table(summary: pd.DataFrame, manifest: pd.DataFrame) -> pd.DataFrame:
    """One row per clip of the manifest: its drawn parameters, verdict and familiarity.

    A clip missing from the summary, failed, or without a verdict gets the
    verdict ``failed/refused`` and familiarity NaN.
    """
    keep = [c for c in ("clip", "verdict", "familiarity", "winner", "status", "error")
            if c in summary.columns]
    table = manifest.drop(columns=[c for c in ("parameters", "truth") if c in manifest.columns])
    table = table.merge(summary[keep], on="clip", how="left")
    none = pd.Series(None, index=table.index, dtype=object)
    verdict = table["verdict"].astype(object) if "verdict" in table else none
    status = table["status"].astype(object) if "status" in table else none
    bad = verdict.isna() | (verdict.astype(str).str.strip() == "") | (status != "ok")
    table["verdict"] = np.where(bad, FAILED, verdict.astype(str))
    table["familiarity"] = pd.to_numeric(table.get("familiarity"), errors="coerce")
    table.loc[bad, "familiarity"] = np.nan
    return table


def auc(positive: np.ndarray, negative: np.ndarray) -> float:
    """ROC AUC of scores separating ``positive`` (higher) from ``negative``: U / (n1 n2).

    NaN scores count as 0; NaN when either side is empty.
    """
    from scipy.stats import mannwhitneyu

    pos = np.nan_to_num(np.asarray(positive, dtype=float), nan=0.0)
    neg = np.nan_to_num(np.asarray(negative, dtype=float), nan=0.0)
    if len(pos) == 0 or len(neg) == 0:
        return math.nan
    u = mannwhitneyu(pos, neg, alternative="two-sided").statistic
    return float(u) / (len(pos) * len(neg))


def confidently_wrong(table: pd.DataFrame) -> pd.DataFrame:
    """The clips given a confidently wrong verdict (see the module's docstring)."""
    fam = table["familiarity"]
    familiar = table["condition"].isin(("normal", "reach"))
    abnormal = table["condition"].isin(("delayed", "open-close-open"))
    wrong = ((familiar & (table["verdict"] == "abnormal") & (fam < LOW))
             | (abnormal & table["verdict"].isin(("normal", "reach")) & (fam > HIGH)))
    return table[wrong]


def metrics(table: pd.DataFrame) -> dict:
    """Confusion, share right per condition, confidently wrong and AUC of a clip table."""
    verdicts = list(VERDICTS) + sorted(set(table["verdict"]) - set(VERDICTS))
    confusion = {c: {v: int(((table["condition"] == c) & (table["verdict"] == v)).sum())
                     for v in verdicts}
                 for c in CONDITIONS if (table["condition"] == c).any()}
    right = {}
    for c in confusion:
        rows = table[table["condition"] == c]
        k = int((rows["verdict"] == EXPECTED[c]).sum())
        right[c] = {"right": k, "n": len(rows), "share": k / len(rows)}
    n_right = sum(r["right"] for r in right.values())
    wrong = confidently_wrong(table)
    fam = table["familiarity"].to_numpy(dtype=float)
    value = auc(fam[(table["condition"] == "normal").to_numpy()],
                fam[table["condition"].isin(("delayed", "open-close-open")).to_numpy()])
    return {"n": len(table), "confusion": confusion, "right": right,
            "right_all": {"right": n_right, "n": len(table),
                          "share": n_right / len(table) if len(table) else math.nan},
            "confidently_wrong": {"count": len(wrong), "clips": list(wrong["clip"])},
            "auc": value}


def groups(table: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """The whole table, its movement-time bands and its frame rates (empty ones left out)."""
    out = {"all": table}
    mt = table["movement_time"].astype(float)
    for label, lo, hi in BANDS:
        out[label] = table[(mt >= lo) & (mt < hi)]
    for fps in sorted(table["fps"].astype(float).unique()):
        out[f"{fps:g} fps"] = table[table["fps"].astype(float) == fps]
    return {k: v for k, v in out.items() if len(v)}


def evaluate(summary: pd.DataFrame, manifest: pd.DataFrame) -> tuple[pd.DataFrame, dict]:
    """The clip table and the metrics of every group."""
    table = clip_table(summary, manifest)
    return table, {name: metrics(t) for name, t in groups(table).items()}


# -- tables ----------------------------------------------------------------------

def _frac(r: dict | None) -> str:
    return "—" if r is None else f"{r['right']} / {r['n']}"


def _auc(x: float) -> str:
    return "—" if x is None or not math.isfinite(x) else f"{x:.3f}"


def markdown(result: dict, table: pd.DataFrame, *, list_clips: bool) -> str:
    """The evaluation as markdown: confusion, share right by group, familiarity, wrong clips."""
    allm = result["groups"]["all"]
    verdicts = list(next(iter(allm["confusion"].values())).keys()) if allm["confusion"] else []
    generator = result.get("generator", "independent")
    lines = [f"## Verdict on the `{result['set']}` population of the `{generator}` generator "
             f"(seeds {result['seeds'][0]}–{result['seeds'][1]}, {allm['n']} clips, "
             f"from {result.get('source', 'video')})",
             "",
             "Confusion, condition × verdict:", "",
             "| condition | " + " | ".join(f"`{v}`" if v != FAILED else v for v in verdicts)
             + " |",
             "|---|" + "---|" * len(verdicts)]
    for c, row in allm["confusion"].items():
        lines.append(f"| {c} | " + " | ".join(str(row[v]) for v in verdicts) + " |")
    lines += ["", "Right (normal → `normal`, delayed and open-close-open → `abnormal`, "
              "reach → `reach`), confidently wrong (familiarity < 0.01 for a wrong `abnormal`, "
              "> 0.5 for a wrong `normal`/`reach`) and ROC AUC of familiarity, normal vs "
              "delayed + open-close-open, overall, by movement time and by frame rate:", "",
              "| clips | n | normal | delayed | open-close-open | reach | all right "
              "| confidently wrong | AUC |",
              "|---|---|---|---|---|---|---|---|---|"]
    for name, m in result["groups"].items():
        cells = [_frac(m["right"].get(c)) for c in CONDITIONS]
        share = m["right_all"]
        lines.append(f"| {name} | {m['n']} | " + " | ".join(cells)
                     + f" | {share['right']} / {share['n']} ({100 * share['share']:.0f} %)"
                     + f" | {m['confidently_wrong']['count']} | {_auc(m['auc'])} |")
    lines += ["", "Familiarity of the best model (median, range; a clip without one counts "
              "as 0):", "", "| condition | median | min | max |", "|---|---|---|---|"]
    for c in CONDITIONS:
        f = table.loc[table["condition"] == c, "familiarity"].fillna(0.0)
        if len(f):
            lines.append(f"| {c} | {f.median():.3g} | {f.min():.3g} | {f.max():.3g} |")
    t = result.get("timing", {})
    if t and result.get("source", "video") == "video":
        lines += ["", f"Rendering {t['render_s']:.0f} s, tracking and recognition "
                  f"{t['batch_s']:.0f} s (`--jobs {result['jobs']}`)."]
    elif t:
        lines += ["", f"Recognition of in-memory tracks {t['batch_s']:.0f} s "
                  f"(`--jobs {result['jobs']}`)."]
    wrong = table[table["verdict"] != table["condition"].map(EXPECTED)]
    if list_clips and len(wrong):
        cols = ["clip", "verdict", "familiarity", "winner", "movement_time", "distance",
                "px_per_m", "fps", "approach_deg", "mga_excess", "mga_time",
                "peak_velocity_time", "curvature"]
        cols = [c for c in cols if c in wrong.columns]
        lines += ["", "Clips with a wrong verdict:", "",
                  "| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
        for _, r in wrong.iterrows():
            lines.append("| " + " | ".join(_cell(r[c]) for c in cols) + " |")
    elif not list_clips:
        lines += ["", "(Held-out set: aggregates only; look at clips on the dev set.)"]
    return "\n".join(lines) + "\n"


def _cell(v) -> str:
    if isinstance(v, float | np.floating):
        return "—" if not math.isfinite(v) else f"{v:.3g}"
    return str(v)


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, float | np.floating):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


# -- running ---------------------------------------------------------------------

def hammer_mv() -> list[str]:
    """The ``hammer-mv`` command of this interpreter's environment."""
    beside = Path(sys.executable).parent / "hammer-mv"
    if beside.is_file():
        return [str(beside)]
    found = shutil.which("hammer-mv")
    if found:
        return [found]
    return [sys.executable, "-c", "import sys; from hammer_mv.cli import main; sys.exit(main())"]


def _fast_ranges(set_name: str) -> dict | None:
    """The independent population's ranges for a set (fast sets: :data:`FAST_DURATION`)."""
    from perception.synthetic.population import POPULATION_RANGES

    return ({**POPULATION_RANGES, "duration": FAST_DURATION} if set_name.startswith("fast")
            else None)


def render_set(generator: str, set_name: str, out: Path, counts: dict[str, int], seed: int,
               *, jobs: int, progress: bool) -> pd.DataFrame:
    """Render a set of ``generator`` into ``out`` with its ``manifest.csv``."""
    if generator == "sigma-lognormal":
        from perception.synthetic.sigma_lognormal_clips import render_sigma_lognormal_set

        return render_sigma_lognormal_set(out, counts, seed=seed,
                                          fast=set_name.startswith("fast"), jobs=jobs,
                                          progress=progress)
    from perception.synthetic.population import render_population_set

    return render_population_set(out, counts, seed=seed, ranges=_fast_ranges(set_name),
                                 jobs=jobs, progress=progress)


def clip_tracks(generator: str, set_name: str, condition: str, clip_seed: int):
    """The in-memory tracks of a set's clip and its manifest row (no video).

    The same movement and filming the rendered clip of that seed shows; the
    tracker's part is pixel noise (and, in the second generator, its own
    marker noise and dropouts).
    """
    rng = np.random.default_rng(clip_seed)
    if generator == "sigma-lognormal":
        from perception.synthetic import sigma_lognormal_clips as sl

        clip = sl.draw_sigma_lognormal_clip(condition, rng, fast=set_name.startswith("fast"))
        return sl.clip_tracks(clip, rng)[0], clip.row()
    from perception.synthetic.independent import independent_paths, tracked_paths
    from perception.synthetic.population import draw_population, population_camera

    draw = draw_population(condition, rng, ranges=_fast_ranges(set_name))
    t, paths = independent_paths(draw.params, draw.fps, seed=rng)
    world = {m: paths[m] for m in ("wrist", "finger", "thumb")}
    world["object"] = np.zeros_like(paths["wrist"])
    tracks = tracked_paths(t, world, population_camera(draw), draw.params.object_size,
                           "independent", seed=clip_seed, noise_px=0.4)
    return tracks, draw.row()


_REPERTOIRE = None


def _recognise_one(work: tuple) -> dict:
    """Recognise one clip's in-memory tracks: its summary row."""
    global _REPERTOIRE
    from perception.pipeline import recognize_clip
    from perception.recognition.repertoire import Repertoire

    generator, set_name, clip, condition, clip_seed = work
    if _REPERTOIRE is None:  # one per worker process: its plans are reused
        _REPERTOIRE = Repertoire.default()
    tracks, row = clip_tracks(generator, set_name, condition, clip_seed)
    base = {"clip": clip, "condition": condition, "seed": clip_seed, **row}
    try:
        rec = recognize_clip(tracks, _REPERTOIRE, clip=clip).to_dict()
    except Exception as exc:  # noqa: BLE001 - a refused clip is a result, counted as such
        return {**base, "status": "failed", "error": f"{type(exc).__name__}: {exc}"}
    return {**base, "status": "ok", "verdict": rec.get("verdict"),
            "familiarity": rec.get("familiarity"), "winner": rec.get("winner")}


def recognise_tracks(generator: str, set_name: str, counts: dict[str, int], seed: int, *,
                     jobs: int) -> list[dict]:
    """Recognise every clip of a set from in-memory tracks; one row per clip."""
    clips = [(cond, i) for cond in CONDITIONS for i in range(counts.get(cond, 0))]
    work = [(generator, set_name, f"{cond}-{i + 1:02d}", cond, seed + k)
            for k, (cond, i) in enumerate(clips)]
    if jobs == 1:
        return [_recognise_one(w) for w in work]
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(jobs) as pool:
        return list(pool.map(_recognise_one, work))


def run(set_name: str, out: str | os.PathLike, counts: dict[str, int], *, jobs: int = 2,
        quiet: bool = False, generator: str = "independent",
        source: str = "video") -> tuple[pd.DataFrame, dict]:
    """Render the set, run ``hammer-mv batch`` on it (or recognise its tracks), evaluate,
    write the tables."""
    out = Path(out)
    n = sum(counts.values())
    seeds = set_seeds(set_name, n)
    tty = sys.stderr.isatty() and not quiet
    t0 = time.perf_counter()
    if source == "tracks":
        rows = recognise_tracks(generator, set_name, counts, seeds.start, jobs=jobs)
        t1, t2 = t0, time.perf_counter()  # nothing rendered
        out.mkdir(parents=True, exist_ok=True)
        result_keys = ("verdict", "familiarity", "winner", "status", "error")
        manifest = pd.DataFrame([{k: v for k, v in r.items() if k not in result_keys}
                                 for r in rows])
        summary = pd.DataFrame([{k: r.get(k) for k in ("clip", *result_keys)} for r in rows])
        exit_code = 0
    else:
        manifest = render_set(generator, set_name, out / "clips", counts, seeds.start,
                              jobs=jobs, progress=tty)
        t1 = time.perf_counter()
        if tty:
            print(f"tracking and recognising {n} clips from video (hammer-mv batch "
                  f"--jobs {jobs}) …", file=sys.stderr)
        cmd = [*hammer_mv(), "batch", str(out / "clips" / "manifest.csv"), "-o",
               str(out / "report"), "--jobs", str(jobs), "--quiet"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        t2 = time.perf_counter()
        summary_path = out / "report" / "summary.csv"
        if not summary_path.is_file():
            raise RuntimeError(f"hammer-mv batch wrote no summary (exit {proc.returncode}): "
                               f"{proc.stderr.strip()[-2000:]}")
        summary = pd.read_csv(summary_path)
        exit_code = proc.returncode
    table, by_group = evaluate(summary, manifest)
    result = {"set": set_name, "generator": generator, "source": source,
              "seeds": [seeds.start, seeds.stop - 1],
              "counts": counts, "jobs": jobs, "batch_exit": exit_code,
              "timing": {"render_s": t1 - t0, "batch_s": t2 - t1},
              "groups": by_group}
    text = markdown(result, table, list_clips=set_name not in HELD_OUT)
    (out / "evaluation.md").write_text(text, encoding="utf-8")
    clips = table[[c for c in table.columns if c != "error"]].to_dict(orient="records")
    (out / "evaluation.json").write_text(
        json.dumps(_jsonable({**result, "clips": clips}), indent=1) + "\n", encoding="utf-8")
    return table, {**result, "markdown": text}


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        description="Render a healthy-adult population of the independent generator, track and "
                    "recognise it from video with `hammer-mv batch`, and report the verdict's "
                    "accuracy (confusion, share right, confidently wrong, AUC; by movement "
                    "time and frame rate).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--set", choices=tuple(SETS), default="dev",
                   help="population: dev (seeds 1000 + k, for tuning) or heldout (seeds "
                        "9000 + k, never for choosing a parameter); fast-dev / fast-heldout: "
                        "the same with movement times of 0.45-0.65 s")
    p.add_argument("--generator", choices=GENERATORS, default="independent",
                   help="independent: the healthy-adult population of the generator the rules "
                        "are tuned on; sigma-lognormal: the second generator, never tuned on "
                        "(docs/generators.md); same set names and seeds")
    p.add_argument("--source", choices=SOURCES, default="video",
                   help="video: render, track and recognise with hammer-mv batch; tracks: "
                        "recognise in-memory tracks of the same movements (no video)")
    p.add_argument("-o", "--output", required=True, metavar="OUT",
                   help="folder for clips/, report/, evaluation.md and evaluation.json")
    p.add_argument("--per-condition", type=parse_counts, default=None, metavar="COUNTS",
                   help="clips per condition (default "
                        + ",".join(f"{k}={v}" for k, v in DEFAULT_COUNTS.items()) + ")")
    p.add_argument("--jobs", type=int, default=2, metavar="N",
                   help="processes for rendering and for hammer-mv batch")
    p.add_argument("--quick", action="store_true",
                   help="one clip per condition (a smoke run, not an evaluation)")
    p.add_argument("--quiet", action="store_true", help="print nothing on success")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.jobs < 1:
        build_parser().error("--jobs: expected at least 1")
    counts = (QUICK_COUNTS if args.quick else args.per_condition or DEFAULT_COUNTS)
    if sum(counts.values()) > MAX_CLIPS:
        build_parser().error(f"--per-condition: at most {MAX_CLIPS} clips in a set")
    _, result = run(args.set, args.output, counts, jobs=args.jobs, quiet=args.quiet,
                    generator=args.generator, source=args.source)
    if not args.quiet:
        print(result["markdown"])
        print(f"wrote {Path(args.output) / 'evaluation.md'} and evaluation.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())

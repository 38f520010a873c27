"""Reproduce thesis chapter 4 (grasping): every figure, table and quantitative claim.

``reproduce(out, trials=500, seed=0)`` runs the seven experiments of
:mod:`minvar.grasp_experiments` (each from its own child of ``seed``), saves
their figures (PNG, named after the thesis's, e.g. ``fig4_10_object_size_mga.png``)
and tables (CSV) into ``out``, and returns one dict per quantitative claim of
the chapter with keys section, claim, thesis, ours, agrees, note.
``tools/reproduce_thesis.py`` calls it; run alone, this script also writes
``claims.csv`` and prints the claims as a markdown table::

    python tools/reproduce_ch4.py -o out/ch4 [--trials 500] [--seed 0]

Trends are judged on the exact (first-order) moments of each plan wherever the
claim is about a standard deviation (``*_exact`` columns), so they do not hinge
on sampling error; the Monte Carlo values are in the tables and figures too.
Nothing in the model was tuned to match these numbers: the parameters are the
thesis's (links, 6 cm wrist stand-off, 1 cm via-point at 70 %, 1 % execution
noise) and the model's cost weights (docs/model.md); the geometric choices the
thesis leaves open are documented in :mod:`minvar.grasp` and docs/coordinates.md.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from hammer_mv.cli.grasp import write_experiment  # noqa: E402
from minvar.grasp import GraspTask, plan_grasp, simulate_grasp  # noqa: E402
from minvar.grasp_experiments import EXPERIMENTS, GraspExperiment  # noqa: E402
from minvar.plotting.grasp import grasp_figure, setup_figure  # noqa: E402
from perception.io.atomic import save_figure, write_csv  # noqa: E402

log = logging.getLogger("reproduce_ch4")

UM = 1e6


def _pct(x: float) -> str:
    return f"{100 * x:.0f} %"


def _cm(x: float) -> str:
    return f"{100 * x:g} cm"


def _p(p: float) -> str:
    return "p < 1e-16" if p < 1e-16 else f"p = {p:.2g}"


def _monotonic(y, increasing: bool) -> bool:
    d = np.diff(np.asarray(y, dtype=float))
    return bool(np.all(d > 0) if increasing else np.all(d < 0))


def _claim(section, claim, thesis, ours, agrees, note="") -> dict:
    return dict(section=section, claim=claim, thesis=thesis, ours=ours, agrees=bool(agrees),
                note=note)


def _viapoint_height(e: GraspExperiment) -> list[dict]:
    s = e.summary
    h = s.viapoint_height.to_numpy()
    out = []
    best = {}
    for digit in ("finger", "thumb"):
        total = np.hypot(s[f"{digit}_sd_x_exact"], s[f"{digit}_sd_y_exact"]).to_numpy()
        best[digit] = (h[np.argmin(total)], total)
    level = np.argmin(np.abs(h))
    agrees = all(abs(b) < 1e-9 for b, _ in best.values())
    f_tot = best["finger"][1]
    ours = (f"lowest total SD at {_cm(best['finger'][0])} (finger), {_cm(best['thumb'][0])} "
            f"(thumb); finger {f_tot[level] * UM:.2f} µm level vs "
            f"{f_tot[0] * UM:.2f} µm at {_cm(h[0])}, {f_tot[-1] * UM:.2f} µm at {_cm(h[-1])}")
    near = f_tot[[max(level - 1, 0), min(level + 1, len(h) - 1)]] / f_tot[level] - 1
    se = 1 / np.sqrt(2 * (int(s.trials.iloc[0]) - 1))
    note = (f"exact SDs (first-order moments). The minimum is shallow: the neighbouring "
            f"settings are {100 * near.min():.1f}-{100 * near.max():.1f} % higher, less than "
            f"the sampling error of an SD from {int(s.trials.iloc[0])} repetitions "
            f"({100 * se:.0f} %), so the Monte Carlo SDs in the table need not show it.")
    if not agrees:
        note = "the minimum is not at the level setting. " + note
    out.append(_claim("4.2.1.1", "Digit end-point SD is lowest with via-points level with the "
                      "targets", "lowest at 0 cm (level)", ours, agrees, note))
    d = s.finger_distance_mean.to_numpy()
    i = int(np.argmin(d))
    agrees = abs(h[i]) < 1e-9
    ours = (f"finger mean distance smallest at {_cm(h[i])} ({d[i] * UM:.0f} µm); "
            f"{d[level] * UM:.0f} µm level, {d[0] * UM:.0f} µm at {_cm(h[0])}, "
            f"{d[-1] * UM:.0f} µm at {_cm(h[-1])}")
    sd_level = np.hypot(s.finger_sd_x_exact, s.finger_sd_y_exact).to_numpy()[level]
    note = ("falls toward level and rises above, as in the thesis" if agrees else
            "falls toward level and rises above, but the minimum sits just above level: "
            f"the distance ({d[level] * UM:.0f} µm at level) is mostly the plan's systematic "
            f"end-point error (the LQG's effort/accuracy trade-off), not the scatter "
            f"({sd_level * UM:.0f} µm SD), and that bias is smallest slightly above the "
            "target line")
    out.append(_claim("4.2.1.1", "End-point distance from target is smallest with level "
                      "via-points", "decreases toward level, increases above", ours,
                      agrees, note))
    return out


def _viapoint_time(e: GraspExperiment) -> list[dict]:
    s = e.summary
    f = s.viapoint_time.to_numpy()
    total = np.hypot(s.finger_sd_x_exact, s.finger_sd_y_exact).to_numpy()
    i_max = int(np.argmax(total))
    early = f <= 0.85
    i_min = int(np.argmin(np.where(early, total, np.inf)))
    i70 = int(np.argmin(np.abs(f - 0.7)))
    wrist_sd = float(e.curves[e.curves.setting == i70].wrist_sd_exact.iloc[-1])
    out = [_claim(
        "4.2.1.2", "End-point SD peaks for a via-point late in the movement",
        "peak at about 87 %",
        f"peak at {_pct(f[i_max])} ({total[i_max] * UM:.1f} µm), falling after it "
        f"({total[-1] * UM:.1f} µm at {_pct(f[-1])})",
        abs(f[i_max] - 0.87) <= 0.05,
        "exact finger SD (thumb identical by symmetry); the thesis explains the fall after "
        "the peak by the via-point's declining weight near the end, as seen here")]
    agrees = abs(f[i_min] - 0.70) <= 0.05
    out.append(_claim(
        "4.2.1.2", "End-point SD is lowest for a via-point near 70 %",
        "minimum near 70 %, rising below it",
        f"lowest at {_pct(f[i_min])} ({total[i_min] * UM:.2f} µm) among 50-85 %; "
        f"{total[i70] * UM:.2f} µm at 70 %",
        agrees,
        "" if agrees else
        f"differs: our SD keeps falling, slightly ({100 * (1 - total[i_min] / total[i70]):.1f} "
        f"% below the 70 % value), as the via-point moves earlier down to {_pct(f[i_min])}; "
        "the thesis's rise below 70 % (faster early movement, more noise) does not appear. "
        f"The wrist, which the via-point does not affect, contributes {wrist_sd * UM:.1f} µm "
        "of the end-point SD."))
    d = s.finger_distance_mean.to_numpy()

    def at(x):
        return d[np.argmin(np.abs(f - x))]

    rise_early, rise_late = at(0.80) - at(0.50), at(0.95) - at(0.80)
    out.append(_claim(
        "4.2.1.2", "End-point distance hardly changes below ~80 % and climbs sharply beyond "
        "85 %", "flat below 80 %, sharp rise beyond 85 %",
        f"{at(0.5) * UM:.0f} µm at 50 %, {at(0.8) * UM:.0f} µm at 80 %, "
        f"{at(0.9) * UM:.0f} µm at 90 %, {at(0.95) * UM:.0f} µm at 95 %",
        rise_late > 5 * rise_early,
        "judged as: the rise from 80 to 95 % is more than 5 times the rise from 50 to 80 %"))
    return out


def _viapoint_distance(e: GraspExperiment) -> list[dict]:
    s = e.summary
    o = s.viapoint_offset.to_numpy()
    m, t = s.mga_mean.to_numpy(), s.mga_time_mean.to_numpy()
    larger = _monotonic(m, True)
    earlier = bool(np.all(np.diff(t) <= 0) and t[-1] < t[0])
    return [
        _claim("4.2.2.1", "A via-point further from the object gives a larger MGA",
               "MGA increases with via-point distance",
               f"MGA {m[0] * 100:.2f} -> {m[-1] * 100:.2f} cm for {_cm(o[0])} -> {_cm(o[-1])} "
               f"(slope {e.stats['mga_slope']:.2f})", larger,
               "slope about 2: both digits move out by the offset"),
        _claim("4.2.2.1", "A via-point further from the object gives an earlier MGA",
               "MGA occurs earlier with via-point distance",
               f"MGA at {_pct(t[0])} -> {_pct(t[-1])} for {_cm(o[0])} -> {_cm(o[-1])}",
               earlier, "relative time of the mean MGA (steps of 1 %), never later"),
    ]


def _object_size(e: GraspExperiment) -> list[dict]:
    s = e.summary
    sz = s.object_size.to_numpy()
    t = s.mga_time_mean.to_numpy()
    slope = e.stats["mga_slope"]
    in_range = bool(np.all((t >= 0.60) & (t <= 0.80)))
    inside = sz[(t >= 0.60) & (t <= 0.80)]
    return [
        _claim("4.2.2.2", "MGA grows linearly with object size; regression slope",
               "0.92 (human studies: about 0.8)",
               f"{slope:.3f} (r = {e.stats['mga_r']:.4f}; MGA = {slope:.2f} size + "
               f"{e.stats['mga_intercept'] * 100:.2f} cm)",
               abs(slope - 0.92) <= 0.05,
               "regression of the mean MGA on 9 sizes 0-8 cm, as in Fig. 4.10; not tuned"),
        _claim("4.2.2.2", "MGA occurs at 60-80 % of the movement",
               "60-80 % for sizes 0-8 cm",
               f"{_pct(t.min())}-{_pct(t.max())} ({', '.join(_pct(x) for x in t)} for "
               f"{', '.join(f'{100 * x:g}' for x in sz)} cm)",
               in_range,
               "" if in_range else
               f"sizes {_cm(inside.min())}-{_cm(inside.max())} fall inside; smaller objects "
               "peak earlier: the fixed 1 cm return from the via-point is a larger part of a "
               "small object's grip movement, so the aperture turns sooner. Where the closed "
               "digits start (tip_start, not given in the thesis) shifts these times by 2-3 %"),
        _claim("4.2.2.2", "MGA occurs later for larger objects",
               "later for larger objects",
               f"{_pct(t[0])} at {_cm(sz[0])} -> {_pct(t[-1])} at {_cm(sz[-1])}",
               bool(np.all(np.diff(t) >= 0) and t[-1] > t[0]),
               "relative time of the mean MGA (1 % steps)"),
    ]


def _movement_time(e: GraspExperiment) -> list[dict]:
    s, st = e.summary, e.stats
    d = s.duration.to_numpy()
    out = []
    for comp, label in (("wrist", "Wrist"), ("aperture", "Aperture")):
        y = s[f"{comp}_sd_peak_exact"].to_numpy()
        out.append(_claim(
            "4.2.3.1", f"{label} peak SD falls as movement time grows",
            "decreases from 600 to 1200 ms",
            f"{y[0] * UM:.1f} -> {y[-1] * UM:.1f} µm ({d[0] * 1000:.0f} -> "
            f"{d[-1] * 1000:.0f} ms); ANOVA {_p(st[f'{comp}_anova_p'])}",
            _monotonic(y, False) and st[f"{comp}_anova_p"] < 0.05,
            "exact peak SDs fall monotonically; one-way ANOVA across durations of each "
            "repetition's peak deviation from its setting's mean path"))
    tw = s.wrist_sd_peak_time_exact.to_numpy()
    ta = s.aperture_sd_peak_time_exact.to_numpy()
    agrees = tw[-1] < tw[0] and ta[-1] < ta[0]
    out.append(_claim(
        "4.2.3.1", "Peak variability occurs earlier in longer movements",
        "generally earlier with longer movement time",
        f"wrist {_pct(tw[0])} -> {_pct(tw[-1])}, aperture {_pct(ta[0])} -> {_pct(ta[-1])} "
        f"(600 -> 1200 ms); ANOVA on peak times {_p(st['wrist_time_anova_p'])} (wrist), "
        f"{_p(st['aperture_time_anova_p'])} (aperture)", agrees,
        "exact peak times as fractions of the movement"))
    return out


def _variability_size(e: GraspExperiment) -> list[dict]:
    s, st = e.summary, e.stats
    sz = s.object_size.to_numpy()
    w = s.wrist_sd_peak_exact.to_numpy()
    a = s.aperture_sd_peak_exact.to_numpy()
    fit = np.polyfit(sz, a, 1)
    r = np.corrcoef(sz, a)[0, 1]
    tw = s.wrist_sd_peak_time_exact.to_numpy()
    ta = s.aperture_sd_peak_time_exact.to_numpy()
    return [
        _claim("4.2.3.2", "Wrist peak SD is unaffected by object size",
               "no significant effect (sizes 2-8 cm)",
               f"exact peak {w[1] * UM:.1f} µm at every size (relative range "
               f"{st['wrist_sd_peak_exact_range']:.1e}); ANOVA {_p(st['wrist_anova_p'])} "
               f"(sizes > 0: {_p(st['wrist_anova_p_nonzero'])})",
               st["wrist_anova_p_nonzero"] > 0.05 and st["wrist_sd_peak_exact_range"] < 0.01,
               "by construction: the transport plan does not depend on the object's size "
               "(the wrist target is 6 cm short of its centre whatever its size)"),
        _claim("4.2.3.2", "With no object (size 0) the wrist peak SD is much higher",
               "much higher at 0 cm",
               f"{w[0] * UM:.1f} µm at 0 cm vs {w[1:].mean() * UM:.1f} µm for 2-8 cm",
               w[0] > 1.2 * w[1:].mean(),
               "not reproduced: in this model (and as the thesis describes it) the arm's plan "
               "and noise are identical for every object size, so nothing can single out "
               "size 0; the thesis's result may come from its implementation (e.g. a "
               "degenerate grip target at zero size)"),
        _claim("4.2.3.2", "Wrist peak SD occurs slightly later for larger objects",
               "slightly later for larger objects",
               f"{_pct(tw[0])} at every size; ANOVA on peak times "
               f"{_p(st['wrist_time_anova_p'])}", tw[-1] > tw[0],
               "not reproduced, for the same reason: the wrist's movement does not depend on "
               "object size in the model"),
        _claim("4.2.3.2", "Aperture peak SD grows (linearly) with object size",
               "strong linear increase",
               f"{a[0] * UM:.1f} -> {a[-1] * UM:.1f} µm for 0 -> 8 cm "
               f"({fit[0] * UM / 100:.2f} µm per cm, r = {r:.3f}); ANOVA "
               f"{_p(st['aperture_anova_p'])}",
               _monotonic(a, True) and r > 0.95 and st["aperture_anova_p"] < 0.05,
               "wider grips need larger digit commands, hence more signal-dependent noise"),
        _claim("4.2.3.2", "Timing of the aperture peak SD does not vary significantly with "
               "object size", "no significant change",
               f"{_pct(ta.min())}-{_pct(ta.max())} (exact); ANOVA on per-repetition peak "
               f"times {_p(st['aperture_time_anova_p'])}",
               st["aperture_time_anova_p"] > 0.05,
               "the exact peak moves by a few % of the movement; the per-repetition ANOVA "
               "detects it" if st["aperture_time_anova_p"] <= 0.05 else
               "the exact peak moves by a few % of the movement at most"),
    ]


def _variability_distance(e: GraspExperiment) -> list[dict]:
    s, st = e.summary, e.stats
    dist = s.distance.to_numpy()
    w = s.wrist_sd_peak_exact.to_numpy()
    a = s.aperture_sd_peak_exact.to_numpy()
    return [
        _claim("4.2.3.3", "Grip aperture SD is unaffected by transport distance",
               "no effect of distance on aperture SD",
               f"exact peak {a[0] * UM:.1f} µm at every distance (relative range "
               f"{st['aperture_sd_peak_exact_range']:.1e}); ANOVA "
               f"{_p(st['aperture_anova_p'])}",
               st["aperture_anova_p"] > 0.05 and st["aperture_sd_peak_exact_range"] < 0.01,
               "by construction: the grip is planned from the wrist target, so its plan does "
               "not depend on distance, and the aperture does not depend on the wrist. Kudoh "
               "et al. found an effect in people, which the thesis also does not reproduce"),
        _claim("4.2.3.3", "Wrist SD changes with transport distance",
               "wrist SD decreases as distance increases (8-24 cm)",
               f"{w[0] * UM:.1f} -> {w[-1] * UM:.1f} µm for {_cm(dist[0])} -> "
               f"{_cm(dist[-1])}; ANOVA {_p(st['wrist_anova_p'])}",
               _monotonic(w, False) and st["wrist_anova_p"] < 0.05,
               "" if _monotonic(w, False) else
               "differs in direction: our wrist SD increases with distance (a significant "
               "effect, as Kudoh et al. found). A longer transport in the same time needs "
               "larger joint commands, so signal-dependent noise grows; the thesis's text "
               "reports a decrease, which we cannot obtain from this model"),
    ]


_CLAIMS = {
    "viapoint-height": _viapoint_height,
    "viapoint-time": _viapoint_time,
    "viapoint-distance": _viapoint_distance,
    "object-size": _object_size,
    "movement-time": _movement_time,
    "variability-size": _variability_size,
    "variability-distance": _variability_distance,
}


def reproduce(out: Path, *, trials: int = 500, seed: int = 0) -> list[dict]:
    """Run every chapter-4 experiment, save figures and tables, return the claims.

    Parameters
    ----------
    out : pathlib.Path
        Folder for the PNG figures (``fig4_*.png``) and CSV tables (created).
    trials : int
        Repetitions per setting (thesis: 500).
    seed : int
        Root seed; each experiment uses its own child.

    Returns
    -------
    list of dict
        One per quantitative claim: section, claim, thesis, ours, agrees, note.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    children = np.random.SeedSequence(seed).spawn(len(EXPERIMENTS) + 1)
    base = GraspTask()
    plan = plan_grasp(base)
    save_figure(out / "fig4_1_setup.png", setup_figure(plan=plan))
    typical = simulate_grasp(base, trials, seed=children[-1], plan=plan)
    save_figure(out / "fig4_6_typical_grasp.png", grasp_figure(typical))
    claims: list[dict] = []
    for (name, run), child in zip(EXPERIMENTS.items(), children):
        t0 = time.perf_counter()
        exp = run(trials=trials, seed=child)
        write_experiment(exp, out)
        claims += _CLAIMS[name](exp)
        log.info("%s: %.1f s", name, time.perf_counter() - t0)
    return claims


def markdown(claims: list[dict]) -> str:
    """The claims as a markdown table.

    Parameters
    ----------
    claims : list of dict
        From :func:`reproduce`.
    """
    rows = ["| section | claim | thesis | ours | agrees | note |", "|---|---|---|---|---|---|"]
    for c in claims:
        cells = [c["section"], c["claim"], c["thesis"], c["ours"],
                 "yes" if c["agrees"] else "**no**", c["note"]]
        rows.append("| " + " | ".join(str(x).replace("|", "/") for x in cells) + " |")
    return "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command line: ``reproduce_ch4.py -o DIR [--trials N] [--seed N]``.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default: ``sys.argv[1:]``).
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "out" / "thesis" / "ch4")
    parser.add_argument("--trials", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    t0 = time.perf_counter()
    claims = reproduce(args.output, trials=args.trials, seed=args.seed)
    write_csv(args.output / "claims.csv", pd.DataFrame(claims))
    print(markdown(claims))
    agree = sum(c["agrees"] for c in claims)
    print(f"{agree} of {len(claims)} claims agree; {time.perf_counter() - t0:.0f} s; "
          f"figures and tables in {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

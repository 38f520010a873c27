"""The same real movements as other labs would record them: do the verdicts stay?

A lab's conventions — where its origin is, which axis points up, the
participant's hand, the clock's start, the sampling rate, the markers it
places beside the digits, a few dropped samples, its system's noise — say
nothing about how a person grasped. Each transform here rewrites real
recordings in one such convention (:data:`TRANSFORMS`) and scores every
reach again; a reach whose verdict changes is a robustness fault, listed with
both results (verdict, movement time, MGA, familiarity).

The transforms that make new samples (another rate, added noise) start from
the samples the system measured: a sample the cleaning finds held (a marker
frozen at its last position while occluded) or off the path is no movement,
so it is left out before them (lost, as :func:`perception.cleaning.clean_path`
marks it) rather than resampled into a ramp or given noise that hides it.

Sources: the shared Optotrak table's trials (``--set dev``, the even ones,
default; ``heldout`` the odd ones) when ``../shared/realdata`` is there, else
the four trials shipped in ``tests/data/mocap/``::

    python tools/evaluate_invariance.py [--set dev|heldout|shipped] [--only rotated ...]
"""

from __future__ import annotations

import argparse
import collections
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from perception.cleaning import CleaningParams, clean_path  # noqa: E402
from perception.errors import HammerMVError  # noqa: E402
from perception.io.mocap import read_mocap  # noqa: E402
from perception.io.mocap_trial import MocapTrial  # noqa: E402
from perception.reach_data import MarkerMap  # noqa: E402
from perception.reaches import trial_reaches  # noqa: E402
from perception.recordings import MocapImport, recognize_reach  # noqa: E402

SHIPPED = ROOT / "tests" / "data" / "mocap" / "optotrak-trials.tsv"
SHARED = ROOT.parent / "shared" / "realdata" / "optotrak-grasps" / "trials.tsv"
#: The Optotrak tables' mapping and rate (no time column).
OPTIONS = MocapImport(markers=MarkerMap(thumb="thumb", finger="index"), rate=85.0)
#: A rotation of the lab's frame (degrees about x, y, z), none of its axes kept.
TURN = (30.0, -50.0, 110.0)


def _markers(trial: MocapTrial, change: Callable[[np.ndarray], np.ndarray],
             time: np.ndarray | None = None, rate: float | None = None) -> MocapTrial:
    """``trial`` with every marker's (N, 3) path changed by ``change``."""
    return MocapTrial(trial.name, trial.source, trial.time if time is None else time,
                      {name: change(path) for name, path in trial.markers.items()},
                      trial.rate if rate is None else rate, trial.units)


def measured(trial: MocapTrial) -> MocapTrial:
    """``trial`` with the samples the cleaning finds held or off the path lost (NaN), and
    nothing bridged: what the system measured."""
    keep = CleaningParams(max_bridge=0.0)
    return _markers(trial, lambda p: clean_path(trial.time, p, keep)[0])


def rotated(trial: MocapTrial) -> MocapTrial:
    """The lab's frame turned (no axis of the original kept)."""
    from scipy.spatial.transform import Rotation

    turn = Rotation.from_euler("xyz", TURN, degrees=True).as_matrix()
    return _markers(trial, lambda p: p @ turn.T)


def resampled(rate: float) -> Callable[[MocapTrial], MocapTrial]:
    """The measured samples at ``rate`` samples/s (linear; lost where a neighbour is)."""
    def resample(trial: MocapTrial) -> MocapTrial:
        trial = measured(trial)
        t = np.arange(trial.time[0], trial.time[-1], 1.0 / rate)

        def at(p):
            return np.stack([np.interp(t, trial.time, p[:, k], left=np.nan, right=np.nan)
                             for k in range(p.shape[1])], axis=1)
        return _markers(trial, at, t, rate)
    return resample


def dropouts(trial: MocapTrial, seed: int = 1) -> MocapTrial:
    """Two-sample dropouts (NaN), one every 60 samples on average, at random."""
    rng = np.random.default_rng(seed)

    def drop(p):
        p = p.copy()
        for s in rng.integers(0, len(p) - 3, max(1, len(p) // 60)):
            p[s:s + 2] = np.nan
        return p
    return _markers(trial, drop)


def noisy(sd: float, seed: int = 2) -> Callable[[MocapTrial], MocapTrial]:
    """White noise of ``sd`` m on every coordinate of the measured samples."""
    def add(trial: MocapTrial) -> MocapTrial:
        rng = np.random.default_rng(seed)
        return _markers(measured(trial), lambda p: p + rng.normal(0.0, sd, p.shape))
    return add


def more_markers(trial: MocapTrial, count: int = 30, seed: int = 3) -> MocapTrial:
    """``count`` more markers (a full-body set's), none of them mapped."""
    rng = np.random.default_rng(seed)
    extra = {f"M{k:02d}": trial.markers["thumb"] + rng.normal(0.0, 0.3, 3)
             for k in range(count)}
    return MocapTrial(trial.name, trial.source, trial.time, {**trial.markers, **extra},
                      trial.rate, trial.units)


#: Each convention's transform of a recorded trial.
TRANSFORMS: dict[str, Callable[[MocapTrial], MocapTrial]] = {
    "rotated frame": rotated,
    "origin 2 m away": lambda t: _markers(t, lambda p: p + np.array([2.0, -1.5, 0.8])),
    "left hand (mirrored)": lambda t: _markers(t, lambda p: p * np.array([-1.0, 1.0, 1.0])),
    "y up (y and z swapped)": lambda t: _markers(t, lambda p: p[:, [0, 2, 1]]),
    "clock from 1234.5 s": lambda t: MocapTrial(t.name, t.source, t.time + 1234.5, t.markers,
                                                t.rate, t.units),
    "30 more markers": more_markers,
    "2-sample dropouts": dropouts,
    "60 samples/s": resampled(60.0),
    "100 samples/s": resampled(100.0),
    "200 samples/s": resampled(200.0),
    "0.3 mm noise": noisy(0.0003),
    "1 mm noise": noisy(0.001),
}


def score(trial: MocapTrial, rep, options: MocapImport = OPTIONS) -> list[dict]:
    """Every reach of ``trial`` scored, and every movement that gives none, as rows."""
    try:
        reaches, unscored = trial_reaches(trial, options.markers, options.reaches)
    except HammerMVError as exc:
        return [{"verdict": "refused", "why": exc.problem}]
    rows = [{"verdict": f"not scored ({u.status})", "why": u.reason} for u in unscored]
    for reach in reaches:
        try:
            rec, _ = recognize_reach(reach, rep, None, options)
        except HammerMVError as exc:
            rows.append({"verdict": "refused", "why": exc.problem})
            continue
        lm = rec.landmarks[0]
        verdict = rec.verdict + (f" ({rec.verdict_detail})" if rec.verdict_detail else "")
        rows.append({"verdict": verdict, "movement_time": lm.movement_time, "mga": lm.mga,
                     "familiarity": rec.decision.familiarity})
    return rows


def trials_of(which: str) -> list[MocapTrial]:
    """The trials of a set: ``dev``/``heldout`` (the shared table), ``shipped``."""
    if which == "shipped" or not SHARED.exists():
        return read_mocap(SHIPPED, rate=OPTIONS.rate)
    trials = read_mocap(SHARED, rate=OPTIONS.rate)
    return trials[0 if which == "dev" else 1::2]


def _line(rows: list[dict]) -> str:
    return "; ".join(r["verdict"] + (f" MT {r['movement_time']:.3f} s MGA {r['mga'] * 1e3:.1f} mm"
                                     f" fam {r['familiarity']:.2f}" if "mga" in r else "")
                     for r in rows)


def main(argv: list[str] | None = None) -> dict[str, list[str]]:
    """Print, per transform, the reaches whose verdicts changed; return them by transform."""
    from perception.recognition.repertoire import Repertoire

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--set", choices=("dev", "heldout", "shipped"), default="dev",
                   help="the shared Optotrak table's even (dev) or odd trials, or the four "
                        "shipped with the tests")
    p.add_argument("--only", nargs="+", choices=sorted(TRANSFORMS), metavar="TRANSFORM",
                   help=f"transforms to run (default: all): {', '.join(TRANSFORMS)}")
    args = p.parse_args(argv)
    rep = Repertoire.default()
    trials = trials_of(args.set)
    base = {t.name: score(t, rep) for t in trials}
    counts = collections.Counter(r["verdict"] for rows in base.values() for r in rows)
    print(f"{len(trials)} trials as recorded: {dict(counts)}")
    changed: dict[str, list[str]] = {}
    for name in args.only or list(TRANSFORMS):
        changed[name] = []
        for trial in trials:
            rows = score(TRANSFORMS[name](trial), rep)
            if [r["verdict"] for r in rows] != [r["verdict"] for r in base[trial.name]]:
                changed[name].append(f"{trial.name}: {_line(base[trial.name])} -> {_line(rows)}")
        print(f"{name}: {len(changed[name])} of {len(trials)} trials changed", flush=True)
        for line in changed[name]:
            print("   " + line)
    return changed


if __name__ == "__main__":
    main()

"""Online settling on clips the settle rule was never chosen on, fed row by row.

Two sources (``--generator``), each fed row by row to
:class:`perception.online.OnlineRecognizer`; per condition it prints the
offline verdicts, how many settled before the scored movement's end, the median
``decision_fraction`` and how many settled verdicts equal the offline one:

* ``minvar`` (default): the minimum variance model's own demonstrations
  (``perception.synthetic.demos``: model paths -> camera -> tracks, no video),
  10 per condition, movement times 0.7-1.3 s, distances 0.20-0.35 m,
  25/30/60 frames/s (seed 5);
* ``sigma-lognormal``: the second generator's held-out set
  (:mod:`perception.synthetic.sigma_lognormal`, docs/generators.md; normal 30,
  delayed 10, open-close-open 10, reach 10, clip *k* drawn from seed 9000 + k,
  the same movements as ``tools/evaluate_verdict.py --generator
  sigma-lognormal --set heldout``) as in-memory tracks; ``--fast`` its fast
  held-out set (0.45-0.65 s, seeds 29000 + k).

The settling rule was never chosen on either. ``independent`` gives the same
figures on the independent generator's held-out population (the generator the
rules are tuned on, its held-out seeds), for the gap between the two::

    python tools/evaluate_online_demos.py
    python tools/evaluate_online_demos.py --generator sigma-lognormal [--fast]
    python tools/evaluate_online_demos.py --generator independent [--fast]

``--generator independent --set dev [--fast]`` gives its dev sets, the only
ones a settle rule may be chosen on.
"""

from __future__ import annotations

import argparse
import collections
import statistics
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tools"))

import evaluate_verdict as ev  # noqa: E402
from _demos import default_repertoire  # noqa: E402

from perception.online import OnlineRecognizer, decision_summary  # noqa: E402

CONDITIONS = ("normal", "delayed", "open-close-open", "reach")


def minvar_clips(per_condition: int = 10, seed: int = 5):
    """(condition, tracks) of the minimum variance model's own demonstrations."""
    from perception.synthetic.demos import demo_tracks

    rng = np.random.default_rng(seed)
    for cond in CONDITIONS:
        for k in range(per_condition):
            duration, distance = float(rng.uniform(0.7, 1.3)), float(rng.uniform(0.2, 0.35))
            fps = float(rng.choice([25.0, 30.0, 60.0]))
            yield cond, demo_tracks(cond, 100 + k, fps=fps, distance=distance,
                                    duration=duration)[0]


def set_clips(generator: str, fast: bool = False, counts: dict[str, int] | None = None,
              part: str = "heldout"):
    """(condition, tracks) of a generator's set in memory: the clips of
    ``tools/evaluate_verdict.py --generator GENERATOR --set [fast-]PART --source tracks``."""
    set_name = f"fast-{part}" if fast else part
    counts = ev.DEFAULT_COUNTS if counts is None else counts
    seed = ev.SETS[set_name]
    for cond in CONDITIONS:
        for _ in range(counts.get(cond, 0)):
            yield cond, ev.clip_tracks(generator, set_name, cond, seed)[0]
            seed += 1


def settle(clips) -> dict[str, list[tuple]]:
    """Each condition's (offline verdict, settled before the end, decision fraction, agrees)."""
    rep = default_repertoire()
    out: dict[str, list[tuple]] = collections.defaultdict(list)
    for cond, tracks in clips:
        rec = OnlineRecognizer(rep, markers=tracks.markers, tracker_attrs=dict(tracks.tracker))
        for i in range(tracks.n_frames):
            rec.update(tracks.position[i], tracks.time[i])
        final = rec.finish()
        s = decision_summary(final, rec.decision)
        out[cond].append((final.verdict, s["settled_before_end"], s["decision_fraction"],
                          s["agrees"]))
    return out


def report(out: dict[str, list[tuple]]) -> None:
    """Print one line per condition."""
    for cond, rows in out.items():
        print(f"{cond}: offline {dict(collections.Counter(r[0] for r in rows))}, settled before "
              f"the end {sum(r[1] for r in rows)}/{len(rows)}, decision_fraction median "
              f"{statistics.median(r[2] for r in rows):.2f}, settled = offline "
              f"{sum(r[3] for r in rows)}/{len(rows)}")


def main(argv: list[str] | None = None) -> dict[str, list[tuple]]:
    """Print (and return) each condition's (offline verdict, settled before the end,
    decision fraction, agrees) per clip."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--generator", choices=("minvar", *ev.GENERATORS), default="minvar",
                   help="the model's own demonstrations, or a generator's held-out set "
                        "(sigma-lognormal: never tuned on)")
    p.add_argument("--fast", action="store_true",
                   help="with a generator: its fast held-out set (0.45-0.65 s movements)")
    p.add_argument("--set", choices=("heldout", "dev"), default="heldout",
                   help="with the independent generator: its dev set (seeds 1000 + k, or "
                        "20000 + k with --fast), where the settle rule is chosen")
    args = p.parse_args(argv)
    if args.set == "dev" and args.generator != "independent":
        p.error("--set dev: the independent generator's only (the others are never tuned on)")
    clips = (minvar_clips() if args.generator == "minvar"
             else set_clips(args.generator, args.fast, part=args.set))
    out = settle(clips)
    report(out)
    return out


if __name__ == "__main__":
    main()

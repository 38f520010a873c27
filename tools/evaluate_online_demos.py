"""Online settling on the model's own demonstrations (the second generator), fed row by row.

``perception.synthetic.demos`` draws the minimum variance model's own movements
(model paths -> camera -> tracks, no video): 10 per condition, movement times
0.7-1.3 s, distances 0.20-0.35 m, 25/30/60 frames/s (seed 5). Each is fed row by row
to :class:`perception.online.OnlineRecognizer`; per condition it prints the
offline verdicts, how many settled before the scored movement's end, the median
``decision_fraction`` and how many settled verdicts equal the offline one. The
settling rule was never chosen on these::

    python tools/evaluate_online_demos.py
"""

from __future__ import annotations

import collections
import statistics
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from _demos import default_repertoire  # noqa: E402

from perception.online import OnlineRecognizer, decision_summary  # noqa: E402
from perception.synthetic.demos import demo_tracks  # noqa: E402

CONDITIONS = ("normal", "delayed", "open-close-open", "reach")


def main(per_condition: int = 10, seed: int = 5) -> dict[str, list[tuple]]:
    """Print (and return) each condition's (offline verdict, settled before the end,
    decision fraction, agrees) per clip."""
    rep = default_repertoire()
    rng = np.random.default_rng(seed)
    out: dict[str, list[tuple]] = collections.defaultdict(list)
    for cond in CONDITIONS:
        for k in range(per_condition):
            duration, distance = float(rng.uniform(0.7, 1.3)), float(rng.uniform(0.2, 0.35))
            fps = float(rng.choice([25.0, 30.0, 60.0]))
            tracks = demo_tracks(cond, 100 + k, fps=fps, distance=distance, duration=duration)[0]
            rec = OnlineRecognizer(rep, markers=tracks.markers, tracker_attrs=dict(tracks.tracker))
            for i in range(tracks.n_frames):
                rec.update(tracks.position[i], tracks.time[i])
            final = rec.finish()
            s = decision_summary(final, rec.decision)
            out[cond].append((final.verdict, s["settled_before_end"], s["decision_fraction"],
                              s["agrees"]))
    for cond, rows in out.items():
        print(f"{cond}: offline {dict(collections.Counter(r[0] for r in rows))}, settled before "
              f"the end {sum(r[1] for r in rows)}/{len(rows)}, decision_fraction median "
              f"{statistics.median(r[2] for r in rows):.2f}, settled = offline "
              f"{sum(r[3] for r in rows)}/{len(rows)}")
    return out


if __name__ == "__main__":
    main()

"""When does the online verdict settle, and does it agree with the offline one?

Renders a population of the independent generator (as
``tools/evaluate_verdict.py``: dev seeds 1000 + k, held-out seeds 9000 + k),
tracks each clip from video, feeds its tracked rows one by one to
:class:`perception.online.OnlineRecognizer` (the tracker is frame by frame,
so the rows are those ``hammer-mv watch`` tracks) and compares the first
settled verdict with the offline one (:meth:`OnlineRecognizer.finish`, which
is ``recognize``'s). Per condition it reports when the verdict settles —
``decision_time``, s after the movement's onset, and ``decision_fraction``,
of the scored movement (onset to end of activity) — and how often the
settled verdict differs from the offline one::

    python tools/evaluate_online.py --set dev -o out/eval-online/dev
    python tools/evaluate_online.py --set heldout -o out/eval-online/heldout

The settling rule (:class:`perception.online.SettleRule`) was chosen on the
dev set; ``--set heldout`` only reports. Writes ``OUT/evaluation.md`` and
``OUT/evaluation.json`` (per clip; the dev set's also every frame's
provisional state, for choosing the rule).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

from evaluate_verdict import (  # noqa: E402
    CONDITIONS,
    DEFAULT_COUNTS,
    EXPECTED,
    QUICK_COUNTS,
    SETS,
    parse_counts,
    set_seeds,
)


def online_clip(tracks, repertoire, clip: str, settle=None) -> dict:
    """Feed ``tracks`` row by row; the first settled verdict, the offline one and the timeline."""
    from perception.errors import InputError
    from perception.online import OnlineRecognizer, decision_summary

    rec = OnlineRecognizer(repertoire, clip=clip, markers=tracks.markers,
                           tracker_attrs=dict(tracks.tracker), settle=settle)
    timeline = []
    try:
        for i in range(tracks.n_frames):
            s = rec.update(tracks.position[i], tracks.time[i], int(tracks.frame[i]))
            if s.phase == "moving":
                timeline.append([round(s.since_onset, 4), round(s.progress, 4), s.verdict,
                                 s.verdict_detail, s.evidence if math.isfinite(s.evidence)
                                 else 1e9])
        offline = rec.finish()
    except InputError as exc:
        return {"clip": clip, "offline": "failed/refused", "error": exc.problem}
    return {"clip": clip, "offline": offline.verdict, **decision_summary(offline, rec.decision),
            "timeline": timeline}


def _median(values) -> str:
    v = [x for x in values if x is not None and math.isfinite(x)]
    return f"{np.median(v):.2f} ({min(v):.2f}–{max(v):.2f})" if v else "—"


def markdown(set_name: str, seeds: range, rows: list[dict]) -> str:
    """Decision fractions and agreement per condition, as markdown."""
    lines = [f"## Online verdict on the `{set_name}` population (seeds {seeds.start}–"
             f"{seeds.stop - 1}, {len(rows)} clips, tracked from video)", "",
             "`decision_fraction`: of the scored movement (onset to end of activity) when the "
             "verdict settled; `decision_time`: s after the onset; median (range). Settled before "
             "the end: clips whose verdict settled before the scored movement ended "
             "(the others settle on the final, offline, result). Agrees: the first settled "
             "verdict equals the offline verdict.", "",
             "| condition | n | offline right | settled before the end | decision_fraction "
             "| decision_time, s | agrees with offline |", "|---|---|---|---|---|---|---|"]
    pooled = {"all": CONDITIONS, "normal + reach": ("normal", "reach")}
    for cond in (*CONDITIONS, *pooled):
        sub = [r for r in rows if r["condition"] in pooled.get(cond, (cond,))]
        if not sub:
            continue
        ok = [r for r in sub if "settled_verdict" in r]
        right = sum(r["offline"] == EXPECTED[r["condition"]] for r in sub)
        early = sum(bool(r.get("settled_before_end")) for r in ok)
        agree = sum(bool(r["agrees"]) for r in ok)
        lines.append(f"| {cond} | {len(sub)} | {right} / {len(sub)} | {early} / {len(ok)} | "
                     f"{_median(r['decision_fraction'] for r in ok)} | "
                     f"{_median(r['decision_time'] for r in ok)} | {agree} / {len(ok)} "
                     f"({100 * agree / max(len(ok), 1):.0f} %) |")
    return "\n".join(lines) + "\n"


def run(set_name: str, out: Path, counts: dict[str, int], jobs: int = 2) -> str:
    """Render, track, recognise online; write and return the markdown."""
    from perception.io.tracks import Tracks
    from perception.recognition.repertoire import Repertoire
    from perception.synthetic.population import render_population_set
    from perception.tracking.video_tracks import track_video

    seeds = set_seeds(set_name, sum(counts.values()))
    t0 = time.perf_counter()
    manifest = render_population_set(out / "clips", counts, seed=seeds.start, jobs=jobs)
    rep = Repertoire.default()
    rows = []
    for _, m in manifest.iterrows():
        tracks = Tracks.load(track_video(out / "clips" / m["video"],
                                         out / "tracks" / f"{m['clip']}.tracks.h5"))
        row = {"condition": m["condition"], "fps": float(m["fps"]),
               "movement_time": float(m["movement_time"]),
               **online_clip(tracks, rep, m["clip"])}
        if set_name == "heldout":
            row.pop("timeline", None)
        rows.append(row)
    text = markdown(set_name, seeds, rows)
    text += f"\n{len(rows)} clips in {time.perf_counter() - t0:.0f} s.\n"
    (out / "evaluation.md").write_text(text, encoding="utf-8")
    (out / "evaluation.json").write_text(json.dumps({"set": set_name, "clips": rows}, indent=1)
                                         + "\n", encoding="utf-8")
    return text


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--set", choices=tuple(SETS), default="dev",
                   help="dev (seeds 1000 + k, for choosing the rule) or heldout (9000 + k)")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="OUT")
    p.add_argument("--per-condition", type=parse_counts, default=None, metavar="COUNTS",
                   help="clips per condition (default "
                        + ",".join(f"{k}={v}" for k, v in DEFAULT_COUNTS.items()) + ")")
    p.add_argument("--jobs", type=int, default=2, help="processes rendering the clips")
    p.add_argument("--quick", action="store_true", help="one clip per condition (a smoke run)")
    args = p.parse_args(argv)
    counts = QUICK_COUNTS if args.quick else args.per_condition or DEFAULT_COUNTS
    args.output.mkdir(parents=True, exist_ok=True)
    print(run(args.set, args.output, counts, args.jobs))
    return 0


if __name__ == "__main__":
    sys.exit(main())

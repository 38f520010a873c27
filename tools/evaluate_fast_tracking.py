"""How well the tracker keeps the digits of fast grasps filmed with motion blur.

Renders fast grasps (the healthy-adult population of the independent
generator with movement times of 0.45-0.65 s, as ``tools/evaluate_verdict.py
--set fast-dev`` draws them: clip *k* from ``default_rng(20000 + k)``, the
conditions in turn), at one frame rate and with a shutter open for
``--exposure`` s (motion blur: :class:`~perception.synthetic.scene.RenderStyle`
``exposure``), writes each as a video, tracks it with
:func:`perception.tracking.track_video` and scores it against the
renderer's ground truth, over the frames of the movement (onset to end):

* **both** — share of frames where thumb and finger are both placed within
  ``--tolerance`` px of the truth;
* per digit: **placed** (within the tolerance), **lost** (reported lost or
  ambiguous: NaN) and **wrong** (reported with likelihood >= 0.5 but more than
  ``--wrong`` px off: a confidently wrong position).

Prints one row per clip and the median over the clips; ``--json`` writes them.
With ``--generator sigma`` it draws from
:mod:`perception.synthetic.sigma_lognormal` instead (:func:`sigma_clip`: its
fast draws and filming, seeds 40000 + k, at ``--fps``); a digit that
generator hides is scored right when reported lost.

Run: ``.venv/bin/python tools/evaluate_fast_tracking.py [--clips 20] [--fps 30]
[--exposure 0.0333]``
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from perception.io.tracks import Tracks
from perception.synthetic.independent import independent_paths
from perception.synthetic.population import (
    POPULATION_RANGES,
    POPULATION_STYLE,
    draw_population,
    population_camera,
)
from perception.synthetic.render import render_clip
from perception.synthetic.scene import Camera, Occlusion, RenderStyle, Scene
from perception.tracking.params import TrackerParams
from perception.tracking.video_tracks import track_video

#: The fast sets' first seed and movement times (as tools/evaluate_verdict.py's fast-dev).
FAST_SEED = 20000
#: The sigma-lognormal generator's clips of this evaluation: its own seeds.
SIGMA_SEED = 40000
FAST_DURATION = (0.45, 0.65)
CONDITIONS = ("normal", "delayed", "open-close-open", "reach")
DIGITS = ("thumb", "finger")


@dataclasses.dataclass(frozen=True)
class ClipScore:
    """One clip's tracking figures over its movement's frames (shares, 0..1)."""

    clip: str
    frames: int
    both: float
    placed: dict[str, float]
    lost: dict[str, float]
    wrong: dict[str, float]
    peak_speed_px: float


def score(tracks: Tracks, truth: Tracks, frames: slice, *, tolerance: float = 5.0,
          wrong_px: float = 10.0, visible: np.ndarray | None = None) -> dict:
    """Shares of ``frames`` where each digit is placed, lost, confidently wrong.

    Parameters
    ----------
    tracks, truth : Tracks
        The tracker's output and the renderer's ground truth (same frames).
    frames : slice
        The frames scored (the movement).
    tolerance : float
        A digit within this many px of the truth is placed.
    wrong_px : float
        A digit reported with likelihood >= 0.5 further than this is wrong.
    visible : (T, M) bool, optional
        Which markers were drawn (the truth file's ``/truth/visible``): a
        hidden digit is right when reported lost and wrong when placed with
        likelihood >= 0.5; ``both`` counts the frames where both are drawn.
    """
    out: dict = {"placed": {}, "lost": {}, "wrong": {}}
    n = len(range(*frames.indices(len(tracks.position))))
    ok_all, both_shown = np.ones(n, bool), np.ones(n, bool)
    for name in DIGITS:
        j, k = tracks.markers.index(name), truth.markers.index(name)
        err = np.linalg.norm(tracks.position[frames, j] - truth.position[frames, k], axis=-1)
        shown = (np.ones(len(err), bool) if visible is None else visible[frames, k])
        lost = ~np.isfinite(err)
        placed = (err <= tolerance) & shown
        sure = tracks.likelihood[frames, j] >= 0.5
        out["placed"][name] = float(placed[shown].mean()) if shown.any() else 1.0
        out["lost"][name] = float((lost & shown).mean())
        out["wrong"][name] = float((sure & ~lost & ((err > wrong_px) | ~shown)).mean())
        ok_all &= placed
        both_shown &= shown
    out["both"] = float(ok_all[both_shown].mean()) if both_shown.any() else 1.0
    return out


@dataclasses.dataclass(frozen=True)
class FastClip:
    """One fast clip to render: its paths (m), camera, look and movement frames."""

    name: str
    paths: dict
    camera: Camera
    object_size: float
    style: RenderStyle
    onset: int
    end: int


def population_clip(k: int, fps: float, exposure: float, duration: tuple[float, float],
                    motion_samples: int = 15) -> FastClip:
    """Clip ``k`` of the fast population (conditions in turn) at ``fps``, shutter ``exposure``."""
    cond = CONDITIONS[k % len(CONDITIONS)]
    rng = np.random.default_rng(FAST_SEED + k)
    draw = draw_population(cond, rng, ranges={**POPULATION_RANGES, "duration": duration},
                           fps_choices=(fps,))
    p = draw.params
    _, paths = independent_paths(p, fps, seed=rng)
    style = dataclasses.replace(POPULATION_STYLE, fps=fps, exposure=exposure,
                                motion_samples=motion_samples)
    return FastClip(f"{cond}-{k:02d}", paths, population_camera(draw), p.object_size, style,
                    int(round(p.rest_before * fps)),
                    int(round((p.rest_before + p.duration) * fps)) + 1)


def sigma_clip(k: int, fps: float, exposure: float, duration: tuple[float, float],
               motion_samples: int = 15) -> FastClip:
    """Clip ``k`` of the sigma-lognormal generator's fast draws, at ``fps``.

    Its own filming (scale, noise, optical blur, lighting) and its own digit
    dropouts (drawn hidden); the movement time drawn from ``duration`` and the
    shutter ``exposure`` (negative: the generator's own share of the frame).
    """
    from perception.synthetic.sigma_lognormal import sigma_lognormal_paths
    from perception.synthetic.sigma_lognormal_clips import draw_sigma_lognormal_clip

    cond = CONDITIONS[k % len(CONDITIONS)]
    rng = np.random.default_rng(SIGMA_SEED + k)
    clip = draw_sigma_lognormal_clip(cond, rng, fast=True)
    p = dataclasses.replace(clip.params, duration=float(rng.uniform(*duration)))
    _, paths = sigma_lognormal_paths(p, fps, seed=rng)
    hidden = tuple(Occlusion(marker=m, start=int(i), stop=int(i) + 1)
                   for m in DIGITS for i in np.flatnonzero(paths["dropped"][m]))
    share = clip.style.exposure * clip.fps
    style = dataclasses.replace(clip.style, fps=fps, occlusions=hidden,
                                exposure=share / fps if exposure < 0 else exposure,
                                motion_samples=motion_samples)
    return FastClip(f"sigma-{cond}-{k:02d}", paths, clip.camera, p.object_size, style,
                    int(round(p.rest_before * fps)),
                    int(round((p.rest_before + p.duration) * fps)) + 1)


def evaluate(n_clips: int, fps: float, exposure: float, *, generator: str = "population",
             duration: tuple[float, float] = FAST_DURATION, tolerance: float = 5.0,
             params: TrackerParams | None = None, out: Path | None = None) -> list[ClipScore]:
    """Render, track and score ``n_clips`` fast clips; one :class:`ClipScore` each."""
    make = population_clip if generator == "population" else sigma_clip
    scores = []
    with tempfile.TemporaryDirectory(prefix="fast_tracking_") as tmp:
        d = Path(tmp) if out is None else out
        for k in range(n_clips):
            c = make(k, fps, exposure, duration)
            scene = Scene(wrist=c.paths["wrist"], finger=c.paths["finger"],
                          thumb=c.paths["thumb"], object_diameter=c.object_size)
            res = render_clip(scene, c.camera, c.style, d / f"{c.name}.mp4", seed=FAST_SEED + k)
            tracks = Tracks.load(track_video(res.video, d / f"{c.name}.tracks.h5",
                                             params=params))
            truth = Tracks.load(res.truth)
            with h5py.File(res.truth, "r") as f:
                visible = f["truth/visible"][()]
            s = score(tracks, truth, slice(c.onset, c.end), tolerance=tolerance,
                      visible=visible)
            px = np.stack([c.camera.world_to_pixel(c.paths[m]) for m in DIGITS])
            speed = float(np.linalg.norm(np.diff(px, axis=1), axis=-1).max())
            scores.append(ClipScore(c.name, c.end - c.onset, s["both"], s["placed"], s["lost"],
                                    s["wrong"], speed))
    return scores


def _pct(x: float) -> str:
    return f"{100 * x:5.1f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clips", type=int, default=20, help="clips (conditions in turn)")
    ap.add_argument("--fps", type=float, default=30.0, help="frame rate, frames/s")
    ap.add_argument("--exposure", type=float, default=1 / 30,
                    help="shutter time, s (sigma: negative keeps the generator's own share)")
    ap.add_argument("--duration", type=float, nargs=2, default=FAST_DURATION,
                    metavar=("LOW", "HIGH"), help="movement times drawn from, s")
    ap.add_argument("--tolerance", type=float, default=5.0, help="placed within this, px")
    ap.add_argument("--generator", choices=("population", "sigma"), default="population")
    ap.add_argument("--json", type=Path, help="write the per-clip figures here")
    ap.add_argument("--quiet", action="store_true", help="print the summary line only")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    scores = evaluate(args.clips, args.fps, args.exposure, generator=args.generator,
                      duration=tuple(args.duration), tolerance=args.tolerance)
    dt = time.perf_counter() - t0
    if not args.quiet:
        print(f"{'clip':<22} {'frames':>6} {'peak px/fr':>10} {'both %':>7} "
              + " ".join(f"{d + ' ok/lost/wrong %':>24}" for d in DIGITS))
        for s in scores:
            cells = " ".join(f"{_pct(s.placed[d])}/{_pct(s.lost[d])}/{_pct(s.wrong[d]):>6}"
                             .rjust(24) for d in DIGITS)
            print(f"{s.clip:<22} {s.frames:>6} {s.peak_speed_px:>10.1f} {_pct(s.both):>7} "
                  + cells)
    both = [s.both for s in scores]
    wrong = [max(s.wrong.values()) for s in scores]
    lost = [max(s.lost.values()) for s in scores]
    lo, hi = args.duration
    print(f"{args.generator} fast clips, {len(scores)} of {lo:g}-{hi:g} s at {args.fps:g} fps, "
          f"exposure {args.exposure:.4f} s: both digits within {args.tolerance:g} px on a median "
          f"{100 * statistics.median(both):.1f} % of the movement's frames (min "
          f"{100 * min(both):.1f} %, clips >= 90 %: {sum(b >= 0.9 for b in both)}/{len(both)}); "
          f"lost median {100 * statistics.median(lost):.1f} %; confidently wrong: "
          f"{sum(w > 0 for w in wrong)} clips, {100 * max(wrong):.1f} % of frames at most "
          f"({dt:.0f} s)")
    if args.json:
        args.json.write_text(json.dumps([dataclasses.asdict(s) for s in scores], indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())

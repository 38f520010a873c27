"""How tracking noise moves the landmarks: the field's definitions at 0.4-3 px of jitter.

Normal grasps of the independent generator (published human kinematics, not
the minimum variance model; 30 frames/s, a 3 cm object), tracked with
0.4, 1, 2 and 3 px of noise (DeepLabCut's typical error on a 640 px frame
is 1-3 px), observed and measured; the truth is the same definitions
applied to the generator's own noise-free marker paths::

    python tools/landmark_noise.py [--clips 12]

Prints a markdown table: per noise level, the clips refused (no still start
found) and the mean and largest error of each landmark.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from perception.errors import InputError
from perception.landmarks import movement_landmarks, observed_landmarks
from perception.observation import ObserveParams, observe
from perception.synthetic.independent import IndependentParams, independent_tracks

NAMES = ("movement_time", "peak_speed_time", "mga_time", "opening_time", "mga")


def measure(noise: float, clips: int) -> tuple[int, dict[str, np.ndarray]]:
    errors: dict[str, list[float]] = {k: [] for k in NAMES}
    refused = 0
    for seed in range(clips):
        p = IndependentParams(condition="normal", object_size=0.03)
        tracks, truth = independent_tracks(p, seed, noise_px=noise)
        w = truth["world"]
        want = movement_landmarks(tracks.time, w["wrist"],
                                  np.linalg.norm(w["finger"] - w["thumb"], axis=1))
        try:
            got = observed_landmarks(observe(tracks, ObserveParams(object_diameter=0.03)))
        except InputError:
            refused += 1
            continue
        for k in NAMES:
            errors[k].append(getattr(got, k) - getattr(want, k))
    return refused, {k: np.array(v) for k, v in errors.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--clips", type=int, default=12)
    args = ap.parse_args(argv)
    print("| noise | refused | " + " | ".join(NAMES) + " |")
    print("|---" * (len(NAMES) + 2) + "|")
    for noise in (0.4, 1.0, 2.0, 3.0):
        refused, err = measure(noise, args.clips)
        cells = []
        for k in NAMES:
            e = err[k][np.isfinite(err[k])]
            scale, unit = (1000, " mm") if k == "mga" else (1, " s" if k == "movement_time" else "")
            cells.append(f"{np.mean(e) * scale:+.3f} ({np.abs(e).max() * scale:.3f}){unit}"
                         if len(e) else "—")
        print(f"| {noise} px | {refused} / {args.clips} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

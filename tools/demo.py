"""`make demo`: the reaching demo of thesis chapter 3 (until the video pipeline lands).

Writes the point-to-point reach (Fig. 3.4), the 's' via-point movement (Fig. 3.6)
and the speed-accuracy sweep (Fig. 3.5) under out/demo/ and prints where they are.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from perception.cli import main  # noqa: E402


def run() -> int:
    out = ROOT / "out" / "demo"
    steps = [
        ["reach", "--trials", "100", "-o", str(out / "reach")],
        ["reach", "--start", "-0.2", "0.5", "--goal", "-0.4", "0.2", "--duration", "1",
         "--via", "-0.4", "0.4", "0.25", "--via", "-0.2", "0.3", "0.75", "-o", str(out / "s")],
        ["reach", "--sweep", "-o", str(out / "speed_accuracy")],
    ]
    for argv in steps:
        status = main(argv)
        if status:
            return status
    print(f"\ndemo figures: {out}/reach/reach.png, {out}/s/reach.png, "
          f"{out}/speed_accuracy/speed_accuracy.png")
    return 0


if __name__ == "__main__":
    sys.exit(run())

"""Regenerate the thesis's figures and its claims table: ``python -m tools.thesis``.

    python tools/reproduce_thesis.py [-o out/thesis] [--trials N] [--seed N] [--quick]
                                     [--skip-ch4] [--skip-ch5] [--skip-verdict] [--jobs N]

The command ``make reproduce`` runs; everything is in :mod:`tools.thesis`.
"""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tools.thesis.cli import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())

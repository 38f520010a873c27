"""``python -m tools.thesis``: see :mod:`tools.thesis.cli`."""

import sys

from tools.thesis.cli import main

sys.exit(main())

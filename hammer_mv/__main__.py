"""``python -m hammer_mv``: the ``hammer-mv`` command."""

import sys

from hammer_mv.cli import entry

sys.exit(entry())

"""``python -m hammer_mv``: the ``hammer-mv`` command."""

import gc
import sys

gc.disable()  # while the command's modules import (hammer_mv.cli.entry)

from hammer_mv.cli import entry  # noqa: E402

sys.exit(entry())

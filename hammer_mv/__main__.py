"""``python -m hammer_mv``: the ``hammer-mv`` command."""

import sys

from hammer_mv.cli import main

sys.exit(main())

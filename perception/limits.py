"""Sizes the perception side believes, checked before anything is allocated.

A number from a header, a recipe or a flag decides how much memory and time
a command takes; an absurd one (a header claiming a billion frames per
second, a recipe asking for a day of rest) must end in one clear line, not
in a MemoryError or the kernel's OOM killer. Each limit is far beyond what a
grasp experiment needs and says why in its comment; docs/recipes.md and the
README's "Bad input" section list them.
"""

from __future__ import annotations

__all__ = ["MAX_CLIPS", "MAX_FPS", "MAX_FRAME_SIDE", "MAX_REST_S"]

#: Highest frame rate believed from a header or accepted from a recipe or
#: ``--fps``, frames/s: high-speed cameras filming reaches run at 100-500.
MAX_FPS = 1000.0
#: Longest side of a rendered frame, px (4K is 3840): one frame of 4096 x
#: 4096 is already 48 MB in memory.
MAX_FRAME_SIDE = 4096
#: Longest rest before or after a synthetic movement, s: the tracker needs
#: a few frames of rest; a minute of it is a minute of video per clip.
MAX_REST_S = 60.0
#: Most clips one recipe renders.
MAX_CLIPS = 10_000

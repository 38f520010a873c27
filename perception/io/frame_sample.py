"""A few frames of a video kept while it is read for something else.

Tracking decodes every frame of a clip; the clip report's contact sheet
shows six of them. Keeping every ``stride``-th frame as tracking passes
spares the sheet a second decode of the whole clip (a tenth of a clip's
time in a batch). A budget bounds the memory: the stride grows with the
clip's length and frame size.
"""

from __future__ import annotations

import math

import numpy as np


class FrameSample:
    """Every ``stride``-th frame of a video, the first included, in memory.

    Parameters
    ----------
    max_frames : int
        Frames kept at most.
    max_bytes : int
        Memory the kept frames may take, bytes.

    Attributes
    ----------
    stride : int
        Frames between two kept ones (set by :meth:`start`).
    frames : dict of int to ndarray
        Kept frames by frame index.
    """

    def __init__(self, max_frames: int = 24, max_bytes: int = 48 << 20):
        if max_frames < 1 or max_bytes < 1:
            raise ValueError(f"FrameSample: expected a positive budget, got max_frames="
                             f"{max_frames}, max_bytes={max_bytes}")
        self.max_frames = int(max_frames)
        self.max_bytes = int(max_bytes)
        self.stride = 1
        self._room = self.max_frames  # frames the budget holds, set by start()
        self.frames: dict[int, np.ndarray] = {}

    def start(self, n_frames: int, frame_bytes: int) -> None:
        """Choose the stride for a video of ``n_frames`` (0: unknown) frames of
        ``frame_bytes`` each, and forget frames kept before."""
        self._room = max(1, min(self.max_frames, self.max_bytes // max(frame_bytes, 1)))
        self.stride = max(1, math.ceil(n_frames / self._room)) if n_frames > 0 else 1
        self.frames = {}

    def offer(self, index: int, frame: np.ndarray) -> None:
        """Keep ``frame`` if ``index`` is on the stride and the budget allows.

        The array itself is kept, not a copy: a decoder yields a new array
        per frame and nothing writes into it.
        """
        if index % self.stride == 0 and len(self.frames) < self._room:
            self.frames[int(index)] = frame

    def nearest(self, index: int) -> int | None:
        """The kept frame closest to ``index``, if one is within half a stride of it.

        None when nothing near was kept (the budget ran out before the end of
        a video whose header undercounts its frames, or nothing was offered).
        """
        if not self.frames:
            return None
        best = min(self.frames, key=lambda k: (abs(k - index), k))
        return best if abs(best - index) <= self.stride // 2 else None

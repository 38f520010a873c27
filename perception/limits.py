"""Sizes the perception side believes, checked before anything is allocated.

A number from a header, a recipe or a flag decides how much memory and time
a command takes; an absurd one (a header claiming a billion frames per
second, a recipe asking for a day of rest, a tracks file claiming a billion
rows) must end in one clear line, not in a MemoryError or the kernel's OOM
killer. Each limit is far beyond what a grasp experiment needs and says why
in its comment; docs/recipes.md and the README's "Bad input" section list them.
"""

from __future__ import annotations

__all__ = ["MAX_CLIPS", "MAX_FPS", "MAX_FRAMES", "MAX_FRAME_SIDE", "MAX_GAIN", "MAX_HDF5_VALUES",
           "MAX_KEYPOINTS", "MAX_MARKERS", "MAX_POSE_POINTS", "MAX_REST_S", "MAX_SUBSTEPS",
           "MAX_VIDEO_PIXELS", "MAX_VIDEO_SIDE", "MIN_FPS", "POSITION_MARGIN"]

#: Highest frame rate accepted from a recipe or ``--fps``, frames/s:
#: high-speed cameras filming reaches run at 100-500. A container header must
#: claim *less*: 1000 is what a Matroska or MP4 millisecond time base reports
#: when the stream states no rate of its own.
MAX_FPS = 1000.0
#: Lowest frame rate believed from a header, frames/s: no reach is filmed
#: slower; FFmpeg reads a header rate of 0 as 25, so such headers are refused
#: where the container can be checked (AVI) and otherwise need ``--fps``.
MIN_FPS = 1.0
#: Longest side of a rendered frame, px (4K is 3840): one frame of 4096 x
#: 4096 is already 48 MB in memory.
MAX_FRAME_SIDE = 4096
#: Longest side of a video read, px (8K is 7680), and most pixels in one of
#: its frames (8K UHD): a decoder holds several frames, each 3 bytes a pixel.
MAX_VIDEO_SIDE = 8192
MAX_VIDEO_PIXELS = 7680 * 4320
#: Most frames in one tracks or pose file: an hour at 500 frames/s.
MAX_FRAMES = 2_000_000
#: Most markers in one tracks file (hammer-mv tracks 4; DeepLabCut's PyTables
#: table holds at most about 500 markers of 3 columns).
MAX_MARKERS = 256
#: Most keypoints in one pose file (body models of DeepLabCut and SLEAP have
#: tens).
MAX_KEYPOINTS = 1000
#: Most points (frames x keypoints x individuals) read from one pose file:
#: 16 bytes each for x and y, so at most 800 MB.
MAX_POSE_POINTS = 50_000_000
#: Most values read from one HDF5 dataset we did not write (8 bytes each:
#: at most 800 MB); a file claiming more is refused before anything is read.
MAX_HDF5_VALUES = 100_000_000
#: How far outside its frame a tracked position may lie, in frame sizes:
#: DeepLabCut extrapolates a little beyond the image; a position of 1e20 px
#: is a corrupt file.
POSITION_MARGIN = 1.0
#: Largest magnitude of a stored gain or dynamics entry of a repertoire model:
#: planned gains are of order 1e3 at most; 1e200 overflows every prediction.
MAX_GAIN = 1e9
#: Most model steps per video frame (10 ms steps at 1 frame/s is 100).
MAX_SUBSTEPS = 1000
#: Longest rest before or after a synthetic movement, s: the tracker needs
#: a few frames of rest; a minute of it is a minute of video per clip.
MAX_REST_S = 60.0
#: Most clips one recipe renders.
MAX_CLIPS = 10_000

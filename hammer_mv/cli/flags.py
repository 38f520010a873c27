"""Flags several commands share that need nothing heavy to declare (``track --help`` stays fast)."""

from __future__ import annotations

import argparse

#: Help of ``--fps``; the recognition commands add what it means for pose files.
FPS_HELP = ("true frame rate, frames/s (default: the file's own): for videos whose header is "
            "wrong")


def add_video_options(p: argparse.ArgumentParser, *, fps: bool = True) -> None:
    """Add the options that say how to read a damaged or mislabelled video.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    fps : bool
        Add ``--fps`` too (the recognition commands have it among the pose options).
    """
    g = p.add_argument_group("videos")
    g.add_argument("--keep-truncated", action="store_true",
                   help="track the frames a truncated or damaged video decodes instead of "
                        "refusing it")
    if fps:
        g.add_argument("--fps", type=float, default=None, metavar="F", help=FPS_HELP)

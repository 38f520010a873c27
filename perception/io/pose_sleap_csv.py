"""SLEAP's analysis CSV -> a ``movement`` poses dataset.

SLEAP writes it with "Export Analysis CSV" (and ``sleap-convert --format
analysis.csv``; ``sleap.info.write_tracking_h5``): one row per instance seen,
the frames without one left out::

    track,frame_idx,instance.score,thumb.x,thumb.y,thumb.score,index.x,...
    mouse1,0,0.97,205.93,187.89,0.91,278.64,...
    ,1,0.95,206.10,188.02,0.90,278.80,...      <- no track: the tracker did not run

``movement`` (0.15) reads SLEAP's analysis HDF5 and labels files, not this
table: the positions are laid out here as its SLEAP reader lays them out
(frames from the video's first, a NaN where a frame holds no instance).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from perception.errors import InputError

__all__ = ["UNTRACKED", "is_sleap_csv", "sleap_csv_dataset"]

#: The columns a SLEAP analysis CSV opens with.
_OPENING = ("track", "frame_idx", "instance.score")
#: The individual of rows without a track.
UNTRACKED = "untracked"


def is_sleap_csv(first_line: str) -> bool:
    """Whether a CSV file's first line is the header of SLEAP's analysis CSV.

    Parameters
    ----------
    first_line : str
        The line.
    """
    return tuple(c.strip().strip('"') for c in first_line.split(",")[:3]) == _OPENING


def sleap_csv_dataset(path: Path, fps: float | None):
    """The table as a ``movement`` poses dataset (x, y and score of each node, per track).

    Parameters
    ----------
    path : Path
        The CSV file.
    fps : float, optional
        The video's frame rate (the table holds none).

    Raises
    ------
    InputError
        A node without its x, y and score, frame numbers that are not whole
        numbers from 0, or a frame holding two instances of one track (or two
        without a track: which is which cannot be told).
    """
    import pandas as pd

    from perception.io.movement_import import movement_loaders

    _, load_poses = movement_loaders()  # movement imported as the other pose readers do
    df = pd.read_csv(path)
    nodes = [c[:-2] for c in df.columns[3:] if c.endswith(".x")]
    bad = next((n for n in nodes if f"{n}.y" not in df or f"{n}.score" not in df), None)
    if not nodes or bad is not None:
        raise InputError(f"a SLEAP analysis CSV whose node {bad!r} lacks its .y or .score "
                         "column" if bad else "a SLEAP analysis CSV naming no node (NODE.x, "
                         "NODE.y, NODE.score)", path)
    frame = pd.to_numeric(df["frame_idx"], errors="coerce").to_numpy()
    if len(frame) == 0 or not np.isfinite(frame).all() or (frame < 0).any() \
            or (frame != np.round(frame)).any():
        raise InputError("frame_idx: expected the frames' numbers, whole numbers from 0", path)
    track = df["track"].fillna("").astype(str).str.strip().replace("", UNTRACKED).to_numpy()
    twice = pd.DataFrame({"track": track, "frame": frame}).duplicated().to_numpy()
    if twice.any():
        row = int(np.argmax(twice))
        what = ("instances without a track: which is which from frame to frame is not known; "
                "track them in SLEAP" if track[row] == UNTRACKED else
                f"instances of track {track[row]!r}")
        raise InputError(f"frame {int(frame[row])} holds two {what}", path)
    who, names = pd.factorize(track)  # the tracks in the order they first appear
    names = list(names)
    frame = frame.astype(int)
    position = np.full((frame.max() + 1, 2, len(nodes), len(names)), np.nan)
    confidence = np.full((frame.max() + 1, len(nodes), len(names)), np.nan)
    for k, node in enumerate(nodes):
        position[frame, 0, k, who] = pd.to_numeric(df[f"{node}.x"], errors="coerce")
        position[frame, 1, k, who] = pd.to_numeric(df[f"{node}.y"], errors="coerce")
        confidence[frame, k, who] = pd.to_numeric(df[f"{node}.score"], errors="coerce")
    return load_poses.from_numpy(position, confidence, individual_names=names,
                                 keypoint_names=nodes, fps=fps, source_software="SLEAP")

"""``hammer-mv track``'s summary line, read from the datasets it needs (issue 45 item 5).

The line used to load the whole tracks file (:meth:`Tracks.load`, 10 ms at
the end of every run); it now reads the markers, positions and statuses
only, and must say what the loaded file says.
"""

from __future__ import annotations

import numpy as np
import pytest

from hammer_mv.cli.track import summary_line
from perception.io.tracks import Status, Tracks


def _line_from_tracks(path) -> str:
    """The summary as it was written, from the whole loaded file."""
    tracks = Tracks.load(path)
    found = ", ".join(
        f"{name} {100 * tracks.valid[:, j].mean():.0f} %"
        + (f" ({int(n)} frames ambiguous)"
           if (n := (tracks.status[:, j] == Status.AMBIGUOUS).sum()) else "")
        for j, name in enumerate(tracks.markers)
    )
    return f"{path}: {tracks.n_frames} frames; found {found}"


def _tracks(n: int) -> Tracks:
    """Four markers over ``n`` frames: lost, ambiguous (no position) and half-placed spans."""
    rng = np.random.default_rng(3)
    position = rng.uniform(0, 600, (n, 4, 2))
    likelihood = np.ones((n, 4), np.float32)
    status = np.full((n, 4), Status.TRACKED, np.int8)
    position[: n // 3, 0] = np.nan  # thumb lost for a third
    status[: n // 3, 0] = Status.LOST
    position[: n // 4, 1] = np.nan  # finger ambiguous at first
    status[: n // 4, 1] = Status.AMBIGUOUS
    position[n // 2 :, 2, 1] = np.nan  # one coordinate missing still counts as lost
    status[n // 2 :, 2] = Status.LOST
    status[5:9, 3] = Status.REACQUIRED
    likelihood[np.isnan(position).any(axis=-1)] = 0
    return Tracks(np.arange(n), np.arange(n) / 30.0, ("thumb", "finger", "wrist", "object"),
                  position, likelihood, status,
                  video={"path": "clip.mp4", "fps_nominal": 30.0, "n_frames": n, "width": 640,
                         "height": 480, "fourcc": "FMP4", "sha256": "ab" * 32},
                  tracker={"method": "test"})


@pytest.mark.parametrize("n", [1, 7, 100])
def test_summary_line_says_what_the_loaded_file_says(tmp_path, n):
    path = _tracks(n).save(tmp_path / "clip.tracks.h5")
    line = summary_line(path)
    assert line == _line_from_tracks(path)
    if n == 100:
        assert line == (f"{path}: 100 frames; found thumb 67 %, finger 75 % (25 frames "
                        "ambiguous), wrist 50 %, object 100 %")

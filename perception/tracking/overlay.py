"""Markers drawn on frames: labelled videos and contact-sheet tiles.

Every marker is drawn in its own colour at its tracked position with its name
and likelihood and a short trail of its recent positions; a lost marker is a
grey cross at its last known position, an ambiguous one a question mark; a
legend in the corner lists every marker's state, so a frame shows at a glance
what the tracker saw (the counterpart of DeepLabCut's labelled videos).
"""

from __future__ import annotations

import json
import os
from collections import deque
from pathlib import Path

import cv2
import numpy as np

from perception.errors import InputError
from perception.io.files import input_file, sha256_file
from perception.io.tracks import Status, Tracks
from perception.io.video import FrameSource, VideoWriter

__all__ = ["Labeller", "render_labelled", "tracked_video"]

_GREY = (160, 160, 160)
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def _text(img: np.ndarray, text: str, org: tuple[int, int], colour, scale: float) -> None:
    """Text with a dark outline, legible on any background."""
    cv2.putText(img, text, org, _FONT, scale, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(img, text, org, _FONT, scale, colour, 1, cv2.LINE_AA)


class Labeller:
    """Draws markers on successive frames, keeping each marker's trail.

    Parameters
    ----------
    names : sequence of str
        Marker names, in column order.
    colours : sequence of (int, int, int)
        BGR drawing colour of each marker.
    trail : int
        Frames of trail behind each marker.
    """

    def __init__(self, names, colours, trail: int = 12):
        self.names = tuple(names)
        self.colours = tuple(tuple(int(c) for c in bgr) for bgr in colours)
        self.trails = [deque(maxlen=max(trail, 1)) for _ in self.names]
        self.last = [None] * len(self.names)

    def draw(self, frame: np.ndarray, position: np.ndarray, likelihood: np.ndarray,
             status: np.ndarray) -> np.ndarray:
        """A copy of ``frame`` with the markers of this frame drawn on it.

        Parameters
        ----------
        frame : (H, W, 3) uint8
            BGR frame.
        position : (M, 2) float
            px; NaN where lost or ambiguous.
        likelihood : (M,) float
            0..1.
        status : (M,) int
            :class:`~perception.io.tracks.Status` codes.
        """
        img = frame.copy()
        scale = max(img.shape[0] / 720, 0.35)
        for j, name in enumerate(self.names):
            ok = bool(np.isfinite(position[j]).all())
            trail = self.trails[j]
            trail.append(tuple(position[j]) if ok else None)
            pts = [p for p in trail if p is not None]
            for a, b in zip(pts, pts[1:]):
                cv2.line(img, (round(a[0]), round(a[1])), (round(b[0]), round(b[1])),
                         self.colours[j], 1, cv2.LINE_AA)
            if ok:
                self.last[j] = tuple(position[j])
                c = (round(position[j, 0]), round(position[j, 1]))
                weak = likelihood[j] < 0.5
                cv2.circle(img, c, max(round(10 * scale), 4), _GREY if weak else self.colours[j],
                           1 if weak else 2, cv2.LINE_AA)
                _text(img, f"{name} {likelihood[j]:.2f}", (c[0] + 8, c[1] - 8),
                      self.colours[j], 0.5 * scale + 0.15)
            elif self.last[j] is not None:
                x, y = (round(v) for v in self.last[j])
                r = max(round(7 * scale), 3)
                cv2.line(img, (x - r, y - r), (x + r, y + r), _GREY, 2, cv2.LINE_AA)
                cv2.line(img, (x - r, y + r), (x + r, y - r), _GREY, 2, cv2.LINE_AA)
            self._legend(img, j, name, status[j], likelihood[j], scale)
        return img

    def _legend(self, img, j: int, name: str, status: int, lik: float, scale: float) -> None:
        state = {Status.LOST: "LOST", Status.AMBIGUOUS: "AMBIGUOUS ?"}.get(int(status))
        text = f"{name}: {state}" if state else f"{name}: {lik:.2f}"
        line = max(round(22 * scale), 12)
        _text(img, text, (8, line * (j + 1)), _GREY if state else self.colours[j],
              0.55 * scale + 0.15)


def _colours(tracks: Tracks) -> list[tuple[int, int, int]]:
    """Each marker's drawing colour: its colour model's ``bgr``, else a default palette."""
    try:
        models = json.loads(tracks.tracker.get("colour_models", "{}"))
    except (TypeError, ValueError):
        models = {}
    if not isinstance(models, dict):
        models = {}
    palette = [(60, 60, 230), (60, 200, 60), (230, 120, 40), (40, 210, 230), (200, 60, 200)]
    colours = []
    for j, m in enumerate(tracks.markers):
        model = models.get(m)
        bgr = model.get("bgr") if isinstance(model, dict) else None
        ok = (isinstance(bgr, list | tuple) and len(bgr) == 3
              and all(isinstance(c, int) and 0 <= c <= 255 for c in bgr))
        colours.append(tuple(bgr) if ok else palette[j % len(palette)])
    return colours


def tracked_video(tracks: Tracks, video: str | os.PathLike | None = None) -> Path:
    """The video ``tracks`` were tracked from, checked to be that very file.

    Parameters
    ----------
    tracks : Tracks
        The tracks; their ``/video`` ``path`` is the default (a relative
        one is looked for beside the tracks file, then in the working
        folder), and their ``sha256``, if recorded, must match the video's.
    video : str or os.PathLike, optional
        The video the user named instead.

    Raises
    ------
    InputError
        No video given or recorded, not a regular file, or a file whose
        SHA-256 differs from the one the tracks record.
    """
    field = "VIDEO" if video is not None else "/video.path"
    if video is None:
        stored = tracks.video.get("path")
        if not stored:
            raise InputError("the tracks name no video: give the VIDEO", tracks.path)
        video = Path(stored)
        if not video.is_absolute() and tracks.path is not None:
            # written relative to the folder the tracker ran in, which may be
            # this one; the SHA-256 below tells whether it is the right file
            beside = Path(tracks.path).parent / video
            video = beside if beside.exists() or not video.exists() else video
    video = input_file(video, "video")
    sha = tracks.video.get("sha256")
    if sha:
        try:
            digest = sha256_file(video)
        except OSError as exc:
            raise InputError(f"cannot read the video: {exc.strerror or exc}", video) from None
        if digest != str(sha).lower():
            raise InputError(f"not the tracked video: its SHA-256 is {digest[:12]}..., the "
                             f"tracks ({tracks.path}) record {str(sha)[:12]}...; give the "
                             "video they were tracked from", video, field=field)
    return video


def render_labelled(tracks: Tracks, video: str | os.PathLike | None,
                    out: str | os.PathLike, *, trail: int = 12) -> Path:
    """Write a labelled copy of a tracked video (atomically).

    Parameters
    ----------
    tracks : Tracks
        The tracks (their ``frame`` indices pick the rows of each frame).
    video : str or os.PathLike, optional
        The video they come from (default: ``/video`` ``path`` of the tracks).
    out : str or os.PathLike
        Output video (``.mp4``, ``.avi`` or ``.mkv``).
    trail : int
        Frames of trail behind each marker.

    Raises
    ------
    InputError
        No video given or recorded, a video other than the tracked one (its
        SHA-256 differs), or a video with fewer frames than the tracks.
    """
    video = tracked_video(tracks, video)
    row = {int(f): i for i, f in enumerate(tracks.frame)}
    labeller = Labeller(tracks.markers, _colours(tracks), trail)
    nan = np.full((len(tracks.markers), 2), np.nan)
    lost = np.full(len(tracks.markers), Status.LOST)
    zeros = np.zeros(len(tracks.markers))
    with FrameSource(video, hash=False) as src:
        fps = src.info.fps_nominal or 30.0
        with VideoWriter(out, fps, (src.info.width, src.info.height)) as vw:
            for index, _, frame in src:
                i = row.get(index)
                if i is None:
                    vw.write(labeller.draw(frame, nan, zeros, lost))
                else:
                    vw.write(labeller.draw(frame, tracks.position[i], tracks.likelihood[i],
                                           tracks.status[i]))
            if src.n_decoded < len(tracks.frame):
                raise InputError(f"the video has {src.n_decoded} frames, the tracks "
                                 f"{len(tracks.frame)}: not the tracked video?", video)
    return Path(out)

"""How well a clip was tracked: the quality table and the contact sheet.

:func:`tracking_quality` summarises a :class:`~perception.io.tracks.Tracks`
per marker — the fraction of frames with a position, the minimum and median
likelihood of those frames, re-acquisitions, ambiguous and lost frames — for
``hammer-mv tracks info``, the ``tracking`` key of ``<clip>.recognition.json``
and the ``track_*`` columns of a batch's ``summary.csv``.
:func:`contact_sheet` draws the first frame with its detections and a few
frames across the movement, markers drawn (``<clip>.tracking.png`` in the
clip and batch reports).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from perception.io.atomic import write_bytes
from perception.io.names import output_stem
from perception.io.tracks import Status, Tracks

if TYPE_CHECKING:
    import pandas as pd

    from perception.io.frame_sample import FrameSample

__all__ = ["MarkerQuality", "TrackingQuality", "contact_sheet", "tracking_columns",
           "tracking_quality", "write_tracking_report"]


@dataclass(frozen=True)
class MarkerQuality:
    """How one marker was tracked.

    Attributes
    ----------
    marker : str
        Its name.
    tracked : float
        Fraction of frames with a position (tracked or re-acquired), 0..1.
    min_likelihood, median_likelihood : float
        Over the frames with a position (NaN if none).
    reacquisitions : int
        Times it was found again after being lost (or found after frame 0).
    ambiguous : int
        Frames reported ambiguous.
    lost : int
        Frames reported lost.
    """

    marker: str
    tracked: float
    min_likelihood: float
    median_likelihood: float
    reacquisitions: int
    ambiguous: int
    lost: int


@dataclass(frozen=True)
class TrackingQuality:
    """The tracking-quality table of one clip.

    Attributes
    ----------
    frames : int
        Frames in the tracks.
    markers : tuple of MarkerQuality
        One per marker, in column order.
    """

    frames: int
    markers: tuple[MarkerQuality, ...]

    def to_dict(self) -> dict:
        """JSON-ready: ``{"frames": T, "markers": {name: {tracked, min_likelihood, ...}}}``."""
        return {"frames": self.frames,
                "markers": {m.marker: {k: _plain(v) for k, v in vars(m).items() if k != "marker"}
                            for m in self.markers}}

    def to_pandas(self) -> pd.DataFrame:
        """One row per marker."""
        import pandas as pd  # not at the top: `recognize` never needs it

        return pd.DataFrame([vars(m) for m in self.markers])


def _plain(v):
    return None if isinstance(v, float) and not np.isfinite(v) else v


def tracking_quality(tracks: Tracks) -> TrackingQuality:
    """The quality table of ``tracks``.

    Parameters
    ----------
    tracks : Tracks
        Tracked (or loaded) tracks.
    """
    rows = []
    valid = tracks.valid
    for j, name in enumerate(tracks.markers):
        ok = valid[:, j]
        lik = tracks.likelihood[ok, j].astype(float)
        st = tracks.status[:, j]
        rows.append(MarkerQuality(
            marker=name,
            tracked=float(ok.mean()) if len(ok) else 0.0,
            min_likelihood=float(lik.min()) if lik.size else float("nan"),
            median_likelihood=float(np.median(lik)) if lik.size else float("nan"),
            reacquisitions=int(np.sum((st == Status.REACQUIRED)
                                      & np.r_[True, st[:-1] != Status.REACQUIRED])),
            ambiguous=int(np.sum(st == Status.AMBIGUOUS)),
            lost=int(np.sum(st == Status.LOST)),
        ))
    return TrackingQuality(tracks.n_frames, tuple(rows))


def tracking_columns(tracking: dict | None) -> dict:
    """``summary.csv`` columns of a clip's ``tracking`` JSON value (empty when None).

    ``track_<marker>`` (fraction of frames tracked) and ``minlik_<marker>``
    per marker, then ``reacquisitions`` and ``ambiguous_frames`` summed over
    the markers.

    Parameters
    ----------
    tracking : dict or None
        :meth:`TrackingQuality.to_dict` of the clip.
    """
    if not tracking:
        return {}
    markers = tracking.get("markers", {})
    out = {}
    for name, q in markers.items():
        out[f"track_{name}"] = q.get("tracked")
        out[f"minlik_{name}"] = q.get("min_likelihood")
    out["reacquisitions"] = sum(int(q.get("reacquisitions", 0)) for q in markers.values())
    out["ambiguous_frames"] = sum(int(q.get("ambiguous", 0)) for q in markers.values())
    return out


#: zlib level of the contact sheet's PNG (lossless whatever the level).
SHEET_PNG_LEVEL = 1


def _sheet_filter(cv2) -> list[int]:
    """OpenCV's flags for the sheet's PNG filter, ``Sub`` on every row (an OpenCV
    without the flag keeps libpng's own choice)."""
    flag = getattr(cv2, "IMWRITE_PNG_FILTER", None)
    return [] if flag is None else [flag, cv2.IMWRITE_PNG_FILTER_SUB]


def _pick_frames(tracks: Tracks, n: int) -> list[int]:
    """The first frame, then ``n - 1`` frames spread over the movement (or the clip)."""
    from perception.errors import InputError
    from perception.observation import movement_span

    try:
        span = movement_span(tracks)
        lo, hi = span.start, span.stop - 1
    except (InputError, ValueError):
        lo, hi = 0, tracks.n_frames - 1
    rows = [0, *np.linspace(lo, hi, max(n - 1, 1)).round().astype(int).tolist()]
    return sorted({int(tracks.frame[r]) for r in rows if 0 <= r < tracks.n_frames})


def contact_sheet(tracks: Tracks, video: str | os.PathLike | None, out: str | os.PathLike, *,
                  n: int = 6, width: int = 1200,
                  frames: FrameSample | None = None) -> Path | None:
    """Write a contact sheet PNG: frames with their markers drawn, in one row or two.

    Parameters
    ----------
    tracks : Tracks
        The tracks.
    video : str or os.PathLike, optional
        Their video (default: the ``/video`` ``path`` the tracks record).
    out : str or os.PathLike
        The PNG.
    n : int
        Frames shown: the first (with its detections), then ``n - 1`` across
        the movement.
    width : int
        Width of the sheet, px.
    frames : FrameSample, optional
        Frames kept while the video was tracked: when they cover the clip,
        the sheet shows the kept frame nearest each chosen one instead of
        decoding the video again.

    Returns
    -------
    Path or None
        None when the video cannot be read (the sheet needs its frames).
    """
    import cv2  # only for a sheet: recognising tracks, pose or mocap files never loads it

    from perception.tracking.overlay import Labeller, _colours

    wanted = _pick_frames(tracks, n)
    if not wanted:  # no frames tracked
        return None
    row = {int(f): i for i, f in enumerate(tracks.frame)}
    labeller = Labeller(tracks.markers, _colours(tracks), trail=1)

    def tile(index: int, time_s: float, frame: np.ndarray) -> np.ndarray:
        i = row[index]
        img = labeller.draw(frame, tracks.position[i], tracks.likelihood[i], tracks.status[i])
        cv2.putText(img, f"frame {index}  {time_s:.2f} s", (8, img.shape[0] - 10),
                    cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 1, cv2.LINE_AA)
        return img

    kept = [frames.nearest(w) for w in wanted] if frames is not None else None
    if kept is not None and all(k is not None and k in row for k in kept):
        tiles = [tile(k, float(tracks.time[row[k]]), frames.frames[k])
                 for k in sorted(set(kept))]
    else:
        tiles = _decoded_tiles(video or tracks.video.get("path"), wanted, row, tile)
    if not tiles:
        return None
    cols = min(len(tiles), 3)
    h, w = tiles[0].shape[:2]
    tw = width // cols
    th = round(h * tw / w)
    small = [cv2.resize(t, (tw, th), interpolation=cv2.INTER_AREA) for t in tiles]
    small += [np.zeros_like(small[0])] * (-len(small) % cols)
    sheet = np.vstack([np.hstack(small[r:r + cols]) for r in range(0, len(small), cols)])
    # encoded here and written by us: OpenCV is never handed a path (a name that
    # is not UTF-8 crashes its writer). OpenCV 5's default PNG settings store a
    # 1200 x 600 sheet in about 1 MB; zlib level 1 in 0.4 MB, as fast (a batch of
    # videos writes one a clip); one filter for every row (Sub) rather than libpng's
    # choice among five per row: half the encoding's time (64 -> 30 ms), 3 % larger
    ok, png = cv2.imencode(".png", sheet, [cv2.IMWRITE_PNG_COMPRESSION, SHEET_PNG_LEVEL,
                                           *_sheet_filter(cv2)])
    if not ok:
        raise OSError(f"{out}: cannot encode the contact sheet")
    return write_bytes(out, png.tobytes())


def _decoded_tiles(video, wanted: list[int], row: dict, tile) -> list[np.ndarray]:
    """``tile`` of each ``wanted`` frame of ``video``, decoded (none if it cannot be read)."""
    from perception.io.video import FrameSource

    if not video or not Path(video).is_file():
        return []
    tiles = []
    try:
        with FrameSource(video, hash=False) as src:
            for index, time_s, frame in src:
                if index in wanted and index in row:
                    tiles.append(tile(index, time_s, frame))
                if index >= wanted[-1]:
                    break
    except (ValueError, OSError):
        return []
    return tiles


def write_tracking_report(tracks: Tracks | str | os.PathLike, out: str | os.PathLike,
                          clip: str, *, sheet: bool = True,
                          frames: FrameSample | None = None) -> dict:
    """The clip's tracking quality (JSON-ready) and its contact sheet ``<clip>.tracking.png``.

    The one call the clip and batch reports make: it returns the value of the
    ``tracking`` key of ``<clip>.recognition.json`` and writes the sheet beside
    it when the clip's video can be read.

    Parameters
    ----------
    tracks : Tracks or path
        The clip's tracks (or its tracks file).
    out : str or os.PathLike
        Report folder.
    clip : str
        Clip name.
    sheet : bool
        Draw the contact sheet (reads frames of the video).
    frames : FrameSample, optional
        Frames kept while the clip was tracked, which spare the sheet a
        second decode (:func:`contact_sheet`).
    """
    if not isinstance(tracks, Tracks):
        tracks = Tracks.load(tracks)
    quality = tracking_quality(tracks).to_dict()
    sheet_path = Path(out) / f"{output_stem(clip)}.tracking.png"
    drawn = (contact_sheet(tracks, None, sheet_path, frames=frames)
             if sheet else None)
    quality["contact_sheet"] = drawn.name if drawn is not None else None
    return quality

"""Colour-marker tracking: videos of marked hands -> tracks files.

``from perception.tracking import track_video`` is all most users need;
:class:`Tracker` tracks frame by frame. The modules, each one job:

* :mod:`~perception.tracking.markers` — the colour models (``docs/markers.md``).
* :mod:`~perception.tracking.params` — :class:`TrackerParams`, every tunable.
* :mod:`~perception.tracking.blobs` — connected components of a colour mask.
* :mod:`~perception.tracking.measurement` — locating a marker near a prediction
  (CamShift, splitting merged blobs, the still-object fast path, its diameter).
* :mod:`~perception.tracking.candidates` — a marker's candidate blobs on the
  first frames and why one is refused (size, shape, colour purity, stillness).
* :mod:`~perception.tracking.hand` — which candidates together look like a
  hand; ambiguity.
* :mod:`~perception.tracking.first_detection` — starting the tracks of
  markers not found yet: candidates, the object's scale, the hand, ROIs.
* :mod:`~perception.tracking.blur` — fast markers: the blur gate and the
  streak gate that see a motion-blurred marker, a streak's expected size.
* :mod:`~perception.tracking.marker_track` — one marker's track: motion
  estimate, window, reference mass.
* :mod:`~perception.tracking.reacquisition` — the global search of lost markers.
* :mod:`~perception.tracking.setup` — a session's colour models and marker
  sizes: ``hammer-mv calibrate`` and ``--setup``.
* :mod:`~perception.tracking.overlay` — markers drawn on frames (labelled
  videos, contact sheets).
* :mod:`~perception.tracking.tracker` — the per-frame loop and motion
  prediction (:class:`Tracker`).
* :mod:`~perception.tracking.blur` — a fast marker found as a motion-blurred streak.
* :mod:`~perception.tracking.video_tracks` — a video or stream of frames into a
  tracks file: :func:`track_frames`, :func:`track_video`.

The tracks file it writes is described in ``docs/tracks-format.md``.
"""

from perception.tracking.markers import (
    MARKER_NAMES,
    MarkerColour,
    MarkerSet,
    default_markers,
    load_markers,
)
from perception.tracking.params import TrackerParams
from perception.tracking.tracker import Tracker
from perception.tracking.video_tracks import track_frames, track_video

__all__ = [
    "MARKER_NAMES",
    "MarkerColour",
    "MarkerSet",
    "Tracker",
    "TrackerParams",
    "default_markers",
    "load_markers",
    "track_frames",
    "track_video",
]

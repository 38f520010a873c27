"""The tracker's tunables, in one frozen dataclass.

Every number that changes what the tracker reports is a field of
:class:`TrackerParams`; all of them are saved as attributes of the tracks
file's ``/tracker`` group (``docs/tracks-format.md``), so a tracks file says
how it was made. Numbers that follow from geometry alone (how large a window
must be to hold a disc) stay as named constants beside the code that uses
them.

Masses and areas are pixel counts of a marker's colour; ratios are taken
against the marker's *reference mass*, the pixel count of the whole marker,
measured when it is first found and then followed slowly
(``ref_update``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import cv2

from perception.geometry import DEFAULT_OBJECT_DIAMETER


@dataclass(frozen=True)
class TrackerParams:
    """Tracker parameters (saved to the ``/tracker`` attributes).

    Parameters
    ----------
    min_window_px : int
        Smallest CamShift window side, px.
    search_margin_px : int
        Margin around the predicted window searched each frame, px.
    initial_margin_px : int
        Margin used until a marker's velocity is known (first frames and
        after re-acquisition), px, where the ``search_margin_px`` one finds
        no marker: covers fast motion from rest.
    velocity_margin : float
        Extra margin per px/frame of predicted speed.
    alpha, beta : float
        Alpha-beta filter gains (position, velocity) of the motion prediction.
    lost_ratio : float
        Window mass below this fraction of the reference: lost.
    reacquire_ratio : float
        A re-acquired blob needs at least this fraction of the reference mass.
    split_ratio : float
        Window mass above this multiple of the reference: separate
        same-coloured blobs by connected components.
    merge_ratio : float
        A component above this multiple of the reference is the marker merged
        with something of its colour.
    max_area_ratio : float
        Global-search components larger than this multiple are not the marker.
    hold_ratio : float
        A still marker whose mass is below this fraction of the reference is
        partly hidden and keeps its position.
    still_jump_px : float
        A still marker's measurement this far (px) from its estimate means it
        was moved: the estimate restarts there.
    still_markers : tuple of str
        Markers expected not to move (the object).
    term_eps_px, term_max_iter : float, int
        CamShift termination criteria: window shift below ``term_eps_px``
        px or ``term_max_iter`` iterations.
    min_area_px : int
        Smallest blob counted as a marker when initialising, px.
    search_scale : int
        Downscale factor of the global search (0: from the marker's size).
    ref_update : float
        Rate at which the reference mass follows a confidently tracked marker.
    lost_velocity_decay : float
        Per-frame decay of the predicted velocity while lost.
    init_candidates : int
        Candidates of each colour that pass the size, shape, purity and
        stillness tests (those nearest the expected size first) among which
        a hand marker is chosen by the hand's structure; the number of
        combinations tried grows as its power.
    search_min_ratio : float
        Global search: a downscaled blob with less than this fraction of the
        reference area is not refined. Lower than ``reacquire_ratio``
        because downscaled areas are rough; the full-resolution refinement
        decides.
    search_tries : int
        Global search: this many plausible blobs nearest the prediction are
        refined at full resolution per frame.
    search_marker_px : float
        With ``search_scale`` 0, the downscale factor keeps the smallest
        marker at least this many px across.
    search_max_scale : int
        With ``search_scale`` 0, the largest downscale factor.
    ref_update_band : float
        The reference mass follows a measurement only while mass / reference
        lies strictly between ``1 / ref_update_band`` and
        ``ref_update_band``: a partly hidden or merged marker must not teach
        it a wrong size.
    still_min_rate : float
        Smallest weight of a new whole-blob measurement in a still marker's
        running mean; the mean then follows slow drift (the camera settling)
        over about ``1 / still_min_rate`` frames.
    still_shift_px : float
        A whole still marker whose centroid is this far (px) from its
        estimate may be moving: it is measured by CamShift instead of by
        one moments call.
    max_window_ratio : float
        A marker's window side is at most this multiple of the side of a
        square holding its reference mass: a window allowed to grow over a
        same-coloured neighbour would stay on it.
    object_diameter : float
        The object's real diameter, m: with its apparent size it gives the
        image scale that the expected marker sizes follow.
    marker_diameter : float
        Thumb and finger marker diameter, m (markers of 1-2.5 cm pass
        ``size_tolerance``; calibrate a setup for others).
    band_size : (float, float)
        Wrist band: across the forearm, along it, m.
    size_tolerance : float
        A candidate's area must lie within this factor of its expected area,
        either way.
    min_roundness : float
        Smallest minor / major axis ratio of a digit marker or the object.
    band_elongation : (float, float)
        Range of the wrist band's major / minor axis ratio.
    min_saturation_ratio, min_value_ratio : float
        A candidate's median saturation and value must reach these fractions
        of its marker's own colour (``MarkerColour.hsv``).
    strict_saturation_ratio, strict_value_ratio : float
        The narrower gate of a marker that touches a large thing of its hue:
        pixels at least these fractions of its own saturation and value.
    own_saturation_margin : int
        A hand marker, once found, keeps only pixels at most this far below
        the 10th percentile of its own saturation (0 disables).
    own_value_ratio : float
        ... and at least this fraction of the 5th percentile of its own value.
    rest_motion_px : float
        A candidate that moves more than this (px) between the first frame
        and frame ``init_frames - 1`` is not a marker of a resting hand.
    init_frames : int
        Frames of the rest looked at before the markers are chosen (1: the
        first frame alone, no stillness test).
    digit_gap : float
        Largest thumb-finger marker distance at rest, m.
    hand_span : float
        Largest distance of a digit marker from the band (and, while moving,
        from the other digit), m.
    min_band_distance : float
        Smallest distance of a digit marker from the band, m.
    ambiguity_margin : float
        Two placements of the hand whose costs differ by less than this are
        equally plausible: a marker they put on different blobs is reported
        ambiguous.
    max_speed : float
        Fastest a marker moves, m/s: a measurement or re-acquisition further
        from the last known position than this allows (plus the marker's
        size) is a jump to something else, and the marker is lost instead.
    merged_likelihood : float
        Likelihood ceiling of a centroid taken among touching blobs of the
        same colour, or of a marker with more than ``clutter_ratio`` times
        its own mass of its colour around it (below 0.5: not to be trusted).
    clutter_ratio : float
        Mass of a hand marker's colour in its search region besides the
        marker, as a multiple of its reference, above which its position is
        not trusted (likelihood at most ``merged_likelihood``).
    max_merged_frames : int
        A marker measured merged with a neighbour of its colour for more
        frames in a row than this is reported lost (its window still
        follows it) until it stands apart again.
    hand_drift : float
        How far a lost hand marker can move relative to the rest of the hand
        per frame lost, m: it is re-acquired only that near where the hand
        markers still tracked put it.
    max_drift : float
        The most a hand marker moves relative to the rest of the hand, m.
    """

    min_window_px: int = 8
    search_margin_px: int = 10
    initial_margin_px: int = 64
    velocity_margin: float = 0.5
    alpha: float = 0.85
    beta: float = 0.5
    lost_ratio: float = 0.3
    reacquire_ratio: float = 0.5
    split_ratio: float = 1.15
    merge_ratio: float = 1.5
    max_area_ratio: float = 4.0
    hold_ratio: float = 0.97
    still_jump_px: float = 2.0
    still_markers: tuple[str, ...] = ("object",)
    term_eps_px: float = 0.5
    term_max_iter: int = 10
    min_area_px: int = 12
    search_scale: int = 0
    ref_update: float = 0.05
    lost_velocity_decay: float = 0.8
    init_candidates: int = 6
    search_min_ratio: float = 0.25
    search_tries: int = 3
    search_marker_px: float = 5.0
    search_max_scale: int = 4
    ref_update_band: float = 1.25
    still_min_rate: float = 0.1
    still_shift_px: float = 1.0
    max_window_ratio: float = 3.0
    object_diameter: float = DEFAULT_OBJECT_DIAMETER
    marker_diameter: float = 0.015
    band_size: tuple[float, float] = (0.07, 0.025)
    size_tolerance: float = 4.0
    min_roundness: float = 0.5
    band_elongation: tuple[float, float] = (1.4, 5.0)
    min_saturation_ratio: float = 0.55
    min_value_ratio: float = 0.3
    strict_saturation_ratio: float = 0.8
    strict_value_ratio: float = 0.45
    own_saturation_margin: int = 30
    own_value_ratio: float = 0.5
    rest_motion_px: float = 3.0
    init_frames: int = 5
    digit_gap: float = 0.05
    hand_span: float = 0.2
    min_band_distance: float = 0.02
    ambiguity_margin: float = 0.3
    max_speed: float = 6.0
    merged_likelihood: float = 0.45
    clutter_ratio: float = 1.0
    max_merged_frames: int = 3
    hand_drift: float = 0.01
    max_drift: float = 0.06

    def __post_init__(self) -> None:
        object.__setattr__(self, "still_markers", tuple(self.still_markers))
        for name in ("band_size", "band_elongation"):
            value = tuple(float(v) for v in getattr(self, name))
            if len(value) != 2 or not all(v > 0 for v in value):
                raise ValueError(f"TrackerParams.{name}: expected two positive numbers, "
                                 f"got {getattr(self, name)!r}")
            object.__setattr__(self, name, value)
        for name in ("object_diameter", "marker_diameter", "digit_gap", "hand_span",
                     "max_speed", "rest_motion_px"):
            if not getattr(self, name) > 0:
                raise ValueError(f"TrackerParams.{name}: expected > 0, got "
                                 f"{getattr(self, name)!r}")
        if self.size_tolerance < 1 or not 0 < self.min_roundness <= 1:
            raise ValueError("TrackerParams: expected size_tolerance >= 1 and "
                             "0 < min_roundness <= 1")
        if self.init_frames < 1 or not 0 <= self.merged_likelihood < 0.5:
            raise ValueError("TrackerParams: expected init_frames >= 1 and "
                             "0 <= merged_likelihood < 0.5")
        if not 0 < self.lost_ratio <= self.reacquire_ratio <= 1:
            raise ValueError(
                "TrackerParams: expected 0 < lost_ratio <= reacquire_ratio <= 1, got "
                f"{self.lost_ratio}, {self.reacquire_ratio}"
            )
        if not 1 <= self.split_ratio <= self.merge_ratio <= self.max_area_ratio:
            raise ValueError(
                "TrackerParams: expected 1 <= split_ratio <= merge_ratio <= max_area_ratio"
            )
        if self.min_window_px < 3 or self.term_max_iter < 1 or self.term_eps_px <= 0:
            raise ValueError(
                "TrackerParams: expected min_window_px >= 3, term_max_iter >= 1, term_eps_px > 0"
            )
        if min(self.init_candidates, self.search_tries, self.search_max_scale) < 1:
            raise ValueError(
                "TrackerParams: expected init_candidates, search_tries, search_max_scale >= 1"
            )
        if self.ref_update_band < 1 or not 0 < self.still_min_rate <= 1:
            raise ValueError(
                "TrackerParams: expected ref_update_band >= 1 and 0 < still_min_rate <= 1"
            )

    @cached_property
    def criteria(self) -> tuple[int, int, float]:
        """OpenCV termination criteria for CamShift (computed once: it is read per measurement)."""
        return (
            cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT,
            int(self.term_max_iter),
            float(self.term_eps_px),
        )

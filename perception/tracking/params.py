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

Every field declares its type and range (:mod:`perception.validation`;
integers are C ints for OpenCV, floats finite): a setup file's ``[tracker]``
and ``[sizes]`` values are checked against them, naming the file and field,
and so is every ``TrackerParams`` built in Python.
"""

from __future__ import annotations

from functools import cached_property
from typing import Annotated

import cv2
from pydantic import Field

from perception.errors import InputError
from perception.geometry import DEFAULT_OBJECT_DIAMETER
from perception.validation import Int32, Tuple, declared

_PX = 4096  # px: a distance or window side no larger than the largest frame side
_Metres = Annotated[float, Field(gt=0, le=1)]
_Ratio = Annotated[float, Field(gt=0, le=100)]


@declared
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
    default_fps : float
        Frame rate assumed where :meth:`Tracker.update` is given no frame
        time (time = index / ``default_fps``), frames/s; it bounds how far a
        marker can move between frames (``max_speed``).
    table_height_m : float
        Until the object has set the scale, the frame's height is taken to
        span this much of the table, m (the expected sizes of hand markers
        found before the object).
    object_rival_ratio : float
        Another round, pure, still blob of the object's colour at least this
        fraction of the largest one's area makes the object ambiguous.
    max_blobs : int
        At most this many blobs of a colour (the largest) are described as
        candidates when a marker is first looked for.
    rest_area_ratio : float
        Stillness test: a candidate whose blob in the later rest frame is
        larger or smaller than this factor of its area has gone or changed
        (it counts as moving).
    typical_reach : float
        A digit marker's usual distance from the band at rest, m: a hand
        placement costs more the further its reaches are from it.
    colour_weight : float
        Weight of a candidate's colour impurity (1 - purity) in a hand
        placement's cost.
    max_band_cos : float
        At rest, the band lies across the forearm: |cos| of the angle between
        its long axis and the band -> digits line above this is not a hand.
    rival_separation_px : float
        Rival blobs of an ambiguous marker closer than this (px) are the
        same blob.
    rim_px : int
        A blob's window is 4 standard deviations per axis (a disc's
        diameter) plus this many px, so that its blurred rim lies inside.
    still_pad_px : int
        A still marker's measured region is its window padded by this many
        px each side: room to see that the blob moved or that something of
        its colour came near.
    min_region_px : int
        A search region narrower than this (px; the prediction left the
        frame) holds no measurable marker.
    min_soft_contrast : float
        A round marker whose colour lies closer than this (BGR distance) to
        its surroundings' has no colour-unmixed diameter (``diameter_px``
        NaN; its gated area sets the scale).
    """

    min_window_px: Annotated[Int32, Field(ge=3, le=_PX)] = 8
    search_margin_px: Annotated[Int32, Field(ge=0, le=_PX)] = 10
    initial_margin_px: Annotated[Int32, Field(ge=0, le=_PX)] = 64
    velocity_margin: Annotated[float, Field(ge=0, le=100)] = 0.5
    alpha: Annotated[float, Field(gt=0, le=1)] = 0.85
    beta: Annotated[float, Field(ge=0, lt=2)] = 0.5
    lost_ratio: Annotated[float, Field(gt=0, le=1)] = 0.3
    reacquire_ratio: Annotated[float, Field(gt=0, le=1)] = 0.5
    split_ratio: Annotated[float, Field(ge=1, le=1000)] = 1.15
    merge_ratio: Annotated[float, Field(ge=1, le=1000)] = 1.5
    max_area_ratio: Annotated[float, Field(ge=1, le=1000)] = 4.0
    hold_ratio: Annotated[float, Field(ge=0, le=1)] = 0.97
    still_jump_px: Annotated[float, Field(ge=0, le=_PX)] = 2.0
    still_markers: Annotated[tuple[str, ...], Tuple] = ("object",)
    term_eps_px: Annotated[float, Field(gt=0, le=100)] = 0.5
    term_max_iter: Annotated[Int32, Field(ge=1, le=1000)] = 10
    min_area_px: Annotated[Int32, Field(ge=1, le=10_000_000)] = 12
    search_scale: Annotated[Int32, Field(ge=0, le=64)] = 0
    ref_update: Annotated[float, Field(ge=0, le=1)] = 0.05
    lost_velocity_decay: Annotated[float, Field(ge=0, le=1)] = 0.8
    init_candidates: Annotated[Int32, Field(ge=1, le=20)] = 6
    search_min_ratio: Annotated[float, Field(ge=0, le=1)] = 0.25
    search_tries: Annotated[Int32, Field(ge=1, le=100)] = 3
    search_marker_px: Annotated[float, Field(gt=0, le=_PX)] = 5.0
    search_max_scale: Annotated[Int32, Field(ge=1, le=64)] = 4
    ref_update_band: Annotated[float, Field(ge=1, le=100)] = 1.25
    still_min_rate: Annotated[float, Field(gt=0, le=1)] = 0.1
    still_shift_px: Annotated[float, Field(ge=0, le=_PX)] = 1.0
    max_window_ratio: Annotated[float, Field(ge=1, le=100)] = 3.0
    object_diameter: Annotated[float, Field(gt=0, le=10)] = DEFAULT_OBJECT_DIAMETER
    marker_diameter: Annotated[float, Field(gt=0, le=1)] = 0.015
    band_size: Annotated[tuple[_Metres, _Metres], Tuple] = (0.07, 0.025)
    size_tolerance: Annotated[float, Field(ge=1, le=100)] = 4.0
    min_roundness: Annotated[float, Field(gt=0, le=1)] = 0.5
    band_elongation: Annotated[tuple[_Ratio, _Ratio], Tuple] = (1.4, 5.0)
    min_saturation_ratio: Annotated[float, Field(ge=0, le=1)] = 0.55
    min_value_ratio: Annotated[float, Field(ge=0, le=1)] = 0.3
    strict_saturation_ratio: Annotated[float, Field(ge=0, le=1)] = 0.8
    strict_value_ratio: Annotated[float, Field(ge=0, le=1)] = 0.45
    own_saturation_margin: Annotated[Int32, Field(ge=0, le=255)] = 30
    own_value_ratio: Annotated[float, Field(ge=0, le=1)] = 0.5
    rest_motion_px: Annotated[float, Field(gt=0, le=_PX)] = 3.0
    init_frames: Annotated[Int32, Field(ge=1, le=1000)] = 5
    digit_gap: Annotated[float, Field(gt=0, le=1)] = 0.05
    hand_span: Annotated[float, Field(gt=0, le=2)] = 0.2
    min_band_distance: Annotated[float, Field(ge=0, le=1)] = 0.02
    ambiguity_margin: Annotated[float, Field(ge=0, le=1000)] = 0.3
    max_speed: Annotated[float, Field(gt=0, le=100)] = 6.0
    merged_likelihood: Annotated[float, Field(ge=0, lt=0.5)] = 0.45
    clutter_ratio: Annotated[float, Field(ge=0, le=1000)] = 1.0
    max_merged_frames: Annotated[Int32, Field(ge=0, le=100_000)] = 3
    hand_drift: Annotated[float, Field(ge=0, le=1)] = 0.01
    max_drift: Annotated[float, Field(ge=0, le=2)] = 0.06
    default_fps: Annotated[float, Field(gt=0, le=1000)] = 30.0
    table_height_m: Annotated[float, Field(gt=0, le=100)] = 0.6
    object_rival_ratio: Annotated[float, Field(ge=0, le=1)] = 0.5
    max_blobs: Annotated[Int32, Field(ge=1, le=100_000)] = 64
    rest_area_ratio: Annotated[float, Field(ge=1, le=100)] = 2.0
    typical_reach: Annotated[float, Field(gt=0, le=2)] = 0.08
    colour_weight: Annotated[float, Field(ge=0, le=100)] = 2.0
    max_band_cos: Annotated[float, Field(ge=0, le=1)] = 0.6
    rival_separation_px: Annotated[float, Field(ge=0, le=_PX)] = 4.0
    rim_px: Annotated[Int32, Field(ge=0, le=_PX)] = 4
    still_pad_px: Annotated[Int32, Field(ge=0, le=_PX)] = 4
    min_region_px: Annotated[Int32, Field(ge=1, le=_PX)] = 3
    min_soft_contrast: Annotated[float, Field(ge=0, le=1000)] = 10.0

    def __post_init__(self) -> None:
        # what the ranges alone cannot say
        for names in (("lost_ratio", "reacquire_ratio"),
                      ("split_ratio", "merge_ratio", "max_area_ratio")):
            values = [getattr(self, n) for n in names]
            if values != sorted(values):
                raise InputError(f"expected {' <= '.join(names)}, got "
                                 f"{', '.join(map(repr, values))}",
                                 location=("TrackerParams", names[0]))
        if self.band_elongation[0] > self.band_elongation[1]:
            raise InputError(f"expected [low, high], got {list(self.band_elongation)}",
                             location=("TrackerParams", "band_elongation"))

    @cached_property
    def criteria(self) -> tuple[int, int, float]:
        """OpenCV termination criteria for CamShift (computed once: it is read per measurement)."""
        return (
            cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT,
            int(self.term_max_iter),
            float(self.term_eps_px),
        )


"""The tracker's parts on drawn frames: blobs, measurement, detection, parameters."""

import math

import cv2
import numpy as np
import pytest

import perception.tracking as tracking
from perception.tracking.blobs import Blob, by_distance, find_blobs, nearest_blob
from perception.tracking.markers import default_markers
from perception.tracking.measurement import (
    clamp_window,
    likelihood,
    measure,
    measure_still,
    soft_diameter,
    split_merged,
)
from perception.tracking.params import TrackerParams
from perception.tracking.reacquisition import (
    downscaled_hsv,
    reacquire,
    search_scale,
)
from perception.tracking.tracker import Tracker

TABLE = (150, 160, 170)
P = TrackerParams()
THUMB = default_markers()["thumb"]


def _frame(discs, size=(240, 320), ss=1):
    """A table with filled discs ``(x, y, radius, bgr)``; ``ss`` > 1 anti-aliases."""
    h, w = size
    img = np.full((h * ss, w * ss, 3), TABLE, np.uint8)
    for x, y, r, bgr in discs:
        # Pixel centres map to pixel centres under the ss x downscale.
        c = (round((x + 0.5) * ss - 0.5), round((y + 0.5) * ss - 0.5))
        cv2.circle(img, c, round(r * ss), bgr, -1)
    return img if ss == 1 else cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA)


def _mask(discs, size=(60, 80)):
    m = np.zeros(size, np.uint8)
    for x, y, r in discs:
        cv2.circle(m, (x, y), r, 255, -1)
    return m


# -- blobs ----------------------------------------------------------------
def test_blobs_are_the_plausible_components_with_their_centres_and_boxes():
    mask = _mask([(10, 10, 2), (40, 30, 6), (70, 50, 4)])
    blobs = find_blobs(mask)
    assert len(blobs) == 3
    big = max(blobs, key=lambda b: b.area)
    assert big.centre == pytest.approx((40, 30))
    assert big.area == np.count_nonzero(mask[20:40, 30:50])
    assert big.box == (34, 24, 13, 13) and big.size == (13, 13)
    assert [b.area for b in find_blobs(mask, min_area=20, max_area=100)] == [
        b.area for b in blobs if 20 <= b.area <= 100
    ]
    moved = big.moved(100, 200)
    assert moved.centre == (140, 230) and moved.box[:2] == (134, 224)
    assert find_blobs(np.zeros((5, 5), np.uint8)) == []


def test_downscaled_blobs_are_in_full_resolution_pixels():
    full = _mask([(41, 21, 6)], size=(60, 80))
    small = cv2.resize(full, (40, 30), interpolation=cv2.INTER_NEAREST)
    (b,) = find_blobs(small, scale=(2.0, 2.0))
    (ref,) = find_blobs(full)
    assert b.centre == pytest.approx(ref.centre, abs=1.0)
    assert b.area == pytest.approx(ref.area, rel=0.2)


def test_nearest_blob_and_order_by_distance():
    blobs = [Blob((0.0, 0.0), 10, (0, 0, 1, 1)), Blob((5.0, 0.0), 10, (5, 0, 1, 1)),
             Blob((-5.0, 0.0), 10, (0, 0, 1, 1)), Blob((1.0, 1.0), 10, (1, 1, 1, 1))]
    assert nearest_blob(blobs, (4, 0)) is blobs[1]
    assert nearest_blob(blobs, (0, 0)) is blobs[0]
    assert nearest_blob(blobs, (0.0, 10.0)) is blobs[3]
    assert nearest_blob([], (0, 0)) is None
    # Ties keep input order.
    assert by_distance(blobs, (0, 0)) == [blobs[0], blobs[3], blobs[1], blobs[2]]
    assert by_distance([], (0, 0)) == []


# -- measurement -----------------------------------------------------------
def test_measure_finds_a_disc_from_a_nearby_prediction():
    frame = _frame([(150.0, 100.0, 8, THUMB.bgr)])
    area = np.count_nonzero(THUMB.backproject(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)))
    meas = measure(frame, THUMB, (156.0, 96.0), (16, 16), area, P.search_margin_px, P)
    assert meas.centre == pytest.approx((150, 100), abs=0.05)
    assert meas.mass == area and not meas.merged
    assert all(16 <= s <= 22 for s in meas.window)
    # Nothing of the colour, or a prediction off the frame: no measurement.
    assert measure(frame, THUMB, (40.0, 40.0), (16, 16), area, 5, P) is None
    assert measure(frame, THUMB, (-50.0, 100.0), (16, 16), area, 5, P) is None
    assert measure(frame, THUMB, (np.nan, 100.0), (16, 16), area, 5, P) is None


def test_measure_recentres_on_a_blob_cut_off_by_its_region():
    frame = _frame([(150.0, 100.0, 6, THUMB.bgr)])
    area = np.count_nonzero(THUMB.backproject(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)))
    # The region (window 8 + margin 2 each side) catches the disc's left part only.
    meas = measure(frame, THUMB, (143.0, 100.0), (8, 8), area, 2, P)
    assert meas.mass == area
    assert meas.centre == pytest.approx((150, 100), abs=0.05)


def test_split_keeps_the_blob_nearest_the_prediction_or_flags_touching_ones():
    apart = _mask([(20, 30, 5), (60, 30, 7)])
    ref = np.count_nonzero(_mask([(20, 30, 5)]))
    meas = split_merged(apart, (25.0, 30.0), (100, 200), ref, P, (9, 9))
    assert meas.centre == pytest.approx((120, 230)) and meas.mass == ref
    assert not meas.merged
    touching = _mask([(30, 30, 5), (39, 30, 5)])
    meas = split_merged(touching, (30.0, 30.0), (0, 0), ref, P, (9, 9))
    assert meas.merged and meas.window == (9, 9)
    assert 30 < meas.centre[0] < 34.5  # pulled toward the neighbour, only partly
    assert split_merged(apart, (0.0, 0.0), (0, 0), 10 * ref, P, (9, 9)) is None


def test_measure_still_takes_one_look_and_defers_on_motion():
    obj = default_markers()["object"]
    frame = _frame([(150.0, 100.0, 12, obj.bgr)])
    area = np.count_nonzero(obj.backproject(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)))
    meas = measure_still(frame, obj, (150.0, 100.0), (28, 28), area, P)
    assert meas.centre == pytest.approx((150, 100)) and meas.mass == area
    # Whole but 2 px off its estimate: moving, left to CamShift.
    assert measure_still(frame, obj, (152.0, 100.0), (28, 28), area, P) is None
    # Larger than the window allows: left to CamShift.
    assert measure_still(frame, obj, (150.0, 100.0), (16, 16), area, P) is None


def test_soft_diameter_is_unbiased_by_partly_coloured_rim_pixels():
    obj = default_markers()["object"]
    frame = _frame([(150.0, 100.0, 20, obj.bgr)], ss=8)
    frame = cv2.GaussianBlur(frame, (0, 0), 1.2)
    gated = np.count_nonzero(obj.backproject(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)))
    d = soft_diameter(frame, obj, (150.0, 100.0), (44, 44))
    assert d == pytest.approx(40.0, rel=0.01)
    assert 2 * math.sqrt(gated / math.pi) > d + 0.5  # the colour gate over-counts
    assert math.isnan(soft_diameter(frame, obj, (20.0, 20.0), (44, 44)))


def test_likelihood_and_window_bounds():
    assert likelihood(1.0) == 1.0
    assert likelihood(0.5) == likelihood(2.0) == 0.5
    assert likelihood(0.0) == 0.0
    assert clamp_window((2, 500), 200.0, P) == (P.min_window_px, 3 * (16 + 4))
    assert clamp_window((2, 500), 0.0, P) == (P.min_window_px, 500)


# -- detection -------------------------------------------------------------
def test_global_search_finds_the_nearest_plausible_blob():
    frame = _frame([(60.0, 60.0, 6, THUMB.bgr), (250.0, 150.0, 6, THUMB.bgr),
                    (200.0, 40.0, 20, THUMB.bgr)])
    ref = float(np.count_nonzero(_mask([(10, 10, 6)])))
    assert search_scale([ref, 1000.0], P) == 2  # a 13 px marker stays >= 5 px across
    assert search_scale([], P) == 1
    assert search_scale([ref], TrackerParams(search_scale=3)) == 3
    small = downscaled_hsv(frame, 2)
    meas = reacquire(frame, small, THUMB, ref, (230.0, 130.0), (16, 16), P)
    assert meas.centre == pytest.approx((250, 150), abs=0.05)
    # The large blob is nearer but implausible; nothing plausible near: None.
    meas = reacquire(frame, small, THUMB, ref, (200.0, 45.0), (16, 16), P)
    assert meas.centre == pytest.approx((250, 150), abs=0.05)
    assert reacquire(frame, small, THUMB, 50 * ref, (60.0, 60.0), (16, 16), P) is None


# -- parameters and the package --------------------------------------------
def test_every_tunable_is_saved_and_new_fields_are_validated():
    attrs = Tracker().attrs()
    for name in ("init_candidates", "search_min_ratio", "search_tries", "ref_update_band",
                 "still_min_rate", "still_shift_px", "max_window_ratio", "lost_ratio"):
        assert attrs[name] == getattr(P, name)
    with pytest.raises(ValueError, match="init_candidates"):
        TrackerParams(init_candidates=0)
    with pytest.raises(ValueError, match="ref_update_band"):
        TrackerParams(ref_update_band=0.9)


def test_package_reexports_the_public_names():
    from perception.tracking import markers, tracker, video_tracks

    assert tracking.track_video is video_tracks.track_video
    assert tracking.Tracker is tracker.Tracker and tracking.TrackerParams is tracker.TrackerParams
    assert tracking.track_frames is video_tracks.track_frames
    for name in ("MarkerColour", "MarkerSet", "default_markers", "load_markers", "MARKER_NAMES"):
        assert getattr(tracking, name) is getattr(markers, name)
    assert sorted(tracking.__all__) == sorted(
        ["Tracker", "TrackerParams", "track_video", "track_frames", "MarkerColour", "MarkerSet",
         "default_markers", "load_markers", "MARKER_NAMES"]
    )

import inspect
import json
import time

import cv2
import h5py
import numpy as np
import pytest
from _clips import render

from perception.io.tracks import Tracks
from perception.io.video import FrameSource
from perception.synthetic.render import render_clip, render_frames
from perception.synthetic.scene import Camera, Distractor, Occlusion, RenderStyle, Scene
from perception.tracking.markers import default_markers


def test_camera_maps_world_to_pixels_as_documented():
    cam = Camera(px_per_m=500.0, origin_px=(100.0, 200.0))
    np.testing.assert_allclose(cam.world_to_pixel([0.0, 0.0]), [100, 200])
    np.testing.assert_allclose(cam.world_to_pixel([0.1, 0.0]), [150, 200])  # +x right
    np.testing.assert_allclose(cam.world_to_pixel([0.0, 0.1]), [100, 150])  # +y up the image
    rot = Camera(px_per_m=500.0, origin_px=(100.0, 200.0), angle_deg=90.0)
    np.testing.assert_allclose(rot.world_to_pixel([0.1, 0.0]), [100, 150], atol=1e-9)
    pts = np.random.default_rng(0).normal(size=(7, 2))
    for c in (cam, rot, Camera(angle_deg=-33.0)):
        np.testing.assert_allclose(c.pixel_to_world(c.world_to_pixel(pts)), pts, atol=1e-12)
        # A similarity: distances scale by px_per_m.
        d_w = np.linalg.norm(pts[0] - pts[1])
        d_p = np.linalg.norm(c.world_to_pixel(pts[0]) - c.world_to_pixel(pts[1]))
        assert d_p == pytest.approx(c.px_per_m * d_w)


def test_frames_stream_and_truth_is_where_each_colour_is_drawn():
    cam = Camera.for_frame(320, 240, angle_deg=25)
    scene = Scene.reach_to_grasp(40, 30, onset=0.1, duration=1.0)
    frames = render_frames(scene, cam, RenderStyle(width=320, height=240, hand=True), seed=1)
    assert inspect.isgenerator(frames)
    for fr in frames:
        if fr.index not in (0, 20):
            continue
        hsv = cv2.cvtColor(fr.image, cv2.COLOR_BGR2HSV)
        for j, m in enumerate(default_markers()):
            if m.name == "object" and fr.index == 20:
                continue  # partly under the hand
            mo = cv2.moments(m.backproject(hsv), True)
            centroid = (mo["m10"] / mo["m00"], mo["m01"] / mo["m00"])
            np.testing.assert_allclose(centroid, fr.truth[j], atol=0.25, err_msg=m.name)
        expected = cam.world_to_pixel(
            np.array([scene.thumb[fr.index], scene.finger[fr.index], scene.wrist[fr.index], (0, 0)])
        )
        np.testing.assert_allclose(fr.truth, expected)


def test_same_seed_same_frames_other_seed_other_noise():
    scene = Scene.reach_to_grasp(3, 30)
    style = RenderStyle(width=160, height=120, noise_sd=5, hand=True)
    cam = Camera.for_frame(160, 120)
    a = [f.image for f in render_frames(scene, cam, style, seed=7)]
    b = [f.image for f in render_frames(scene, cam, style, seed=7)]
    c = [f.image for f in render_frames(scene, cam, style, seed=8)]
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not np.array_equal(a[0], c[0])


def test_occlusion_and_distractor_are_drawn():
    scene = Scene.reach_to_grasp(10, 30)
    cam = Camera.for_frame(320, 240)
    style = RenderStyle(
        width=320,
        height=240,
        texture=False,
        occlusions=(Occlusion("thumb", 2, 5),),
        distractors=(Distractor("thumb", start=(0.15, 0.0), end=(0.15, 0.1), frames=(0, 10)),),
    )
    thumb = default_markers()["thumb"]
    for fr in render_frames(scene, cam, style):
        mask = thumb.backproject(cv2.cvtColor(fr.image, cv2.COLOR_BGR2HSV))
        near_thumb = mask[int(fr.truth[0, 1]), int(fr.truth[0, 0])]
        assert bool(near_thumb) == (not 2 <= fr.index < 5)
        assert fr.visible[0] == (not 2 <= fr.index < 5)
        d = cam.world_to_pixel(style.distractors[0].position(fr.index, 10))
        assert mask[int(round(d[1])), int(round(d[0]))] == 255
    assert np.allclose(style.distractors[0].position(9, 10), (0.15, 0.1))


def test_render_clip_writes_video_and_truth_in_the_tracks_schema(tmp_path):
    clip, cam = render(
        tmp_path,
        "c.avi",
        n=12,
        width=320,
        height=240,
        hand=True,
        occlusions=(Occlusion("finger", 3, 6),),
    )
    assert clip.video.exists() and clip.truth.name == "c.truth.h5"
    truth = Tracks.load(clip.truth)
    assert truth.markers == ("thumb", "finger", "wrist", "object")
    assert truth.n_frames == 12 and (truth.status == 0).all() and (truth.likelihood == 1).all()
    np.testing.assert_allclose(truth.time, np.arange(12) / 30)
    np.testing.assert_allclose(truth.marker("object")[0], cam.origin_px)
    assert truth.attrs["label"] == "test"
    assert json.loads(truth.attrs["camera"])["angle_deg"] == 20.0
    assert json.loads(truth.attrs["style"])["occlusions"][0]["marker"] == "finger"
    assert truth.video["fourcc"] == "MJPG" and truth.video["n_frames"] == 12
    with h5py.File(clip.truth) as fh:
        visible = fh["truth/visible"][()]
    assert not visible[3:6, 1].any() and visible[:3].all() and visible[6:].all()
    src = FrameSource(clip.video)
    assert src.info.sha256 == truth.video["sha256"]
    assert sum(1 for _ in src) == 12


def test_params_are_stored_as_json(tmp_path):
    scene = Scene.reach_to_grasp(4, 30)
    res = render_clip(
        scene,
        Camera.for_frame(160, 120),
        RenderStyle(width=160, height=120),
        tmp_path / "p.mp4",
        seed=3,
        label="delayed_opening",
        params={"peak_at": np.float64(0.8), "via": np.array([0.1, 0.2])},
    )
    attrs = Tracks.load(res.truth).attrs
    assert attrs["label"] == "delayed_opening" and attrs["seed"] == 3
    assert json.loads(attrs["params"]) == {"peak_at": 0.8, "via": [0.1, 0.2]}


@pytest.mark.parametrize("fps, size", [(25.0, (640, 480)), (60.0, (640, 480)), (30.0, (1280, 720))])
def test_frame_rates_and_resolutions(tmp_path, fps, size):
    clip, _ = render(tmp_path, n=6, fps=fps, width=size[0], height=size[1], hand=True)
    src = FrameSource(clip.video)
    assert (src.info.width, src.info.height) == size
    assert src.info.fps_nominal == pytest.approx(fps)
    times = [t for _, t, _ in src]
    np.testing.assert_allclose(times, np.arange(6) / fps, atol=1e-6)


def test_rendering_is_fast(tmp_path):
    scene = Scene.reach_to_grasp(64, 30)
    style = RenderStyle(width=320, height=240, hand=True, noise_sd=5, lighting=0.4, blur_sigma=0.7)
    cam = Camera.for_frame(320, 240)
    render_clip(scene, cam, style, tmp_path / "warm.mp4")  # first-call costs aside
    # this process's CPU time, not the wall clock: other processes on a busy machine do
    # not count (a performance test still depends on the CPU: 10 times the usual ~0.1 s)
    t0 = time.process_time()
    render_clip(scene, cam, style, tmp_path / "fast.mp4")
    assert time.process_time() - t0 < 1.0


def test_failed_render_leaves_no_files(tmp_path, monkeypatch):
    scene = Scene.reach_to_grasp(5, 30)
    style = RenderStyle(width=160, height=120)
    # A frame fails to draw after the video is opened: nothing is left behind.
    def no_frames(*args, **kwargs):
        yield from ()
        raise ValueError("unknown marker")

    with monkeypatch.context() as m:
        m.setattr("perception.synthetic.render.render_frames", no_frames)
        with pytest.raises(ValueError, match="unknown marker"):
            render_clip(scene, Camera(), style, tmp_path / "x.mp4")
    assert list(tmp_path.iterdir()) == []

    # The truth fails after the video is complete: the video is taken back too.
    def broken(path):
        raise OSError("disk full")

    monkeypatch.setattr("perception.synthetic.render.sha256_file", broken)
    with pytest.raises(OSError, match="disk full"):
        render_clip(scene, Camera.for_frame(160, 120), style, tmp_path / "y.mp4")
    assert list(tmp_path.iterdir()) == []


def test_scene_validation():
    with pytest.raises(ValueError, match=r"Scene.finger: expected shape \(T, 2\)"):
        Scene(np.zeros((5, 2)), np.zeros((5, 3)), np.zeros((5, 2)))
    with pytest.raises(ValueError, match="expected T = 5"):
        Scene(np.zeros((5, 2)), np.zeros((4, 2)), np.zeros((5, 2)))
    with pytest.raises(ValueError, match="finite"):
        Scene(np.full((5, 2), np.nan), np.zeros((5, 2)), np.zeros((5, 2)))


def test_reach_to_grasp_stand_in_ends_on_the_object():
    s = Scene.reach_to_grasp(90, 30, onset=0.2, duration=1.0)
    np.testing.assert_allclose(s.wrist[-1], [0, -0.06], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(s.finger[-1] - s.thumb[-1]), 0.10)
    assert s.finger[-1, 0] > 0 > s.thumb[-1, 0]  # right hand seen from above
    aperture = np.linalg.norm(s.finger - s.thumb, axis=1)
    assert aperture.max() == pytest.approx(0.14) and aperture.argmax() < 89


def test_discs_are_drawn_at_their_nominal_size():
    from perception.synthetic.render import _disc

    # object-sized discs to a tenth of a pixel; small ones (markers) within half a
    # pixel: OpenCV's anti-aliased rasteriser is irregular around 8-10 px
    for r, tol in ((5.0, 0.5), (10.0, 0.5), (20.0, 0.1), (40.0, 0.1), (60.0, 0.1)):
        for centre in (100.0, 100.3):
            img = np.zeros((200, 200), np.uint8)
            _disc(img, np.array([centre, 100.0]), r, 255)
            assert 2 * np.sqrt((img / 255.0).sum() / np.pi) == pytest.approx(2 * r, abs=tol)

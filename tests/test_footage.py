"""Realistic footage: photographs under the hand, H.264 4:2:0, motion blur, flicker, lit markers."""

import cv2
import numpy as np
import pytest

from perception.errors import InputError
from perception.synthetic.footage import flicker_gain, load_background, photo_names
from perception.synthetic.recipes import render_style
from perception.synthetic.render import render_frames
from perception.synthetic.scene import Camera, Distractor, RenderStyle, Scene

pytest.importorskip("skimage")
pytest.importorskip("imageio_ffmpeg")


def _scene(n=6, speed=0.0, gap=0.0065):
    wrist = np.stack([np.arange(n) * speed / 30, np.full(n, -0.25)], axis=1)
    return Scene(wrist, wrist + (gap, 0.06), wrist + (-gap, 0.06))


def test_photo_background_covers_the_frame_and_only_packaged_photos_are_used():
    assert {"coffee", "astronaut", "rocket"} <= set(photo_names())
    bg = next(load_background("photo:coffee", 320, 240))
    assert bg.shape == (240, 320, 3) and bg.std() > 20  # a photograph, not a flat table
    frame = next(render_frames(_scene(), Camera.for_frame(320, 240),
                               RenderStyle(width=320, height=240, background="photo:coffee")))
    corner = (slice(0, 20), slice(0, 20))  # nothing drawn there
    np.testing.assert_array_equal(frame.image[corner], bg[corner])
    with pytest.raises(InputError, match="no such sample photograph"):
        next(load_background("photo:nonesuch", 32, 32))
    with pytest.raises(ValueError, match="photo:NAME or video:PATH"):
        RenderStyle(background="painting:x")


def test_h264_clip_is_4_2_0_at_29_97_frames_per_second(tmp_path):
    import imageio_ffmpeg

    from perception.synthetic.render import render_clip

    style = RenderStyle(fps=30000 / 1001, width=160, height=120, codec="h264", hand=True)
    res = render_clip(_scene(8), Camera.for_frame(160, 120), style, tmp_path / "c.mp4")
    gen = imageio_ffmpeg.read_frames(str(res.video))
    meta = next(gen)
    gen.close()
    assert meta["codec"].startswith("h264") and "yuv420p" in meta["pix_fmt"]
    cap = cv2.VideoCapture(str(res.video))
    assert cap.get(cv2.CAP_PROP_FPS) == pytest.approx(29.97, abs=0.005)
    assert cap.get(cv2.CAP_PROP_FRAME_COUNT) == 8
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.mp4", "c.truth.h5"]


def test_motion_blur_smears_a_moving_marker_along_its_path():
    cam = Camera.for_frame(320, 240)
    scene = _scene(6, speed=1.5, gap=0.06)  # 1.5 m/s: 20 px per frame at 400 px/m
    sharp, blurred = (list(render_frames(scene, cam, RenderStyle(width=320, height=240,
                                                                 texture=False, exposure=e,
                                                                 marker_diameter=0.04)))
                      for e in (0.0, 1 / 60))

    def reddish_columns(img):
        red = (img[..., 2].astype(int) - img[..., 1]) > 25
        return np.flatnonzero(red.any(axis=0))

    cols_sharp, cols_blur = reddish_columns(sharp[3].image), reddish_columns(blurred[3].image)
    # 1/60 s at 1.5 m/s is 10 px of smear; the truth is the exposure's middle
    assert np.ptp(cols_blur) >= np.ptp(cols_sharp) + 8
    assert cols_blur.mean() == pytest.approx(cols_sharp.mean(), abs=1.0)


def test_flicker_beats_at_10_hz_at_29_97_frames_per_second():
    fps = 30000 / 1001
    gains = np.array([flicker_gain(i, fps, 0.05) for i in range(60)])
    assert 1.04 < gains.max() <= 1.05 and 0.95 <= gains.min() < 0.96
    spectrum = np.abs(np.fft.rfft(gains - 1))
    assert np.fft.rfftfreq(60, 1 / fps)[spectrum.argmax()] == pytest.approx(10.0, abs=0.6)


def test_shaded_markers_have_a_dark_rim_and_a_pale_highlight():
    cam = Camera.for_frame(640, 480)
    style = RenderStyle(texture=False, shading=1.0, marker_diameter=0.04)
    img = next(render_frames(_scene(), cam, style)).image
    x, y = np.round(cam.world_to_pixel(_scene().thumb[0])).astype(int)
    r = 0.02 * cam.px_per_m
    hsv = cv2.cvtColor(img, cv2.COLOR_BGR2HSV)
    top_left = hsv[int(y - 0.3 * r), int(x - 0.3 * r)]
    rim = hsv[int(y + 0.85 * r), int(x + 0.3 * r)]
    assert top_left[2] > rim[2] + 40  # lit from the top left
    yy, xx = np.mgrid[:480, :640]
    inside = hsv[..., 1][np.hypot(xx - x, yy - y) < 0.8 * r]
    assert inside.min() < 0.85 * np.median(inside)  # the highlight is paler


def test_recipe_render_table_takes_the_realism_options_and_names_the_nearest_key():
    style = render_style({"background": "photo:rocket", "codec": "h264", "exposure": 0.0167,
                          "flicker": 0.04, "shading": 0.6, "sleeve": "wrist",
                          "distractors": [{"colour": "wrist", "start": [0.1, 0.0],
                                           "shape": "bar", "aspect": 0.3, "angle_deg": 20}]})
    assert style.background == "photo:rocket" and style.distractors[0].shape == "bar"
    with pytest.raises(ValueError, match="did you mean 'background'"):
        render_style({"backgound": "photo:rocket"})
    with pytest.raises(ValueError, match="did you mean 'aspect'"):
        render_style({"distractors": [{"colour": "wrist", "start": [0, 0], "aspekt": 0.3}]})
    with pytest.raises(InputError, match="no such sample photograph"):
        render_style({"background": "photo:nonesuch"})
    with pytest.raises(ValueError, match="Distractor.shape"):
        Distractor("thumb", (0, 0), shape="star")

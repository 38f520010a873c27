import hashlib
import logging

import cv2
import numpy as np
import pytest

from perception.errors import InputError
from perception.io.video import FrameSource, TimeResolver, VideoWriter, write_video


def _frames(n, w=96, h=64):
    """Smooth frames (lossy codecs keep them) with a red band 4*i px wide."""
    yy, xx = np.mgrid[0:h, 0:w]
    base = np.stack([xx * 2, yy * 3, 120 + 0 * xx], axis=-1).astype(np.uint8)
    for i in range(n):
        frame = base.copy()
        frame[:, : 4 * i] = (0, 0, 220)  # tells frames apart after decoding
        yield frame


def _band_width(frame):
    return int(((frame[:, :, 2] > 180) & (frame[:, :, 1] < 60)).sum(axis=1).mean().round())


@pytest.mark.parametrize(
    "ext, fourcc, lossless",
    [(".mp4", "FMP4", False), (".avi", "MJPG", False), (".mkv", "FFV1", True)],
)
@pytest.mark.parametrize("fps", [25.0, 30.0, 60.0])
def test_codec_round_trip_with_container_timestamps(tmp_path, ext, fourcc, lossless, fps):
    path = tmp_path / f"clip{ext}"
    n = 12  # band up to 44 px of 96
    assert write_video(_frames(n), path, fps) == n
    src = FrameSource(path)
    assert (src.info.width, src.info.height) == (96, 64)
    assert src.info.fourcc.upper() == fourcc
    assert src.info.fps_nominal == pytest.approx(fps)
    assert src.info.sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    got = list(src)
    assert [i for i, _, _ in got] == list(range(n))
    times = np.array([t for _, t, _ in got])
    # FFV1 in Matroska keeps millisecond timestamps: 1 ms tolerance.
    np.testing.assert_allclose(times, np.arange(n) / fps, atol=1.001e-3)
    assert src.time_source == "container"
    assert src.complete and src.n_decoded == n
    assert src.attrs()["n_frames"] == n
    for (_, _, frame), want in zip(got, _frames(n), strict=True):
        if lossless:
            np.testing.assert_array_equal(frame, want)
        else:
            assert np.abs(frame.astype(int) - want).mean() < 6
            assert abs(_band_width(frame) - _band_width(want)) <= 2


def test_prefetch_and_direct_reading_agree_and_early_stop_is_clean(tmp_path):
    path = tmp_path / "clip.mkv"
    write_video(_frames(20), path, 30)
    direct = [(i, t, f) for i, t, f in FrameSource(path, prefetch=0)]
    threaded = [(i, t, f) for i, t, f in FrameSource(path, prefetch=3)]
    assert [(i, t) for i, t, _ in direct] == [(i, t) for i, t, _ in threaded]
    assert all(np.array_equal(a[2], b[2]) for a, b in zip(direct, threaded, strict=True))
    src = FrameSource(path, prefetch=2)
    for i, _, _ in src:
        if i == 3:
            break
    src.close()  # must not hang on a full queue
    assert not src.complete
    with pytest.raises(RuntimeError, match="once"):
        iter(src)


@pytest.mark.parametrize("ext", [".mp4", ".mkv"])
def test_one_decoder_thread_gives_the_same_frames(tmp_path, ext):
    path = tmp_path / f"clip{ext}"
    write_video(_frames(20), path, 30)
    default = list(FrameSource(path))
    src = FrameSource(path, threads=1)  # as a batch worker decodes
    assert src._cap.get(cv2.CAP_PROP_N_THREADS) == 1  # FFmpeg was told
    single = list(src)
    assert [(i, t) for i, t, _ in default] == [(i, t) for i, t, _ in single]
    assert all(np.array_equal(a[2], b[2]) for a, b in zip(default, single, strict=True))


def test_header_is_there_at_once_and_info_waits_for_the_hash(tmp_path, monkeypatch):
    import threading

    from perception.io import video

    path = tmp_path / "clip.mkv"
    write_video(_frames(4), path, 30)
    release = threading.Event()

    def slow_sha256(p):
        assert release.wait(10)
        return "digest"

    monkeypatch.setattr(video, "sha256_file", slow_sha256)
    src = FrameSource(path)
    assert (src.header.width, src.header.n_frames_header, src.header.sha256) == (96, 4, "")
    assert [i for i, _, _ in src] == [0, 1, 2, 3]  # frames flow while the hash is read
    release.set()
    assert src.info.sha256 == "digest" and src.info.width == 96


def test_writer_is_atomic(tmp_path):
    path = tmp_path / "clip.mp4"
    with pytest.raises(RuntimeError), VideoWriter(path, 30, (96, 64)) as vw:
        vw.write(next(_frames(1)))
        raise RuntimeError("renderer crashed")
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="expected a \\(64, 96, 3\\) uint8"):
        with VideoWriter(path, 30, (96, 64)) as vw:
            vw.write(np.zeros((10, 10, 3), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_unknown_extension_needs_a_codec(tmp_path):
    with pytest.raises(InputError, match="unknown video extension"):
        VideoWriter(tmp_path / "clip.webm", 30, (96, 64))


def test_missing_empty_and_non_video_files(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        FrameSource(tmp_path / "none.mp4")
    empty = tmp_path / "empty.mp4"
    empty.touch()
    with pytest.raises(InputError, match="empty file"):
        FrameSource(empty)
    text = tmp_path / "notes.mp4"
    text.write_text("not a video\n" * 100)
    with pytest.raises(InputError, match="not a readable video") as err:
        FrameSource(text)
    assert str(err.value).startswith(str(text))


def test_mp4_cut_before_its_index_is_unreadable(tmp_path):
    path = tmp_path / "clip.mp4"
    write_video(_frames(30), path, 30)
    cut = tmp_path / "cut.mp4"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    with pytest.raises(InputError):
        FrameSource(cut)


def test_truncated_avi_is_refused_unless_asked_to_keep_it(tmp_path, caplog):
    path = tmp_path / "clip.avi"
    write_video(_frames(30), path, 30)
    cut = tmp_path / "cut.avi"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    src = FrameSource(cut)
    assert src.info.n_frames_header == 30
    with pytest.raises(InputError, match="truncated or corrupt video: decoded .* of the 30"):
        sum(1 for _ in src)
    src = FrameSource(cut, keep_truncated=True)
    with caplog.at_level(logging.WARNING, logger="perception.io.video"):
        n = sum(1 for _ in src)
    assert 0 < n < 30
    assert src.attrs()["n_frames"] == n
    assert src.attrs()["n_frames_header"] == 30
    assert any("header claims" in r.getMessage() for r in caplog.records)


def test_a_frame_rate_no_camera_has_is_refused_and_fps_overrides_the_container(tmp_path):
    path = tmp_path / "fast.mp4"  # (OpenCV's AVI muxer cannot write 2000 frames/s at all)
    write_video(_frames(10), path, 2000.0)
    with pytest.raises(InputError, match="claims 2000 frames/s.*`fps`"):
        FrameSource(path)
    src = FrameSource(path, fps=25.0)
    times = [t for _, t, _ in src]
    np.testing.assert_allclose(times, np.arange(10) / 25.0)
    with pytest.raises(InputError, match="^fps: expected a frame rate"):
        FrameSource(path, fps=0.0)


def test_time_resolver_uses_container_times_and_falls_back_per_frame():
    r = TimeResolver(fps=25.0)
    assert [r(ms) for ms in (0.0, 40.0, 80.0)] == [0.0, 0.04, 0.08]
    assert r.source == "container"
    # A stream without timestamps reports 0 for every frame: index / fps.
    r = TimeResolver(fps=25.0)
    times = [r(0.0) for _ in range(4)]
    np.testing.assert_allclose(times, np.arange(4) / 25.0)
    assert r.source == "index/fps"
    # One bad stamp in a good stream: previous + 1/fps, recorded as mixed.
    r = TimeResolver(fps=10.0)
    times = [r(ms) for ms in (0.0, 100.0, float("nan"), 300.0)]
    np.testing.assert_allclose(times, [0.0, 0.1, 0.2, 0.3])
    assert r.source == "mixed"
    r = TimeResolver(fps=0.0)
    r(0.0)
    with pytest.raises(InputError, match="neither"):
        r(0.0)

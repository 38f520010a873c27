"""Frames decoded into the buffers of frames nothing holds any more (issue 45 item 5).

:class:`~perception.io.video.FramePool` decodes into a frame's buffer again
once its reference count says that only the pool holds it: a frame the
caller keeps (a look-ahead, a crop, a contact sheet) is never written over,
the pixels are the plain decoder's, and a buffer of another size is not
decoded into.
"""

from __future__ import annotations

import threading

import cv2
import numpy as np
import pytest

from perception.io.video import FramePool, FrameSource, write_video


def _frames(n, w=96, h=64):
    """Frames that differ everywhere from one to the next (noise, drawn once)."""
    rng = np.random.default_rng(5)
    for _ in range(n):
        yield rng.integers(0, 256, (h, w, 3), dtype=np.uint8)


def _plain(path):
    cap = cv2.VideoCapture(str(path))
    out = []
    while (got := cap.read())[0]:
        out.append(got[1])
    cap.release()
    return out


@pytest.mark.parametrize("prefetch", [0, 3])
def test_frames_kept_by_the_caller_are_never_decoded_into(tmp_path, prefetch):
    path = tmp_path / "clip.mkv"  # FFV1: lossless, every frame its own
    n = 40
    write_video(_frames(n), path, 30)
    plain = _plain(path)
    src = FrameSource(path, prefetch=prefetch)
    kept, views, copies = {}, {}, []
    for i, _, frame in src:
        copies.append(frame.copy())
        if i % 7 == 0:
            kept[i] = frame  # the frame itself
        if i % 11 == 5:
            views[i] = frame[10:30, 20:50]  # a crop holds its frame
    assert len(copies) == n
    assert all(np.array_equal(a, b) for a, b in zip(copies, plain, strict=True))
    for i, frame in kept.items():
        assert np.array_equal(frame, plain[i]), i
    for i, view in views.items():
        assert np.array_equal(view, plain[i][10:30, 20:50]), i
    # frames no one held were decoded into buffers again
    assert src._pool.n_reused >= n // 2


def test_a_consumer_that_drops_each_frame_decodes_into_few_buffers(tmp_path):
    path = tmp_path / "clip.mkv"
    write_video(_frames(30), path, 30)
    cap = cv2.VideoCapture(str(path))
    pool = FramePool(8)
    sums = [int(frame.sum()) for frame, _ in pool.read(cap)]
    cap.release()
    assert sums == [int(f.sum()) for f in _plain(path)]
    assert len(pool._buffers) == 2  # the frame in hand, the one being decoded
    assert pool.n_reused == 28


class _Capture:
    """A capture whose frames change size after the first four (as a stream may)."""

    def __init__(self):
        self.shapes = [(4, 6, 3)] * 4 + [(8, 6, 3)] * 4
        self.n = 0

    def read(self, image=None):
        if self.n == len(self.shapes):
            return False, None
        shape = self.shapes[self.n]
        self.n += 1
        if image is not None and image.shape == shape:
            image[...] = self.n
            return True, image
        return True, np.full(shape, self.n, np.uint8)  # OpenCV's new memory

    def get(self, _prop):
        return 1000.0 * self.n / 30


def test_a_frame_of_another_size_is_not_decoded_into_a_buffer_of_the_old_one():
    pool = FramePool(4)
    # the loop holds each frame while the next is read: two buffers take turns
    got = [(frame.shape, int(frame[0, 0, 0])) for frame, _ in pool.read(_Capture())]
    assert got == [((4, 6, 3), k) for k in range(1, 5)] + [((8, 6, 3), k) for k in range(5, 9)]
    assert [b.shape for b in pool._buffers] == [(8, 6, 3)] * 2  # the old size dropped
    assert pool.n_reused == 4  # frames 3, 4, 7 and 8


def test_the_pool_keeps_at_most_its_size():
    pool = FramePool(2)
    held = [pool.read_one(_Capture())[1] for _ in range(5)]  # all held: none free
    assert len(pool._buffers) == 2 and pool.n_reused == 0
    assert len({id(f) for f in held}) == 5


@pytest.mark.parametrize("size, ahead", [((96, 64), 32), ((1280, 720), 12), ((1920, 1080), 8)])
def test_read_ahead_by_default_is_what_fits_in_32_mib(tmp_path, size, ahead):
    path = tmp_path / "clip.mp4"
    w, h = size
    write_video([np.full((h, w, 3), 90, np.uint8)] * 2, path, 30)
    src = FrameSource(path, prefetch=None)
    assert src.prefetch == ahead
    assert [i for i, _, _ in src] == [0, 1]
    assert FrameSource(path).prefetch == 8  # the class's own default stays


def _decoding(path) -> bool:
    return any(t.name == f"decode:{path.name}" and t.is_alive() for t in threading.enumerate())


def test_decoding_ahead_starts_with_the_first_frame_taken(tmp_path):
    path = tmp_path / "clip.mkv"
    write_video(_frames(12), path, 30)
    src = FrameSource(path, prefetch=4)
    assert not _decoding(path)  # opening decodes the first frame only
    frames = iter(src)
    next(frames)
    assert _decoding(path)  # the caller's work on frame 0 overlaps decoding
    assert [i for i, _, _ in frames] == list(range(1, 12))
    src.close()
    assert not _decoding(path)

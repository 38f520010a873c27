"""What real cameras do to a clip: backgrounds from photographs, H.264, flicker, lit markers.

The renderer's own table is kind to the tracker; a researcher's footage is
not. These pieces let a rendered grasp be composited onto real pictures and
encoded the way cameras encode, so the tracker can be measured (and users can
stress their own setups) on what it will meet:

* :func:`load_background` — the table replaced by a photograph (a sample
  image that scikit-image ships, e.g. ``photo:coffee``, or an image file,
  ``photo:PATH``) or by the frames of a video (``video:PATH``, looped);
* :class:`H264Writer` — H.264 with 4:2:0 chroma (colour at half
  resolution, as phones and webcams record) through the ffmpeg binary that
  the ``imageio-ffmpeg`` package ships;
* :func:`flicker_gain` — mains-light flicker beating against the frame rate;
* :func:`shaded_disc`, :func:`shaded_band` — markers lit from one side:
  darker rims and a small specular highlight, whose desaturated pixels fail
  the colour gate as a real marker's do.

Motion blur from an exposure of finite length is drawn by
:func:`perception.synthetic.render.render_frames` (``RenderStyle.exposure``):
the moving parts are drawn at several instants of the exposure and averaged.
The optional packages are needed only when a style asks for them; a missing
one is named in a one-line error.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np

from perception.errors import InputError
from perception.io.atomic import atomic_path

__all__ = ["BACKGROUND_KINDS", "H264_CODECS", "H264Writer", "check_background", "flicker_gain",
           "load_background", "photo_names", "shaded_band", "shaded_disc"]

#: Prefixes of ``RenderStyle.background``.
BACKGROUND_KINDS = ("photo", "video")

#: ``RenderStyle.codec`` values written as H.264 (4:2:0) through imageio-ffmpeg.
H264_CODECS = ("h264", "avc1", "H264", "AVC1")

#: The extra that brings the optional packages (``pip install 'hammer-mv[footage]'``).
_EXTRA = "hammer-mv[footage]"

#: Mains lights flicker at twice the mains frequency; 100 Hz (50 Hz mains).
_MAINS_FLICKER_HZ = 100.0


def _require(module: str, what: str):
    try:
        return __import__(module, fromlist=["_"])
    except ImportError:
        raise InputError(f"{what} needs the package {module.split('.')[0]!r}: "
                         f"pip install '{_EXTRA}'") from None


def photo_names() -> tuple[str, ...]:
    """Colour photographs inside the scikit-image package usable as ``photo:NAME``.

    Only images shipped in the package itself are listed: nothing is downloaded.
    """
    skdata = _require("skimage.data", "photo backgrounds")
    folder = Path(skdata.__file__).parent
    names = []
    for path in sorted(folder.glob("*")):
        if path.suffix.lower() in (".png", ".jpg") and not path.stem.endswith("GRAY"):
            img = cv2.imread(os.fspath(path), cv2.IMREAD_UNCHANGED)
            if img is not None and img.ndim == 3:
                names.append(path.stem)
    return tuple(names)


def _photo(name: str) -> np.ndarray:
    """A bundled sample photograph or an image file, BGR uint8."""
    path = Path(name)
    if not path.suffix:
        skdata = _require("skimage.data", "photo backgrounds")
        candidates = [p for p in Path(skdata.__file__).parent.glob(f"{name}.*")
                      if p.suffix.lower() in (".png", ".jpg")]
        if not candidates:
            raise InputError(f"background photo:{name}: no such sample photograph (expected "
                             f"one of {', '.join(photo_names())}, or an image file)")
        path = candidates[0]
    img = cv2.imread(os.fspath(path), cv2.IMREAD_COLOR)
    if img is None:
        raise InputError("background: not a readable image", path)
    return img


def _cover(img: np.ndarray, width: int, height: int) -> np.ndarray:
    """Scale ``img`` to cover ``width x height`` and crop the centre."""
    h, w = img.shape[:2]
    s = max(width / w, height / h)
    big = cv2.resize(img, (max(width, round(w * s)), max(height, round(h * s))),
                     interpolation=cv2.INTER_AREA if s < 1 else cv2.INTER_LINEAR)
    y0 = (big.shape[0] - height) // 2
    x0 = (big.shape[1] - width) // 2
    return np.ascontiguousarray(big[y0:y0 + height, x0:x0 + width])


def load_background(spec: str, width: int, height: int) -> Iterator[np.ndarray]:
    """Background frames for a ``RenderStyle.background`` spec, endlessly.

    Parameters
    ----------
    spec : str
        ``photo:NAME`` (a sample photograph of scikit-image, see
        :func:`photo_names`, or the path of an image file) or
        ``video:PATH`` (a video's frames, looped).
    width, height : int
        Frame size, px; the picture is scaled to cover it and centred.

    Yields
    ------
    (height, width, 3) uint8
        BGR; a photograph yields the same (read-only) array every time.

    Raises
    ------
    InputError
        Unknown kind, unknown photograph, unreadable file, or the optional
        package missing.
    """
    kind, _, name = spec.partition(":")
    if kind not in BACKGROUND_KINDS or not name:
        raise InputError(f"background {spec!r}: expected photo:NAME or video:PATH")
    if kind == "photo":
        img = _cover(_photo(name), width, height)
        img.setflags(write=False)
        while True:
            yield img
    from perception.io.video import FrameSource

    while True:
        with FrameSource(name, prefetch=0, hash=False) as src:
            for _, _, frame in src:
                yield _cover(frame, width, height)


def check_background(spec: str | None) -> None:
    """Refuse a bad ``RenderStyle.background`` early (before anything is rendered).

    Parameters
    ----------
    spec : str or None
        The style's background (None: the drawn table).
    """
    if spec is None:
        return
    kind, _, name = spec.partition(":")
    if kind not in BACKGROUND_KINDS or not name:
        raise ValueError(f"RenderStyle.background: expected photo:NAME or video:PATH, "
                         f"got {spec!r}")


def flicker_gain(index: int, fps: float, amplitude: float, phase: float = 0.0) -> float:
    """Brightness gain of frame ``index`` under lights flickering at 100 Hz.

    A 1/60 s exposure integrates most of the 100 Hz cycle, but not all of it:
    what is left beats against the frame rate (10 Hz at 29.97 frames/s).

    Parameters
    ----------
    index : int
        Frame index.
    fps : float
        Frame rate, frames/s.
    amplitude : float
        Peak relative change of brightness (0.05: +-5 %).
    phase : float
        Phase of the flicker at frame 0, rad.
    """
    beat = _MAINS_FLICKER_HZ - fps * round(_MAINS_FLICKER_HZ / fps)
    return 1.0 + amplitude * math.sin(2 * math.pi * beat * index / fps + phase)


def _lit(light: np.ndarray, bgr, shading: float, spec: np.ndarray) -> np.ndarray:
    """The marker's colour under a light: diffuse scaled by ``light``, plus a white highlight."""
    base = np.asarray(bgr, np.float32)
    diffuse = (1.0 - shading) + shading * light
    col = diffuse[..., None] * base
    return col + (255.0 - col) * (0.75 * shading * spec)[..., None]


def _composite(img: np.ndarray, x0: int, y0: int, cover: np.ndarray, col: np.ndarray) -> None:
    h, w = cover.shape
    patch = img[y0:y0 + h, x0:x0 + w].astype(np.float32)
    out = patch * (1.0 - cover[..., None]) + col * cover[..., None]
    img[y0:y0 + h, x0:x0 + w] = np.clip(out + 0.5, 0, 255).astype(np.uint8)


def _patch(img: np.ndarray, centre, half: float):
    """Integer bounds of a square patch around ``centre``, clipped to the image."""
    h, w = img.shape[:2]
    cx, cy = centre[0], centre[1]
    x0, y0 = max(math.floor(cx - half), 0), max(math.floor(cy - half), 0)
    x1, y1 = min(math.ceil(cx + half) + 1, w), min(math.ceil(cy + half) + 1, h)
    if x1 <= x0 or y1 <= y0:
        return None
    yy, xx = np.mgrid[y0:y1, x0:x1].astype(np.float32)
    return x0, y0, xx - np.float32(cx), yy - np.float32(cy)


def shaded_disc(img: np.ndarray, centre, radius: float, bgr, shading: float) -> None:
    """Draw a ball-like marker lit from the top left, anti-aliased, in place.

    Parameters
    ----------
    img : (H, W, 3) uint8
        BGR image, drawn on in place.
    centre : (float, float)
        Centre (x, y), px.
    radius : float
        px.
    bgr : (int, int, int)
        The marker's colour in full light.
    shading : float
        0: flat colour; 1: a sphere's full shading (dark rim, highlight).
    """
    p = _patch(img, centre, radius + 2)
    if p is None:
        return
    x0, y0, dx, dy = p
    d = np.sqrt(dx * dx + dy * dy)
    cover = np.clip(radius + 0.5 - d, 0.0, 1.0)
    nz = np.sqrt(np.clip(1.0 - (d / max(radius, 1e-6)) ** 2, 0.0, 1.0))
    nx, ny = dx / max(radius, 1e-6), dy / max(radius, 1e-6)
    light = np.clip((-0.45 * nx - 0.45 * ny + 0.77 * nz), 0.0, 1.0)
    spec = np.clip((-0.3 * nx - 0.3 * ny + 0.9 * nz), 0.0, 1.0) ** 40
    _composite(img, x0, y0, cover, _lit(0.35 + 0.65 * light, bgr, shading, spec))


def shaded_band(img: np.ndarray, corners: np.ndarray, bgr, shading: float) -> None:
    """Draw a wrist band (a quadrilateral) lit like a cylinder across its long side.

    Parameters
    ----------
    img : (H, W, 3) uint8
        BGR image, drawn on in place.
    corners : (4, 2) float
        Corners in drawing order, px; edges 0-1 and 2-3 are the long sides.
    bgr : (int, int, int)
        The band's colour in full light.
    shading : float
        0: flat colour; 1: full shading (dark toward both ends).
    """
    corners = np.asarray(corners, np.float64)
    centre = corners.mean(axis=0)
    half = float(np.abs(corners - centre).max()) + 2
    p = _patch(img, centre, half)
    if p is None:
        return
    x0, y0, dx, dy = p
    h, w = dx.shape
    ss = 4  # coverage from a 4x supersampled mask
    mask = np.zeros((h * ss, w * ss), np.uint8)
    pts = (corners - (x0, y0) + 0.5) * ss - 0.5
    cv2.fillConvexPoly(mask, np.round(pts * 16).astype(np.int32), 255, cv2.LINE_AA, 4)
    cover = cv2.resize(mask, (w, h), interpolation=cv2.INTER_AREA).astype(np.float32) / 255
    axis = corners[1] - corners[0]
    length = float(np.hypot(*axis)) / 2
    u = (dx * axis[0] + dy * axis[1]) / (2 * length * length)  # -0.5..0.5 along the band
    light = np.sqrt(np.clip(1 - (2 * u) ** 2, 0, 1))
    spec = np.clip(1 - np.abs(u + 0.15) * 12, 0, 1) ** 2
    _composite(img, x0, y0, cover, _lit(0.3 + 0.7 * light, bgr, shading, spec * 0.5))


class H264Writer:
    """Write a clip as H.264 with 4:2:0 chroma in an ``.mp4``; it appears only when complete.

    The interface of :class:`perception.io.video.VideoWriter`; the encoder is
    the ffmpeg binary of the ``imageio-ffmpeg`` package (libx264, CRF 23,
    ``yuv420p``), as most cameras and phones record.

    Parameters
    ----------
    path : str or os.PathLike
        Output file (``.mp4``).
    fps : float
        Frame rate, frames/s (e.g. 30000/1001).
    size : (int, int)
        ``(width, height)``, px; both even (4:2:0 halves the chroma planes).
    crf : int
        x264 constant rate factor: 23 is its default, lower is better quality.
    """

    def __init__(self, path: str | os.PathLike, fps: float, size: tuple[int, int],
                 crf: int = 23):
        self.path = Path(path)
        self.fps = float(fps)
        self.size = (int(size[0]), int(size[1]))
        if self.size[0] % 2 or self.size[1] % 2:
            raise ValueError(f"H264Writer.size: 4:2:0 chroma needs even width and height, "
                             f"got {self.size}")
        self.crf = int(crf)
        self.n_written = 0
        self._stack: contextlib.ExitStack | None = None
        self._gen = None

    def __enter__(self) -> H264Writer:
        ffmpeg = _require("imageio_ffmpeg", "H.264 encoding")
        stack = contextlib.ExitStack()
        try:
            tmp = stack.enter_context(atomic_path(self.path))
            gen = ffmpeg.write_frames(
                os.fspath(tmp), self.size, fps=self.fps, codec="libx264", pix_fmt_in="bgr24",
                pix_fmt_out="yuv420p", quality=None, macro_block_size=1,
                ffmpeg_log_level="error",
                output_params=["-crf", str(self.crf), "-preset", "veryfast"])
            gen.send(None)
        except BaseException:
            stack.close()
            raise
        self._stack, self._gen = stack, gen
        return self

    def write(self, frame: np.ndarray) -> None:
        """Append one frame: ``(height, width, 3)`` uint8, BGR."""
        w, h = self.size
        if frame.shape != (h, w, 3) or frame.dtype != np.uint8:
            raise ValueError(f"H264Writer.write: expected a ({h}, {w}, 3) uint8 frame, "
                             f"got {frame.shape} {frame.dtype}")
        self._gen.send(np.ascontiguousarray(frame))
        self.n_written += 1

    def __exit__(self, exc_type, exc, tb) -> bool:
        assert self._stack is not None and self._gen is not None
        try:
            self._gen.close()
        except Exception:  # noqa: BLE001 - an encoder failure fails the block
            if exc_type is None:
                self._stack.__exit__(RuntimeError, None, None)
                raise
        if exc_type is None and self.n_written == 0:
            err = ValueError(f"{self.path}: no frames written")
            self._stack.__exit__(ValueError, err, None)
            raise err
        return bool(self._stack.__exit__(exc_type, exc, tb))

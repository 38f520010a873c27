"""Render synthetic top-down grasp clips with ground truth.

A :class:`Scene` holds the wrist, index-finger and thumb paths in the world
frame (DESIGN.md: metres, origin at the object centre, +y from the
demonstrator's start toward the object) and the object. A :class:`Camera`
maps world to pixels by a similarity transform (scale, rotation, pixel y
down). A :class:`RenderStyle` says how hard the clip is: textured table,
skin-coloured hand and forearm under the markers (skin's hue is close to the
red thumb marker's), similar-hue distractors, occlusions, camera noise, blur,
a lighting gradient, frame rate, resolution and codec.

:func:`render_frames` generates frames one at a time; :func:`render_clip`
writes them to a video and the ground truth beside it as ``<clip>.truth.h5``
in the tracks schema (true pixel centre of every marker as drawn, status 0,
likelihood 1; root attributes ``label``, ``params``, ``seed``, ``camera``,
``style`` as JSON; ``/truth/visible`` (T, M) says which markers were drawn).

The interface is array-based so that stimuli from the grasp model plug in:
build a :class:`Scene` from its world-frame paths and call
:func:`render_clip`. :meth:`Scene.reach_to_grasp` is an analytic stand-in
(minimum-jerk transport, bell-shaped aperture) for tests and benchmarks.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterator, Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, NamedTuple

import cv2
import numpy as np

from perception.tracking.markers import MarkerSet, default_markers
from perception.io.tracks import TracksWriter
from perception.io.video import VideoWriter, codec_for, sha256_file

#: BGR of the hand and forearm. Hue ~10 (OpenCV units), saturation ~110:
#: beside the red thumb marker's hue, below its saturation gate.
SKIN_BGR = (120, 150, 215)

#: BGR of the plain table and base of the texture: low saturation.
TABLE_BGR = (140, 160, 178)

_SHIFT = 4  # fractional bits of OpenCV drawing coordinates (1/16 px)
_ONE = 1 << _SHIFT
_AA_CIRCLE_EXCESS_PX = 0.6


@dataclass(frozen=True)
class Camera:
    """World (m) to image (px) similarity transform.

    ``pixel = origin_px + px_per_m * R(angle) @ (x, -y)``: at ``angle_deg = 0``
    world +x points right and +y up the image; a positive angle rotates the
    world counter-clockwise on screen, so the approach need not be vertical.

    Parameters
    ----------
    px_per_m : float
        Scale, px/m.
    origin_px : (float, float)
        Image position of the world origin (the object centre), px.
    angle_deg : float
        Rotation of the world axes in the image, degrees.
    """

    px_per_m: float = 800.0
    origin_px: tuple[float, float] = (320.0, 144.0)
    angle_deg: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.px_per_m) and self.px_per_m > 0):
            raise ValueError(f"Camera.px_per_m: expected a positive scale, got {self.px_per_m!r}")
        origin = tuple(float(v) for v in self.origin_px)
        if len(origin) != 2 or not all(math.isfinite(v) for v in origin):
            raise ValueError(f"Camera.origin_px: expected (x, y) px, got {self.origin_px!r}")
        object.__setattr__(self, "origin_px", origin)
        object.__setattr__(self, "px_per_m", float(self.px_per_m))
        object.__setattr__(self, "angle_deg", float(self.angle_deg))

    @classmethod
    def for_frame(
        cls,
        width: int,
        height: int,
        *,
        px_per_m: float | None = None,
        angle_deg: float = 0.0,
        origin: tuple[float, float] = (0.5, 0.3),
    ) -> Camera:
        """A camera whose frame height spans 0.6 m of table, object 30 % from the top.

        Parameters
        ----------
        width, height : int
            Frame size, px.
        px_per_m : float, optional
            Scale, px/m (default ``height / 0.6``).
        angle_deg : float
            See :class:`Camera`.
        origin : (float, float)
            Object position as fractions of (width, height).
        """
        scale = height / 0.6 if px_per_m is None else px_per_m
        return cls(scale, (origin[0] * width, origin[1] * height), angle_deg)

    @property
    def matrix(self) -> np.ndarray:
        """(2, 3) affine matrix: ``pixel = M[:, :2] @ world + M[:, 2]``."""
        a = math.radians(self.angle_deg)
        c, s = math.cos(a), math.sin(a)
        k = self.px_per_m
        return np.array([[k * c, -k * s, self.origin_px[0]], [-k * s, -k * c, self.origin_px[1]]])

    def world_to_pixel(self, xy: np.ndarray) -> np.ndarray:
        """Map (..., 2) world positions (m) to (..., 2) pixels."""
        m = self.matrix
        return np.asarray(xy, dtype=np.float64) @ m[:, :2].T + m[:, 2]

    def pixel_to_world(self, px: np.ndarray) -> np.ndarray:
        """Map (..., 2) pixels to (..., 2) world positions (m)."""
        m = self.matrix
        # M[:, :2] / k is a reflection, its own inverse.
        return (np.asarray(px, dtype=np.float64) - m[:, 2]) @ m[:, :2] / self.px_per_m**2


def world_to_pixel(camera: Camera, xy: np.ndarray) -> np.ndarray:
    """Ground-truth mapping of world positions ``xy`` (..., 2) m to pixels (..., 2).

    Parameters
    ----------
    camera : Camera
        The camera that rendered the clip.
    xy : (..., 2) array
        World positions, m.
    """
    return camera.world_to_pixel(xy)


@dataclass(frozen=True)
class Distractor:
    """A disc of a marker's colour (or any colour) on the table.

    Parameters
    ----------
    colour : str or (int, int, int)
        A marker name (its render colour is used) or BGR.
    start : (float, float)
        World position, m, at the first visible frame.
    end : (float, float), optional
        World position at the last visible frame; linear motion between
        (``None``: static).
    diameter : float
        m.
    frames : (int, int), optional
        Visible frames ``[first, stop)`` (default: the whole clip).
    """

    colour: str | tuple[int, int, int]
    start: tuple[float, float]
    end: tuple[float, float] | None = None
    diameter: float = 0.02
    frames: tuple[int, int] | None = None

    def position(self, index: int, n_frames: int) -> np.ndarray | None:
        """World position (2,) m at frame ``index``, or None when not visible."""
        first, stop = self.frames if self.frames is not None else (0, n_frames)
        if not first <= index < stop:
            return None
        start = np.asarray(self.start, dtype=np.float64)
        if self.end is None or stop - first <= 1:
            return start
        w = (index - first) / (stop - first - 1)
        return start + w * (np.asarray(self.end, dtype=np.float64) - start)


@dataclass(frozen=True)
class Occlusion:
    """Hide ``marker`` (not drawn) during frames ``[start, stop)``."""

    marker: str
    start: int
    stop: int


@dataclass(frozen=True)
class RenderStyle:
    """How a clip looks.

    Parameters
    ----------
    fps : float
        Frame rate, frames/s (30; 25 and 60 work).
    width, height : int
        Frame size, px (640 x 480; 1280 x 720 works).
    codec : str, optional
        FourCC; default from the output extension (``.mp4`` mp4v, ``.avi``
        MJPG, ``.mkv`` FFV1).
    texture : bool
        Textured (wood-like) table instead of a plain one.
    hand : bool
        Draw a skin-coloured hand and forearm under the markers.
    marker_diameter : float
        Thumb and finger marker discs, m.
    band_size : (float, float)
        Wrist band (across, along the forearm), m.
    noise_sd : float
        Camera noise, grey levels (Gaussian, per channel).
    blur_sigma : float
        Optical blur, px (Gaussian sigma; 0 = none).
    lighting : float
        Lighting gradient: brightness falls linearly to ``1 - lighting`` of
        full across the frame (0 = even light).
    lighting_angle_deg : float
        Direction of the gradient in the image (0 = darkening to the right).
    distractors : tuple of Distractor
        Similar-hue objects on the table.
    occlusions : tuple of Occlusion
        Intervals in which a marker is hidden.
    """

    fps: float = 30.0
    width: int = 640
    height: int = 480
    codec: str | None = None
    texture: bool = True
    hand: bool = False
    marker_diameter: float = 0.02
    band_size: tuple[float, float] = (0.07, 0.025)
    noise_sd: float = 0.0
    blur_sigma: float = 0.0
    lighting: float = 0.0
    lighting_angle_deg: float = 30.0
    distractors: tuple[Distractor, ...] = ()
    occlusions: tuple[Occlusion, ...] = ()

    def __post_init__(self) -> None:
        if not (math.isfinite(self.fps) and self.fps > 0):
            raise ValueError(f"RenderStyle.fps: expected a positive frame rate, got {self.fps!r}")
        if int(self.width) < 16 or int(self.height) < 16:
            raise ValueError(
                f"RenderStyle: expected width, height >= 16 px, got {self.width} x {self.height}"
            )
        for name in ("noise_sd", "blur_sigma", "marker_diameter"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"RenderStyle.{name}: expected >= 0, got {getattr(self, name)!r}")
        if not 0 <= self.lighting < 1:
            raise ValueError(
                f"RenderStyle.lighting: expected 0 <= lighting < 1, got {self.lighting!r}"
            )
        object.__setattr__(self, "distractors", tuple(self.distractors))
        object.__setattr__(self, "occlusions", tuple(self.occlusions))

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (JSON-ready)."""
        return asdict(self)


@dataclass(frozen=True, eq=False)
class Scene:
    """What moves: hand marker paths and the object, in the world frame.

    Parameters
    ----------
    wrist, finger, thumb : (T, 2) array_like
        Marker centres, m.
    object_centre : (float, float)
        m (the world origin by definition, but settable).
    object_diameter : float
        m (0.10: the thesis's ball).
    """

    wrist: np.ndarray
    finger: np.ndarray
    thumb: np.ndarray
    object_centre: tuple[float, float] = (0.0, 0.0)
    object_diameter: float = 0.10

    def __post_init__(self) -> None:
        n = None
        for name in ("wrist", "finger", "thumb"):
            arr = np.asarray(getattr(self, name), dtype=np.float64)
            if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
                raise ValueError(f"Scene.{name}: expected shape (T, 2) in m, got {arr.shape}")
            if n is not None and arr.shape[0] != n:
                raise ValueError(
                    f"Scene.{name}: expected T = {n} rows like wrist, got {arr.shape[0]}"
                )
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"Scene.{name}: expected finite positions, found NaN or inf")
            n = arr.shape[0]
            object.__setattr__(self, name, arr)
        if not self.object_diameter > 0:
            raise ValueError(f"Scene.object_diameter: expected > 0 m, got {self.object_diameter!r}")
        object.__setattr__(self, "object_centre", tuple(float(v) for v in self.object_centre))

    @property
    def n_frames(self) -> int:
        """T."""
        return int(self.wrist.shape[0])

    def positions(self, names: tuple[str, ...]) -> np.ndarray:
        """(T, M) x 2 world positions of the named markers (the object is static), m."""
        out = np.empty((self.n_frames, len(names), 2))
        for j, name in enumerate(names):
            out[:, j] = self.object_centre if name == "object" else getattr(self, name)
        return out

    @classmethod
    def reach_to_grasp(
        cls,
        n_frames: int,
        fps: float,
        *,
        start: tuple[float, float] = (0.0, -0.40),
        onset: float = 0.3,
        duration: float = 1.0,
        aperture: tuple[float, float] = (0.035, 0.14),
        peak_at: float = 0.7,
        object_diameter: float = 0.10,
        wrist_offset: float = 0.06,
    ) -> Scene:
        """Analytic reach-to-grasp: minimum-jerk transport, aperture up then down.

        A stand-in for grasp-model stimuli in tests and benchmarks. The wrist
        moves from ``start`` to ``wrist_offset`` short of the object centre
        along +y; the digit tips lead the wrist by ``wrist_offset`` and sit
        ``aperture/2`` either side of the approach axis (thumb at -x, a right
        hand seen from above), so they end on the object's surface.

        Parameters
        ----------
        n_frames : int
            T.
        fps : float
            frames/s.
        start : (float, float)
            Wrist start, m.
        onset, duration : float
            Movement start and duration, s; the hand rests before and after.
        aperture : (float, float)
            Initial and maximal grip aperture, m; the final one is the object
            diameter.
        peak_at : float
            Time of maximal aperture as a fraction of the movement.
        object_diameter : float
            m.
        wrist_offset : float
            m.
        """
        t = np.arange(n_frames) / fps
        tau = np.clip((t - onset) / duration, 0.0, 1.0)
        s = _min_jerk(tau)
        start_arr = np.asarray(start, dtype=np.float64)
        goal = np.array([0.0, -wrist_offset])
        wrist = start_arr + s[:, None] * (goal - start_arr)
        a0, amax = aperture
        opening = _min_jerk(np.clip(tau / peak_at, 0, 1))
        closing = _min_jerk(np.clip((tau - peak_at) / (1 - peak_at), 0, 1))
        ap = a0 + (amax - a0) * opening + (object_diameter - amax) * closing
        ahead = wrist + np.array([0.0, wrist_offset])
        lateral = np.stack([ap / 2, np.zeros_like(ap)], axis=1)
        return cls(wrist, ahead + lateral, ahead - lateral, object_diameter=object_diameter)


def _min_jerk(tau: np.ndarray) -> np.ndarray:
    return tau**3 * (10 - 15 * tau + 6 * tau**2)


class RenderedFrame(NamedTuple):
    """One rendered frame and its ground truth.

    index : int; time : s; image : (H, W, 3) uint8 BGR;
    truth : (M, 2) px marker centres as drawn; visible : (M,) bool.
    """

    index: int
    time: float
    image: np.ndarray
    truth: np.ndarray
    visible: np.ndarray


@dataclass(frozen=True)
class RenderResult:
    """Files written by :func:`render_clip`.

    Attributes
    ----------
    video : Path
        The clip.
    truth : Path
        Its ground truth (``<stem>.truth.h5``, tracks schema).
    n_frames : int
        Frames rendered.
    """

    video: Path
    truth: Path
    n_frames: int


def truth_path_for(video: str | os.PathLike) -> Path:
    """Ground-truth file of a rendered clip ``video``: ``<stem>.truth.h5`` beside it."""
    v = Path(video)
    return v.with_name(f"{v.stem}.truth.h5")


# -- drawing ------------------------------------------------------------------
def _fixed(px: np.ndarray) -> np.ndarray:
    """Pixels -> OpenCV fixed-point int32 coordinates (1/16 px)."""
    return np.round(np.asarray(px) * _ONE).astype(np.int32)


def _disc(img: np.ndarray, centre_px: np.ndarray, radius_px: float, bgr) -> None:
    c = _fixed(centre_px)
    # OpenCV's filled anti-aliased circle covers about 0.6 px more radius than
    # asked for (81.2 px across for a 40 px radius): without this the ground
    # truth's object would be 1.5 % smaller than drawn. Discs under 4 px keep
    # their drawn size (only their centres matter, and they must stay findable).
    r = radius_px - _AA_CIRCLE_EXCESS_PX if radius_px >= 4.0 else radius_px
    cv2.circle(img, (int(c[0]), int(c[1])), int(round(r * _ONE)), bgr, -1, cv2.LINE_AA, _SHIFT)


def _poly(img: np.ndarray, pts_px: np.ndarray, bgr) -> None:
    cv2.fillConvexPoly(img, _fixed(pts_px), bgr, cv2.LINE_AA, _SHIFT)


def _rect(centre: np.ndarray, half: tuple[float, float]) -> np.ndarray:
    """Corners (4, 2) of an axis-aligned world rectangle."""
    hx, hy = half
    return centre + np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])


def _unit_circle(n: int = 32) -> np.ndarray:
    """(n, 2) points on the unit circle (a polygon for ellipses drawn in world units)."""
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack([np.cos(a), np.sin(a)], axis=1)


def _draw_hand(img, camera: Camera, wrist, finger, thumb) -> None:
    """Forearm, palm and two digits, in skin colour, in the world frame."""
    k = camera.px_per_m
    to_px = camera.world_to_pixel
    # The hand frame is translated, never rotated (DESIGN.md): fingers point +y.
    forearm = np.array([[-0.033, 0.0], [0.033, 0.0], [0.03, -0.32], [-0.03, -0.32]]) + wrist
    _poly(img, to_px(forearm), SKIN_BGR)
    palm = wrist + np.array([0.0, 0.022]) + _unit_circle() * np.array([0.038, 0.03])
    _poly(img, to_px(palm), SKIN_BGR)
    width = max(1, int(round(0.016 * k)))
    for base, tip in ((wrist + (0.022, 0.04), finger), (wrist + (-0.03, 0.015), thumb)):
        b, t = _fixed(to_px(base)), _fixed(to_px(tip))
        cv2.line(
            img,
            (int(b[0]), int(b[1])),
            (int(t[0]), int(t[1])),
            SKIN_BGR,
            width,
            cv2.LINE_AA,
            _SHIFT,
        )


def _background(style: RenderStyle, rng: np.random.Generator) -> np.ndarray:
    """Table image (H, W, 3) uint8: plain or wood-like texture, low saturation."""
    h, w = style.height, style.width
    base = np.array(TABLE_BGR, dtype=np.float32)
    if not style.texture:
        return np.broadcast_to(base.astype(np.uint8), (h, w, 3)).copy()
    coarse = rng.standard_normal((h // 40 + 3, w // 40 + 3)).astype(np.float32)
    blotch = cv2.resize(coarse, (w, h), interpolation=cv2.INTER_CUBIC)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    period = 0.03 * max(h, w)
    grain = np.sin(2 * np.pi * (yy * 0.94 + xx * 0.34) / period + 2.5 * blotch)
    fine = rng.standard_normal((h, w)).astype(np.float32)
    lum = 1.0 + 0.08 * blotch + 0.06 * grain + 0.03 * fine
    img = lum[..., None] * base
    return np.clip(img, 0, 255).astype(np.uint8)


def _lighting_gain(style: RenderStyle) -> np.ndarray | None:
    if style.lighting <= 0:
        return None
    h, w = style.height, style.width
    a = math.radians(style.lighting_angle_deg)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    ramp = xx * math.cos(a) + yy * math.sin(a)
    ramp = (ramp - ramp.min()) / max(float(ramp.max() - ramp.min()), 1e-9)
    gain = 1.0 - style.lighting * ramp
    return np.repeat(gain[..., None], 3, axis=2)


class _NoiseBank:
    """Camera noise without drawing H*W*3 normals per frame.

    A few noise images a little larger than the frame; each frame takes one at
    a random offset, so consecutive frames' noise is unrelated but the cost
    is one slice.
    """

    def __init__(self, style: RenderStyle, rng: np.random.Generator, n: int = 4, pad: int = 16):
        h, w = style.height, style.width
        self.rng, self.pad, self.h, self.w = rng, pad, h, w
        self.bank = [
            np.round(
                rng.standard_normal((h + pad, w + pad, 3), dtype=np.float32) * style.noise_sd
            ).astype(np.int16)
            for _ in range(n)
        ]

    def next(self) -> np.ndarray:
        k, dy, dx = self.rng.integers(len(self.bank)), *self.rng.integers(self.pad, size=2)
        return self.bank[k][dy : dy + self.h, dx : dx + self.w]


def render_frames(
    scene: Scene,
    camera: Camera,
    style: RenderStyle | None = None,
    *,
    seed: int = 0,
    markers: MarkerSet | None = None,
) -> Iterator[RenderedFrame]:
    """Generate the clip's frames one at a time (streaming; nothing is kept).

    Parameters
    ----------
    scene : Scene
        Paths (T frames) and object, world frame.
    camera : Camera
        World -> pixel mapping.
    style : RenderStyle, optional
        Appearance (default :class:`RenderStyle()`).
    seed : int
        Seed of every random draw (texture, noise); same seed, same frames.
    markers : MarkerSet, optional
        Colour models (default :func:`perception.tracking.markers.default_markers`);
        must contain thumb, finger, wrist and object.

    Yields
    ------
    RenderedFrame
        ``(index, time, image, truth, visible)``; see :class:`RenderedFrame`.
    """
    style = RenderStyle() if style is None else style
    markers = default_markers() if markers is None else markers
    names = markers.names
    _check_scene(scene, style, markers)
    rng = np.random.default_rng(seed)
    background = _background(style, rng)
    gain = _lighting_gain(style)
    noise = _NoiseBank(style, rng) if style.noise_sd > 0 else None
    world = scene.positions(names)  # (T, M, 2) m
    truth = camera.world_to_pixel(world)  # (T, M, 2) px
    visible = visibility(style, names, scene.n_frames)
    k = camera.px_per_m
    colours = {m.name: m.bgr for m in markers}
    band = np.array(style.band_size) / 2
    band_corners = _rect(np.zeros(2), (band[0], band[1]))
    for i in range(scene.n_frames):
        img = background.copy()
        if visible[i, names.index("object")]:
            _disc(
                img,
                truth[i, names.index("object")],
                scene.object_diameter / 2 * k,
                colours["object"],
            )
        for d in style.distractors:
            pos = d.position(i, scene.n_frames)
            if pos is not None:
                bgr = colours[d.colour] if isinstance(d.colour, str) else tuple(d.colour)
                _disc(img, camera.world_to_pixel(pos), d.diameter / 2 * k, bgr)
        if style.hand:
            _draw_hand(img, camera, scene.wrist[i], scene.finger[i], scene.thumb[i])
        for j, name in enumerate(names):
            if name == "object" or not visible[i, j]:
                continue
            if name == "wrist":
                _poly(img, camera.world_to_pixel(band_corners + scene.wrist[i]), colours[name])
            else:
                _disc(img, truth[i, j], style.marker_diameter / 2 * k, colours[name])
        if gain is not None:
            img = cv2.multiply(img, gain, dtype=cv2.CV_8U)
        if style.blur_sigma > 0:
            img = cv2.GaussianBlur(img, (0, 0), style.blur_sigma)
        if noise is not None:
            img = cv2.add(img, noise.next(), dtype=cv2.CV_8U)
        yield RenderedFrame(i, i / style.fps, img, truth[i], visible[i])


def visibility(style: RenderStyle, names: tuple[str, ...], n_frames: int) -> np.ndarray:
    """Which markers are drawn in which frame.

    Parameters
    ----------
    style : RenderStyle
        Its ``occlusions`` hide markers.
    names : tuple of str
        Marker names, M of them.
    n_frames : int
        T.

    Returns
    -------
    (T, M) bool
        False where an :class:`Occlusion` hides the marker.
    """
    vis = np.ones((n_frames, len(names)), dtype=bool)
    for occ in style.occlusions:
        vis[max(occ.start, 0) : max(occ.stop, 0), names.index(occ.marker)] = False
    return vis


def _check_scene(scene: Scene, style: RenderStyle, markers: MarkerSet) -> None:
    names = markers.names
    missing = [n for n in ("thumb", "finger", "wrist", "object") if n not in names]
    if missing:
        raise ValueError(
            f"render: markers: expected thumb, finger, wrist, object; missing {missing}"
        )
    for occ in style.occlusions:
        if occ.marker not in names:
            raise ValueError(f"RenderStyle.occlusions: unknown marker {occ.marker!r}")
    for d in style.distractors:
        if isinstance(d.colour, str) and d.colour not in names:
            raise ValueError(f"RenderStyle.distractors: unknown marker colour {d.colour!r}")


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.integer, np.floating, np.bool_)):
        return value.item()
    if isinstance(value, Path):
        return os.fspath(value)
    if isinstance(value, (set, frozenset)):
        return sorted(value)
    raise TypeError(f"not JSON-serialisable: {type(value).__name__}")


def render_clip(
    scene: Scene,
    camera: Camera,
    style: RenderStyle | None,
    out_path: str | os.PathLike,
    *,
    seed: int = 0,
    label: str | None = None,
    params: Mapping[str, Any] | None = None,
    markers: MarkerSet | None = None,
) -> RenderResult:
    """Render a clip to ``out_path`` and its ground truth to ``<stem>.truth.h5``.

    Frames are generated and written one at a time. Both files are written
    under temporary names and appear only when both are complete.

    Parameters
    ----------
    scene, camera, style, seed, markers
        As :func:`render_frames`.
    out_path : str or os.PathLike
        Video file (``.mp4``, ``.avi``, ``.mkv``; see :class:`RenderStyle`).
    label : str, optional
        Stimulus label (e.g. ``"normal"``, ``"delayed_opening"``).
    params : mapping, optional
        Stimulus parameters; stored as JSON in the truth file's root attrs.

    Returns
    -------
    RenderResult
    """
    style = RenderStyle() if style is None else style
    markers = default_markers() if markers is None else markers
    out = Path(out_path)
    codec = codec_for(out, style.codec)
    truth_path = truth_path_for(out)
    root = {
        "label": label or "",
        "params": json.dumps(dict(params or {}), default=_jsonable),
        "seed": int(seed),
        "camera": json.dumps(asdict(camera)),
        "style": json.dumps(style.to_dict(), default=_jsonable),
        "object_diameter": scene.object_diameter,
    }
    tracker = {"method": "render", "colour_models": markers.to_json()}
    n_markers = len(markers)
    ones = np.ones(n_markers, np.float32)
    zeros = np.zeros(n_markers, np.int8)
    video_done = False
    try:
        with TracksWriter(truth_path, markers.names, tracker=tracker, attrs=root) as tw:
            with VideoWriter(out, style.fps, (style.width, style.height), codec) as vw:
                for fr in render_frames(scene, camera, style, seed=seed, markers=markers):
                    vw.write(fr.image)
                    tw.append(fr.index, fr.time, fr.truth, ones, zeros)
            video_done = True
            tw.update(
                video={
                    "path": os.fspath(out),
                    "sha256": sha256_file(out),
                    "fps_nominal": float(style.fps),
                    "n_frames": scene.n_frames,
                    "width": style.width,
                    "height": style.height,
                    "fourcc": codec,
                }
            )
            tw.file.create_dataset(
                "truth/visible", data=visibility(style, markers.names, scene.n_frames)
            )
    except BaseException:
        if video_done:  # the truth failed after the video appeared: take it back
            out.unlink(missing_ok=True)
        raise
    return RenderResult(out, truth_path, scene.n_frames)


__all__ = [
    "Camera",
    "Distractor",
    "Occlusion",
    "RenderResult",
    "RenderStyle",
    "RenderedFrame",
    "Scene",
    "render_clip",
    "render_frames",
    "truth_path_for",
    "visibility",
    "world_to_pixel",
]

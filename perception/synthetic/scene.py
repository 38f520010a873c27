"""What a synthetic clip shows: the scene, the camera and the rendering style.

A :class:`Scene` holds the wrist, index-finger and thumb paths in the world
frame (metres, origin at the object centre, +y from the demonstrator's start
toward the object; docs/coordinates.md) and the object. A :class:`Camera`
maps world to pixels by the similarity transform of :mod:`perception.geometry`.
A :class:`RenderStyle` says how hard the clip is: textured table,
skin-coloured hand and forearm under the markers (skin's hue is close to the
red thumb marker's), similar-hue :class:`Distractor` discs and bars,
:class:`Occlusion` intervals, camera noise, blur, a lighting gradient, frame
rate, resolution and codec, and what real cameras add
(:mod:`perception.synthetic.footage`): a photograph or footage under the
hand, motion blur from the exposure, flicker, lit markers, H.264.
:mod:`perception.synthetic.render` draws them.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field

from perception.errors import InputError
from perception.geometry import DEFAULT_OBJECT_DIAMETER, SimilarityTransform
from perception.limits import MAX_FPS, MAX_FRAME_SIDE
from perception.synthetic.footage import check_background
from perception.tracking.markers import MARKER_NAMES
from perception.validation import Int, Tuple, declared

__all__ = ["Camera", "Colour", "Distractor", "Occlusion", "RenderStyle", "Scene", "visibility"]

#: Largest frame index, and largest distance from the object, m, of a distractor.
_MAX_FRAME = 10_000_000
_Frame = Annotated[Int, Field(ge=0, le=_MAX_FRAME)]
_Metres = Annotated[float, Field(ge=-10, le=10)]
_Degrees = Annotated[float, Field(ge=-360, le=360)]
_Byte = Annotated[Int, Field(ge=0, le=255)]
_Span = Annotated[float, Field(gt=0, le=1)]
_PX = "width and height in px"
#: A marker's name (its render colour) or BGR, 0..255 each.
Colour = Literal[MARKER_NAMES] | Annotated[tuple[_Byte, _Byte, _Byte], Tuple]


@dataclass(frozen=True)
class Camera:
    """Where the renderer's camera looks: world (m) to image (px).

    ``(px - ox, oy - py) = px_per_m * R(angle) @ (x, y)`` with ``R`` the
    counter-clockwise rotation and ``(ox, oy) = origin_px``: at
    ``angle_deg = 0`` world +x points right and +y up the image; a positive
    angle rotates the world counter-clockwise on screen, so the approach
    need not be vertical.
    The mapping itself is :attr:`transform`, the same similarity transform
    observation uses to go back from pixels to metres.

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
        object.__setattr__(self, "origin_px", tuple(float(v) for v in self.origin_px))
        object.__setattr__(self, "px_per_m", float(self.px_per_m))
        object.__setattr__(self, "angle_deg", float(self.angle_deg))
        self.transform  # noqa: B018 - validates scale, origin and angle

    @classmethod
    def for_frame(cls, width: int, height: int, *, px_per_m: float | None = None,
                  angle_deg: float = 0.0, origin: tuple[float, float] = (0.5, 0.3)) -> Camera:
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
    def transform(self) -> SimilarityTransform:
        """The world <-> pixel similarity (the model's +y at ``angle_deg + 90`` degrees)."""
        return SimilarityTransform(self.origin_px, self.px_per_m,
                                   math.radians(self.angle_deg) + math.pi / 2)

    @property
    def matrix(self) -> np.ndarray:
        """(2, 3) affine matrix: ``pixel = M[:, :2] @ world + M[:, 2]``."""
        return self.transform.matrix

    def world_to_pixel(self, xy: np.ndarray) -> np.ndarray:
        """Map (..., 2) world positions ``xy`` (m) to (..., 2) pixels."""
        return self.transform.to_pixels(xy)

    def pixel_to_world(self, px: np.ndarray) -> np.ndarray:
        """Map (..., 2) pixels ``px`` to (..., 2) world positions (m)."""
        return self.transform.to_model(px)


@declared
class Distractor:
    """A disc of a marker's colour (or any colour) on the table.

    Parameters
    ----------
    colour : str or (int, int, int)
        A marker name (its render colour is used) or BGR, 0..255 each.
    start : (float, float)
        World position, m, at the first visible frame.
    end : (float, float), optional
        World position at the last visible frame; linear motion between
        (``None``: static).
    diameter : float
        m; a bar's length.
    frames : (int, int), optional
        Visible frames ``[first, stop)`` (default: the whole clip).
    shape : {"disc", "bar"}
        A disc (an ellipse when ``aspect`` < 1) or a rectangle (a stripe,
        a pen, a sleeve's cuff).
    aspect : float
        Width over length (0 < aspect <= 1; 1: round or square).
    angle_deg : float
        Direction of the long axis in the world frame, degrees from +x.
    """

    colour: Colour
    start: Annotated[tuple[_Metres, _Metres], Tuple]
    end: Annotated[tuple[_Metres, _Metres], Tuple] | None = None
    diameter: Annotated[float, Field(gt=0, le=1)] = 0.02
    frames: Annotated[tuple[_Frame, _Frame], Tuple] | None = None
    shape: Literal["disc", "bar"] = "disc"
    aspect: Annotated[float, Field(gt=0, le=1)] = 1.0
    angle_deg: _Degrees = 0.0

    def __post_init__(self) -> None:
        if self.frames is not None and self.frames[0] > self.frames[1]:
            raise InputError(f"expected [first, stop], got {list(self.frames)}",
                             location=("Distractor", "frames"))

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


@declared
class Occlusion:
    """Hide ``marker`` (not drawn) during frames ``[start, stop)``."""

    marker: Literal[MARKER_NAMES]
    start: _Frame
    stop: _Frame


@declared
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
    background : str, optional
        Replace the table: ``photo:NAME`` (a sample photograph that
        scikit-image ships, e.g. ``photo:coffee``, or an image file) or
        ``video:PATH`` (a video's frames, looped); see
        :mod:`perception.synthetic.footage`.
    exposure : float
        Shutter time, s (0: instantaneous). Moving parts are drawn at
        ``motion_samples`` instants across the exposure, centred on the
        frame's time, and averaged: motion blur.
    motion_samples : int
        Instants averaged per frame when ``exposure`` > 0.
    flicker : float
        Mains-light flicker: peak relative change of brightness between
        frames (0.04: +-4 %).
    shading : float
        Markers lit from one side, 0 (flat colour) to 1 (a ball's dark rim
        and specular highlight; the band shaded like a cylinder).
    sleeve : str or (int, int, int), optional
        Draw a sleeve of this colour (a marker name or BGR) on the forearm,
        touching the wrist band: the hardest case for the band.
    """

    # below MAX_FPS: a header claiming MAX_FPS is read as "no rate stated"
    fps: Annotated[float, Field(gt=0, lt=MAX_FPS, description="a frame rate, frames/s")] = 30.0
    width: Annotated[Int, Field(ge=16, le=MAX_FRAME_SIDE, description=_PX)] = 640
    height: Annotated[Int, Field(ge=16, le=MAX_FRAME_SIDE, description=_PX)] = 480
    codec: str | None = None
    texture: bool = True
    hand: bool = False
    marker_diameter: Annotated[float, Field(ge=0, le=0.5, description="m")] = 0.02
    band_size: Annotated[tuple[_Span, _Span], Tuple] = (0.07, 0.025)
    noise_sd: Annotated[float, Field(ge=0, le=255, description="grey levels")] = 0.0
    blur_sigma: Annotated[float, Field(ge=0, le=100, description="px")] = 0.0
    lighting: Annotated[float, Field(ge=0, lt=1)] = 0.0
    lighting_angle_deg: _Degrees = 30.0
    distractors: Annotated[tuple[Distractor, ...], Tuple] = ()
    occlusions: Annotated[tuple[Occlusion, ...], Tuple] = ()
    background: str | None = None
    exposure: Annotated[float, Field(ge=0, le=1, description="s")] = 0.0
    motion_samples: Annotated[Int, Field(ge=1, le=100)] = 5
    flicker: Annotated[float, Field(ge=0, le=1)] = 0.0
    shading: Annotated[float, Field(ge=0, le=1)] = 0.0
    sleeve: Colour | None = None

    def __post_init__(self) -> None:
        if self.exposure > 1 / self.fps:
            raise InputError(f"expected at most one frame period ({1 / self.fps:.4f} s), "
                             f"got {self.exposure!r}", location=("RenderStyle", "exposure"))
        check_background(self.background)

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
        m (default: the thesis's 0.10 m ball).
    """

    wrist: np.ndarray
    finger: np.ndarray
    thumb: np.ndarray
    object_centre: tuple[float, float] = (0.0, 0.0)
    object_diameter: float = DEFAULT_OBJECT_DIAMETER

    def __post_init__(self) -> None:
        n = None
        for name in ("wrist", "finger", "thumb"):
            arr = np.asarray(getattr(self, name), dtype=np.float64)
            if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
                raise ValueError(f"Scene.{name}: expected shape (T, 2) in m, got {arr.shape}")
            if n is not None and arr.shape[0] != n:
                raise ValueError(f"Scene.{name}: expected T = {n} rows like wrist, "
                                 f"got {arr.shape[0]}")
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
    def reach_to_grasp(cls, n_frames: int, fps: float, *,
                       start: tuple[float, float] = (0.0, -0.40), onset: float = 0.3,
                       duration: float = 1.0, aperture: tuple[float, float] = (0.035, 0.14),
                       peak_at: float = 0.7, object_diameter: float = DEFAULT_OBJECT_DIAMETER,
                       wrist_offset: float = 0.06) -> Scene:
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
        s = min_jerk(tau)
        start_arr = np.asarray(start, dtype=np.float64)
        goal = np.array([0.0, -wrist_offset])
        wrist = start_arr + s[:, None] * (goal - start_arr)
        a0, amax = aperture
        opening = min_jerk(tau / peak_at)
        closing = min_jerk((tau - peak_at) / (1 - peak_at))
        ap = a0 + (amax - a0) * opening + (object_diameter - amax) * closing
        ahead = wrist + np.array([0.0, wrist_offset])
        lateral = np.stack([ap / 2, np.zeros_like(ap)], axis=1)
        return cls(wrist, ahead + lateral, ahead - lateral, object_diameter=object_diameter)



def min_jerk(tau: np.ndarray) -> np.ndarray:
    """The minimum-jerk profile 10τ³ − 15τ⁴ + 6τ⁵ at ``tau`` clipped to [0, 1]."""
    tau = np.clip(tau, 0.0, 1.0)
    return tau**3 * (10 - 15 * tau + 6 * tau**2)


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

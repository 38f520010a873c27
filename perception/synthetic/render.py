"""Render synthetic top-down grasp clips with ground truth.

:func:`render_frames` draws a :class:`~perception.synthetic.scene.Scene`
through a :class:`~perception.synthetic.scene.Camera` in a
:class:`~perception.synthetic.scene.RenderStyle`, one frame at a time;
:func:`render_clip` writes them to a video and the ground truth beside it as
``<clip>.truth.h5`` in the tracks schema (docs/tracks-format.md): the true
pixel centre of every marker as drawn, status 0, likelihood 1; root
attributes ``label``, ``params``, ``seed``, ``camera``, ``style`` as JSON and
``object_diameter``; ``/tracker`` attribute ``diameter_px`` (the object's
true apparent diameter); ``/truth/visible`` (T, M) says which markers were drawn.

The interface is array-based so that stimuli from the grasp model plug in:
build a Scene from its world-frame paths and call :func:`render_clip`.
``Scene.reach_to_grasp`` is an analytic stand-in (minimum-jerk transport,
bell-shaped aperture) for tests and benchmarks.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterator, Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, NamedTuple

import cv2
import numpy as np

from perception.io.atomic import jsonable
from perception.io.files import sha256_file
from perception.io.tracks import TracksWriter
from perception.io.video import VideoWriter, codec_for
from perception.synthetic.footage import (
    H264_CODECS,
    H264Writer,
    flicker_gain,
    load_background,
    shaded_band,
    shaded_disc,
)
from perception.synthetic.scene import Camera, RenderStyle, Scene, visibility
from perception.tracking.markers import MarkerSet, default_markers

#: BGR of the hand and forearm. Hue ~10 (OpenCV units), saturation ~110:
#: beside the red thumb marker's hue, below its saturation gate.
SKIN_BGR = (120, 150, 215)

#: BGR of the plain table and base of the texture: low saturation.
TABLE_BGR = (140, 160, 178)

_SHIFT = 4  # fractional bits of OpenCV drawing coordinates (1/16 px)
_ONE = 1 << _SHIFT
_AA_CIRCLE_EXCESS_PX = 0.6


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
    # The hand frame is translated, never rotated (docs/coordinates.md): fingers point +y.
    forearm = np.array([[-0.033, 0.0], [0.033, 0.0], [0.03, -0.32], [-0.03, -0.32]]) + wrist
    _poly(img, to_px(forearm), SKIN_BGR)
    palm = wrist + np.array([0.0, 0.022]) + _unit_circle() * np.array([0.038, 0.03])
    _poly(img, to_px(palm), SKIN_BGR)
    width = max(1, int(round(0.016 * k)))
    for base, tip in ((wrist + (0.022, 0.04), finger), (wrist + (-0.03, 0.015), thumb)):
        b, t = _fixed(to_px(base)), _fixed(to_px(tip))
        cv2.line(img, (int(b[0]), int(b[1])), (int(t[0]), int(t[1])), SKIN_BGR, width,
                 cv2.LINE_AA, _SHIFT)


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
        self.bank = [np.round(rng.standard_normal((h + pad, w + pad, 3), dtype=np.float32)
                              * style.noise_sd).astype(np.int16) for _ in range(n)]

    def next(self) -> np.ndarray:
        k, dy, dx = self.rng.integers(len(self.bank)), *self.rng.integers(self.pad, size=2)
        return self.bank[k][dy : dy + self.h, dx : dx + self.w]


def _at(path: np.ndarray, t: float) -> np.ndarray:
    """Position on a (T, 2) path at fractional frame ``t`` (linear, clamped to the clip)."""
    t = min(max(t, 0.0), path.shape[0] - 1.0)
    i = min(int(t), path.shape[0] - 2) if path.shape[0] > 1 else 0
    w = t - i
    return path[i] if w == 0 or path.shape[0] == 1 else (1 - w) * path[i] + w * path[i + 1]


def _instants(style: RenderStyle) -> np.ndarray:
    """Offsets (frames) of the instants averaged into a frame: the exposure, centred."""
    n = int(style.motion_samples) if style.exposure > 0 else 1
    if n == 1:
        return np.zeros(1)
    return (np.arange(n) / (n - 1) - 0.5) * style.exposure * style.fps


def _draw_distractors(img, camera: Camera, style: RenderStyle, colours, i: int,
                      n_frames: int) -> None:
    k = camera.px_per_m
    for d in style.distractors:
        pos = d.position(i, n_frames)
        if pos is None:
            continue
        bgr = colours[d.colour] if isinstance(d.colour, str) else tuple(d.colour)
        if d.shape == "disc" and d.aspect == 1:
            _disc(img, camera.world_to_pixel(pos), d.diameter / 2 * k, bgr)
            continue
        a = math.radians(d.angle_deg)
        axis = np.array([math.cos(a), math.sin(a)])
        side = np.array([-axis[1], axis[0]])
        half_l, half_w = d.diameter / 2, d.diameter * d.aspect / 2
        if d.shape == "bar":
            pts = [pos + sx * half_l * axis + sy * half_w * side
                   for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        else:
            pts = [pos + half_l * c * axis + half_w * s_ * side for c, s_ in _unit_circle()]
        _poly(img, camera.world_to_pixel(np.array(pts)), bgr)


def _draw_moving(img, camera: Camera, style: RenderStyle, scene: Scene, t: float,
                 names: tuple[str, ...], visible: np.ndarray, colours) -> None:
    """The hand, the sleeve and the hand markers at fractional frame ``t``."""
    k = camera.px_per_m
    wrist, finger, thumb = (_at(getattr(scene, n), t) for n in ("wrist", "finger", "thumb"))
    if style.hand:
        _draw_hand(img, camera, wrist, finger, thumb)
    half = np.array(style.band_size) / 2
    if style.sleeve is not None:
        bgr = colours[style.sleeve] if isinstance(style.sleeve, str) else style.sleeve
        # The sleeve's cuff touches the band and runs up the forearm.
        cuff = _rect(wrist + (0.0, -half[1] - 0.06), (half[0] * 0.95, 0.06))
        _poly(img, camera.world_to_pixel(cuff), bgr)
    world = {"wrist": wrist, "finger": finger, "thumb": thumb}
    for j, name in enumerate(names):
        if name == "object" or not visible[j]:
            continue
        if name == "wrist":
            corners = camera.world_to_pixel(_rect(wrist, half))
            if style.shading > 0:
                shaded_band(img, corners, colours[name], style.shading)
            else:
                _poly(img, corners, colours[name])
        else:
            centre = camera.world_to_pixel(world[name])
            if style.shading > 0:
                shaded_disc(img, centre, style.marker_diameter / 2 * k, colours[name],
                            style.shading)
            else:
                _disc(img, centre, style.marker_diameter / 2 * k, colours[name])


def render_frames(scene: Scene, camera: Camera, style: RenderStyle | None = None, *,
                  seed: int = 0, markers: MarkerSet | None = None) -> Iterator[RenderedFrame]:
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
        The truth is each marker's centre at the frame's time (the middle
        of the exposure).
    """
    style = RenderStyle() if style is None else style
    markers = default_markers() if markers is None else markers
    names = markers.names
    _check_scene(scene, style, markers)
    rng = np.random.default_rng(seed)
    table = _background(style, rng)
    photos = (load_background(style.background, style.width, style.height)
              if style.background else None)
    gain = _lighting_gain(style)
    noise = _NoiseBank(style, rng) if style.noise_sd > 0 else None
    phase = float(rng.uniform(0, 2 * np.pi)) if style.flicker > 0 else 0.0
    truth = camera.world_to_pixel(scene.positions(names))  # (T, M, 2) px
    visible = visibility(style, names, scene.n_frames)
    colours = {m.name: m.bgr for m in markers}
    obj = names.index("object")
    instants = _instants(style)
    for i in range(scene.n_frames):
        still = (next(photos) if photos is not None else table).copy()
        if visible[i, obj]:
            _disc(still, truth[i, obj], scene.object_diameter / 2 * camera.px_per_m,
                  colours["object"])
        _draw_distractors(still, camera, style, colours, i, scene.n_frames)
        if len(instants) == 1:
            img = still
            _draw_moving(img, camera, style, scene, float(i), names, visible[i], colours)
        else:  # motion blur: the moving parts at instants across the exposure, averaged
            acc = np.zeros(still.shape, np.float32)
            for dt in instants:
                sub = still.copy()
                _draw_moving(sub, camera, style, scene, i + float(dt), names, visible[i],
                             colours)
                acc += sub
            img = (acc / len(instants) + 0.5).astype(np.uint8)
        img = _light(img, gain, style, i, phase)
        if style.blur_sigma > 0:
            img = cv2.GaussianBlur(img, (0, 0), style.blur_sigma)
        if noise is not None:
            img = cv2.add(img, noise.next(), dtype=cv2.CV_8U)
        yield RenderedFrame(i, i / style.fps, img, truth[i], visible[i])


def _light(img: np.ndarray, gain: np.ndarray | None, style: RenderStyle, i: int,
           phase: float) -> np.ndarray:
    """The lighting gradient and the flicker of frame ``i``."""
    f = flicker_gain(i, style.fps, style.flicker, phase) if style.flicker > 0 else 1.0
    if gain is None and f == 1.0:
        return img
    if gain is None:
        g = np.full(img.shape, f, np.float32)
    else:
        g = gain if f == 1.0 else gain * np.float32(f)
    return cv2.multiply(img, g, dtype=cv2.CV_8U)


def _check_scene(scene: Scene, style: RenderStyle, markers: MarkerSet) -> None:
    names = markers.names
    missing = [n for n in ("thumb", "finger", "wrist", "object") if n not in names]
    if missing:
        raise ValueError(f"render: markers: expected thumb, finger, wrist, object; "
                         f"missing {missing}")
    for occ in style.occlusions:
        if occ.marker not in names:
            raise ValueError(f"RenderStyle.occlusions: unknown marker {occ.marker!r}")
    for d in style.distractors:
        if isinstance(d.colour, str) and d.colour not in names:
            raise ValueError(f"RenderStyle.distractors: unknown marker colour {d.colour!r}")


def render_clip(scene: Scene, camera: Camera, style: RenderStyle | None,
                out_path: str | os.PathLike, *, seed: int = 0, label: str | None = None,
                params: Mapping[str, Any] | None = None,
                markers: MarkerSet | None = None) -> RenderResult:
    """Render a clip to ``out_path`` and its ground truth to ``<stem>.truth.h5``.

    Frames are generated and written one at a time. Both files are written
    under temporary names and appear only when both are complete.

    Parameters
    ----------
    scene, camera, style, seed, markers
        As :func:`render_frames`.
    out_path : str or os.PathLike
        Video file (``.mp4``, ``.avi``, ``.mkv``; see :class:`RenderStyle`;
        codec ``h264`` writes H.264 4:2:0 in an ``.mp4``).
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
        "params": json.dumps(dict(params or {}), default=jsonable),
        "seed": int(seed),
        "camera": json.dumps(asdict(camera)),
        "style": json.dumps(style.to_dict(), default=jsonable),
        "object_diameter": scene.object_diameter,
    }
    # The object's true apparent size, where a tracker records the size it
    # measured: the metric scale comes from the same attribute either way.
    diameter = [scene.object_diameter * camera.px_per_m if n == "object" else math.nan
                for n in markers.names]
    tracker = {"method": "render", "colour_models": markers.to_json(), "diameter_px": diameter}
    ones = np.ones(len(markers), np.float32)
    zeros = np.zeros(len(markers), np.int8)
    video_done = False
    try:
        with TracksWriter(truth_path, markers.names, tracker=tracker, attrs=root) as tw:
            size = (style.width, style.height)
            writer = (H264Writer(out, style.fps, size) if codec in H264_CODECS
                      else VideoWriter(out, style.fps, size, codec))
            with writer as vw:
                for fr in render_frames(scene, camera, style, seed=seed, markers=markers):
                    vw.write(fr.image)
                    tw.append(fr.index, fr.time, fr.truth, ones, zeros)
            video_done = True
            tw.update(video={"path": os.fspath(out), "sha256": sha256_file(out),
                             "fps_nominal": float(style.fps), "n_frames": scene.n_frames,
                             "width": style.width, "height": style.height, "fourcc": codec})
            tw.file.create_dataset("truth/visible",
                                   data=visibility(style, markers.names, scene.n_frames))
    except BaseException:
        if video_done:  # the truth failed after the video appeared: take it back
            out.unlink(missing_ok=True)
        raise
    return RenderResult(out, truth_path, scene.n_frames)


class _Indexed:
    """``render(work)`` of item ``(index, work)``: a :mod:`perception.workers` job."""

    def __init__(self, render: Callable[[Any], dict]):
        self.render = render

    def run(self, item: tuple[int, Any], shared: None) -> tuple[int, dict]:
        return item[0], self.render(item[1])


def render_rows(render: Callable[[Any], dict], work: list, jobs: int, bar) -> list[dict]:
    """``render(item)`` of every item of ``work``, in its order: a set's manifest rows.

    Parameters
    ----------
    render : callable
        One item -> its clip's manifest row (a module-level function: it is
        sent to the worker processes).
    work : list
        The items.
    jobs : int
        Worker processes (1: here, one OpenCV thread each otherwise).
    bar : tqdm
        Advanced by one per clip done.
    """
    from perception.workers import run_pool

    rows: list[dict | None] = [None] * len(work)
    for i, row in run_pool(enumerate(work), _Indexed(render), jobs):
        rows[i] = row
        bar.update()
    return rows


__all__ = ["SKIN_BGR", "TABLE_BGR", "RenderResult", "RenderedFrame", "render_clip",
           "render_frames", "truth_path_for"]

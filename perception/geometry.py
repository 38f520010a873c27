"""The one similarity transform between image pixels and the model frame.

Image: pixels, x right, y down, the centre of the top-left pixel at (0, 0)
(as OpenCV's moments and drawing have it). Model (world)
frame: metres, origin at the object's centre, +y from the demonstrator's
start toward the object (docs/coordinates.md). The two differ by a
similarity: a translation (where the object is in the image), a scale
(pixels per metre), a rotation (which way the approach points in the image)
and possibly a reflection (a view in which the finger lies on the model's
-x side). The renderer's camera and the observation of tracked clips both use
:class:`SimilarityTransform`, so a rendered clip and its recognition agree by
construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["DEFAULT_OBJECT_DIAMETER", "DEFAULT_TIP_START", "SimilarityTransform"]

#: Diameter of the thesis's ball, m: the default object, which sets the
#: metric scale of a clip (its apparent size in pixels over this).
DEFAULT_OBJECT_DIAMETER = 0.10
#: How far ahead of the wrist band a demonstrator's touching digit tips rest, m:
#: a human hand, for the default scene and the synthetic demonstrations. Not the
#: grasp model's chapter-4 start (``minvar.GraspTask.tip_start``, 2 cm): that
#: close, the digit markers would overlap the wrist band.
DEFAULT_TIP_START = 0.06


@dataclass(frozen=True)
class SimilarityTransform:
    """Pixels (x right, y down) <-> model frame (m); or a plane's metres (x right, y up).

    ``pixel = origin_px + px_per_m * flip(R(rotation) @ S @ model)`` where ``S``
    mirrors the model's x axis when ``mirror`` is set, ``R`` turns the model's
    axes into the image's "up" coordinates (x right, y up) and ``flip`` turns
    y up into y down. A motion-capture reach's tracks are metres in the
    movement's plane, y up (``y_down`` false, ``px_per_m`` 1): the same
    rotation, translation and mirror, no flip, no scale.

    Parameters
    ----------
    origin_px : (2,) array_like
        Image position of the model origin (the object centre), px.
    px_per_m : float
        Scale, px/m.
    rotation : float
        Direction of the model's +y axis in the image, rad, counter-clockwise
        from image right with image y pointing up (pi/2: the approach points
        up the image).
    mirror : bool
        Mirror the model's x axis (the finger on the model's -x side).
    y_down : bool
        The "pixels" run y down (an image's); false for metres, y up.
    """

    origin_px: np.ndarray
    px_per_m: float
    rotation: float = math.pi / 2
    mirror: bool = False
    y_down: bool = True

    def __post_init__(self) -> None:
        origin = np.asarray(self.origin_px, dtype=np.float64).reshape(-1)
        if origin.shape != (2,) or not np.all(np.isfinite(origin)):
            raise ValueError(
                f"SimilarityTransform.origin_px: expected finite (x, y) px, got {self.origin_px!r}"
            )
        if not (math.isfinite(self.px_per_m) and self.px_per_m > 0):
            raise ValueError(
                f"SimilarityTransform.px_per_m: expected a positive scale, got {self.px_per_m!r}"
            )
        if not math.isfinite(self.rotation):
            raise ValueError(
                f"SimilarityTransform.rotation: expected a finite angle, got {self.rotation!r}"
            )
        object.__setattr__(self, "origin_px", origin)
        object.__setattr__(self, "px_per_m", float(self.px_per_m))
        object.__setattr__(self, "rotation", float(self.rotation))
        object.__setattr__(self, "mirror", bool(self.mirror))
        object.__setattr__(self, "y_down", bool(self.y_down))

    @property
    def basis(self) -> np.ndarray:
        """(2, 2): columns are the model's x and y axes in image "up" coordinates."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        ey = np.array([c, s])
        ex = np.array([s, -c])
        if self.mirror:
            ex = -ex
        return np.stack([ex, ey], axis=1)

    @property
    def matrix(self) -> np.ndarray:
        """(2, 3) affine matrix: ``pixel = M[:, :2] @ model + M[:, 2]``."""
        linear = self.basis * self.px_per_m
        if self.y_down:
            linear[1] *= -1.0  # image y points down
        return np.column_stack([linear, self.origin_px])

    def to_model(self, px: np.ndarray) -> np.ndarray:
        """Pixels ``(..., 2)`` -> model frame ``(..., 2)``, m (NaN stays NaN):
        :meth:`rotated` of :meth:`to_plane`, bit for bit."""
        return self.rotated(self.to_plane(px))

    def to_plane(self, px: np.ndarray) -> np.ndarray:
        """Pixels ``(..., 2)`` -> metres ``(..., 2)`` about the origin, x right and y up: the
        scale and the flip, not the rotation (a :class:`~perception.records.
        MovementRecord`'s frame). NaN stays NaN."""
        rel = np.asarray(px, dtype=np.float64) - self.origin_px
        return np.stack([rel[..., 0] / self.px_per_m,
                         (-rel[..., 1] if self.y_down else rel[..., 1]) / self.px_per_m], axis=-1)

    def rotated(self, plane: np.ndarray) -> np.ndarray:
        """Metres about the origin, x right and y up ``(..., 2)`` (:meth:`to_plane`) ->
        model frame ``(..., 2)``: the rotation (and mirror) alone."""
        u, w = plane[..., 0], plane[..., 1]
        b = self.basis
        # element by element, not a matrix product (whose kernels may round a row
        # differently with other rows beside it): a row maps alike in any array, so a
        # stream maps only its new rows (perception.observation)
        return np.stack([u * b[0, 0] + w * b[1, 0], u * b[0, 1] + w * b[1, 1]], axis=-1)

    def to_pixels(self, xy: np.ndarray) -> np.ndarray:
        """Model frame ``(..., 2)``, m -> pixels ``(..., 2)`` (NaN stays NaN)."""
        up = np.asarray(xy, dtype=np.float64) @ self.basis.T * self.px_per_m
        return (np.stack([up[..., 0], -up[..., 1]], axis=-1) if self.y_down else up
                ) + self.origin_px

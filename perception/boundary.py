"""The type check of a public function's arguments, at the boundary.

An object of the wrong type given to a public function (a string for the
options, a name for a repertoire) would fail far inside, at its first use,
as an ``AttributeError`` naming neither the argument nor what was expected.
:func:`expect` refuses it on entry, as ``judge(None)`` and
``OnlineRecognizer(None)`` do: a ``TypeError`` saying what was expected and
what came.
"""

from __future__ import annotations

__all__ = ["expect", "expect_frame"]


def expect(value, kind: type | tuple[type, ...], name: str, *, optional: bool = False,
           hint: str = ""):
    """``value`` if it is a ``kind`` (or None where ``optional``); else a TypeError.

    Parameters
    ----------
    value
        The argument given.
    kind : type or tuple of types
        What it must be.
    name : str
        Where it was given: ``"read_reaches(options=)"``.
    optional : bool
        Whether None is allowed (the function's default).
    hint : str
        Where such an object comes from (``"Repertoire.load or Repertoire.build"``).

    Returns
    -------
    The value, unchanged.

    Raises
    ------
    TypeError
        ``read_reaches(options=): expected MocapImport or None, got str 'fast'``.
    """
    if (optional and value is None) or isinstance(value, kind):
        return value
    kinds = kind if isinstance(kind, tuple) else (kind,)
    wanted = " or ".join([k.__name__ for k in kinds] + (["None"] if optional else []))
    shown = repr(value)
    shown = shown if len(shown) <= 40 else shown[:37] + "..."
    raise TypeError(f"{name}: expected {wanted}{f' ({hint})' if hint else ''}, got "
                    f"{type(value).__name__} {shown}")


def expect_frame(frame, name: str, *, field: str | None = None):
    """``frame`` if it is a video frame the tracker reads, an (H, W, 3) uint8 BGR array;
    else an :class:`~perception.errors.InputError` naming ``field`` (refused before any
    tracking: not OpenCV's error from its first look at it).

    Parameters
    ----------
    frame : numpy.ndarray
        The frame given.
    name : str
        Who was given it: ``"Tracker.update"``.
    field : str, optional
        The argument that gave it.
    """
    from perception.errors import InputError

    if frame.ndim != 3 or frame.shape[2] != 3 or frame.dtype.name != "uint8":
        raise InputError(f"{name}: expected an (H, W, 3) uint8 BGR frame, got {frame.shape} "
                         f"{frame.dtype}", field=field)
    return frame

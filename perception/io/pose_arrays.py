"""A pose file's frames, keypoints and individuals checked and picked, from plain arrays.

:func:`perception.io.pose.read_pose` reads most formats as ``movement``
datasets (xarray), but a DeepLabCut table as :class:`PoseTable`: movement's
validated arrays, not made into a dataset, because making an xarray array
imports dask wherever dask is installed (xarray checks every array against
it), which with numba (through numbagg) cost ~0.6 s of a command's start-up
(issue 45). The checks and messages here serve both, so that a file says
the same whichever way it was read.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from perception.errors import InputError
from perception.limits import MAX_FPS, MAX_FRAMES, MAX_KEYPOINTS, MAX_POSE_POINTS

__all__ = ["UNIQUE_BODYPARTS", "PoseTable", "check_sizes", "frame_times", "marker_keys",
           "pick_individual", "unique_fill"]


def check_sizes(sizes: Mapping[str, int], path: Path) -> None:
    """Refuse more frames, keypoints or points than a pose file may hold.

    Parameters
    ----------
    sizes : mapping
        Size of each dimension (``time``, ``keypoints``, ``individuals``).
    path : Path
        The file.
    """
    frames, keypoints = sizes.get("time", 0), sizes.get("keypoints", 0)
    points = frames * keypoints * sizes.get("individuals", 1)
    if frames > MAX_FRAMES:
        raise InputError(f"claims {frames} frames, more than the {MAX_FRAMES} a pose file may "
                         "hold", path, field="time")
    if keypoints > MAX_KEYPOINTS:
        raise InputError(f"claims {keypoints} keypoints, more than {MAX_KEYPOINTS}", path,
                         field="keypoints")
    if points > MAX_POSE_POINTS:
        raise InputError(f"claims {points:.3g} points (frames x keypoints x individuals), more "
                         f"than the {MAX_POSE_POINTS:.3g} a pose file may hold", path,
                         field="position")


#: The individual DeepLabCut's multi-animal tables file their unique body parts under
#: (``uniquebodyparts`` of the project: often the object), not an animal.
UNIQUE_BODYPARTS = "single"


def pick_individual(names: Sequence[str], individual: str | None, path: Path,
                    seen: Sequence[str] | None = None) -> tuple[str | None, list[str]]:
    """The individual scored: ``individual`` (in the file), else the file's only one seen.

    An individual never seen (a SLEAP track defined but given no instance) and
    DeepLabCut's ``single`` (its unique body parts, read with any individual:
    :func:`unique_fill`) are no choice to make.

    Parameters
    ----------
    names : sequence of str
        The file's individuals (none: the file has no such dimension).
    individual : str, optional
        The one asked for.
    path : Path
        The file.
    seen : sequence of str, optional
        The individuals with a position in some frame (default: all of them).

    Returns
    -------
    tuple
        Its name (None where the file names none) and notes on what was left aside.
    """
    if individual is not None:
        if individual not in names:
            raise InputError(f"`individual` {individual!r}: not in the file "
                             f"(individuals: {', '.join(names) or 'none'})", path)
        return individual, []
    seen = list(names) if seen is None else [n for n in names if n in set(seen)]
    animals = [n for n in seen if n != UNIQUE_BODYPARTS] or seen
    if len(animals) > 1:
        # SLEAP's analysis export names the slots of untracked instances so
        untracked = all(re.fullmatch(r"track_\d+", n) for n in animals)
        raise InputError(f"the file holds {len(animals)} individuals ({', '.join(animals)}): "
                         "choose one with `individual`" + (
                             " (if SLEAP's tracker did not run, these are its slots for "
                             "untracked instances, no one animal from frame to frame: "
                             "track them in SLEAP first)" if untracked else ""), path)
    if not animals:  # nothing seen anywhere: as the file's only one, if it is
        if len(names) > 1:
            raise InputError(f"the file holds {len(names)} individuals ({', '.join(names)}): "
                             "choose one with `individual`", path)
        return (names[0] if names else None), []
    aside = [n for n in names if n not in seen]
    notes = [f"individual{'s' if len(aside) > 1 else ''} {', '.join(map(repr, aside))} never "
             f"seen: {animals[0]!r} read"] if aside else []
    return animals[0], notes


def unique_fill(names: Sequence[str], who: str | None, keys: Mapping[str, str],
                arrays: Callable[[str], tuple[np.ndarray, np.ndarray]]
                ) -> tuple[np.ndarray, np.ndarray, list[str]] | None:
    """The individual's ``(T, M, 2)`` positions and ``(T, M)`` likelihoods with the
    keypoints it never has taken from DeepLabCut's unique body parts, or None
    where the file has none or ``who`` is that individual.

    Parameters
    ----------
    names : sequence of str
        The file's individuals.
    who : str
        The one read.
    keys : mapping
        The file's keypoint of each marker, in the arrays' order.
    arrays : callable
        ``arrays(individual)``: its positions and likelihoods of ``keys``.
    """
    if who is None or who == UNIQUE_BODYPARTS or UNIQUE_BODYPARTS not in names:
        return None
    xy, conf = arrays(who)
    shared, shared_conf = arrays(UNIQUE_BODYPARTS)
    own = np.isfinite(xy).all(axis=-1).any(axis=0)
    unique = np.isfinite(shared).all(axis=-1).any(axis=0)
    take = ~own & unique
    if not take.any():
        return xy, conf, []
    xy, conf = xy.copy(), conf.copy()
    xy[:, take], conf[:, take] = shared[:, take], shared_conf[:, take]
    taken = [k for k, t in zip(keys.values(), take) if t]
    return xy, conf, [f"keypoint{'s' if len(taken) > 1 else ''} {', '.join(map(repr, taken))} "
                      f"read from DeepLabCut's unique body parts (individual "
                      f"{UNIQUE_BODYPARTS!r}) with {who!r}"]


def frame_times(n: int, coords: Any, attrs: Mapping[str, Any], fps_given: float | None,
                own: np.ndarray | None, video_rate: Callable[[], float],
                path: Path) -> tuple[np.ndarray, np.ndarray, float]:
    """Frame indices, times (s) and the frame rate of ``n`` frames.

    Parameters
    ----------
    n : int
        Frames.
    coords : array_like
        The time coordinate (seconds or frames, as ``attrs["time_unit"]`` says).
    attrs : mapping
        The dataset's attributes (``fps``, ``time_unit``).
    fps_given : float, optional
        The user's frame rate, where the file has none.
    own : numpy.ndarray, optional
        The file's own frame numbers (a DeepLabCut table's index), kept as the
        tracks' frame indices; times are then ``frame / fps``.
    video_rate : callable
        The rate of the video beside the file (or an error), where neither has one.
    path : Path
        The file.
    """
    coords = np.asarray(coords, dtype=float)
    unit = attrs.get("time_unit", "frames")
    fps = attrs.get("fps")
    try:
        fps = float(fps) if fps is not None else None
    except (TypeError, ValueError):
        fps = None
    fps = fps if fps is not None and math.isfinite(fps) and 0 < fps <= MAX_FPS else None
    if own is None and unit == "seconds" and fps:
        if not np.all(np.isfinite(coords)):
            raise InputError("time stamps are not finite", path, field="time")
        return np.rint(coords * fps).astype(np.int64), coords, fps
    fps = fps or fps_given or video_rate()
    if own is not None:
        frames = own
    elif len(coords) == n and np.all(np.isfinite(coords)) and np.all(np.abs(coords) < 2 ** 53):
        frames = coords.astype(np.int64)
    else:
        frames = np.arange(n)
    return frames, frames / fps, fps


def marker_keys(names: Sequence[str], keys: Mapping[str, str], path: Path) -> list[str]:
    """The file's keypoint of each marker, refusing one the file does not have.

    Parameters
    ----------
    names : sequence of str
        The file's keypoints.
    keys : mapping
        Marker -> the keypoint asked for.
    path : Path
        The file.
    """
    missing = [m for m, k in keys.items() if k not in names]
    if missing:
        raise InputError(f"keypoint {keys[missing[0]]!r} (for {missing[0]}) is not "
                         f"in the file (keypoints: {', '.join(names)}); map the markers with "
                         "`keypoints` thumb=NAME finger=NAME wrist=NAME object=NAME", path)
    return list(keys.values())


def check_space(n_space: int, path: Path) -> None:
    """Refuse poses that are not 2-D (``n_space`` coordinates) of the file at ``path``."""
    if n_space == 3:  # DeepLabCut's triangulate writes its 3-D table as .h5 and .csv
        raise InputError("expected 2-D poses (x, y), got 3 coordinates: a 3-D table is "
                         "motion capture, read from its .csv (DeepLabCut's triangulate "
                         "writes one with save_as_csv=True) with its `rate`", path)
    if n_space != 2:
        raise InputError(f"expected 2-D poses (x, y), got {n_space} coordinates", path)


class PoseTable:
    """A DeepLabCut table's poses as movement validates them (``ValidPosesInputs``).

    Holds what :meth:`ValidPosesInputs.to_dataset` would make a dataset of,
    read by the functions of this module as a dataset is.

    Parameters
    ----------
    valid : movement.validators.datasets.ValidPosesInputs
        Position ``(time, space, keypoints, individuals)``, confidence
        ``(time, keypoints, individuals)``, names, frame rate and source.
    """

    def __init__(self, valid: Any):
        self.position = valid.position_array
        self.confidence = valid.confidence_array
        if not np.any(np.isfinite(np.asarray(self.confidence, dtype=np.float64))):
            # a table without likelihoods (x, y only; movement fills NaN): as a file without
            # scores, every point it has is seen
            self.confidence = np.isfinite(np.asarray(self.position, dtype=np.float64)).all(
                axis=1).astype(np.float64)
        self.individuals = [str(n) for n in valid.individual_names]
        self.keypoints = [str(k) for k in valid.keypoint_names]
        n = self.position.shape[0]
        # the time coordinate and attributes movement's dataset would have
        self.attrs: dict[str, Any] = {"source_software": valid.source_software,
                                      "ds_type": "poses"}
        if valid.fps is not None:
            self.time = np.arange(n, dtype=np.float64) / valid.fps
            self.attrs.update(fps=valid.fps, time_unit="seconds")
        else:
            self.time = np.arange(n, dtype=np.int64)
            self.attrs["time_unit"] = "frames"

    @property
    def sizes(self) -> dict[str, int]:
        """Size of each dimension, as a dataset's ``sizes``."""
        t, s, k, i = self.position.shape
        return {"time": t, "space": s, "keypoints": k, "individuals": i}

    def markers(self, individual: str | None, keys: Mapping[str, str],
                path: Path) -> tuple[np.ndarray, np.ndarray]:
        """``(T, M, 2)`` positions (px) and ``(T, M)`` likelihoods of the markers' keypoints.

        Parameters
        ----------
        individual : str
            Whose (:func:`pick_individual`).
        keys : mapping
            The file's keypoint of each marker.
        path : Path
            The file.
        """
        at = self.keypoints.index  # names are unique: movement refuses a table where not
        index = [at(k) for k in marker_keys(self.keypoints, keys, path)]
        check_space(self.position.shape[1], path)
        who = self.individuals.index(individual)
        xy = self.position[:, :, :, who].transpose(0, 2, 1)[:, index]
        conf = self.confidence[:, :, who][:, index]
        try:
            xy, conf = np.asarray(xy, dtype=np.float64), np.asarray(conf, dtype=np.float64)
        except (TypeError, ValueError):  # a cell of text read into an object column
            raise InputError(f"a value of keypoint {_not_numeric(xy, conf, keys)!r} is "
                             "not a number", path) from None
        return xy, np.clip(np.nan_to_num(conf, nan=0.0), 0.0, 1.0)


def _not_numeric(xy: np.ndarray, conf: np.ndarray, keys: Mapping[str, str]) -> str:
    """The first keypoint of ``keys`` with a value that is not a number."""
    def number(value) -> bool:
        try:
            float(value)
        except (TypeError, ValueError):
            return False
        return True

    for j, key in enumerate(keys.values()):
        values = [*np.ravel(xy[:, j]), *np.ravel(conf[:, j])]
        if not all(map(number, values)):
            return key
    return next(iter(keys.values()))

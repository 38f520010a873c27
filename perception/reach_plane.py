"""A reach brought into the movement's own plane as the tracks the recognition reads.

:func:`fit_plane` fits the transport path's plane (SVD); :func:`reach_tracks`
writes the reach as tracks in it, in metres (y up: :attr:`Tracks.units` ``"m"``), with
the grip placed across the approach at its 3D aperture, the models' wrist
behind it, the object where it is (or where the grip closes) and rest before
the onset where the recording has too little. :mod:`perception.reaches`
describes each step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from perception.boundary import expect
from perception.errors import InputError
from perception.io.tracks import Status, Tracks
from perception.reach_data import Reach, ReachParams

__all__ = ["PlaneFit", "ReachTracks", "fit_plane", "reach_tracks"]


@dataclass(frozen=True)
class PlaneFit:
    """The movement's plane: an origin and two in-plane axes, with how far the path left it.

    Attributes
    ----------
    origin : (3,) array
        The object's centre, m (the model frame's origin).
    x, y : (3,) arrays
        Unit axes: y from start toward the end within the plane, x across it.
    rms, largest : float
        RMS and largest distance of the transport path from the plane, m.
    """

    origin: np.ndarray
    x: np.ndarray
    y: np.ndarray
    rms: float
    largest: float

    def project(self, p: np.ndarray) -> np.ndarray:
        """(N, 3) points -> (N, 2) in-plane coordinates, m."""
        d = np.asarray(p) - self.origin
        return np.stack([d @ self.x, d @ self.y], axis=-1)

    def to_dict(self) -> dict:
        """JSON values (m)."""
        return {"normal": np.cross(self.x, self.y).round(6).tolist(),
                "rms_out_of_plane": round(self.rms, 6),
                "largest_out_of_plane": round(self.largest, 6)}


def fit_plane(reach: Reach, origin: np.ndarray) -> PlaneFit:
    """The plane of a reach's transport path from onset to end (SVD), through ``origin``."""
    seg = reach.transport[reach.onset:reach.end + 1]
    seg = seg[np.isfinite(seg).all(axis=1)]
    if len(seg) < 3:
        raise InputError("the hand is seen too little during the reach to find its plane",
                         reach.source)
    centre = seg.mean(axis=0)
    _, _, vt = np.linalg.svd(seg - centre, full_matrices=False)
    normal = vt[2]
    along = seg[-1] - seg[0]
    y = along - (along @ normal) * normal
    if np.linalg.norm(y) < 1e-9:
        y = vt[0]
    y /= np.linalg.norm(y)
    x = np.cross(y, normal)
    off = (seg - centre) @ normal
    return PlaneFit(np.asarray(origin, dtype=float), x, y, float(np.sqrt(np.mean(off ** 2))),
                    float(np.abs(off).max()))


class ReachTracks(NamedTuple):
    """A reach as the recognition reads it (:func:`reach_tracks`).

    Attributes
    ----------
    tracks : Tracks
        Markers thumb, finger, wrist and object in the movement's plane, m,
        y along the approach (:attr:`Tracks.units` ``"m"``).
    info : dict
        What the report says of it: ``plane`` (normal, out-of-plane RMS and
        largest, m), ``object_size`` (m), ``rest_aperture`` (m), ``notes``,
        ``bounds`` (the onset's and end's rows in ``tracks`` and the rules
        that placed them, :attr:`Reach.onset_bound`).
    transport, aperture : (T, 3) and (T,) arrays
        The 3D transport point and aperture, m, row for row with ``tracks``:
        the landmarks are measured on these, not on their projection.
    """

    tracks: Tracks
    info: dict
    transport: np.ndarray
    aperture: np.ndarray


def reach_tracks(reach: Reach, params: ReachParams | None = None) -> ReachTracks:
    """A reach as tracks in its plane (metres), and what the report says of it.

    Parameters
    ----------
    reach : Reach
        From :func:`recording_reaches`.
    params : ReachParams, optional
        Its ``object_size``, if given, is the object's.
    """
    expect(reach, Reach, "reach_tracks(reach=)", hint="read_reaches or read_recording")
    expect(params, ReachParams, "reach_tracks(params=)", optional=True)
    params = ReachParams() if params is None else params
    notes = list(reach.notes)
    if not 0 <= reach.onset < reach.end < len(reach.time):
        raise InputError(f"{reach.name}: the reach's onset (row {reach.onset}) and end (row "
                         f"{reach.end}) are not in order within its {len(reach.time)} samples",
                         reach.source)
    g = reach.aperture
    seen_end = np.flatnonzero(np.isfinite(reach.transport[:reach.end + 1]).all(axis=1))
    if not len(seen_end):
        raise InputError(f"{reach.name}: the hand is not seen up to the reach's end",
                         reach.source)
    if reach.object is not None:
        origin = reach.object
    else:
        origin = reach.transport[seen_end[-1]]
        notes.append("object: where the grip closes (the reach's end)")
    plane = fit_plane(reach, origin)
    mid = plane.project(0.5 * (reach.finger + reach.thumb))
    near_onset = g[max(0, reach.onset - 5):reach.onset + 1]
    near_onset = near_onset[np.isfinite(near_onset)]
    rest_g = float(np.median(near_onset)) if len(near_onset) else 0.0
    if params.object_size is not None:
        size = float(params.object_size)
    else:
        at_end = g[max(0, reach.end - 2):reach.end + 1]
        at_end = at_end[np.isfinite(at_end)]
        size = (float(np.median(at_end)) if len(at_end) else math.nan) - rest_g
        if size > 0.005:
            notes.append(f"object size: the grip's opening at the reach's end, "
                         f"{size * 1000:.0f} mm")
        else:  # the note gives the size used, and why it is not the opening
            notes.append(f"object size: 5 mm, the least used (the grip's opening at the "
                         f"reach's end, {size * 1000:.0f} mm, is no size)")
    if not size > 0.005:
        size = 0.005
    # the models' hand: a wrist behind the grip, whatever markers the lab put on it
    # (a marker on the back of the hand projects anywhere near the grip)
    wrist = mid - np.array([0.0, params.wrist_behind])
    across = np.array([1.0, 0.0])
    finger = mid + 0.5 * g[:, None] * across
    thumb = mid - 0.5 * g[:, None] * across
    obj = np.zeros_like(mid)
    time = reach.time.copy()
    pos = np.stack([thumb, finger, wrist, obj], axis=1)
    solid = np.concatenate([reach.transport, g[:, None]], axis=1)
    dt = float(np.median(np.diff(time)))
    # rest the recognition can read: stillness before the onset, first clean sample held
    whole = np.flatnonzero(np.isfinite(pos[:reach.end + 1, :3]).all(axis=(1, 2)))
    if not len(whole):
        raise InputError(f"{reach.name}: the digits are not seen together up to the reach's "
                         "end", reach.source)
    first = int(whole[0])
    still = time[reach.onset] - time[first]
    shift = -first
    if still < params.min_rest:
        n = int(math.ceil((params.min_rest - still) / dt)) + 1
        notes.append(f"{max(still, 0) * 1000:.0f} ms of rest before the movement: "
                     f"{n * dt * 1000:.0f} ms of its first clean sample added")
        time = np.r_[time[first] - dt * np.arange(n, 0, -1), time[first:]]
        pos = np.concatenate([np.repeat(pos[first:first + 1], n, axis=0), pos[first:]])
        solid = np.concatenate([np.repeat(solid[first:first + 1], n, axis=0), solid[first:]])
        shift += n
    elif first:
        time, pos, solid = time[first:], pos[first:], solid[first:]
    if reach.end_bound == "the object's first motion" or reach.end_bound.startswith(
            "the speed minimum"):
        # the hand goes on (with the object): what the models read ends at the grasp, held
        # there as a hand at rest on the object (what follows is no part of the reach)
        last = reach.end + shift
        k = int(math.ceil(params.min_rest / dt))
        notes.append(f"the reach ends at {reach.end_bound}: its last sample held "
                     f"{k * dt * 1000:.0f} ms in place of what follows")
        time = np.r_[time[:last + 1], time[last] + dt * np.arange(1, k + 1)]
        pos = np.concatenate([pos[:last + 1], np.repeat(pos[last:last + 1], k, axis=0)])
        solid = np.concatenate([solid[:last + 1], np.repeat(solid[last:last + 1], k, axis=0)])
    lost = ~np.isfinite(pos).all(axis=-1)
    status = np.where(lost, Status.LOST, Status.TRACKED).astype(np.int8)
    tracks = Tracks(frame=np.arange(len(time)), time=time - time[0],
                    markers=("thumb", "finger", "wrist", "object"), position=pos,
                    likelihood=np.where(lost, 0.0, 1.0).astype(np.float32), status=status,
                    video={"path": reach.source, "fps_nominal": 1 / dt},
                    tracker={"units": "m", "source": "mocap"}, attrs={"clip": reach.name})
    info = {"plane": plane.to_dict(), "object_size": size, "notes": notes,
            "rest_aperture": rest_g,
            "bounds": {"onset": max(0, reach.onset + shift), "end": reach.end + shift,
                       "onset_bound": reach.onset_bound, "end_bound": reach.end_bound}}
    return ReachTracks(tracks, info, solid[:, :3], solid[:, 3])


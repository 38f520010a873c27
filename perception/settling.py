"""A clip that does not start at rest is scored, not refused: its scene from the data.

The recognition fixes a clip's scene (where the object is, the hand's rest
posture, the tracking noise) from still frames before the movement
(:func:`perception.observation.rest_scene`). Real clips do not always
offer them: a tracker's or a motion-capture system's first sample is often
a spike, a hand may settle for a moment after the recording starts, and a
trial may start with the hand already moving. :func:`settle_start` finds
the scene in the data instead, and says what it did:

* the first still stretch within :data:`SEARCH` of the start, the frames
  before it left out ("a spike or a settling hand");
* otherwise (the hand moves from the start) the first frame in which every
  marker is seen, held for as long as the scene needs, with a note: the
  onset is then the first frame. A clip whose grip is already open there
  started in the middle of the movement and cannot be judged (its
  landmarks still can: :func:`perception.measure.landmarks`).

:func:`perception.observation.observe` itself stays strict (the online
recogniser and the library's callers decide); the pipeline settles a clip
before it observes it.
"""

from __future__ import annotations

import numpy as np

from perception.errors import InputError
from perception.observation import (
    NEEDED_MARKERS,
    ObserveParams,
    check_hand,
    movement_span,
    rest_scene,
)

__all__ = ["SEARCH", "settle_start"]

#: How far into a clip a still stretch is looked for, s.
SEARCH = 0.5


def _at_rest(tracks, params: ObserveParams, start: int) -> bool:
    """Whether the frames from ``start`` show a still, visible hand with its digits
    together, before the movement (not a slow stretch of it)."""
    n = 2 * params.rest_frames
    try:
        check_hand(rest_scene(tracks.rows(start, start + n), params), params)
        span = movement_span(tracks.rows(start, len(tracks.time)), params)
    except InputError:
        return False
    return span.start >= params.rest_frames


def _check_hand(scene, params: ObserveParams, clip: str | None,
                moving: bool = False) -> None:
    """:func:`check_hand`, naming a start in the middle of the movement as such."""
    try:
        check_hand(scene, params)
    except InputError:
        wrist = scene.raw[: 2 * params.rest_frames, 0]
        drift = float(np.nanmax(np.linalg.norm(wrist - wrist[0], axis=-1), initial=0.0))
        if not (moving or drift > params.onset_displacement):
            raise
        raise InputError("the clip starts in the middle of the movement (the grip is already "
                         "open): it cannot be judged, but its landmarks can be measured "
                         "(hammer-mv landmarks)", clip or scene.source) from None


def settle_start(tracks, params: ObserveParams | None = None, *,
                 clip: str | None = None) -> tuple[object, str | None]:
    """The tracks from their first still frames, or given a held start; and a note.

    Parameters
    ----------
    tracks : Tracks
        A clip's tracks.
    params : ObserveParams, optional
        The rest rule.
    clip : str, optional
        The clip's name, for messages.

    Returns
    -------
    Tracks, str or None
        The tracks to observe and what was done (None: they start at rest).

    Raises
    ------
    InputError
        The original refusal, where no scene can be found in the data (an
        object never seen, a marker missing, time stamps that are not seconds).
    """
    params = ObserveParams() if params is None else params
    try:
        scene = rest_scene(tracks, params, clip=clip)
    except InputError as exc:
        refusal = exc
    else:
        _check_hand(scene, params, clip)
        return tracks, None
    n = 2 * params.rest_frames
    time = np.asarray(tracks.time, dtype=float)
    if len(time) <= 2 * n or not np.isfinite(time).all():
        raise refusal
    dt = float(np.median(np.diff(time)))
    for start in range(1, len(time) - n):
        if time[start] - time[0] > SEARCH:
            break
        if _at_rest(tracks, params, start):
            return tracks.rows(start, len(time)), (
                f"the first {start} frame(s) ({time[start] - time[0]:.2f} s) left out: the hand "
                "was not still and visible there (a spike, or a settling hand)")
    idx = [tracks.markers.index(m) for m in NEEDED_MARKERS if m in tracks.markers]
    seen = np.isfinite(tracks.position[:, idx]).all(axis=(1, 2))
    if not seen.any():
        raise refusal
    k = int(np.argmax(seen))
    held = tracks.rows(k, len(time))
    lead = np.arange(n, 0, -1)
    settled = held.replace(
        frame=np.r_[np.full(n, held.frame[0]), held.frame],
        time=np.r_[held.time[0] - dt * lead, held.time],
        position=np.concatenate([np.repeat(held.position[:1], n, axis=0), held.position]),
        likelihood=np.concatenate([np.repeat(held.likelihood[:1], n, axis=0),
                                   held.likelihood]),
        status=np.concatenate([np.repeat(held.status[:1], n, axis=0), held.status]))
    try:
        scene = rest_scene(settled.rows(0, n), params)
    except InputError:
        raise refusal from None
    _check_hand(scene, params, clip, moving=True)
    return settled, (f"no still start: frame {int(held.frame[0])} held for {n * dt:.2f} s as "
                     "the rest the scene is fixed from (the hand was moving)")

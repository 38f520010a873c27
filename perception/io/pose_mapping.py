"""Which keypoint of a pose file is which marker, and the object where none is tracked.

Labs name their keypoints as they like (``Thumb_tip``, ``index_finger_tip``,
``Wrist``) and many track the hand alone. :func:`keypoint_mapping` reads a
marker's keypoint from the user's mapping, else from a keypoint of the
marker's own name, else from the names by the rules motion-capture markers
are guessed by (:meth:`perception.reach_data.MarkerMap.guess`: ``thumb*``,
``index*``/``finger*``, ``wrist*``/``hand*``, a tip before another point;
an object's words), and says what it guessed. A file with no object
keypoint gets the object where the grip ends its reach
(:func:`object_at_grip`), as a motion-capture reach without object markers
does; its size then comes from ``object_diameter_px`` or the scale given.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

__all__ = ["keypoint_mapping", "object_at_grip"]


def keypoint_mapping(names: Sequence[str], given: Mapping[str, str],
                     markers: Sequence[str]) -> tuple[dict[str, str | None], list[str]]:
    """Each marker's keypoint in a file of keypoints ``names``, and what was guessed.

    Parameters
    ----------
    names : sequence of str
        The file's keypoints.
    given : mapping of str to str
        The user's marker -> keypoint mapping (markers left out are found).
    markers : sequence of str
        The markers needed (``thumb, finger, wrist, object``).

    Returns
    -------
    dict, list of str
        Marker -> keypoint (the object's None where the file has none to
        take); one note per marker whose keypoint was guessed or is absent.
        A digit's or the wrist's keypoint that neither the mapping nor the
        names give stays its own name: the caller refuses it, naming the
        file's keypoints.
    """
    from perception.reach_data import MarkerMap  # the motion-capture markers' words

    names = list(names)
    guess = MarkerMap.guess(names)
    by_role = {"thumb": guess.thumb, "finger": guess.finger,
               "wrist": guess.wrist[0] if guess.wrist else None,
               "object": guess.object[0] if guess.object else None}
    taken = set(given.values())
    mapping: dict[str, str | None] = {}
    notes = []
    for marker in markers:
        if marker in given:
            mapping[marker] = given[marker]
        elif marker in names:
            mapping[marker] = marker
        elif by_role.get(marker) in names and by_role[marker] not in taken:
            mapping[marker] = by_role[marker]
            notes.append(f"keypoint {by_role[marker]!r} taken as the {marker} (from its name)")
        elif marker == "object":
            mapping[marker] = None
            notes.append("no object keypoint: the object is where the grip ends its reach")
        else:
            mapping[marker] = marker
        taken.add(mapping[marker])
    return mapping, notes


def object_at_grip(hand: np.ndarray) -> np.ndarray:
    """(T, 2) the object's position where a file tracks the hand alone: where the grip's
    midpoint is when the wrist is farthest from where it started (the reach's end, before
    any return), held for every frame; NaN where that is never seen.

    Parameters
    ----------
    hand : (T, 3, 2) array
        Thumb, finger and wrist positions, px, in that order (NaN where lost).
    """
    grip = 0.5 * (hand[:, 0] + hand[:, 1])
    wrist = hand[:, 2]
    seen = np.flatnonzero(np.isfinite(wrist).all(axis=1) & np.isfinite(grip).all(axis=1))
    if not len(seen):
        return np.full((len(hand), 2), np.nan)
    far = seen[np.argmax(np.linalg.norm(wrist[seen] - wrist[seen[0]], axis=1))]
    return np.repeat(grip[far][None], len(hand), axis=0)

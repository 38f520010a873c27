"""When a movement begins and ends, found on the rows seen so far.

:func:`onset_time` and :func:`end_row` are the observation's
(:func:`perception.observation.observe`) rules for a movement's bounds. Each
reads rows only up to what decides it, so the online recogniser applies them
to a stream's prefix; each keeps, per thread, the rows that decided its last
answer, and a longer prefix that begins with them resumes from there,
bitwise as a pass over every row.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from perception.errors import InputError
from perception.resume import Kept

if TYPE_CHECKING:
    from perception.observation import ObserveParams

__all__ = ["end_row", "onset_time"]


def onset_time(filtered: np.ndarray, time: np.ndarray, noise: float, params: ObserveParams,
               name: str, rest: np.ndarray | None = None) -> float:
    """When the movement's command began, s: the wrist's crossing less the model's latency.

    The crossing is where the wrist's displacement from rest first exceeds
    the threshold for ``onset_hold_frames`` frames, interpolated between
    frames. It looks at no frame past those ``onset_hold_frames``, so the
    online recogniser applies it to the rows seen so far.

    Parameters
    ----------
    filtered : (T, 3, 2) array
        Smoothed wrist, finger and thumb positions in the model frame, m.
    time : (T,) array
        Their times, s.
    noise : float
        Tracking noise at rest, m (:attr:`RestScene.noise`).
    params : ObserveParams
        The onset rule's settings.
    name : str
        What an error names.
    rest : (2,) array, optional
        The wrist's rest position, m (default: the median of the first
        ``rest_frames``): given, the rows may be the latest few of a stream.

    Raises
    ------
    InputError
        The wrist never leaves its rest position.
    """
    # the onset found in rows this one begins with (a stream's last recognition): the
    # rows up to the crossing's hold decide it, and they are the same numbers
    kept = _ONSET.longest((params, noise), (filtered, time)) if rest is None else None
    if kept is not None:
        return kept[1]
    w = filtered[:, 0]
    given = rest is not None
    rest = np.median(w[: params.rest_frames], axis=0) if rest is None else rest
    disp = np.linalg.norm(w - rest, axis=1)
    threshold = max(params.onset_displacement, params.onset_noise_factor * noise)
    above = np.nan_to_num(disp, nan=0.0) > threshold
    hold = params.onset_hold_frames
    held = np.ones_like(above)
    for k in range(hold):
        held &= np.roll(above, -k)
    held[len(held) - hold + 1:] = False  # np.roll wrapped the last frames around
    if not held.any():
        raise InputError("no movement found: the wrist never leaves its rest position", name)
    i = int(np.argmax(held))
    if i > 0 and np.isfinite(disp[i - 1]):
        frac = (threshold - disp[i - 1]) / (disp[i] - disp[i - 1])
        crossing = time[i - 1] + frac * (time[i] - time[i - 1])
    else:
        crossing = time[i]
    onset = float(crossing - params.onset_latency(threshold))
    m = max(i + hold, params.rest_frames)
    if not given and m <= len(filtered):
        # rows after the crossing's hold never change it: more rows, the same onset
        _ONSET.keep((params, noise), (np.array(filtered[:m]), np.array(time[:m])), onset)
    return onset


#: The last onset found in this thread and the rows that decided it (:func:`onset_time`).
_ONSET = Kept(1)
#: The last end scanned in this thread: its rule, rows and last moving row (:func:`end_row`).
_END = Kept(1)


def end_row(filtered: np.ndarray, time: np.ndarray, noise: float, dt: float,
             params: ObserveParams) -> int:
    """The last row of the movement: a few frames after any hand marker last moved.

    Speeds are measured over ``params.end_speed_window`` (``k`` frames, one at
    30 frames/s or less): over one frame of a 120 frames/s clip the noise
    floor would be four times as high, and a slow movement's approach would
    count as stopped long before it ends.

    Parameters
    ----------
    filtered : (T, 3, 2) array
        Smoothed wrist, finger and thumb positions in the model frame, m.
    time : (T,) array
        Their times, s.
    noise : float
        Tracking noise at rest, m (:attr:`RestScene.noise`).
    dt : float
        The clip's frame period, s.
    params : ObserveParams
        The end rule's settings.
    """
    k = max(1, int(round(params.end_speed_window / dt)))
    if len(time) <= k:
        return len(time) - 1
    floor = max(params.end_speed, params.end_noise_factor * noise / (k * dt))
    # A row's speed reads it and the row k after: with the rule of the last scan and
    # rows that begin with its rows, the rows it measured are as it found them, and
    # the scan goes on from its end (a stream's rows at rest, one more each time).
    start, active = 0, -1
    kept = _END.longest((params, k, floor), (filtered, time))
    if kept is not None:
        start, active = len(kept[0][0]) - k, kept[1]
    f, t = filtered[start:], time[start:]
    speed = np.linalg.norm(f[k:] - f[:-k], axis=-1) / (t[k:] - t[:-k])[:, None]
    moving = np.flatnonzero(np.nanmax(np.where(np.isfinite(speed), speed, 0), axis=1) > floor)
    active = int(moving[-1]) + start if len(moving) else active
    _END.keep((params, k, floor), (np.array(filtered), np.array(time)), active)
    last = len(time) - 1
    return int(min(last, active + k * params.end_pad_frames)) if active >= 0 else last

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

__all__ = ["FIT_SPAN", "end_row", "onset_time"]

#: The onset's time scale is fitted only to crossings whose displacements span this
#: ratio (the highest passed over the threshold): closer together, at 30 frames/s and
#: a noise-raised threshold, the crossing times' own noise would decide the scale.
FIT_SPAN = 3.0


def onset_time(filtered: np.ndarray, time: np.ndarray, noise: float, params: ObserveParams,
               name: str) -> float:
    """When the movement's command began, s: the wrist's crossing less the model's latency.

    The crossing is where the wrist's displacement from rest first exceeds
    the threshold for ``onset_hold_frames`` frames, interpolated between
    frames. With ``params.onset_scale_range``, the latency is the profile's
    at the time scale of the movement's own start: the crossings of the
    profile's larger displacements (each held as the first) are fitted as
    onset + scale x latency. It looks at no frame past the last crossing's
    hold, so the online recogniser applies it to the rows seen so far (a
    prefix that has not passed every displacement yet fits those it has).

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

    Raises
    ------
    InputError
        The wrist never leaves its rest position.
    """
    # the onset found in rows this one begins with (a stream's last recognition): the
    # rows up to the crossing's hold decide it, and they are the same numbers
    kept = _ONSET.longest((params, noise), (filtered, time))
    if kept is not None:
        return kept[1]
    w = filtered[:, 0]
    disp = np.linalg.norm(w - np.median(w[: params.rest_frames], axis=0), axis=1)
    threshold = max(params.onset_displacement, params.onset_noise_factor * noise)
    i = _held_above(disp, threshold, params.onset_hold_frames)
    if i is None:
        raise InputError("no movement found: the wrist never leaves its rest position", name)
    latency = [params.onset_latency(threshold)]
    crossing = [_crossing(disp, time, i, threshold)]
    m = i + params.onset_hold_frames
    levels = ([d for d, _ in params.onset_profile if d > threshold]
              if params.onset_scale_range is not None else [])
    passed = threshold  # the highest displacement passed
    for level in levels:
        j = _held_above(disp[i:], level, params.onset_hold_frames)
        if j is None or not np.isfinite(disp[i:i + j + 1]).all():
            # not passed yet (a stream's prefix, a short reach), or passed unseen (the
            # wrist lost on the way): what it has
            break
        passed = level
        latency.append(params.onset_latency(level))
        crossing.append(_crossing(disp, time, i + j, level))
        m = i + j + params.onset_hold_frames
    t0, tc = np.array(latency), np.array(crossing)
    onset = float(tc[0] - t0[0])  # the first crossing less its latency, unscaled
    if passed >= FIT_SPAN * threshold:
        lo, hi = params.onset_scale_range
        scale = float(np.clip(np.polyfit(t0, tc, 1)[0], lo, hi))
        onset = float(np.mean(tc - scale * t0))
    m = max(m, params.rest_frames)
    if m <= len(filtered) and len(t0) == len(levels) + 1:
        # rows after the last crossing's hold never change it: more rows, the same onset
        _ONSET.keep((params, noise), (filtered[:m], time[:m]), onset)
    return onset


def _held_above(disp: np.ndarray, level: float, hold: int) -> int | None:
    """The first row from which ``disp`` stays above ``level`` for ``hold`` rows (None)."""
    above = np.nan_to_num(disp, nan=0.0) > level
    held = np.ones_like(above)
    for k in range(hold):
        held &= np.roll(above, -k)
    held[len(held) - hold + 1:] = False  # np.roll wrapped the last rows around
    return int(np.argmax(held)) if held.any() else None


def _crossing(disp: np.ndarray, time: np.ndarray, i: int, level: float) -> float:
    """When ``disp`` rose through ``level`` between rows ``i - 1`` and ``i``, interpolated, s."""
    if i > 0 and np.isfinite(disp[i - 1]):
        frac = (level - disp[i - 1]) / (disp[i] - disp[i - 1])
        return float(time[i - 1] + frac * (time[i] - time[i - 1]))
    return float(time[i])


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
    _END.keep((params, k, floor), (filtered, time), active)  # copied there
    last = len(time) - 1
    return int(min(last, active + k * params.end_pad_frames)) if active >= 0 else last

"""Whether a recording's numbers can be a human hand's, and the likely cause when they cannot.

A wrong unit or rate does not fail where it is made: millimetres read as
metres give a hand at 700 m/s that no speed bound can hold, centimetres read
as millimetres a 4 cm reach at 0.08 m/s that is judged ``normal``, a
``--rate`` ten times too low 12 s movements. :func:`check_scale` looks at a
recording's markers before any reach is found and refuses, in one line
naming the unit or rate, where it came from and the value that would fit,
what no human reach can be.

The bounds are wide on purpose (they catch a factor of 10, not a slow
participant): a hand's peak speed in reaching and grasping is 0.3-2.5 m/s
(Jeannerod 1984; Marteniuk et al. 1987; the shared recordings: 0.5-1.3 m/s),
and the fastest aimed arm movements peak at 3-4 m/s; a reach, with the
hand's return, lasts 0.6-3 s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from perception.errors import InputError

__all__ = ["MAX_MOVEMENT", "MAX_PEAK_SPEED", "SCALE_TRIALS", "check_scale", "peak_speed"]

#: Peak speed, m/s, of a hand's fastest marker that a recording of human reaching
#: and grasping stays below (the fastest aimed arm movements peak at 3-4 m/s). A
#: slower hand may be still: there is no lower bound, so a unit too small for the
#: numbers (centimetres read as millimetres) is not caught here.
MAX_PEAK_SPEED = 5.0
#: Longest a movement of human reaching and grasping can last without a pause, s:
#: a reach and its return together last 0.6-3 s.
MAX_MOVEMENT = 6.0
#: Trials a recording's scale is judged on (the first ones: a unit or a rate is every
#: trial's, and a large table's trials are read one at a time).
SCALE_TRIALS = 5
#: A marker moves while its speed is above this share of its peak.
_MOVING = 0.2
#: Length units and metres per unit, the readers' (perception.io.mocap_trial.UNITS).
_UNITS = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}


def _speed(time: np.ndarray, xyz: np.ndarray, step: int = 5) -> np.ndarray:
    """Speed over ``step`` samples, m/s (NaN where lost): one-sample spikes weigh little."""
    if len(time) <= step:
        return np.full(0, np.nan)
    return np.linalg.norm(xyz[step:] - xyz[:-step], axis=1) / (time[step:] - time[:-step])


def peak_speed(time: np.ndarray, xyz: np.ndarray) -> tuple[float, float]:
    """A marker's peak speed, m/s, and its longest movement, s (NaN if it never moves).

    The peak is the 95th percentile of the speed over five samples, so that
    spikes and held samples (a real Optotrak's first sample) do not count;
    the movement is the longest stretch above a fifth of it.

    Parameters
    ----------
    time : (N,) array
        Seconds.
    xyz : (N, 3) array
        Metres; NaN where lost.
    """
    time = np.asarray(time, float)
    v = _speed(time, np.asarray(xyz, float))
    seen = np.isfinite(v)
    if seen.sum() < 3:
        return math.nan, math.nan
    peak = float(np.percentile(v[seen], 95))
    if not peak > 0:
        return math.nan, math.nan
    moving = np.r_[False, np.where(seen, v > _MOVING * peak, False), False]
    edges = np.flatnonzero(np.diff(moving.astype(int)))
    starts, ends = edges[::2], edges[1::2] - 1
    longest = max((time[e + 5] - time[s] for s, e in zip(starts, ends)), default=0.0)
    return peak, float(longest)


def _hand(trials: Sequence) -> tuple[float, float]:
    """The median over trials of the fastest marker's peak speed (m/s) and longest movement (s)."""
    found = []
    for trial in trials:
        each = [peak_speed(trial.time, xyz) for xyz in trial.markers.values()]
        each = [e for e in each if math.isfinite(e[0])]
        if each:
            found.append(max(each))
    if not found:
        return math.nan, math.nan
    speeds, spans = zip(*found)
    return float(np.median(speeds)), float(np.median(spans))


def _where(options, trial, what: str) -> str:
    """How the unit or the rate was chosen: the setting (named as a field, which the command
    line gives as its flag), the file, or an inference."""
    given = getattr(options, what, None)
    if given is not None:
        return f"`{what}` {given:g}" if what == "rate" else f"`{what}` {given}"
    if what == "units":
        inferred = any(n.startswith("units inferred") for n in trial.notes)
        return "inferred from the positions' spread" if inferred else "as the file declares"
    return "the file's clock"


def check_scale(trials: Sequence, path, options=None) -> None:
    """Refuse a recording whose hand moves as no human hand does, naming the likely cause.

    Parameters
    ----------
    trials : sequence of MocapTrial
        The recording's trials (:func:`perception.io.mocap.read_mocap`), in metres.
    path : str or os.PathLike
        The file, named in the error.
    options : MocapImport, optional
        The user's ``rate`` and ``units`` (None: the file's, or inferred).

    Raises
    ------
    InputError
        The median trial's longest movement lasts over :data:`MAX_MOVEMENT`
        (the rate: ``field`` ``--rate``), or its fastest marker peaks over
        :data:`MAX_PEAK_SPEED` (the unit that would fit is named: ``--units``).
    """
    if not trials:
        return
    speed, span = _hand(trials)
    if not math.isfinite(speed):
        return
    trial = trials[0]
    if span > MAX_MOVEMENT:
        raise InputError(
            f"the hand moves without a pause for {span:.3g} s at {trial.rate:g} samples/s "
            f"({_where(options, trial, 'rate')}): a reach and its return last under "
            f"{MAX_MOVEMENT:g} s; is the rate right (`rate`)?", path, field="rate")
    if speed > MAX_PEAK_SPEED:
        units = trial.units
        fits = [(u, speed * _UNITS[u] / _UNITS[units]) for u in _UNITS
                if _UNITS[u] < _UNITS[units]]
        # the unit that brings the hand nearest a typical reach's 1 m/s
        fits = sorted(((abs(math.log(s)), u, s) for u, s in fits if s <= MAX_PEAK_SPEED))
        hint = (f"; in {fits[0][1]} it would be {fits[0][2]:.2g} m/s (`units` {fits[0][1]})"
                if fits else "; are the units (`units`) and the rate (`rate`) right?")
        raise InputError(
            f"the hand moves at up to {speed:.3g} m/s with the positions in {units} "
            f"({_where(options, trial, 'units')}): no arm moves over {MAX_PEAK_SPEED:g} m/s"
            f"{hint}", path, field="units")

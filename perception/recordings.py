"""3D motion-capture recordings in, one recognition per reach out.

:func:`read_reaches` reads a recording (:func:`perception.io.mocap.read_mocap`:
C3D, Qualisys TSV, lab tables with X/Y/Z per marker, long tables with a
trial column), finds every reach to grasp in each of its trials
(:func:`perception.reaches.recording_reaches`) and :func:`recognize_reach`
scores one, in the movement's own plane, with the settings the reach's own
geometry asks for (its scale is a millimetre per "pixel", its object's size
is the grip's or the one given, and the digits need not touch at rest).

docs/mocap.md describes the formats, the mapping and what is reported.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from perception.errors import InputError
from perception.landmarks import movement_landmarks
from perception.reaches import PX_PER_M, MarkerMap, Reach, ReachParams, reach_tracks

__all__ = ["MocapImport", "cached_reaches", "read_reaches", "recognize_reach"]


@dataclass(frozen=True)
class MocapImport:
    """How a motion-capture file becomes reaches.

    Parameters
    ----------
    markers : MarkerMap, optional
        Which markers are thumb, finger, wrist and object (default: guessed
        from the names, :meth:`MarkerMap.guess`).
    rate : float, optional
        Samples per second, for tables without a time column.
    units : str, optional
        The file's length unit (``mm``, ``cm``, ``m``), if it does not say.
    trial_column : str, optional
        The column that numbers the trials of a long table.
    reaches : ReachParams
        How reaches are found, cleaned and brought into their plane.
    """

    markers: MarkerMap | None = None
    rate: float | None = None
    units: str | None = None
    trial_column: str | None = None
    reaches: ReachParams = field(default_factory=ReachParams)

    def to_dict(self) -> dict:
        """JSON-able settings (for a report's fingerprint)."""
        return dataclasses.asdict(self)


def read_reaches(path, options: MocapImport | None = None) -> list[Reach]:
    """Every reach to grasp in a motion-capture file, trial by trial.

    Parameters
    ----------
    path : str or os.PathLike
        The recording.
    options : MocapImport, optional

    Raises
    ------
    InputError
        The file cannot be read, a mapped marker is missing, or no trial holds a reach.
    """
    from perception.io.mocap import read_mocap
    from perception.reaches import recording_reaches

    options = MocapImport() if options is None else options
    trials = read_mocap(path, rate=options.rate, units=options.units,
                        trial_column=options.trial_column)
    out: list[Reach] = []
    errors = []
    for trial in trials:
        try:
            out += recording_reaches(trial, options.markers, options.reaches)
        except InputError as exc:
            if len(trials) == 1:
                raise
            errors.append(f"{trial.name}: {exc.problem}")
    if not out:
        raise InputError(f"no reach to grasp in any of its {len(trials)} trials "
                         f"({errors[0] if errors else ''})", path)
    return out


@functools.lru_cache(maxsize=4)
def _cached(key: tuple, options: MocapImport) -> tuple[Reach, ...]:
    """The reaches of ``key[0]``; its size and time of change, the rest of ``key``, keep a
    changed file from being answered from the cache."""
    return tuple(read_reaches(key[0], options))


def cached_reaches(path, options: MocapImport | None = None) -> tuple[Reach, ...]:
    """:func:`read_reaches`, read once per process while the file is unchanged.

    A batch scores a recording's reaches one by one, perhaps in several
    processes: each reads the file once, not once per reach.

    Parameters
    ----------
    path : str or os.PathLike
        The recording.
    options : MocapImport, optional
    """
    import os

    st = os.stat(path)
    return _cached((str(path), st.st_size, st.st_mtime_ns), options or MocapImport())


def recognize_reach(reach: Reach, repertoire, settings=None,
                    options: MocapImport | None = None, plan_cache=None):
    """Score one reach: its tracks in the movement's plane, recognised as a clip's.

    Parameters
    ----------
    reach : Reach
        From :func:`read_reaches`.
    repertoire : Repertoire
    settings : RecognitionSettings, optional
        Its ``observe`` scale, object size and rest aperture are set from the reach.
    options : MocapImport, optional
    plan_cache : PlanCache, optional

    Returns
    -------
    Recognition, dict
        The recognition and the ``mocap`` entry of its report (plane,
        object size, notes).
    """
    from perception.pipeline import RecognitionSettings, recognize_tracks

    options = MocapImport() if options is None else options
    settings = RecognitionSettings() if settings is None else settings
    tracks, info, transport, aperture = reach_tracks(reach, options.reaches)
    at_rest = aperture[:2 * settings.observe.rest_frames]
    widest = float(np.max(at_rest, initial=0.0, where=np.isfinite(at_rest)))
    observe = dataclasses.replace(
        settings.observe, px_per_m=PX_PER_M, object_diameter=info["object_size"],
        # a whole-hand grasp may rest with the digits apart: the rest
        # aperture is taken off like the markers' separation at rest
        max_rest_aperture=max(settings.observe.max_rest_aperture, widest + 0.01))
    rec = recognize_tracks(tracks, repertoire, dataclasses.replace(settings, observe=observe),
                           clip=reach.name, source=reach.source, plan_cache=plan_cache)
    # the landmarks from the 3D speed and aperture, on the observation's clock (its
    # last row is the tracks' last: settling only ever trims or holds the first)
    clock = tracks.time - (tracks.time[-1] - rec.observation.clip_time[-1])
    rec = dataclasses.replace(rec, measured=movement_landmarks(clock, transport, aperture,
                                                               options.reaches.landmarks))
    info = {**info, "trial": reach.name, "source": reach.source,
            "rate": round(1 / float(_median_step(reach.time)), 3)}
    return rec, info


def _median_step(time) -> float:
    step = float(np.median(np.diff(time)))
    return step if math.isfinite(step) and step > 0 else 1.0

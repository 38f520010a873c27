"""3D motion-capture recordings in, one recognition per reach out, every trial accounted for.

:func:`read_recording` reads a recording (:func:`perception.io.mocap.read_mocap`:
C3D, OpenSim TRC, Qualisys TSV, lab tables with X/Y/Z per marker, long tables with a
trial column, headerless tables with ``columns``), finds every reach to grasp
in each of its trials (:func:`perception.reaches.trial_reaches`) and says why
of every trial or movement that gives none (:class:`~perception.reaches.Unscored`):
a :class:`Recording`. One trial's failure never stops the trials after it.
:func:`read_reaches` is its reaches alone. :func:`recognize_reach` scores one
reach, in the movement's own plane, with the settings the reach's own
geometry asks for (its tracks are metres in that plane, its object's size
is the grip's or the one given, and the digits need not touch at rest), and
measures its landmarks by the verdict rules' ``[verdict.landmarks]``, as a
video's are: :func:`prepare_reach`, then the recognition with the reach's 3D
paths (``hammer-mv watch`` feeds its rows to an online recogniser first).

docs/mocap.md describes the formats, the mapping and what is reported.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import logging
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Annotated, Literal, NamedTuple

import numpy as np
from pydantic import AfterValidator, BeforeValidator, Field

from perception.boundary import expect
from perception.errors import InputError
from perception.factors import NAME_FLAG as FACTORS_FROM_NAME
from perception.factors import merge_factors, name_factors
from perception.landmarks import MeasuredPaths
from perception.limits import MAX_FPS
from perception.reaches import (
    MarkerMap,
    Reach,
    ReachParams,
    Unscored,
    ever_seen,
    reach_tracks,
    trial_reaches,
)
from perception.validation import Tuple, declared

__all__ = ["MocapImport", "PreparedReach", "Recording", "cached_reaches", "cached_recording",
           "iter_recording", "prepare_reach", "read_reaches", "read_recording",
           "recognize_reach", "trial_summary", "unknown_layout"]

log = logging.getLogger(__name__)


_POSE_LAYOUT = ("a pose file (DeepLabCut or Lightning Pose CSV: scorer, bodyparts and coords "
                "header rows)")
_TABLE_SUFFIXES = (".csv", ".tsv", ".txt")


def unknown_layout(path) -> str | None:
    """Why a ``.csv``, ``.tsv`` or ``.txt`` file is neither a motion-capture table nor a pose file.

    Only the first lines are read. A file a motion-capture reader or a pose
    reader takes (whatever it then finds wrong inside) gives None, as does
    any other kind of file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    str or None
        The one-line problem (``not a motion-capture table or pose file of a
        known layout (expected ...)``), or None.
    """
    from pathlib import Path

    from perception.io.mocap import is_mocap_file
    from perception.io.pose import pose_output
    from perception.io.pose_sleap_csv import is_sleap_csv

    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in _TABLE_SUFFIXES or is_mocap_file(p):
        return None
    try:
        with open(p, encoding="utf-8", errors="replace") as fh:
            lines = [fh.readline() for _ in range(12)]
    except OSError:
        return None  # the reader says what is wrong with it
    if not any(line.strip() for line in lines):
        return None  # empty: the reader says so
    if suffix == ".csv" and (pose_output(p.name) is not None or {"bodyparts", "coords"} <= {
            line.split(",", 1)[0].strip().strip('"').lower() for line in lines[:4]}):
        return None  # DeepLabCut's header rows (Lightning Pose writes them too)
    if suffix == ".csv" and is_sleap_csv(lines[0]):
        return None  # SLEAP's analysis CSV
    # a .txt of prose (notes) is no table at all: the plain "not a clip" fits it
    if suffix == ".txt" and not any(_tabular(line) for line in lines):
        return None
    # the motion-capture reader's own words for what it found and the layouts it reads
    from perception.io.mocap import unknown_layout as told

    return f"{told(p).problem}; or {_POSE_LAYOUT}"


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _tabular(line: str) -> bool:
    """Whether a line looks like a table's: cells between tabs, commas or semicolons, or
    three numbers or more between spaces (a headerless table)."""
    if max(line.count("\t"), line.count(","), line.count(";")) >= 2:
        return True
    cells = line.split()
    return len(cells) >= 3 and all(_NUMBER.fullmatch(c) for c in cells)


def _column_name(name: str) -> str:
    if not name.strip():
        raise ValueError("a marker name, not an empty one")
    return name.strip()


#: A marker's name in ``columns``: not empty.
ColumnName = Annotated[str, AfterValidator(_column_name)]


def _factor_names(value):
    if isinstance(value, str):  # "participant,block", as the flag writes it
        value = value.split(",")
    if isinstance(value, (list, tuple)):
        value = tuple(str(v).strip() if isinstance(v, str) else v for v in value)
        repeated = sorted({v for v in value if value.count(v) > 1})
        if repeated:
            raise ValueError(f"each column named once ({repeated[0]!r} is twice)")
    return value


def _name_pattern(value: str) -> str:
    try:
        re.compile(value)
    except re.error as exc:  # said as "expected ..., got ..." by the declared class
        raise ValueError(f"a regular expression ({exc})") from None
    if not re.compile(value).groupindex:
        raise ValueError("a regular expression with a named group per factor, "
                         "such as (?P<participant>P\\d+)")
    return value


#: The columns read as factors: names, each once (``"a,b"`` is two).
FactorNames = Annotated[tuple[ColumnName, ...], BeforeValidator(_factor_names), Tuple,
                        Field(min_length=1)]
#: A regular expression with named groups (:func:`perception.factors.name_pattern`).
NamePattern = Annotated[str, AfterValidator(_name_pattern)]


@declared
class MocapImport:
    """How a motion-capture file becomes reaches.

    Parameters
    ----------
    markers : MarkerMap, optional
        Which markers are thumb, finger, wrist and object (default: guessed
        from the names, :meth:`MarkerMap.guess`).
    rate : float, optional
        Samples per second (above 0, up to 1000), for tables without a time
        column.
    units : {"mm", "cm", "m"}, optional
        The file's length unit, if it does not say.
    trial_column : str, optional
        The column that numbers the trials of a long table.
    time_column : str, optional
        The column that holds the time; ``"none"``: the file's time column,
        if any, is ignored and ``rate`` gives the clock.
    columns : tuple of str, optional
        The markers' names in column order, for a table without a header
        (X, Y and Z of each, as RTMocap writes them).
    reaches : ReachParams
        How reaches are found, cleaned and brought into their plane.
    factors : tuple of str, optional
        Columns of a long table read as the design's factors, each constant
        within a trial (participant, subject, condition, session, block and
        group are by default: :func:`perception.factors.table_factors`).
    factors_from_name : str, optional
        A regular expression whose named groups, searched in each file's
        name, are factors of its every row
        (``(?P<participant>P\\d+)_(?P<condition>[a-z]+)``).
    """

    markers: MarkerMap | None = None
    rate: Annotated[float, Field(gt=0, le=MAX_FPS)] | None = None
    units: Literal["mm", "cm", "m"] | None = None
    trial_column: str | None = None
    time_column: str | None = None
    columns: Annotated[tuple[ColumnName, ...], Tuple, Field(min_length=1)] | None = None
    reaches: ReachParams = field(default_factory=ReachParams)
    factors: FactorNames | None = None
    factors_from_name: NamePattern | None = None

    def to_dict(self) -> dict:
        """JSON-able settings (for a report's fingerprint)."""
        return dataclasses.asdict(self)

    def read_options(self) -> dict:
        """The keyword arguments of :func:`~perception.io.mocap.read_mocap` these ask for."""
        return {"rate": self.rate, "units": self.units, "trial_column": self.trial_column,
                "time_column": self.time_column, "columns": self.columns,
                "factors": self.factors}

    def name_factors(self, path) -> dict[str, str]:
        """The factors :attr:`factors_from_name` finds in ``path``'s name (``{}`` if none,
        or if it does not match: a note is logged).

        Parameters
        ----------
        path : str or os.PathLike
            An input file.
        """
        return name_factors(self.factors_from_name, path) or {}

    def with_landmarks(self, params) -> MocapImport:
        """These settings with reaches bounded by ``params`` (a :class:`LandmarkParams`).

        The user's landmark definitions (``[verdict.landmarks]``, ``landmarks
        --threshold``) bound each reach as they bound its measured landmarks,
        so that a row's window and its landmarks follow one rule.

        Parameters
        ----------
        params : LandmarkParams
        """
        return dataclasses.replace(self, reaches=dataclasses.replace(self.reaches,
                                                                     landmarks=params))


def _start(entry: Reach | Unscored) -> float:
    """Where a reach or an unscored movement starts on its trial's clock (inf if unknown)."""
    if isinstance(entry, Reach):
        return float(entry.time[entry.onset])
    for t in (entry.onset_time, entry.end_time):
        if math.isfinite(t):
            return t
    return math.inf


@dataclass(frozen=True, eq=False)
class Recording:
    """Every trial of a recording: its reaches to score, and what gives none, and why.

    Attributes
    ----------
    source : str
        The file.
    trials : tuple of str
        The trials' names, in file order.
    entries : tuple of Reach or Unscored
        Trial by trial in file order, and within a trial by start time: each
        reach found, and each trial or movement that gives none
        (:class:`~perception.reaches.Unscored`, with its status and reason).
        Every trial has at least one.
    """

    source: str
    trials: tuple[str, ...]
    entries: tuple[Reach | Unscored, ...]

    @property
    def reaches(self) -> list[Reach]:
        """The reaches to score, in order."""
        return [e for e in self.entries if isinstance(e, Reach)]

    @property
    def unscored(self) -> list[Unscored]:
        """The trials and movements that give no reach, with why."""
        return [e for e in self.entries if isinstance(e, Unscored)]


def trial_summary(trials: int, scored: int, not_scored: int) -> str:
    """The accounting line every command prints: ``"N trials, M reaches scored, K not scored"``.

    Parameters
    ----------
    trials : int
        Trials read (a video, tracks or pose file is one).
    scored : int
        Reaches that got a result.
    not_scored : int
        Trials, movements or reaches that did not, each listed with its reason.
    """
    return (f"{trials} trial{'s' if trials != 1 else ''}, {scored} "
            f"reach{'es' if scored != 1 else ''} scored, {not_scored} not scored")


def read_recording(path, options: MocapImport | None = None) -> Recording:
    """Every trial of a motion-capture file: its reaches, and what gives none, and why.

    Parameters
    ----------
    path : str or os.PathLike
        The recording.
    options : MocapImport, optional

    Returns
    -------
    Recording
        Each trial leaves reaches or an :class:`~perception.reaches.Unscored`
        entry; a trial on which the reach finder fails (a bug) leaves one with
        status ``failed``, and the trials after it are read as usual.

    Raises
    ------
    InputError
        The file cannot be read, the marker mapping names a marker it lacks,
        or a digit's (or a mapped wrist's) marker is never seen in any trial
        (mistakes that hold for every trial).
    """
    trials = list(iter_recording(path, options))
    return Recording(str(path), tuple(name for name, _ in trials),
                     tuple(e for _, entries in trials for e in entries))


def iter_recording(path, options: MocapImport | None = None
                   ) -> Iterator[tuple[str, list[Reach | Unscored]]]:
    """:func:`read_recording` trial by trial, each as soon as it is read: what a batch
    hands out while it reads the rest.

    Parameters
    ----------
    path : str or os.PathLike
        The recording.
    options : MocapImport, optional

    Yields
    ------
    (str, list of Reach or Unscored)
        A trial's name and its entries (:attr:`Recording.entries`).

    Raises
    ------
    InputError
        As :func:`read_recording`; a marker never seen in any trial only once
        every trial has been yielded.
    """
    from perception.io.mocap import read_mocap
    from perception.plausibility import SCALE_TRIALS, check_scale

    expect(options, MocapImport, "read_recording(options=)", optional=True)
    options = MocapImport() if options is None else options
    trials = read_mocap(path, **options.read_options())
    from_name = options.name_factors(path)
    # one pass: a large table's trials are read from the file on each (TrialStream)
    count, seen = 0, {}
    # a unit or a rate no human hand fits is every trial's: said before any reach is sought
    read = iter(trials)
    first = list(itertools.islice(read, SCALE_TRIALS))
    if first:  # no hand's markers: said before the hand's pace (a gait trial's walk is long)
        mapped = options.markers or MarkerMap.guess(first[0].markers)
        mapped.matched(first[0].markers).check(first[0].markers, path)
    check_scale(first, path, options)
    for trial in itertools.chain(first, read):
        count += 1
        _note_seen(seen, trial, options.markers)
        source = str(trial.source)
        factors = merge_factors([("the table's columns", trial.factors),
                                 (f"the file name (`{FACTORS_FROM_NAME}`)", from_name)], path)
        if factors != trial.factors:
            trial = dataclasses.replace(trial, factors=factors)
        labels = {"factors": factors, "trial_number": trial.trial_number}
        try:
            reaches, unscored = trial_reaches(trial, options.markers, options.reaches)
        except InputError:
            raise  # a mapping naming a marker the file lacks: every trial's mistake
        except Exception as exc:  # noqa: BLE001 - one trial must not take the others
            log.exception("%s: the reach finder failed (a bug in hammer-mv)", trial.name)
            said = str(exc).strip().splitlines()
            reaches, unscored = [], [Unscored(
                trial.name, source, "failed", f"failed: unexpected {type(exc).__name__} "
                f"(a bug in hammer-mv){': ' + said[0] if said else ''}", **labels)]
        if not reaches and not unscored:  # every trial leaves a word
            unscored = [Unscored(trial.name, source, "no reach", "no reach found", **labels)]
        yield trial.name, sorted([*reaches, *unscored], key=_start)
    if (lost := _never_seen(seen, count)) is not None:
        raise InputError(lost, path)


def _note_seen(seen: dict, trial, markers: MarkerMap | None) -> None:
    """Mark in ``seen`` (``(name, role) -> bool``) whether ``trial`` sees each marker its
    mapping (``markers``, or the guess) gives a digit or the wrist."""
    mapped = MarkerMap.guess(trial.markers) if markers is None else markers.matched(
        trial.markers)
    for name, role in mapped.roles():
        if role != "object" and name in trial.markers:  # a missing one: check() says
            seen[name, role] = seen.get((name, role), False) or ever_seen(trial.markers[name])


def _never_seen(seen: dict, trials: int) -> str | None:
    """Why the recording gives no reach anywhere: a digit's or a mapped wrist's marker that
    none of its ``trials`` ever sees (``seen`` by :func:`_note_seen`; None if each is seen
    somewhere).

    The marker is named, not the "no reach" it leads to: a lost marker or a
    wrong mapping, the user's to fix for every trial at once. A trial that
    loses one another trial sees is that trial's (``marker lost``). The
    object's markers may be lost (the object is then where the grip closes).
    """
    lost = [(name, role) for (name, role), ok in seen.items() if not ok]
    if not lost:
        return None
    name, role = lost[0]
    what = f"marker {name!r}" + ("" if name == role else f" (the {role})")
    where = f"any of its {trials} trials" if trials > 1 else "the recording"
    return (f"{what} is never seen in {where}: every sample of it is "
            "missing (empty, NaN, all zeros or flagged); check `markers` or the recording")


def read_reaches(path, options: MocapImport | None = None) -> list[Reach]:
    """Every reach to grasp in a motion-capture file, trial by trial.

    The trials and movements that give none are :func:`read_recording`'s
    :attr:`Recording.unscored`; here they are logged (INFO) and left out.

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
    expect(options, MocapImport, "read_reaches(options=)", optional=True)
    recording = read_recording(path, options)
    for u in recording.unscored:
        log.info("%s: not scored: %s", u.name, u.reason)
    if not recording.reaches:
        n = len(recording.trials)
        first = recording.unscored[0].reason if recording.unscored else ""
        where = "its trial" if n == 1 else f"any of its {n} trials"
        raise InputError(f"no reach to grasp in {where} ({first})", path)
    return recording.reaches


@functools.lru_cache(maxsize=4)
def _cached(key: tuple, options: MocapImport) -> Recording:
    """The recording ``key[0]``; its size and time of change, the rest of ``key``, keep a
    changed file from being answered from the cache."""
    return read_recording(key[0], options)


def cached_recording(path, options: MocapImport | None = None) -> Recording:
    """:func:`read_recording`, read once per process while the file is unchanged.

    A batch scores a recording's reaches one by one, perhaps in several
    processes: each reads the file once, not once per reach.

    Parameters
    ----------
    path : str or os.PathLike
        The recording.
    options : MocapImport, optional
    """
    import os

    expect(options, MocapImport, "cached_recording(options=)", optional=True)
    st = os.stat(path)
    return _cached((str(path), st.st_size, st.st_mtime_ns), options or MocapImport())


def cached_reaches(path, options: MocapImport | None = None) -> tuple[Reach, ...]:
    """:func:`cached_recording`'s reaches.

    Parameters
    ----------
    path : str or os.PathLike
        The recording.
    options : MocapImport, optional
    """
    expect(options, MocapImport, "cached_reaches(options=)", optional=True)
    return tuple(cached_recording(path, options).reaches)


def recognize_reach(reach: Reach, repertoire, settings=None,
                    options: MocapImport | None = None, plan_cache=None):
    """Score one reach: its tracks in the movement's plane, recognised as a clip's.

    Parameters
    ----------
    reach : Reach
        From :func:`read_reaches`.
    repertoire : Repertoire
    settings : RecognitionSettings, optional
        Its ``observe`` scale, object size and rest aperture are set from the reach;
        the landmarks are measured by its ``rules.landmarks`` (``[verdict.landmarks]``).
    options : MocapImport, optional
    plan_cache : PlanCache, optional

    Returns
    -------
    Recognition, dict
        The recognition and the ``mocap`` entry of its report (plane,
        object size, notes).
    """
    from perception.pipeline import RecognitionSettings, recognize_tracks
    from perception.recognition import Repertoire

    # each refused here, not as an AttributeError at its first use
    expect(reach, Reach, "recognize_reach(reach=)", hint="read_reaches or read_recording")
    expect(repertoire, Repertoire, "recognize_reach(repertoire=)",
           hint="Repertoire.load or Repertoire.build")
    expect(settings, RecognitionSettings, "recognize_reach(settings=)", optional=True)
    expect(options, MocapImport, "recognize_reach(options=)", optional=True)
    prepared = prepare_reach(reach, settings, options)
    rec = recognize_tracks(prepared.tracks, repertoire, prepared.settings, clip=reach.name,
                           source=reach.source, plan_cache=plan_cache, paths=prepared.paths)
    return rec, prepared.info


class PreparedReach(NamedTuple):
    """A reach ready to be scored, offline or row by row (:func:`prepare_reach`).

    Attributes
    ----------
    tracks, info
        :func:`~perception.reaches.reach_tracks`' (``info`` with the reach's
        ``trial``, ``source`` and ``rate``: the report's ``mocap`` entry).
    paths : MeasuredPaths
        Its 3D transport and aperture, which its landmarks are measured on
        (by the verdict rules' ``[verdict.landmarks]``, as a video's are; the
        reach finder's own bounds only choose the reach's window), and the
        recording's clock.
    settings : RecognitionSettings
        The settings its geometry asks for: the grip's object size, a whole
        hand's rest aperture.
    """

    tracks: object
    info: dict
    paths: MeasuredPaths
    settings: object


def prepare_reach(reach: Reach, settings=None, options: MocapImport | None = None
                  ) -> PreparedReach:
    """A reach's tracks in its plane and the settings they are scored with.

    :func:`recognize_reach` scores them offline; ``hammer-mv watch`` of a
    recording feeds their rows to an :class:`~perception.online.OnlineRecognizer`;
    both end in :func:`perception.pipeline.recognize_tracks` with its ``paths``.

    Parameters
    ----------
    reach : Reach
    settings : RecognitionSettings, optional
        The user's; its ``observe`` scale, object size and rest aperture are
        set from the reach.
    options : MocapImport, optional
    """
    from perception.pipeline import RecognitionSettings

    expect(reach, Reach, "prepare_reach(reach=)", hint="read_reaches or read_recording")
    expect(settings, RecognitionSettings, "prepare_reach(settings=)", optional=True)
    expect(options, MocapImport, "prepare_reach(options=)", optional=True)
    options = MocapImport() if options is None else options
    settings = RecognitionSettings() if settings is None else settings
    tracks, info, transport, aperture = reach_tracks(reach, options.reaches)
    at_rest = aperture[:2 * settings.observe.rest_frames]
    widest = float(np.max(at_rest, initial=0.0, where=np.isfinite(at_rest)))
    observe = dataclasses.replace(
        settings.observe, object_diameter=info["object_size"],
        # a whole-hand grasp may rest with the digits apart: the rest
        # aperture is taken off like the markers' separation at rest
        max_rest_aperture=max(settings.observe.max_rest_aperture, widest + 0.01))
    info = {**info, "trial": reach.name, "source": reach.source,
            "rate": round(1 / float(_median_step(reach.time)), 3)}
    bounds = (info["bounds"]["onset"], info["bounds"]["end"])
    # the recording's clock at the tracks' onset row: the onset row's time in the file
    paths = MeasuredPaths(tracks.time, transport, aperture, bounds,
                          float(reach.time[reach.onset] - tracks.time[bounds[0]]))
    return PreparedReach(tracks, info, paths, dataclasses.replace(settings, observe=observe))


def _median_step(time) -> float:
    step = float(np.median(np.diff(time)))
    return step if math.isfinite(step) and step > 0 else 1.0

"""What every motion-capture reader shares: the trial object and its assembly.

:class:`MocapTrial` is what :func:`perception.io.mocap.read_mocap` returns;
:func:`assemble` turns a reader's pieces (one per trial, positions in the
file's unit) into trials in metres: lost samples marked, the unit stated or
inferred, markers never seen named. The checks of a rate and a unit, and the
rule that reconciles a given rate with a file's own, live here so that every
format applies them alike.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from perception.errors import InputError
from perception.limits import MAX_FPS, MAX_FRAMES, MAX_KEYPOINTS

__all__ = ["UNITS", "MocapTrial", "Spread", "TrialStream", "reading_progress"]

_log = logging.getLogger(__name__)

#: Length units a file may be in, and metres per unit.
UNITS = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
#: A human reach spans tens of cm: positions ranging over more than this are not metres.
_MM_ABOVE = 5.0
#: Coordinates this large are NDI's missing-marker value (-3.697314e28), not positions.
_NDI_MISSING = 1e25
#: Where a table read trial by trial says how far it is (:func:`reading_progress`).
_PROGRESS: ContextVar = ContextVar("mocap_progress", default=None)
#: A rate given and a file's own clock may differ by this share before they disagree.
RATE_TOLERANCE = 0.01


@dataclass(frozen=True, eq=False)
class MocapTrial:
    """One trial (or a whole recording) of 3D marker positions.

    Parameters
    ----------
    name : str
        ``<file stem>``, or ``<file stem>-trial<ID>`` for a table with a trial column.
    source : str
        The file, as the caller named it.
    time : (N,) ndarray
        Sample times, s, increasing; they start where the file's clock starts
        (0 when the file has none).
    markers : mapping of str to (N, 3) ndarray
        Marker name -> positions in metres, NaN where the marker was lost.
    rate : float
        Samples/s.
    units : str
        The file's length unit, ``"mm"``, ``"cm"`` or ``"m"`` (stated or inferred).
    notes : tuple of str
        What the reader inferred or repaired, in words.
    extra : mapping of str to (N,) ndarray
        Other numeric per-sample columns of a table (``graspPhase``, ...).
    factors : mapping of str to str
        The design's factors the trial's own columns give (participant,
        condition, ...: :func:`perception.factors.table_factors`), as written.
    trial_number : str
        The trial's id as its trial column writes it (``"38"``); for a file
        without one, the trial's 1-based index in the file.
    """

    name: str
    source: str
    time: np.ndarray
    markers: Mapping[str, np.ndarray]
    rate: float
    units: str
    notes: tuple[str, ...] = ()
    extra: Mapping[str, np.ndarray] = field(default_factory=dict)
    factors: Mapping[str, str] = field(default_factory=dict)
    trial_number: str = "1"

    def __post_init__(self) -> None:
        object.__setattr__(self, "markers", MappingProxyType(dict(self.markers)))
        object.__setattr__(self, "extra", MappingProxyType(dict(self.extra)))
        object.__setattr__(self, "factors", MappingProxyType(dict(self.factors)))
        object.__setattr__(self, "notes", tuple(self.notes))

    def __reduce__(self):
        # MappingProxyType does not pickle: batch workers get the trial sent
        return MocapTrial, (self.name, self.source, self.time, dict(self.markers), self.rate,
                            self.units, self.notes, dict(self.extra), dict(self.factors),
                            self.trial_number)

    def marker_names(self) -> tuple[str, ...]:
        """The markers' names, in the file's order."""
        return tuple(self.markers)

    def lost_markers(self) -> tuple[str, ...]:
        """The markers never seen in this trial (every sample empty, NaN or at the origin)."""
        return tuple(m for m, xyz in self.markers.items() if not np.isfinite(xyz).all(axis=1).any())


def check_rate(value, path: Path, where: str) -> float:
    """``value`` as a rate in samples/s, or an InputError naming ``where``.

    Parameters
    ----------
    value : float or str
        The rate.
    path : Path
        The file, for the message.
    where : str
        The flag or header field the value came from.
    """
    try:
        ok = not isinstance(value, bool) and math.isfinite(float(value)) and float(value) > 0
    except (TypeError, ValueError):
        ok = False
    if not ok or float(value) > MAX_FPS:
        raise InputError(f"expected a sampling rate above 0 and up to {MAX_FPS:g} samples/s, "
                         f"got {value!r}", path, field=where)
    return float(value)


def check_unit(value, path: Path, where: str) -> str:
    """``value`` as one of :data:`UNITS`, or an InputError naming ``where``.

    Parameters
    ----------
    value : str
        The unit (``mm``, ``cm``, ``m``, any case).
    path : Path
        The file, for the message.
    where : str
        The flag or header field the value came from.
    """
    unit = str(value).strip().lower()
    if unit not in UNITS:
        # a file's own word: the flag says what it means
        fix = "" if where == "units" else ": give the file's unit with `units`"
        raise InputError(f"unknown length unit {value!r} (expected mm, cm or m){fix}", path,
                         field=where)
    return unit


def header_rate(rate: float | None, own, path: Path, where: str) -> tuple[float, list[str]]:
    """The rate of a file whose header states one (``own``) and whose times come from it.

    A rate given wins, with a note, and the times are built from it: the note is
    true. (Where a file's time column is its clock, :func:`clock_rate` applies.)

    Parameters
    ----------
    rate : float or None
        The rate the caller gave.
    own : float or str
        The header's rate.
    path : Path
        The file.
    where : str
        The header field of ``own``.
    """
    own = check_rate(own, path, where)
    if rate is None or rate == own:
        return own, []
    return rate, [f"rate {rate:g} samples/s given; the file's {where} says {own:g}: "
                  "the times are built from the rate given"]


def clock_rate(rate: float | None, own: float, path: Path, column: str,
               source: str) -> float:
    """The rate of samples timed by a clock column: a rate given must agree with it.

    Within :data:`RATE_TOLERANCE` the rate given is used; further apart the two
    cannot both be true, and the reader refuses rather than pick one.

    Parameters
    ----------
    rate : float or None
        The rate the caller gave.
    own : float
        The rate the clock (or the header beside it) implies.
    path : Path
        The file.
    column : str
        The clock's column, for the message.
    source : str
        Where ``own`` comes from, in words (``"its steps"``, ``"FREQUENCY"``).
    """
    if rate is None:
        return own
    if abs(rate / own - 1) > RATE_TOLERANCE:
        raise InputError(f"`rate` {rate:g} disagrees with the time column {column!r} "
                         f"({own:.6g} samples/s from {source}): leave `rate` out, or give "
                         "`time_column` none to time the samples by `rate` instead", path,
                         field="rate")
    return rate


def unique_name(name: str, taken) -> str:
    """``name``, or ``name_2``, ``name_3``, ... whichever is not in ``taken``.

    Parameters
    ----------
    name : str
        The name wanted.
    taken : container of str
        Names already used.
    """
    base, k = name, 1
    while name in taken:
        k += 1
        name = f"{base}_{k}"
    return name


def strip_subject(names: list[str]) -> tuple[list[str], list[str]]:
    """``Subject:Marker`` names without their subject, where that keeps them apart.

    Vicon and OptiTrack prefix each labelled marker with its subject (or rigid
    body). The prefix is left out unless two markers would then share a name
    (two subjects with the same marker set): those keep their full names.

    Parameters
    ----------
    names : list of str
        The names as the file writes them.

    Returns
    -------
    list of str, list of str
        The names to use (unique), and notes.
    """
    short = [n.rpartition(":")[2] or n for n in names]
    clash = {s for s in short if short.count(s) > 1}
    out = [n if s in clash else s for n, s in zip(names, short)]
    subjects = sorted({n.rpartition(":")[0] for n, s in zip(names, short)
                       if ":" in n and s not in clash})
    notes = []
    if subjects:
        notes.append(f"subject prefix{'es' if len(subjects) > 1 else ''} "
                     f"{', '.join(repr(s + ':') for s in subjects)} left out of the marker names")
    if clash:
        notes.append(f"markers of several subjects share names ({', '.join(sorted(clash))}): "
                     "they keep their full Subject:Marker names")
    unique: list[str] = []
    for name in out:
        unique.append(unique_name(name, unique))
    repeated = sorted({a for a, b in zip(out, unique) if a != b})
    if repeated:
        said = "; ".join(f"{a!r} as {', '.join(repr(b) for o, b in zip(out, unique) if o == a)}"
                         for a in repeated)
        notes.append(f"marker names written more than once ({', '.join(map(repr, repeated))}): "
                     f"read {said}, in the file's order")
    return unique, notes


class Spread:
    """Each marker's range over a recording, without its most extreme 1 % of values, gathered
    a piece at a time (:func:`_infer_units`' rule, for a table read in chunks).

    Only the smallest and the largest ``bound`` values of each marker are
    kept, ``bound`` being 1 % of the most values there can be, plus one: the
    1 % cut of the values there are is among them, so the range is the one
    the whole table gives, and the memory is that of 2 % of it.

    Parameters
    ----------
    names : list of str
        The markers.
    most : int
        The most values (rows x 3) any marker can have.
    """

    def __init__(self, names, most: int):
        self.bound = int(0.01 * most) + 1
        self.count = dict.fromkeys(names, 0)
        self.low = {n: np.empty(0) for n in names}
        self.high = {n: np.empty(0) for n in names}

    def add(self, markers: Mapping[str, np.ndarray]) -> None:
        """Take in a piece: marker -> positions (lost samples NaN).

        Parameters
        ----------
        markers : mapping of str to ndarray
        """
        for name, xyz in markers.items():
            values = xyz.ravel()
            values = values[np.isfinite(values)]
            self.count[name] += len(values)
            self.low[name] = _extreme(np.concatenate([self.low[name], values]), self.bound)
            self.high[name] = -_extreme(np.concatenate([-self.high[name], -values]), self.bound)

    def spans(self) -> list[float]:
        """Each seen marker's range without its extreme 1 %, in order."""
        out = []
        for name, n in self.count.items():
            if n:
                cut = int(0.01 * n)
                low, high = np.sort(self.low[name]), np.sort(self.high[name])
                out.append(float(high[len(high) - 1 - cut] - low[cut]))
        return out


def _extreme(values: np.ndarray, k: int) -> np.ndarray:
    """The ``k`` smallest of ``values`` (all of them if fewer)."""
    return values if len(values) <= k else np.partition(values, k - 1)[:k]


def _spans(pieces) -> list[float]:
    """Each marker's range over ``pieces`` without its extreme 1 %."""
    spans = []
    names = list(pieces[0][2])
    for name in names:
        values = np.concatenate([piece[2][name].ravel() for piece in pieces])
        values = np.sort(values[np.isfinite(values)])
        if len(values):
            cut = int(0.01 * len(values))
            spans.append(float(values[len(values) - 1 - cut] - values[cut]))
    return spans


def infer_units(spans: list[float]) -> tuple[str, str]:
    """The unit a table's positions are in, from their spread, and the note saying so.

    Each marker's coordinates range over the capture volume: tens of cm or more
    for the markers of a reach (more than 5 in mm, less in m). The range is
    taken per marker without its most extreme 1 % of values, and the median
    over markers decides: one glitch, or one marker off on its own, does not.

    Parameters
    ----------
    spans : list of float
        Each marker's range (:class:`Spread`).
    """
    span = float(np.median(spans)) if spans else 0.0
    units = "mm" if span > _MM_ABOVE else "m"
    markers = f"{len(spans)} marker{'s' if len(spans) != 1 else ''}"
    return units, (f"units inferred: {units} (the positions span {span:.4g}: the median over "
                   f"{markers} of each one's range, without its extreme 1 %; give `units` to "
                   "say)")


def mark_lost(markers: Mapping[str, np.ndarray]) -> int:
    """Mark lost samples NaN in place (all three coordinates 0, NDI's missing value); return
    how many were at the origin.

    Parameters
    ----------
    markers : mapping of str to (N, 3) ndarray
        Positions in the file's unit.
    """
    count = 0
    for xyz in markers.values():
        at_origin = (xyz == 0).all(axis=1)
        # NDI systems write -3.697314e28 for a marker they lost
        xyz[at_origin | ~(np.abs(xyz) < _NDI_MISSING).all(axis=1)] = np.nan
        count += int(at_origin.sum())
    return count


def check_size(samples: int, markers: int, path: Path) -> None:
    """Refuse a recording of more samples or markers than are read.

    Parameters
    ----------
    samples : int
        Its samples, all trials together.
    markers : int
        Its markers.
    path : Path
        The file.
    """
    if samples > MAX_FRAMES or markers > MAX_KEYPOINTS:
        raise InputError(f"more than {MAX_FRAMES} samples or {MAX_KEYPOINTS} markers", path)


def assemble(path: Path, source: str, pieces, rate: float, units: str | None,
             own: tuple[str, str] | None, notes: list[str],
             labels: list[tuple[str, dict]] | None = None) -> list[MocapTrial]:
    """Trials from ``(name suffix, time, {marker: (N, 3) in file units}, extra)`` pieces.

    Marks lost samples (all three coordinates 0, NDI's missing value), settles
    the unit (given, else the file's ``own`` as ``(unit, field)``, else
    inferred) and scales to metres.

    Parameters
    ----------
    path : Path
        The file.
    source : str
        The file as the caller named it.
    pieces : list of tuple
        One per trial.
    rate : float
        Samples/s.
    units : str or None
        The unit given.
    own : tuple of str, or None
        The file's own unit and the field that states it.
    notes : list of str
        Notes for every trial.
    labels : list of (str, dict), optional
        Each piece's trial number and factors (default: its 1-based index, none).
    """
    if labels is None:
        labels = [(str(k + 1), {}) for k in range(len(pieces))]
    check_size(sum(len(p[1]) for p in pieces), len(pieces[0][2]), path)
    zeros = [mark_lost(markers) for _, _, markers, _ in pieces]
    if units is None and own is not None:
        units = check_unit(own[0], path, own[1])
    if units is None:
        units, note = infer_units(_spans(pieces))
        notes = [*notes, note]
    return [make_trial(path, source, piece, count, rate, units, notes, label)
            for piece, count, label in zip(pieces, zeros, labels)]


def make_trial(path: Path, source: str, piece, zeros: int, rate: float, units: str,
               notes: list[str], label: tuple[str, dict]) -> MocapTrial:
    """One trial in metres from its piece (lost samples marked: :func:`mark_lost`).

    Parameters
    ----------
    path : Path
        The file.
    source : str
        The file as the caller named it.
    piece : tuple
        ``(name suffix, time, {marker: (N, 3) in file units}, extra)``.
    zeros : int
        Its samples found at the origin.
    rate : float
        Samples/s.
    units : str
        The file's unit.
    notes : list of str
        Notes for every trial.
    label : tuple of (str, dict)
        Its trial number and factors.
    """
    suffix, time, markers, extra = piece
    number, factors = label
    own_notes = notes + ([f"{zeros} samples at exactly (0, 0, 0) read as lost"] if zeros
                         else [])
    lost = [m for m, xyz in markers.items() if not np.isfinite(xyz).all(axis=1).any()]
    if lost and len(lost) < len(markers):
        own_notes.append(f"marker{'s' if len(lost) > 1 else ''} "
                         f"{', '.join(map(repr, lost))} never seen (every sample empty, "
                         "NaN or at (0, 0, 0))")
    elif lost:
        own_notes.append("no marker is ever seen (every sample empty, NaN or at (0, 0, 0))")
    for note in own_notes:
        _log.debug("%s%s: %s", source, suffix, note)
    return MocapTrial(
        name=path.stem + suffix, source=source, time=np.asarray(time, dtype=float),
        markers={m: xyz * UNITS[units] for m, xyz in markers.items()},
        rate=rate, units=units, notes=tuple(own_notes), extra=extra, factors=factors,
        trial_number=number)


class TrialStream(Sequence):
    """A long table's trials, read one by one as they are reached.

    What :func:`perception.io.mocap.read_mocap` returns for a large table
    (:data:`perception.io.mocap_stream.STREAM_BYTES`): a sequence of
    :class:`MocapTrial` like the list it returns otherwise, whose every pass
    reads the file once more, a chunk at a time, and holds one trial (and one
    chunk) at a time. The file was checked whole when it was opened: a
    mistake in it is raised then, not halfway.

    Parameters
    ----------
    names : sequence of str
        The trials' names, in file order.
    read : callable
        ``read()`` -> an iterator over the trials, from the first.
    """

    def __init__(self, names, read):
        self.names = tuple(names)
        self._read = read

    def __len__(self) -> int:
        return len(self.names)

    def __iter__(self):
        return self._read()

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[k] for k in range(len(self))[index]]
        k = range(len(self))[index]  # an IndexError as a list's
        return next(itertools.islice(self._read(), k, None))

    def __repr__(self) -> str:
        return f"TrialStream({len(self)} trials)"


@contextmanager
def reading_progress(callback):
    """Within it, a table read trial by trial says how far it is: ``callback(done, total,
    what)`` (rows checked, then trials read; ``what`` says which, and of which file).

    The library never prints: a command passes a callback that draws a
    progress bar (``hammer-mv landmarks`` on a terminal), through the layers
    between it and the reader.

    Parameters
    ----------
    callback : callable or None
        ``callback(done: int, total: int, what: str)``; None: nothing is said.
    """
    token = _PROGRESS.set(callback)
    try:
        yield
    finally:
        _PROGRESS.reset(token)


def progress_callback():
    """The callback :func:`reading_progress` set here, or None."""
    return _PROGRESS.get()

"""Motion-capture recordings -> :class:`MocapTrial`: 3D marker positions in metres.

Three kinds of file are read: Qualisys Track Manager (QTM) TSV exports,
delimited tables with X, Y and Z columns per marker (Optotrak/NDI exports and
lab tables, one recording or many trials in a long table with a trial column),
and C3D files through ``ezc3d`` (an optional extra: ``pip install
'hammer-mv[mocap]'``). Positions come back in metres whatever the file's unit;
lost samples (empty cells, NaN, a marker at exactly (0, 0, 0), a C3D residual
below 0) are NaN. The reader repairs nothing else: spikes and gaps are left
for a later stage. docs/mocap.md describes each format.
"""

from __future__ import annotations

import io
import logging
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from perception.errors import InputError
from perception.io.files import input_file, is_regular_file
from perception.limits import MAX_FPS, MAX_FRAMES, MAX_KEYPOINTS

__all__ = ["MOCAP_SUFFIXES", "UNITS", "MocapTrial", "is_mocap_file", "read_mocap"]

_log = logging.getLogger(__name__)

#: File endings read as motion-capture files (a table's header decides on reading).
MOCAP_SUFFIXES = (".c3d", ".tsv", ".txt", ".csv")
#: Length units a file may be in, and metres per unit.
UNITS = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
#: A human reach spans tens of cm: positions ranging over more than this are not metres.
_MM_ABOVE = 5.0
_MOCAP_EXTRA = "reading C3D files needs ezc3d: pip install 'hammer-mv[mocap]'"
_QTM_KEY = re.compile(r"[A-Z][A-Z0-9_]*")
_TIME = re.compile(r"(?:t|time|times|timestamp)(?:[\s_]*[(\[]?(s|sec|secs|seconds|ms|msec)[)\]]?)?",
                   re.IGNORECASE)
_TRIAL = re.compile(r"trial[\s_.-]*(?:n|no|nr|num|number|id|index|idx)?", re.IGNORECASE)
_SEPS = " _.:-|/"
#: Coordinates this large are NDI's missing-marker value (-3.697314e28), not positions.
_NDI_MISSING = 1e25
#: C3D point groups that hold modelled outputs (Vicon Plug-in Gait), not markers.
_C3D_MODELLED = ("ANGLES", "FORCES", "MOMENTS", "POWERS", "SCALARS", "REACTIONS")


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
    """

    name: str
    source: str
    time: np.ndarray
    markers: Mapping[str, np.ndarray]
    rate: float
    units: str
    notes: tuple[str, ...] = ()
    extra: Mapping[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "markers", MappingProxyType(dict(self.markers)))
        object.__setattr__(self, "extra", MappingProxyType(dict(self.extra)))
        object.__setattr__(self, "notes", tuple(self.notes))

    def __reduce__(self):
        # MappingProxyType does not pickle: batch workers get the trial sent
        return MocapTrial, (self.name, self.source, self.time, dict(self.markers), self.rate,
                            self.units, self.notes, dict(self.extra))

    def marker_names(self) -> tuple[str, ...]:
        """The markers' names, in the file's order."""
        return tuple(self.markers)


def is_mocap_file(path: str | os.PathLike) -> bool:
    """Whether ``path`` looks like a motion-capture file.

    A ``.c3d`` is one by its name; a ``.tsv``, ``.txt`` or ``.csv`` is one when
    its first line is a QTM header key or names X, Y and Z columns of a marker.
    Only the file's first bytes are read.

    Parameters
    ----------
    path : str or os.PathLike
        A file name.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".c3d":
        return True
    if suffix not in MOCAP_SUFFIXES or not is_regular_file(p):
        return False
    try:
        with open(p, "rb") as fh:
            first = fh.read(65536).decode("utf-8", "replace").lstrip("\ufeff").splitlines()
    except OSError:
        return False
    if not first:
        return False
    if _is_qtm(first[0]):
        return True
    sep = _delimiter(first[0])
    return bool(_marker_columns(first[0].split() if sep == r"\s+" else first[0].split(sep)))


def read_mocap(path: str | os.PathLike, *, rate: float | None = None, units: str | None = None,
               trial_column: str | None = None,
               time_column: str | None = None) -> list[MocapTrial]:
    """Read a motion-capture file: QTM TSV, a table of marker X/Y/Z columns, or C3D.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.tsv``, ``.txt``, ``.csv`` or ``.c3d`` file.
    rate : float, optional
        Samples/s (up to 1000). Needed for a table without a time column;
        otherwise it wins over the file's own rate.
    units : {"mm", "cm", "m"}, optional
        The file's length unit; wins over the file's own, or what is inferred.
    trial_column : str, optional
        The column of a long table that names the trial (default: a column
        called ``trial``, ``trialN``, ``trial_id``, ...). Tables only.
    time_column : str, optional
        The column of a table that holds the time (default: ``time``, ``t``,
        ``time_s``, ``Time (s)``, ...). Tables only: QTM's is ``Time``.

    Returns
    -------
    list of MocapTrial
        One per trial of a long table, in file order; otherwise one.

    Raises
    ------
    InputError
        A missing or unreadable file, no marker columns, ragged rows, a
        non-numeric value, a bad rate or unit, a time that does not increase,
        or (for C3D) the ``mocap`` extra not installed.
    """
    p = input_file(path, "motion-capture file")
    if p.suffix.lower() not in MOCAP_SUFFIXES:
        raise InputError("expected a .c3d, .tsv, .txt or .csv motion-capture file", p)
    if units is not None:
        units = _unit(units, p, "--units")
    if rate is not None:
        rate = _rate(rate, p, "--rate")
    if p.suffix.lower() == ".c3d":
        return _read_c3d(p, os.fspath(path), rate, units)
    raw = p.read_bytes()
    lines = raw[:65536].decode("utf-8", "replace").lstrip("\ufeff").splitlines()
    if not lines:
        raise InputError("the file is empty", p)
    if _is_qtm(lines[0]):
        return _read_qtm(p, os.fspath(path), raw, rate, units)
    return _read_table(p, os.fspath(path), raw, lines, rate, units, trial_column, time_column)


# -- shared checks and assembly -------------------------------------------------------
def _rate(value, path: Path, where: str) -> float:
    try:
        ok = not isinstance(value, bool) and math.isfinite(float(value)) and float(value) > 0
    except (TypeError, ValueError):
        ok = False
    if not ok or float(value) > MAX_FPS:
        raise InputError(f"expected a sampling rate above 0 and up to {MAX_FPS:g} samples/s, "
                         f"got {value!r}", path, field=where)
    return float(value)


def _unit(value, path: Path, where: str) -> str:
    unit = str(value).strip().lower()
    if unit not in UNITS:
        raise InputError(f"unknown length unit {value!r} (expected mm, cm or m)", path,
                         field=where)
    return unit


def _assemble(path: Path, source: str, pieces, rate: float, units: str | None,
              own: tuple[str, str] | None, notes: list[str]) -> list[MocapTrial]:
    """Trials from ``(name suffix, time, {marker: (N, 3) in file units}, extra)`` pieces."""
    if sum(len(p[1]) for p in pieces) > MAX_FRAMES or len(pieces[0][2]) > MAX_KEYPOINTS:
        raise InputError(f"more than {MAX_FRAMES} samples or {MAX_KEYPOINTS} markers", path)
    zeros = []
    for _, _, markers, _ in pieces:
        count = 0
        for xyz in markers.values():
            at_origin = (xyz == 0).all(axis=1)
            # NDI systems write -3.697314e28 for a marker they lost
            xyz[at_origin | ~(np.abs(xyz) < _NDI_MISSING).all(axis=1)] = np.nan
            count += int(at_origin.sum())
        zeros.append(count)
    if units is None and own is not None:
        units = _unit(own[0], path, own[1])
    if units is None:
        values = np.concatenate([xyz.ravel() for piece in pieces for xyz in piece[2].values()])
        values = values[np.isfinite(values)]
        span = float(values.max() - values.min()) if len(values) else 0.0
        units = "mm" if span > _MM_ABOVE else "m"
        notes = [*notes, f"units inferred: {units} (the positions span {span:.4g})"]
    trials = []
    for (suffix, time, markers, extra), count in zip(pieces, zeros):
        own_notes = notes + ([f"{count} samples at exactly (0, 0, 0) read as lost"] if count
                             else [])
        for note in own_notes:
            _log.debug("%s%s: %s", source, suffix, note)
        trials.append(MocapTrial(
            name=path.stem + suffix, source=source, time=np.asarray(time, dtype=float),
            markers={m: xyz * UNITS[units] for m, xyz in markers.items()},
            rate=rate, units=units, notes=tuple(own_notes), extra=extra))
    return trials


def _check_time(time: np.ndarray, path: Path, where: str) -> None:
    if not np.isfinite(time).all():
        raise InputError("empty or non-numeric time", path, field=where)
    steps = np.flatnonzero(np.diff(time) <= 0)
    if len(steps):
        raise InputError(f"the time does not increase ({time[steps[0]]:g} then "
                         f"{time[steps[0] + 1]:g})", path, field=where)


def _file_rate(rate: float | None, own, path: Path, where: str) -> tuple[float, list[str]]:
    """The rate to use where the file states its own (``own``) and the caller may give one."""
    own = _rate(own, path, where)
    if rate is None or rate == own:
        return own, []
    return rate, [f"rate {rate:g} samples/s given; the file says {own:g}"]


def _unique(name: str, taken) -> str:
    base, k = name, 1
    while name in taken:
        k += 1
        name = f"{base}_{k}"
    return name


# -- tables: QTM TSV and delimited marker tables ----------------------------------------
def _is_qtm(first_line: str) -> bool:
    key = first_line.split("\t", 1)[0].strip()
    return key == "FILE_VERSION" or key.startswith("NO_OF_")


def _delimiter(line: str) -> str:
    counts = {sep: line.count(sep) for sep in ("\t", ",", ";")}
    best = max(counts, key=counts.get)
    return best if counts[best] else r"\s+"


def _load(path: Path, raw: bytes, sep: str, skip: int, header: int | None, decimal: str = "."):
    """The table below the first ``skip`` lines as pandas reads it; a short row is an error."""
    import pandas as pd

    try:
        df = pd.read_csv(io.BytesIO(raw), sep=sep, skiprows=skip, header=header, decimal=decimal,
                         index_col=False, nrows=MAX_FRAMES + 1, encoding="utf-8-sig",
                         encoding_errors="replace", skipinitialspace=True, low_memory=False)
    except pd.errors.EmptyDataError:
        raise InputError("no data rows", path) from None
    except pd.errors.ParserError as exc:
        raise InputError(f"ragged rows: {str(exc).rpartition('C error: ')[2].strip()}",
                         path) from None
    if df.empty:
        raise InputError("no data rows", path)
    if header is None:  # rows ending in a separator
        while df.shape[1] > 1 and df.iloc[:, -1].isna().all():
            df = df.iloc[:, :-1]
        width = df.shape[1]
    else:
        df.columns = [str(c).strip() for c in df.columns]
        width = len(df.columns)  # a header ending in a separator names a last empty column
        while width > 1 and df.columns[width - 1].startswith("Unnamed: "):
            width -= 1
    if sep != r"\s+":  # pandas fills a short row with NaN: count its fields
        data = np.frombuffer(raw, np.uint8)
        ends = np.flatnonzero(data == 10)
        if not len(ends) or ends[-1] != len(data) - 1:
            ends = np.append(ends, len(data))
        starts = np.concatenate([[0], ends[:-1] + 1])
        cum = np.concatenate([[0], np.cumsum(data == ord(sep))])
        fields = cum[ends] - cum[starts] + 1
        length = ends - starts - ((ends > starts) & (data[np.maximum(ends - 1, 0)] == 13))
        first = skip + (header is not None)
        bad = np.flatnonzero((fields < width) & (length > 0) & (np.arange(len(ends)) >= first))
        if len(bad):
            raise InputError(f"line {bad[0] + 1} has {fields[bad[0]]} fields; the rows above "
                             f"have {width}", path, field=str(df.columns[fields[bad[0]]]))
    return df


def _numeric(column, path: Path, name: str) -> np.ndarray:
    """A column as floats (empty cells NaN); a non-numeric cell is an InputError."""
    import pandas as pd

    values = pd.to_numeric(column, errors="coerce")
    bad = np.flatnonzero(values.isna().to_numpy() & column.notna().to_numpy())
    if len(bad):
        raise InputError(f"not a number: {column.iloc[bad[0]]!r} (data row {bad[0] + 1})",
                         path, field=name)
    return values.to_numpy(dtype=float)


def _marker_columns(columns) -> dict[str, tuple]:
    """Marker name -> its (X, Y, Z) columns, found by the axis letter each name carries."""
    keys: dict[tuple[str, str], dict] = {}
    for col in columns:
        name = str(col).strip()
        for i, ch in enumerate(name):
            if ch.lower() in "xyz":
                entry = keys.setdefault((name[:i].lower(), name[i + 1:].lower()),
                                        {"parts": (name[:i], name[i + 1:])})
                entry.setdefault(ch.lower(), col)
    found = sorted((e for e in keys.values() if all(a in e for a in "xyz")),
                   key=lambda e: list(columns).index(e["x"]))
    groups, used = {}, set()
    for entry in found:
        cols = (entry["x"], entry["y"], entry["z"])
        if used & set(cols) or len(set(cols)) < 3:
            continue
        before, after = (part.strip(_SEPS) for part in entry["parts"])
        name = before or after or "marker"
        groups[_unique(f"{before}_{after}".strip(_SEPS) if name in groups else name, groups)] = cols
        used.update(cols)
    return groups


def _find_column(columns, asked: str | None, pattern: re.Pattern, path: Path, flag: str):
    if asked is not None:
        if asked not in columns:
            shown = ", ".join(map(repr, columns[:12])) + (", ..." if len(columns) > 12 else "")
            raise InputError(f"no column {asked!r} (the columns are {shown})", path, field=flag)
        return asked
    return next((c for c in columns if pattern.fullmatch(c)), None)


def _read_qtm(path: Path, source: str, raw: bytes, rate, units) -> list[MocapTrial]:
    lines = raw[:1 << 20].decode("utf-8", "replace").lstrip("\ufeff").splitlines()
    header: dict[str, list[str]] = {}
    skip = 0
    for line in lines:
        fields = [f.strip() for f in line.split("\t")]
        if not _QTM_KEY.fullmatch(fields[0]):
            break
        header.setdefault(fields[0], [f for f in fields[1:] if f])
        skip += 1
    names = header.get("MARKER_NAMES")
    if not names or len(set(names)) < len(names):
        raise InputError("expected the markers' names, each once", path, field="MARKER_NAMES")
    included = " ".join(header.get("DATA_INCLUDED", ["3D"]))
    if included.upper() != "3D":
        raise InputError(f"expected 3D marker data, got {included!r}", path,
                         field="DATA_INCLUDED")
    if header.get("FREQUENCY"):
        rate, notes = _file_rate(rate, header["FREQUENCY"][0], path, "FREQUENCY")
    elif rate is None:
        raise InputError("no sampling rate: give it with --rate", path, field="FREQUENCY")
    else:
        notes = []
    groups = {m: tuple(f"{m} {a}" for a in "XYZ") for m in names}
    first = lines[skip].split("\t")[0].strip() if skip < len(lines) else ""
    titled = bool(first) and not re.fullmatch(r"[-+0-9.eE]+", first)
    df = _load(path, raw, "\t", skip, 0 if titled else None)
    if not titled:  # older exports: X Y Z per marker, perhaps after Frame and Time
        columns = [c for cols in groups.values() for c in cols]
        if df.shape[1] not in (len(columns), len(columns) + 2):
            raise InputError(f"the rows have {df.shape[1]} fields; {len(names)} markers need "
                             f"{len(columns)} (X Y Z each) or {len(columns) + 2} (after Frame "
                             "and Time)", path, field="MARKER_NAMES")
        df.columns = ["Frame", "Time", *columns][len(columns) + 2 - df.shape[1]:]
    missing = next((c for cols in groups.values() for c in cols if c not in df.columns), None)
    if missing:
        raise InputError(f"no column {missing!r} for a marker it lists", path,
                         field="MARKER_NAMES")
    stated = (header.get("NO_OF_FRAMES") or [""])[0]
    if stated and stated != str(len(df)):
        notes.append(f"NO_OF_FRAMES says {stated}; the file holds {len(df)} frames")
    time_col = "Time" if "Time" in df.columns else None
    own_units = ((header.get("UNITS") or ["mm"])[0], "UNITS")  # QTM writes mm
    return _trials(path, source, df, groups, time_col, None, rate, units, own_units, notes,
                   extra=False)


def _read_table(path: Path, source: str, raw: bytes, lines: list[str], rate, units,
                trial_column, time_column) -> list[MocapTrial]:
    sep = _delimiter(lines[0])
    decimal = "," if sep == ";" and len(lines) > 1 and re.search(r"\d,\d", lines[1]) else "."
    df = _load(path, raw, sep, 0, 0, decimal)
    columns = list(df.columns)
    time_col = _find_column(columns, time_column, _TIME, path, "--time-column")
    trial_col = _find_column(columns, trial_column, _TRIAL, path, "--trial-column")
    groups = _marker_columns([c for c in columns if c not in (time_col, trial_col)])
    if not groups:
        raise InputError("no marker columns: expected X, Y and Z columns for each marker "
                         "(such as thumb_x, thumb_y, thumb_z)", path, field="header")
    return _trials(path, source, df, groups, time_col, trial_col, rate, units, None, [])


def _trials(path: Path, source: str, df, groups, time_col, trial_col, rate, units, own_units,
            notes: list[str], extra: bool = True) -> list[MocapTrial]:
    """Split a table into trials; read its markers, time and (``extra``) other numbers."""
    markers = {m: np.column_stack([_numeric(df[c], path, c) for c in cols])
               for m, cols in groups.items()}
    used = {c for cols in groups.values() for c in cols} | {time_col, trial_col}
    others = {}
    for c in df.columns if extra else ():
        if c in used or df[c].isna().all():
            continue
        if df[c].dtype.kind in "biuf":
            others[c] = df[c].to_numpy(dtype=float)
        else:
            notes.append(f"column {c!r} is not numeric: not read")
    rows = [("", np.arange(len(df)))]
    if trial_col is not None:
        if df[trial_col].isna().any():
            raise InputError(f"empty trial (data row {int(np.argmax(df[trial_col].isna())) + 1})",
                             path, field=trial_col)
        ids = df[trial_col].astype(str).str.strip().str.replace(r"\.0+$", "", regex=True)
        rows = [(f"-trial{t}", np.flatnonzero((ids == t).to_numpy())) for t in ids.unique()]
    if time_col is None:
        if rate is None:
            raise InputError("the table has no time column: give the sampling rate "
                             "(samples/s) or name the time column", path, field="--rate")
        times = [np.arange(len(r)) / rate for _, r in rows]
    else:
        time = _numeric(df[time_col], path, time_col)
        times = [time[r] for _, r in rows]
        for t in times:
            _check_time(t, path, time_col)
        steps = np.concatenate([np.diff(t) for t in times])
        step = float(np.median(steps)) if len(steps) else math.nan
        stated = _TIME.fullmatch(time_col).group(1) if _TIME.fullmatch(time_col) else None
        if (stated or "").lower() in ("ms", "msec") or (stated is None and step > 0.5):
            notes.append(f"time column {time_col!r} in ms (from its "
                         f"{'name' if stated else 'steps'}): converted to s")
            times, step = [t / 1000 for t in times], step / 1000
        if rate is None:
            if not math.isfinite(step):
                raise InputError("one sample per trial: give the sampling rate", path,
                                 field="--rate")
            rate = _rate(round(1 / step, 6), path, time_col)
            notes.append(f"rate {rate:g} samples/s from the time column")
    pieces = [(suffix, t, {m: xyz[r] for m, xyz in markers.items()},
               {c: v[r] for c, v in others.items()}) for (suffix, r), t in zip(rows, times)]
    return _assemble(path, source, pieces, rate, units, own_units, notes)


# -- C3D ------------------------------------------------------------------------------
def _read_c3d(path: Path, source: str, rate, units) -> list[MocapTrial]:
    try:
        import ezc3d
    except ImportError:
        raise InputError(_MOCAP_EXTRA, path) from None
    try:
        c3d = ezc3d.c3d(os.fspath(path))
    except (OSError, RuntimeError, ValueError, IndexError) as exc:
        raise InputError(f"not a readable C3D file ({exc})", path) from None
    point = c3d["parameters"]["POINT"]
    points = np.asarray(c3d["data"]["points"], dtype=float)[:3]  # (3, n_points, n_frames)
    residuals = np.asarray(c3d["data"]["meta_points"]["residuals"], dtype=float)
    labels = [str(x).strip() for x in _c3d_values(point, "LABELS")]
    labels = [labels[i] if i < len(labels) and labels[i] else f"point{i + 1}"
              for i in range(points.shape[1])]
    modelled = {str(x).strip() for g in _C3D_MODELLED for x in _c3d_values(point, g)}
    own = _c3d_values(point, "RATE") or [c3d["header"]["points"]["frame_rate"]]
    rate, notes = _file_rate(rate, float(own[0]), path, "POINT:RATE")
    markers = {}
    for i, label in enumerate(labels):
        if label in modelled:
            continue
        xyz = points[:, i, :].T.copy()
        lost = ~np.isfinite(residuals[0, i]) | (residuals[0, i] < 0) if residuals.size else False
        xyz[lost] = np.nan
        markers[_unique(label, markers)] = xyz
    if len(markers) < len(labels):
        notes.append(f"{len(labels) - len(markers)} modelled points (angles, forces, ...) "
                     "not read")
    if not markers:
        raise InputError("no marker points", path, field="POINT:LABELS")
    first = int(c3d["header"]["points"].get("first_frame", 0))
    time = (first + np.arange(points.shape[2])) / rate
    stated = [str(u).strip() for u in _c3d_values(point, "UNITS") if str(u).strip()]
    own_units = (stated[0], "POINT:UNITS") if stated else None
    return _assemble(path, source, [("", time, markers, {})], rate, units, own_units, notes)


def _c3d_values(group: Mapping, name: str) -> list:
    """A C3D parameter's values as a list (empty when the parameter is absent)."""
    value = group.get(name, {}).get("value", [])
    return list(value) if isinstance(value, list | tuple) else list(np.atleast_1d(value))

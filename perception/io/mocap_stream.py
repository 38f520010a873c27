"""Large long tables read trial by trial, in bounded memory.

A table with a trial column above :data:`STREAM_BYTES` is checked whole in
chunks of :data:`CHUNK_ROWS` rows (every check of
:func:`perception.io.mocap_tables.read_xyz_table`), then read one trial at a
time on each pass (:class:`~perception.io.mocap_trial.TrialStream`); any
fault is said by reading it whole, in the same words.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from perception.errors import InputError
from perception.factors import DEFAULT_FACTORS, table_factors
from perception.io.mocap_tables import (
    _TRIAL,
    _clock,
    _find_column,
    _mixed_spaces,
    _stated_unit,
    marker_columns,
    time_column_of,
    trial_spans,
)
from perception.io.mocap_text import (
    TableText,
    check_fields,
    check_header,
    decimal_mark,
    delimiter,
    header_width,
    is_utf16,
    load_chunks,
    numeric,
    split,
)
from perception.io.mocap_trial import (
    Spread,
    TrialStream,
    check_size,
    infer_units,
    make_trial,
    mark_lost,
    progress_callback,
)
from perception.limits import MAX_FRAMES

__all__ = ["CHUNK_ROWS", "HEAD_BYTES", "STREAM_BYTES", "stream_xyz_table"]

#: A table with a trial column larger than this (bytes) is read trial by trial
#: (:func:`stream_xyz_table`): a 95 MB table read whole took 0.7 GB.
STREAM_BYTES = 16 << 20
#: Rows parsed at a time when a table is read trial by trial.
CHUNK_ROWS = 20_000
#: Bytes of a large table's head decoded to tell its layout, separator and decimal mark.
HEAD_BYTES = 1 << 20


def stream_xyz_table(path: Path, source: str, text: TableText, rate, units, trial_column,
                     time_column, factors=None) -> TrialStream | None:
    """A long table whose header names X, Y and Z per marker, read trial by trial.

    The file is read twice, a chunk of :data:`CHUNK_ROWS` rows at a time:
    first to check it as :func:`read_xyz_table` does (short rows, numbers, the
    trial ids, the clock, the factors, the unit from every marker's spread),
    keeping only the trial column's changes, the clock and the factor
    columns; then, on each pass over the :class:`TrialStream` returned, to
    give its trials one by one, each read, built and handed on before the
    next. The trials, their notes and their numbers are those
    :func:`read_xyz_table` gives.

    Parameters
    ----------
    path : Path
        The file (UTF-8).
    source : str
        The file as the caller named it.
    text : TableText
        Its first lines (:data:`HEAD_BYTES`).
    rate, units, trial_column, time_column, factors
        As :func:`perception.io.mocap.read_mocap` takes them.

    Returns
    -------
    TrialStream or None
        None where the table is read whole: no trial column, a separator of
        white space, columns whose kind changes down the file, or a mistake
        (read whole, it is refused in the words :func:`read_xyz_table` has
        for it, which name what they found anywhere in the table).
    """
    with open(path, "rb") as fh:
        if is_utf16(fh.read(4096)):
            return None
    sep = delimiter(text.first)
    try:
        if sep == r"\s+" or _mixed_spaces(text, sep, path)[1]:
            return None
        return _checked_stream(path, source, text, sep, rate, units, trial_column, time_column,
                               factors)
    except (InputError, TypeError):
        return None


def _checked_stream(path: Path, source: str, text: TableText, sep: str, rate, units,
                    trial_column, time_column, factors) -> TrialStream | None:
    """:func:`stream_xyz_table`'s first pass: the checks, and what each trial is read with."""
    import itertools

    import pandas as pd

    check_header(split(text.first, sep), path)
    decimal = decimal_mark(text.lines[text.skip + 1:], sep)
    notes = list(text.notes) + (["decimal commas read"] if decimal == "," else [])
    chunks = load_chunks(path, sep, text.skip, decimal, CHUNK_ROWS)
    first = next(chunks, None)
    if first is None or first.empty:
        return None
    names = list(first.columns)
    time_col = time_column_of(names, time_column, path, notes)
    trial_col = _find_column(names, trial_column, _TRIAL, path, "trial_column")
    asked = list(factors or ())
    if trial_col is None or any(a not in names for a in asked):
        return None
    lines = check_fields(path, sep, text.skip, header_width(first), first)
    groups = marker_columns([c for c in names if c not in (time_col, trial_col)
                             and c not in asked])
    if not groups:
        return None
    if units is None and (own := _stated_unit(groups, path)) is not None:
        units = own[0]  # the columns say it, as read_xyz_table reads them
    used = {c for cols in groups.values() for c in cols} | {time_col, trial_col}
    # the columns a check reads down the whole table: the clock, the factors
    keep = [c for c in names if c == time_col or c in asked
            or (c.casefold() in DEFAULT_FACTORS and c not in used)]
    spread = Spread(list(groups), 3 * lines) if units is None else None
    kinds: dict[str, set] = {c: set() for c in names}
    empty = dict.fromkeys(names, True)
    ids, at, kept, rows, last = [], [], [], 0, None
    progress = progress_callback()
    for chunk in itertools.chain([first], chunks):
        for c in names:
            kinds[c].add(chunk[c].dtype.kind in "biuf")
            empty[c] = empty[c] and bool(chunk[c].isna().all())
        if chunk[trial_col].isna().any():
            return None
        raw = chunk[trial_col].to_numpy()
        change = np.flatnonzero(np.r_[last is None or raw[0] != last, raw[1:] != raw[:-1]])
        ids.append(raw[change])
        at.append(change + rows)
        last = raw[-1]
        markers = {m: np.column_stack([numeric(chunk[c], path, c) for c in cols])
                   for m, cols in groups.items()}
        if spread is not None:
            mark_lost(markers)
            spread.add(markers)
        # text as categories: a cell's str took some 60 bytes a row
        kept.append({c: chunk[c].astype("category") if chunk[c].dtype == object
                     else chunk[c].copy() for c in keep})
        rows += len(chunk)
        if rows > MAX_FRAMES:
            return None
        if progress is not None:
            progress(rows, max(lines - text.skip - 1, rows), f"checking {path.name}")
    if any(len(k) > 1 for k in kinds.values()):
        return None  # a column of numbers in some rows, of text in others: read whole
    spans = trial_spans(np.concatenate(ids), np.concatenate(at), rows, trial_col, path)
    trials = [range(s, e) for _, s, e in spans]  # the rows, without an index per row
    small = pd.DataFrame({c: _joined([k[c] for k in kept]) for c in keep}, index=range(rows))
    del kept
    per_trial, taken = table_factors(small, trials, factors, path, notes, skip=used)
    numbers = [suffix[len("-trial"):] for suffix, _, _ in spans]
    others = []
    for c in names:
        if c in used or empty[c]:
            continue
        if True in kinds[c]:
            others.append(c)
        elif c not in taken:
            notes.append(f"column {c!r} is not numeric: not read (`factors` {c} reads it as "
                         "a factor)")
    if time_col is None:
        if rate is None:
            return None
        times = None
    else:
        skip = {c for cols in groups.values() for c in cols} | {trial_col}
        times, rate = _clock(small, time_col, [(sfx, r) for (sfx, _, _), r in zip(spans, trials)],
                             rate, None, skip, path, notes)
    del small
    check_size(rows, len(groups), path)
    if units is None:
        units, note = infer_units(spread.spans())
        notes.append(note)
    plan = _Plan(path, source, sep, text.skip, decimal, groups, others, spans, times, rate,
                 units, notes, list(zip(numbers, per_trial)),
                 sorted(names.index(c) for c in {*others, *(c for cols in groups.values()
                                                            for c in cols)}))
    return TrialStream([path.stem + suffix for suffix, _, _ in spans], plan.trials)


def _joined(pieces):
    """A column's chunks as one column (text kept as categories)."""
    import pandas as pd

    if any(isinstance(p.dtype, pd.CategoricalDtype) for p in pieces):
        from pandas.api.types import union_categoricals

        # a TypeError (numbers in one chunk, text in another) reads the table whole
        return pd.Series(union_categoricals([p.astype("category") for p in pieces]))
    return pd.concat(pieces, ignore_index=True)


@dataclass(frozen=True)
class _Plan:
    """What each pass over a streamed table reads, and how it makes the trials."""

    path: Path
    source: str
    sep: str
    skip: int
    decimal: str
    groups: dict
    others: list
    spans: list
    times: list | None
    rate: float
    units: str
    notes: list
    labels: list
    usecols: list

    def trials(self):
        """The trials, read a chunk at a time, each given as soon as its last row is read."""
        progress = progress_callback()
        k, offset, pending = 0, 0, []
        for chunk in load_chunks(self.path, self.sep, self.skip, self.decimal, CHUNK_ROWS,
                                 usecols=self.usecols):
            n = len(chunk)
            markers = {m: np.column_stack([numeric(chunk[c], self.path, c) for c in cols])
                       for m, cols in self.groups.items()}
            extra = {c: chunk[c].to_numpy(dtype=float) for c in self.others}
            del chunk
            while k < len(self.spans):
                suffix, s, e = self.spans[k]
                lo, hi = max(s, offset) - offset, min(e, offset + n) - offset
                pending.append(({m: v[lo:hi] for m, v in markers.items()},
                                {c: v[lo:hi] for c, v in extra.items()}))
                if e > offset + n:
                    break  # the trial goes on in the next chunk
                xyz = {m: np.concatenate([p[0][m] for p in pending]) for m in markers}
                more = {c: np.concatenate([p[1][c] for p in pending]) for c in extra}
                pending = []
                time = self.times[k] if self.times is not None else np.arange(e - s) / self.rate
                yield make_trial(self.path, self.source, (suffix, time, xyz, more),
                                 mark_lost(xyz), self.rate, self.units, self.notes,
                                 self.labels[k])
                k += 1
                if progress is not None:
                    progress(k, len(self.spans), f"reading {self.path.name}")
            offset += n
        if k < len(self.spans):  # rows checked on opening are gone
            raise InputError(f"the file changed while it was read ({len(self.spans) - k} of "
                             f"its {len(self.spans)} trials gone): read it again", self.path)

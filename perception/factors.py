"""A design's factors: which columns of a long table name them, what a file's name says,
and how the sources agree.

A lab's design (participant, condition, session, block, ...) reaches the
outputs from three places: the columns of a long table, constant within
each trial (:func:`table_factors`); a batch manifest's columns, which tag a
whole file; and a regular expression's named groups searched in a file's
name (:func:`name_factors`). :func:`merge_factors` joins them: the same
factor from two sources must agree, since two values for one trial are the
user's mistake, not a choice to make for them. Values are text, as written
(``"P01"``, ``"38"``).
"""

from __future__ import annotations

import logging
import math
import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np

from perception.errors import InputError

__all__ = ["DEFAULT_FACTORS", "FACTOR_FLAG", "NAME_FLAG", "entry_columns", "factor_names",
           "merge_factors", "name_factors", "name_pattern", "table_factors"]

log = logging.getLogger(__name__)

#: Columns of a long table taken as factors without being named (any case), where
#: each is constant within every trial.
DEFAULT_FACTORS = ("participant", "subject", "condition", "session", "block", "group")
#: The fields that name factors (MocapImport's; the command line's --factors and
#: --factors-from-name), named by errors.
FACTOR_FLAG = "factors"
NAME_FLAG = "factors_from_name"


def factor_names(value) -> tuple[str, ...] | None:
    """``--factors``' names: ``"participant,block"`` or a sequence, each once, none empty.

    Parameters
    ----------
    value : str, sequence of str, or None
        The names.
    """
    if value is None:
        return None
    names = value.split(",") if isinstance(value, str) else list(value)
    names = [str(n).strip() for n in names]
    if not names or not all(names):
        raise InputError(f"expected column names parted by commas, got {value!r}",
                         field=FACTOR_FLAG)
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise InputError(f"factor {repeated[0]!r} named twice", field=FACTOR_FLAG)
    return tuple(names)


def name_pattern(pattern: str | re.Pattern | None) -> re.Pattern | None:
    """``--factors-from-name`` compiled: a regular expression with at least one named group.

    Parameters
    ----------
    pattern : str or re.Pattern or None
        Such as ``(?P<participant>P\\d+)_(?P<condition>[a-z]+)``.

    Raises
    ------
    InputError
        Not a regular expression, or one without a named group (it would give
        no factor).
    """
    if pattern is None or isinstance(pattern, re.Pattern) and pattern.groupindex:
        return pattern
    try:
        compiled = re.compile(pattern)
    except (re.error, TypeError) as exc:
        raise InputError(f"not a regular expression ({exc}): {pattern!r}",
                         field=NAME_FLAG) from None
    if not compiled.groupindex:
        raise InputError(f"{pattern!r} has no named group: write each factor as "
                         "(?P<name>...), e.g. (?P<participant>P\\d+)", field=NAME_FLAG)
    return compiled


def name_factors(pattern, name: str | os.PathLike) -> dict[str, str] | None:
    """The factors a file's name gives: the pattern's named groups, searched in its stem.

    Parameters
    ----------
    pattern : str or re.Pattern or None
        :func:`name_pattern`'s.
    name : str or os.PathLike
        The file (only its stem is searched: ``P01_fast.tsv`` -> ``P01_fast``).

    Returns
    -------
    dict of str to str, or None
        Factor -> value (a group that took part in no match is left out);
        ``{}`` without a pattern; None when the pattern does not match the
        name (a note is logged: the file's rows get no factor from its name,
        and are never dropped).
    """
    compiled = name_pattern(pattern)
    if compiled is None:
        return {}
    stem = Path(name).stem
    found = compiled.search(stem)
    if found is None:
        log.warning("%s: `factors_from_name` %r does not match the file name %r: no factors "
                    "from its name", name, compiled.pattern, stem)
        return None
    return {k: v for k, v in found.groupdict().items() if v is not None}


def merge_factors(sources: Iterable[tuple[str, Mapping[str, str]]], where=None
                  ) -> dict[str, str]:
    """One set of factors from several sources; a factor two sources give must agree.

    Parameters
    ----------
    sources : iterable of (str, mapping)
        ``(where it comes from, in words, {factor: value})``, in the order
        their factors are listed.
    where : str or os.PathLike, optional
        The file, for the message.

    Raises
    ------
    InputError
        Two sources give one factor different values: which is right is the
        user's to say.
    """
    out: dict[str, str] = {}
    said: dict[str, str] = {}
    for source, factors in sources:
        for name, value in (factors or {}).items():
            value = "" if value is None else str(value)
            if name in out and out[name] != value:
                raise InputError(f"factor {name!r} is {out[name]!r} in {said[name]} and "
                                 f"{value!r} in {source}: give it in one place, or make "
                                 "them agree", where)
            if name not in out:
                out[name], said[name] = value, source
    return out


def _text(value) -> str:
    """A cell as text, as written: ``38.0`` read by pandas is ``"38"``, an empty cell ``""``."""
    if value is None or isinstance(value, float) and math.isnan(value):
        return ""
    if isinstance(value, (float, np.floating)):
        return str(int(value)) if float(value).is_integer() else repr(float(value))
    return str(value).strip()


def table_factors(df, trials: list[np.ndarray], asked: Iterable[str] | None, path,
                  notes: list[str], *, skip: Iterable[str] = ()) -> tuple[list[dict], set[str]]:
    """Each trial's factors from a long table's columns.

    A column named in ``asked`` (text or numbers) is a factor; so by default
    is any column named as in :data:`DEFAULT_FACTORS` (any case). A factor
    holds one value per trial: a named column that varies within a trial is
    refused; a default one is not taken (with a note).

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    trials : list of ndarray
        Each trial's rows, in file order (consecutive).
    asked : iterable of str, or None
        The columns named (``--factors``).
    path : Path
        The file.
    notes : list of str
        Gets a note for each factor read, and each default one not taken.
    skip : iterable of str
        Columns that are not factors by default (markers, the clock).

    Returns
    -------
    list of dict, set of str
        Factor -> value per trial; the columns taken as factors.

    Raises
    ------
    InputError
        A column named that the table lacks (the columns it has are named),
        or one that varies within a trial.
    """
    columns = [str(c) for c in df.columns]
    asked = list(asked or ())
    for name in asked:
        if name not in columns:
            shown = ", ".join(map(repr, columns[:20])) + (", ..." if len(columns) > 20 else "")
            raise InputError(f"no column {name!r} to read as a factor (the columns are "
                             f"{shown})", path, field=FACTOR_FLAG)
    skip = set(skip)
    defaults = [c for c in columns if c.casefold() in DEFAULT_FACTORS and c not in asked
                and c not in skip]
    starts = np.array([r[0] for r in trials], dtype=np.int64)
    taken: list[str] = []
    values: dict[str, list[str]] = {}
    for name in [*asked, *defaults]:
        raw = df[name].to_numpy()
        empty = np.asarray(df[name].isna().to_numpy())
        with np.errstate(invalid="ignore"):
            same = (raw[1:] == raw[:-1]) | (empty[1:] & empty[:-1])
        changes = np.flatnonzero(~np.asarray(same, dtype=bool)) + 1
        inside = changes[~np.isin(changes, starts)]
        if len(inside):
            row = int(inside[0])
            k = int(np.searchsorted(starts, row, side="right")) - 1
            said = (f"column {name!r} changes within a trial ({_text(raw[row - 1])!r} then "
                    f"{_text(raw[row])!r} at data row {row + 1}, trial {k + 1}): a factor "
                    "holds one value per trial")
            if name in asked:
                raise InputError(said, path, field=FACTOR_FLAG)
            notes.append(f"{said}; not read as a factor")
            continue
        taken.append(name)
        values[name] = [_text(raw[s]) for s in starts]
    if taken:
        notes.append(f"factor{'s' if len(taken) > 1 else ''} read from the column"
                     f"{'s' if len(taken) > 1 else ''} {', '.join(map(repr, taken))}")
    return [{n: values[n][k] for n in taken} for k in range(len(trials))], set(taken)


def entry_columns(entry) -> dict[str, object]:
    """A reach's or an unscored entry's factors, ``trial_number`` and ``reach_number``, as
    a table's columns (the factors first, in their order).

    Parameters
    ----------
    entry : Reach or Unscored
        From :func:`perception.recordings.read_recording` (anything without
        them gives empty columns).
    """
    return {**dict(getattr(entry, "factors", {}) or {}),
            "trial_number": getattr(entry, "trial_number", None) or None,
            "reach_number": getattr(entry, "reach_number", None)}

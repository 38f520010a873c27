"""Tables of plain numbers read without pandas, where pandas would read them the same.

Importing pandas costs a ``recognize`` about 0.2 s of its start-up (0.25 s
of CPU on a 2-core machine, with what pandas pulls in): the whole margin
issue 45 allows a pose or motion-capture file over importing numpy and
scipy.signal. The files a command is given are mostly the plain case: a
header, then numbers and empty cells, every row as wide as the header, as
DeepLabCut and Qualisys Track Manager write them. This module reads that
case with numpy and the ``csv`` module, and answers None for anything else
(quotes in the data, blank lines, a cell that is not a plain number,
ragged rows, a name pandas would rename, ...), which the caller then reads
with pandas as before. What it returns is what pandas' reading gives, value
for value (``tests/test_plain_tables.py`` compares both, on tricky files too):

* a cell is a number written plainly (``-12.5``, ``.5``, ``3.``, ``1e-3``; an
  integer of at most 15 digits, not ``-0``, which pandas reads as the integer
  0 where Python reads -0.0), or ``nan``, ``NaN`` or empty (NaN, as pandas'
  defaults read them); Python's and pandas' parsers agree on every such text
  (both round correctly);
* the rows end in ``\\n`` or ``\\r\\n`` and hold no other line break Python
  would split at (pandas splits lines at fewer characters than
  :meth:`str.splitlines`).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["NumericColumn", "NumericTable", "dlc_table", "numbers", "numeric_table"]

#: A number as written plainly; integers as pandas reads them exactly into int64.
_NUMBER = (r"-?(?:\d+\.\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+"
           r"|[1-9]\d{0,14})|0")
#: The missing values read here (pandas' defaults hold these and more).
_MISSING = r"|nan|NaN|"
#: Characters :meth:`str.splitlines` splits at, besides ``\n`` and ``\r``: a text holding
#: one is left to pandas, which does not.
_OTHER_BREAKS = re.compile("[\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029]")
_CELLS: dict[str, re.Pattern] = {}


def _rows_pattern(sep: str) -> re.Pattern:
    """Rows of cells separated by ``sep``, each a number or missing, lines joined by ``\\n``."""
    if sep not in _CELLS:
        cell = f"(?:{_NUMBER}{_MISSING})"
        row = f"{cell}(?:{re.escape(sep)}{cell})*"
        _CELLS[sep] = re.compile(f"{row}(?:\n{row})*")
    return _CELLS[sep]


def _lines(text: str) -> list[str] | None:
    """``text`` split into lines as pandas splits it, or None where the two might differ
    (a lone ``\\r``, a break pandas does not know, a blank line pandas would skip)."""
    if _OTHER_BREAKS.search(text):
        return None
    text = text.replace("\r\n", "\n")
    if "\r" in text:
        return None
    lines = text.removesuffix("\n").split("\n")
    return None if any(not line for line in lines) else lines


def numbers(lines: Sequence[str], sep: str, width: int, least: int | None = None
            ) -> np.ndarray | None:
    """``(rows, width)`` floats of data lines of plain numbers, or None where pandas is needed.

    Parameters
    ----------
    lines : sequence of str
        The data lines (no line break in them, none blank).
    sep : str
        Their one-character separator.
    width : int
        The cells each holds.
    least : int, optional
        Or as few as this, every line alike, the rest NaN (pandas pads a row shorter
        than a header that ends in a separator); default ``width``.

    Returns
    -------
    numpy.ndarray or None
        The values (empty cells and ``nan`` NaN); None when a cell is not a plain
        number (module docstring) or the rows are not as wide as asked.
    """
    body = "\n".join(lines)
    if not lines or not _rows_pattern(sep).fullmatch(body):
        return None
    cells = lines[0].count(sep) + 1
    if (not (least or width) <= cells <= width
            or any(line.count(sep) != cells - 1 for line in lines)):
        return None
    texts = body.replace("\n", sep).split(sep)
    # NaN as pandas gives it (positive); "" is not a number to numpy
    texts = ["nan" if not c or c == "NaN" else c for c in texts]
    values = np.array(texts, dtype=np.float64).reshape(len(lines), cells)
    if cells < width:
        values = np.hstack([values, np.full((len(lines), width - cells), np.nan)])
    return values


class NumericColumn:
    """One column of a :class:`NumericTable`: what the mocap readers ask of a pandas Series.

    Parameters
    ----------
    values : numpy.ndarray
        Its values (float64, NaN missing), or a mask (bool).
    """

    def __init__(self, values: np.ndarray):
        self._values = values

    @property
    def dtype(self) -> np.dtype:
        """float64 (pandas' int64 for a column of integers reads as the same numbers)."""
        return self._values.dtype

    @property
    def iloc(self) -> np.ndarray:
        """The values by position."""
        return self._values

    def __len__(self) -> int:
        return len(self._values)

    def to_numpy(self, dtype: Any = None) -> np.ndarray:
        """The values (as ``dtype``)."""
        return self._values if dtype is None else self._values.astype(dtype)

    def isna(self) -> NumericColumn:
        """Where a value is missing."""
        return NumericColumn(np.isnan(self._values))

    def notna(self) -> NumericColumn:
        """Where a value is present."""
        return NumericColumn(~np.isnan(self._values))

    def any(self) -> bool:
        """Whether any value is true."""
        return bool(self._values.any())

    def all(self) -> bool:
        """Whether every value is true."""
        return bool(self._values.all())


class NumericTable:
    """A table of numbers under a header row: what the mocap readers ask of a DataFrame.

    Parameters
    ----------
    columns : list of str
        The header's names (stripped, unique).
    values : numpy.ndarray
        ``(rows, columns)`` floats.
    """

    def __init__(self, columns: list[str], values: np.ndarray):
        self.columns = columns
        self.values = values

    def __len__(self) -> int:
        return self.values.shape[0]

    @property
    def shape(self) -> tuple[int, int]:
        """Rows and columns."""
        return self.values.shape

    @property
    def empty(self) -> bool:
        """Whether the table holds no value."""
        return self.values.size == 0

    def __getitem__(self, name: str) -> NumericColumn:
        return NumericColumn(self.values[:, self.columns.index(name)])

    def __contains__(self, name: str) -> bool:
        return name in self.columns


def numeric_table(raw: bytes, sep: str, skip: int, max_rows: int) -> NumericTable | None:
    """The table below ``skip`` lines of ``raw`` (a header row, then numbers), read as
    ``pandas.read_csv`` reads it with :func:`perception.io.mocap_text.load`'s options; None
    where that needs pandas.

    Parameters
    ----------
    raw : bytes
        The file (UTF-8).
    sep : str
        The one-character separator.
    skip : int
        Lines above the header row.
    max_rows : int
        More data rows than this are left to pandas (which reads only so many).

    Returns
    -------
    NumericTable or None
        The header's names, stripped (as ``header_width`` strips them), and the values.
    """
    text = raw.decode("utf-8", "replace").removeprefix("\ufeff")
    lines = _lines(text)
    if lines is None or len(lines) <= skip + 1 or len(lines) - skip - 1 > max_rows:
        return None
    if '"' in "".join(lines[: skip + 1]):  # quoting in the lines skipped or the header
        return None
    names = lines[skip].split(sep)
    stripped = [n.strip() for n in names]
    named = len(stripped)
    while named > 1 and not stripped[named - 1]:  # a header ending in separators (QTM's)
        named -= 1
    # pandas calls an empty name "Unnamed: k" (only those at the end are read here), and
    # renames one met twice
    if (not all(stripped[:named]) or len(set(names)) < len(names)
            or len(set(stripped)) < len(stripped)):
        return None
    stripped[named:] = [f"Unnamed: {k}" for k in range(named, len(names))]
    values = numbers(lines[skip + 1:], sep, len(names), least=named)
    return None if values is None else NumericTable(stripped, values)


def dlc_table(text: str, levels: int) -> tuple[list[tuple[str, ...]], np.ndarray,
                                                np.ndarray] | None:
    """A DeepLabCut csv as ``pandas.read_csv(path, header=list(range(levels)))`` and
    ``set_index`` on its first column read it, or None where that needs pandas.

    Parameters
    ----------
    text : str
        The file, decoded (UTF-8).
    levels : int
        Header rows (3, or 4 with ``individuals``).

    Returns
    -------
    tuple or None
        The columns' header tuples (the first column's left out), the index (int64 frame
        numbers) and the ``(rows, columns)`` values, as ``df.to_numpy()`` gives them.
    """
    lines = _lines(text)
    if lines is None or len(lines) <= levels:
        return None
    head, data = lines[:levels], lines[levels:]
    if any(line.count('"') % 2 for line in head) or any('"' in line for line in data):
        return None  # a quoted line break, or quotes pandas and csv might read apart
    rows = list(csv.reader(head))
    width = len(rows[0])
    if width < 2 or any(len(r) != width for r in rows):
        return None
    columns = list(zip(*(r[1:] for r in rows)))
    if not all(all(t) for t in columns) or len(set(columns)) < len(columns):
        return None  # pandas names an empty cell "Unnamed: ..."
    values = numbers(data, ",", width)
    if values is None:
        return None
    index = values[:, 0]
    # frame numbers pandas reads as int64 (not labelled-image paths, not floats)
    if not all(re.fullmatch(r"0|[1-9]\d{0,14}", line.partition(",")[0]) for line in data):
        return None
    return columns, index.astype(np.int64), values[:, 1:]

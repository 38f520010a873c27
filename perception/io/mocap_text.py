"""Motion-capture tables as text: encoding, comment lines, separator, decimal mark, loading.

Labs write tables with whatever their software or locale gives: Excel's
"Unicode text" (UTF-16 with a byte-order mark, tabs), semicolons and decimal
commas, ``#`` comment lines above the header, a header ending in a separator.
These helpers turn a file's bytes into a :class:`pandas.DataFrame` the same
way for every layout, and say what was wrong in one line when they cannot.
"""

from __future__ import annotations

import codecs
import csv
import io
import re
from pathlib import Path

import numpy as np

from perception.errors import InputError
from perception.io.plain_tables import NumericColumn
from perception.limits import MAX_FRAMES

__all__ = ["TableText", "check_fields", "header_width", "load_chunks", "table_text"]

#: Data lines looked at to tell the decimal mark (not only the first: a table
#: may start at integer positions, 0;100;20, and write 0,01 further down).
_DECIMAL_SAMPLE = 500
_COMMA_NUMBER = re.compile(r"[-+]?\d*,\d+(?:[eE][-+]?\d+)?")
_DOT_NUMBER = re.compile(r"[-+]?\d*\.\d+(?:[eE][-+]?\d+)?")
#: Bytes of a UTF-8 table decoded into lines (its header, the rows that tell the
#: decimal mark); pandas reads the rest from the bytes.
_LINES_BYTES = 1 << 20
_NUMBER = re.compile(r"[-+]?(?:\d+[.,]?\d*|[.,]\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|NaN|NAN|inf)")


class TableText:
    """A table file's text, decoded, with the lines above its content counted.

    Parameters
    ----------
    raw : bytes
        The file's bytes as UTF-8 (re-encoded when the file was UTF-16).
    lines : list of str
        Its first lines (up to about 1 MB; all of them when ``complete``).
    skip : int
        Blank and ``#`` comment lines above the first line of content.
    notes : list of str
        What decoding found (a UTF-16 file, comment lines).
    complete : bool
        Whether ``lines`` holds the whole file.
    """

    def __init__(self, raw: bytes, lines: list[str], skip: int, notes: list[str],
                 complete: bool = True):
        self.raw, self.lines, self.skip, self.notes = raw, lines, skip, notes
        self.complete = complete

    @property
    def first(self) -> str:
        """The first line of content ("" when there is none)."""
        return self.lines[self.skip] if self.skip < len(self.lines) else ""

    def all_lines(self) -> list[str]:
        """Every line of the file (decoded once more when only the first were kept)."""
        if not self.complete:
            self.lines = self.raw.decode("utf-8", "replace").removeprefix("\ufeff").splitlines()
            self.complete = True
        return self.lines


def is_utf16(raw: bytes) -> bool:
    """Whether ``raw`` is UTF-16 text (a byte-order mark, or every other byte 0).

    Parameters
    ----------
    raw : bytes
        A file's first bytes.
    """
    head = raw[:4096]
    return (head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE))
            or (len(head) >= 4 and max(head[1::2].count(0), head[0::2].count(0))
                > 0.4 * len(head[1::2])))


def _utf16(raw: bytes, path: Path) -> str:
    """The text of UTF-16 bytes: by the byte-order mark, else by where the zeros are."""
    if raw.startswith(codecs.BOM_UTF16_LE):
        name, raw = "utf-16-le", raw[2:]
    elif raw.startswith(codecs.BOM_UTF16_BE):
        name, raw = "utf-16-be", raw[2:]
    else:
        name = "utf-16-le" if raw[1:4096:2].count(0) >= raw[0:4096:2].count(0) else "utf-16-be"
    try:
        return raw[: len(raw) // 2 * 2].decode(name)
    except UnicodeDecodeError as exc:
        raise InputError(f"a UTF-16 text file that does not decode ({exc.reason} at byte "
                         f"{exc.start}): save it as UTF-8 (CSV) instead", path) from None


def table_text(path: Path, *, head: int | None = None) -> TableText:
    """A table file's text: decoded, with its leading blank and ``#`` lines counted.

    Parameters
    ----------
    path : Path
        The file.
    head : int, optional
        Read only this many bytes (to sniff a layout); default the whole file
        (its first lines decoded, the rest left as bytes for pandas).
    """
    with open(path, "rb") as fh:
        raw = fh.read() if head is None else fh.read(head)
    cut = head is not None and len(raw) == head
    notes = []
    if is_utf16(raw):  # Excel's "Unicode text": decoded whole, kept as UTF-8 for pandas
        text = _utf16(raw, path)
        raw = text.encode("utf-8")
        notes.append("read as UTF-16 text")
    else:
        if b"\x00" in raw[:4096]:
            raise InputError("a binary file, not a text table (it holds NUL bytes)", path)
        cut = cut or len(raw) > _LINES_BYTES
        text = raw[:_LINES_BYTES].decode("utf-8", "replace").removeprefix("\ufeff")
    lines = text.splitlines()
    if cut and lines:  # the last line may be cut short
        lines.pop()
    skip = 0
    while skip < len(lines) and (not lines[skip].strip() or lines[skip].lstrip().startswith("#")):
        skip += 1
    comments = sum(1 for line in lines[:skip] if line.strip())
    if comments:
        notes.append(f"{comments} comment line{'s' if comments > 1 else ''} (#) above the "
                     "table skipped")
    return TableText(raw, lines, skip, notes, complete=not cut)


def delimiter(line: str) -> str:
    """The separator of a header or data line: tab, comma or semicolon, else white space.

    Parameters
    ----------
    line : str
        A line of the table.
    """
    counts = {sep: line.count(sep) for sep in ("\t", ",", ";")}
    best = max(counts, key=counts.get)
    return best if counts[best] else r"\s+"


def split(line: str, sep: str) -> list[str]:
    """The fields of one line, stripped (quotes removed as CSV writes them).

    Parameters
    ----------
    line : str
        A line of the table.
    sep : str
        Its separator (:func:`delimiter`).
    """
    if sep == r"\s+":
        return line.split()
    return [f.strip() for f in next(csv.reader([line], delimiter=sep))] if line else []


def decimal_mark(lines: list[str], sep: str) -> str:
    """``","`` when a table not separated by commas writes decimal commas, else ``"."``.

    Looks at up to 500 data lines: a decimal comma anywhere and no decimal point.

    Parameters
    ----------
    lines : list of str
        The data lines (below any header).
    sep : str
        The separator.
    """
    if sep == ",":
        return "."
    commas = dots = 0
    for line in lines[:_DECIMAL_SAMPLE]:
        for cell in split(line, sep):
            if _COMMA_NUMBER.fullmatch(cell):
                commas += 1
            elif _DOT_NUMBER.fullmatch(cell):
                dots += 1
    return "," if commas and not dots else "."


def is_number(cell: str) -> bool:
    """Whether a cell is a number (a decimal comma allowed).

    Parameters
    ----------
    cell : str
        One field.
    """
    return bool(_NUMBER.fullmatch(cell.strip()))


def check_header(names: list[str], path: Path) -> None:
    """Refuse a header that names a column twice (exactly, or but for case).

    Parameters
    ----------
    names : list of str
        The header's fields, stripped.
    path : Path
        The file.
    """
    seen: dict[str, int] = {}
    for i, name in enumerate(names):
        if not name:
            continue
        j = seen.setdefault(name.lower(), i)
        if j != i:
            how = ("appears twice" if names[j] == name
                   else f"and {names[j]!r} differ only in case")
            raise InputError(f"the column {name!r} {how} (columns {j + 1} and {i + 1}): each "
                             "column needs a name of its own", path, field=name)


def load(path: Path, raw: bytes, sep: str, skip: int, header: int | None, decimal: str = "."):
    """The table below the first ``skip`` lines as pandas reads it; a short row is an error.

    Parameters
    ----------
    path : Path
        The file, for messages.
    raw : bytes
        Its bytes (UTF-8).
    sep : str
        The separator.
    skip : int
        Lines above the table (or above its header).
    header : int or None
        0 when the first line read is a header row.
    decimal : str
        The decimal mark.
    """
    import pandas as pd

    try:
        df = pd.read_csv(io.BytesIO(raw), **_read_options(sep, skip, header, decimal),
                         nrows=MAX_FRAMES + 1, low_memory=False)
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
        width = header_width(df)
    if sep != r"\s+":  # pandas fills a short row with NaN: count its fields
        _check_fields(path, raw, sep, skip + (header is not None), width, df)
    return df


#: Bytes of a table counted at once for its fields per line: a whole-file cumulative
#: count took 8 bytes per byte of the file (770 MB and 20 s for a 96 MB table).
_FIELDS_CHUNK = 1 << 23


def _line_blocks(source):
    """Blocks of whole lines of ``source`` (bytes, or a path read a block at a time)."""
    if isinstance(source, (bytes, bytearray)):
        start = 0
        while start < len(source):
            stop = min(start + _FIELDS_CHUNK, len(source))
            if stop < len(source):
                newline = source.rfind(b"\n", start, stop)
                stop = (newline + 1 if newline >= start
                        else source.find(b"\n", stop) + 1 or len(source))
            yield source[start:stop]
            start = stop
        return
    with open(source, "rb") as fh:
        rest = b""
        # smaller blocks from a file: its reader holds one chunk, not the whole text
        while block := fh.read(_FIELDS_CHUNK // 8):
            block = rest + block
            cut = block.rfind(b"\n") + 1
            if not cut:  # one long line so far
                rest = block
                continue
            rest = block[cut:]
            yield block[:cut]
        if rest:
            yield rest


def _check_fields(path: Path, source, sep: str, first: int, width: int, df) -> int:
    """Refuse the first line below ``first`` with fewer than ``width`` fields (pandas pads it);
    return the lines counted. ``source`` is the table's bytes, or its path."""
    sep_byte, line = ord(sep), 0
    for block in _line_blocks(source):
        chunk = np.frombuffer(block, np.uint8)
        ends = np.flatnonzero(chunk == 10)
        if not len(ends) or ends[-1] != len(chunk) - 1:
            ends = np.append(ends, len(chunk))
        starts = np.concatenate([[0], ends[:-1] + 1])
        # separators per line summed line by line: a cumulative count over every byte
        # took 8 bytes per byte of the block
        fields = np.add.reduceat(chunk == sep_byte, starts, dtype=np.int64) + 1
        last = np.maximum(ends - 1, 0)
        length = ends - starts - ((ends > starts) & (chunk[last] == 13))
        rows = line + np.arange(len(ends))
        bad = np.flatnonzero((fields < width) & (length > 0) & (rows >= first))
        if len(bad):
            b = bad[0]
            raise InputError(f"line {rows[b] + 1} has {fields[b]} fields; the rows above "
                             f"have {width}", path, field=str(df.columns[fields[b]]))
        line += len(ends)
    return line


def _read_options(sep: str, skip: int, header: int | None, decimal: str) -> dict:
    """pandas' options for a table, read whole or in chunks alike."""
    return dict(sep=sep, skiprows=skip, header=header, decimal=decimal, index_col=False,
                encoding="utf-8-sig", encoding_errors="replace", skipinitialspace=True)


def header_width(df) -> int:
    """Columns of a table read with its header: a header ending in a separator names a last
    empty column, not counted.

    Parameters
    ----------
    df : pandas.DataFrame
        The table (or its first chunk); its column names are stripped of spaces in place.
    """
    df.columns = [str(c).strip() for c in df.columns]
    width = len(df.columns)
    while width > 1 and df.columns[width - 1].startswith("Unnamed: "):
        width -= 1
    return width


def load_chunks(path: Path, sep: str, skip: int, decimal: str, rows: int, usecols=None):
    """The table below ``skip`` lines (a header row first) from the file, ``rows`` at a time.

    Read so, a table takes the memory of one chunk rather than of its every
    row: for a long table read trial by trial
    (:func:`perception.io.mocap_tables.read_xyz_table`'s large files). The
    chunks' columns are stripped of spaces; nothing is checked here (the
    caller compares the chunks' kinds, and counts fields with
    :func:`check_fields`).

    Parameters
    ----------
    path : Path
        The file (UTF-8).
    sep : str
        A one-character separator.
    skip : int
        Lines above the header.
    decimal : str
        The decimal mark.
    rows : int
        Rows per chunk.
    usecols : list of int, optional
        The columns read, by position.
    """
    import pandas as pd

    with pd.read_csv(path, **_read_options(sep, skip, 0, decimal), chunksize=rows,
                     usecols=usecols) as reader:
        for chunk in reader:
            chunk.columns = [str(c).strip() for c in chunk.columns]
            yield chunk


def check_fields(path: Path, sep: str, skip: int, width: int, df) -> int:
    """Refuse a line of the file below its header with fewer than ``width`` fields, read a
    block at a time; return the file's lines.

    Parameters
    ----------
    path : Path
        The file.
    sep : str
        Its one-character separator.
    skip : int
        Lines above the header.
    width : int
        The header's columns.
    df : pandas.DataFrame
        A frame with the table's columns (to name the first missing one).
    """
    return _check_fields(path, path, sep, skip + 1, width, df)


def numeric(column, path: Path, name: str) -> np.ndarray:
    """A column as floats (empty cells NaN); a non-numeric cell is an InputError.

    Parameters
    ----------
    column : pandas.Series or NumericColumn
        The column.
    path : Path
        The file.
    name : str
        The column's name, for the message.
    """
    if isinstance(column, NumericColumn):  # read as numbers (plain_tables): every cell is
        return column.to_numpy(dtype=float)
    import pandas as pd

    values = pd.to_numeric(column, errors="coerce")
    bad = np.flatnonzero(values.isna().to_numpy() & column.notna().to_numpy())
    if len(bad):
        raise InputError(f"not a number: {column.iloc[bad[0]]!r} (data row {bad[0] + 1})",
                         path, field=name)
    return values.to_numpy(dtype=float)

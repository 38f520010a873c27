"""Outputs appear whole or not at all, and never in place of something that is not ours.

Every writer goes through :func:`atomic_path`: the output is written under a
temporary name beside its final one and renamed only when complete, so a
crash, a Ctrl-C or a full disk never leaves a half-written file under the
final name. Before anything is written the destination is checked: an
existing directory, FIFO, device or socket is refused (``-o /dev/null``
must not replace /dev/null), and :func:`check_output` refuses an output that
is one of the command's inputs. A write that fails for want of space or
permission ends in one :class:`OSError` naming the file, with the temporary
file removed.

A temporary name is ``.<stem>.<owner>.<random>.part<suffix>``, or for a long
final name ``.<hash>.<owner>.<random>.part<suffix>`` (a hash of the final
name): never longer than a long final name, so it fits wherever that fits.
Temporary names carry their writer's host and process (:func:`owner_tag`):
a write killed by SIGKILL or a power cut leaves its temporary file behind,
and the next write of the same output removes it once that process is gone
(:func:`remove_stale`), without touching what a live writer — another batch
into the same folder — is still writing.

HDF5 files are built in memory and written with plain file I/O
(:func:`atomic_hdf5`): HDF5's own writes on a full disk fail late, at close
or at interpreter exit, where they cannot be caught (and crash h5py).
"""

from __future__ import annotations

import contextlib
import csv
import glob
import hashlib
import os
import re
import socket
import stat
import tempfile
import warnings
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path

import numpy as np

from perception.errors import InputError

__all__ = [
    "atomic_hdf5",
    "atomic_path",
    "check_output",
    "jsonable",
    "owner_gone",
    "owner_tag",
    "remove_stale",
    "save_figure",
    "write_bytes",
    "write_csv",
    "write_csv_chunks",
    "write_json",
    "write_text",
]


def _refuse_non_regular(final: Path) -> None:
    try:
        mode = final.stat().st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise OSError(exc.errno, f"cannot write {final}: {exc.strerror}") from None
    if stat.S_ISDIR(mode):
        raise InputError("is a folder, not a file to write", final)
    if not stat.S_ISREG(mode):
        raise InputError("exists and is not a regular file (a device, FIFO or socket); "
                         "refusing to replace it", final)


#: This host, shortly: temporary names from other hosts (a shared folder) are
#: never judged by this host's process table.
_HOST = hashlib.sha1(socket.gethostname().encode()).hexdigest()[:6]
_TAG = re.compile(r"(?:^|[.-])h([0-9a-f]{6})p(\d+)(?:[.-]|$)")


def owner_tag() -> str:
    """``h<host>p<pid>``: who is writing a temporary file or folder."""
    return f"h{_HOST}p{os.getpid()}"


def owner_gone(name: str) -> bool:
    """Whether the writer tagged in ``name`` is a process of this host that has ended."""
    import psutil

    tags = _TAG.findall(name)  # the last: a clip's own name may look like one
    if not tags or tags[-1][0] != _HOST:
        return False
    try:
        return not psutil.pid_exists(int(tags[-1][1]))
    except OverflowError:  # no such process id on this system: not one we can judge
        return False


def remove_stale(folder: str | os.PathLike, pattern: str) -> int:
    """Remove the temporary files and folders matching ``pattern`` whose writer has ended.

    Parameters
    ----------
    folder : str or os.PathLike
        Where to look.
    pattern : str
        Glob of the temporary names (e.g. ``".clip.h*p*.part*"``).

    Returns
    -------
    int
        How many were removed.
    """
    import shutil

    removed = 0
    for path in Path(folder).glob(pattern):
        if not owner_gone(path.name):
            continue
        with contextlib.suppress(OSError):
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink()
            removed += 1
    return removed


def check_output(path: str | os.PathLike, inputs: Iterable[str | os.PathLike] = ()) -> Path:
    """Refuse an output path that would destroy an input or something that is not a file.

    Parameters
    ----------
    path : str or os.PathLike
        The output the command is about to write.
    inputs : iterable of str or os.PathLike
        The command's input files.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InputError
        ``path`` is one of ``inputs`` (the same file, through any name or
        link), or exists and is not a regular file.
    """
    final = Path(path)
    _refuse_non_regular(final)
    for source in inputs:
        source = Path(source)
        same = False
        with contextlib.suppress(OSError):
            same = final.exists() and source.exists() and os.path.samefile(final, source)
        if same or final.resolve() == source.resolve():
            raise InputError(f"is also an input of this command ({source}); "
                             "choose another output name", final)
    return final


#: Final names up to this long (bytes) keep their stem in their temporary name;
#: a longer one is written under a hash of it, which is shorter than it.
_LONG_NAME = 128


def _temporary_key(final: Path, suffix: str) -> tuple[str, str]:
    """What a temporary name of ``final`` starts with (after the dot), and its suffix.

    ``.<stem>.<owner>.<random>.part<suffix>`` while that is short; for a long
    final name, ``.<hash12>.<owner>.<random>.part<suffix>`` instead, so the
    temporary name fits in a file name (255 bytes) whenever the final one
    does, and is no longer than it. The key is the same for every write of
    one output, so :func:`remove_stale` finds what a killed writer left.
    """
    name = os.fsencode(final.name)
    if len(name) <= _LONG_NAME:
        return final.stem, suffix
    if len(os.fsencode(suffix)) > 16:  # not a format's suffix: not needed by a writer
        suffix = ""
    return hashlib.sha1(name).hexdigest()[:12], suffix


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, *, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` on success.

    If the body raises, the temporary file is removed and ``path`` is left as it
    was (absent or the previous complete version). An :class:`OSError` (a full
    disk, no permission) is raised again as one naming ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        Final destination. Its folder is created if missing; it must not be
        a folder, device, FIFO or socket.
    suffix : str, optional
        Suffix of the temporary name (default: that of ``path``), for writers
        that infer the format from the extension (OpenCV, matplotlib).
    """
    final = Path(path)
    _refuse_non_regular(final)
    suffix = final.suffix if suffix is None else suffix
    key, suffix = _temporary_key(final, suffix)
    try:
        final.parent.mkdir(parents=True, exist_ok=True)
        remove_stale(final.parent, f".{glob.escape(key)}.h*p*.part*")
        fd, tmp = tempfile.mkstemp(prefix=f".{key}.{owner_tag()}.",
                                   suffix=f".part{suffix}", dir=final.parent)
    except OSError as exc:
        raise OSError(exc.errno, f"cannot write {final}: {exc.strerror or exc}") from None
    os.close(fd)
    tmp_path = Path(tmp)
    # mkstemp creates the file 0600; the output should get the usual
    # permissions (0666 less the umask) like any other file the user writes.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_path, 0o666 & ~umask)
    try:
        yield tmp_path
        os.replace(tmp_path, final)
    except OSError as exc:
        tmp_path.unlink(missing_ok=True)
        if isinstance(exc, InputError | FileNotFoundError) or exc.errno is None:
            raise
        raise OSError(exc.errno, f"cannot write {final}: {exc.strerror or exc}") from None
    except BaseException:
        tmp_path.unlink(missing_ok=True)
        raise


def write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; return the path.

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    data : bytes
        Its content.
    """
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())  # a full disk shows here, not after the rename
    return Path(path)


@contextlib.contextmanager
def atomic_hdf5(path: str | os.PathLike) -> Iterator:
    """Yield a new, in-memory ``h5py.File``; write it to ``path`` whole when the block ends.

    Parameters
    ----------
    path : str or os.PathLike
        Final destination (checked as by :func:`atomic_path`).
    """
    import h5py

    _refuse_non_regular(Path(path))
    # A unique in-memory name: h5py's core driver keys open files by name.
    fh = h5py.File(f"hammer-mv-{id(object())}.h5", "w", driver="core", backing_store=False)
    try:
        yield fh
        fh.flush()
        image = fh.id.get_file_image()
    finally:
        fh.close()
    write_bytes(path, image)


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; return the path.

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    text : str
        Its content (written as UTF-8; a file name's undecodable bytes,
        which Python holds as lone surrogates, as ``\\udcff`` escapes).
    """
    return write_bytes(path, text.encode("utf-8", "backslashreplace"))


def jsonable(value):
    """``json.dumps(default=...)`` hook: numpy arrays and scalars, paths and sets as JSON.

    Parameters
    ----------
    value : object
        Something :mod:`json` cannot encode by itself.
    """
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, set | frozenset):
        return sorted(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def write_json(path: str | os.PathLike, obj) -> Path:
    """Write ``obj`` as indented JSON to ``path`` atomically (NaN written as null).

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    obj : object
        JSON-able data; numpy values are converted (see :func:`jsonable`).
    """
    import json

    # one encoding: the text of encoding, decoding and encoding again (a clip's report
    # made the three passes, 7 ms of a trial's JSON, encoding alone 3 ms)
    text = json.dumps(_plain(obj), indent=2)
    return write_text(path, text + "\n")


def _plain(o):
    """``o`` as ``json.loads(json.dumps(o, default=jsonable))`` gives it, NaN as None.

    A float array without NaN is its ``tolist()`` as it is; an object :mod:`json`
    cannot encode goes through :func:`jsonable`, as its first encoding did.
    """
    if isinstance(o, str) or o is None or o is True or o is False:
        return o
    if isinstance(o, float):  # NumPy's float64 too: written as the float it is
        return None if o != o else o
    if isinstance(o, int):
        return o
    if isinstance(o, dict):
        return {k if isinstance(k, str) else _json_key(k): _plain(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [_plain(v) for v in o]
    if isinstance(o, np.ndarray) and o.dtype.kind == "f" and not np.isnan(o).any():
        return o.tolist()
    return _plain(jsonable(o))


def _json_key(key) -> str:
    """A key that is not text as :mod:`json` writes it (``1`` as ``"1"``, ``True`` as
    ``"true"``); a TypeError for one it refuses."""
    import json

    return next(iter(json.loads(json.dumps({key: None}))))


def write_csv(path: str | os.PathLike, table) -> Path:
    """Write a table to CSV at ``path`` atomically (no index).

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    table : pandas.DataFrame or mapping of str to array_like
        The table, or its columns: those are written by the standard
        library's ``csv`` module as pandas would write them (NaN empty), so
        that ``recognize`` does not load pandas for one table (0.11 s of its
        start-up). A column name Python could not decode (a surrogate) is
        written escaped, not lost.
    """
    with atomic_path(path) as tmp:
        if isinstance(table, Mapping):
            with open(tmp, "w", newline="", encoding="utf-8", errors="backslashreplace") as f:
                writer = csv.writer(f, lineterminator="\n")
                writer.writerow(table)
                writer.writerows([_cell(v) for v in row] for row in zip(*table.values()))
        else:
            table.to_csv(tmp, index=False, errors="backslashreplace")
    return Path(path)


def write_csv_chunks(path: str | os.PathLike, tables: Iterable) -> Path:
    """Write the tables ``tables`` gives, one after another, as one CSV at ``path``
    atomically (no index; the first's header only): a long table written a piece at a
    time, never whole in memory.

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    tables : iterable of pandas.DataFrame
        The pieces, in order, each with the same columns (at least one: an empty
        table gives the header alone).
    """
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", errors="backslashreplace",
                                        newline="") as f:
        for i, table in enumerate(tables):
            table.to_csv(f, index=False, header=i == 0)
    return Path(path)


def _cell(value):
    return "" if isinstance(value, float) and value != value else value


#: Metadata matplotlib would stamp with the time of writing, left out so that the same
#: figure is the same file (``None`` removes a key).
_NO_DATES = {"svg": {"Date": None}, "pdf": {"CreationDate": None}}


def save_figure(path: str | os.PathLike, fig, *, dpi: int = 120) -> Path:
    """Save a matplotlib figure ``fig`` to ``path`` atomically at ``dpi``.

    The format follows the suffix of ``path``; an SVG or PDF carries no date,
    so the same figure gives the same bytes. A character the font lacks (a
    clip name in another script) is drawn as a box without a warning on stderr.
    """
    final = Path(path)
    fmt = final.suffix.lstrip(".") or "png"
    with atomic_path(final) as tmp, warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Glyph .* missing from", category=UserWarning)
        fig.savefig(tmp, dpi=dpi, format=fmt, metadata=_NO_DATES.get(fmt))
    return final

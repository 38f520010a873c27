"""Outputs appear whole or not at all: write to a temporary name, then rename."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, *, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` on success.

    If the body raises, the temporary file is removed and ``path`` is left as it
    was (absent or the previous complete version).

    Parameters
    ----------
    path : str or os.PathLike
        Final destination. Its folder is created if missing.
    suffix : str, optional
        Suffix of the temporary name (default: that of ``path``), for writers
        that infer the format from the extension (OpenCV, matplotlib).
    """
    final = Path(path)
    final.parent.mkdir(parents=True, exist_ok=True)
    suffix = final.suffix if suffix is None else suffix
    fd, tmp = tempfile.mkstemp(prefix=f".{final.stem}.", suffix=f".part{suffix}", dir=final.parent)
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
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; return the path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def jsonable(value):
    """``json.dumps(default=...)`` hook: numpy arrays and scalars, paths and sets as JSON.

    Parameters
    ----------
    value : object
        Something :mod:`json` cannot encode by itself.
    """
    import numpy as np

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

    def clean(o):
        if isinstance(o, float) and o != o:
            return None
        if isinstance(o, dict):
            return {k: clean(v) for k, v in o.items()}
        if isinstance(o, list | tuple):
            return [clean(v) for v in o]
        return o

    text = json.dumps(clean(json.loads(json.dumps(obj, default=jsonable))), indent=2)
    return write_text(path, text + "\n")


def write_csv(path: str | os.PathLike, frame) -> Path:
    """Write a pandas DataFrame ``frame`` to CSV at ``path`` atomically (no index)."""
    with atomic_path(path) as tmp:
        frame.to_csv(tmp, index=False)
    return Path(path)


def save_figure(path: str | os.PathLike, fig, *, dpi: int = 120) -> Path:
    """Save a matplotlib figure ``fig`` to ``path`` atomically at ``dpi``.

    The format follows the suffix of ``path``.
    """
    final = Path(path)
    with atomic_path(final) as tmp:
        fig.savefig(tmp, dpi=dpi, format=final.suffix.lstrip(".") or "png")
    return final

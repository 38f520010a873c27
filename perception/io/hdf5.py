"""Reading HDF5 files we did not necessarily write: every object checked before use.

A tracks or repertoire file may come from anywhere. Each dataset a reader
touches must be a hard-linked dataset (not a soft or external link, not a
group) of the expected kind of dtype (numbers or strings; never compound)
and number of dimensions; each attribute must be of the expected type (a
scalar where one is expected, not an array). Anything else is one
:class:`~perception.errors.InputError` naming the file and the object.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from perception.errors import InputError

__all__ = ["decode_attrs", "open_hdf5", "read_dataset", "scalar_attr"]

#: dtype kinds by what a reader expects.
_KINDS = {"number": "biuf", "integer": "iu", "string": "SOU"}


def open_hdf5(path: str | os.PathLike, what: str):
    """Open ``path`` read-only as HDF5.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What it should be ("tracks file", "repertoire"), for messages.

    Raises
    ------
    InputError
        Missing, not a regular file, or not HDF5.
    """
    import h5py

    p = Path(path)
    if not p.exists():
        raise InputError("no such file", p)
    if not p.is_file():
        raise InputError(f"not a regular file (expected a {what})", p)
    try:
        return h5py.File(p, "r")
    except OSError:
        raise InputError(f"not an HDF5 file (or unreadable; expected a {what})", p) from None


def read_dataset(fh, name: str, kind: str, ndim: int, path: str | os.PathLike) -> np.ndarray:
    """The whole of dataset ``name``, checked to be a hard-linked array of ``kind`` and ``ndim``.

    Parameters
    ----------
    fh : h5py.File or h5py.Group
        Where to look.
    name : str
        Path of the dataset below ``fh``.
    kind : {"number", "integer", "string"}
        What its elements must be.
    ndim : int
        Its number of dimensions.
    path : str or os.PathLike
        The file, for messages.
    """
    import h5py

    where = f"/{fh.name.strip('/')}/{name}".replace("//", "/")
    link = fh.get(name, getlink=True)
    if link is None:
        raise InputError(f"missing dataset {where}", path)
    if not isinstance(link, h5py.HardLink):
        raise InputError(f"{where} is a {type(link).__name__}, not a dataset stored in the file",
                         path)
    obj = fh[name]
    if not isinstance(obj, h5py.Dataset):
        raise InputError(f"{where} is a group, not a dataset", path)
    dtype = obj.dtype
    if dtype.fields is not None or dtype.kind not in _KINDS[kind]:
        raise InputError(f"{where} has dtype {dtype}, expected {kind}s", path)
    if obj.ndim != ndim:
        raise InputError(f"{where} has {obj.ndim} dimensions, expected {ndim}", path)
    return obj[()]


def _plain(value: Any, key: str, where: str, path: str | os.PathLike) -> Any:
    if isinstance(value, bytes):
        try:
            return value.decode("utf-8")
        except UnicodeDecodeError:
            raise InputError(f"attribute {where}.{key} is not UTF-8 text", path) from None
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        if value.dtype.fields is not None or value.dtype.kind not in "biufSOU":
            raise InputError(f"attribute {where}.{key} has dtype {value.dtype}", path)
        if value.dtype.kind in "SO":
            return np.array([v.decode("utf-8", "replace") if isinstance(v, bytes) else v
                             for v in value.ravel()], dtype=object).reshape(value.shape)
    return value


def decode_attrs(attrs, where: str, path: str | os.PathLike) -> dict[str, Any]:
    """Attributes as Python values: text decoded, numpy scalars as Python numbers.

    Parameters
    ----------
    attrs : h5py.AttributeManager
        The attributes.
    where : str
        Their object ("/", "/video"), for messages.
    path : str or os.PathLike
        The file, for messages.
    """
    try:
        items = list(attrs.items())
    except (OSError, TypeError, ValueError) as exc:
        raise InputError(f"unreadable attributes of {where}: {exc}", path) from None
    return {key: _plain(value, key, where, path) for key, value in items}


def scalar_attr(values: dict[str, Any], key: str, kind: str, where: str,
                path: str | os.PathLike) -> Any:
    """Attribute ``key`` of decoded ``values`` if present, checked to be one ``kind`` value.

    Parameters
    ----------
    values : dict
        From :func:`decode_attrs`.
    key : str
        The attribute.
    kind : {"number", "integer", "string"}
        What it must be.
    where : str
        Its object, for messages.
    path : str or os.PathLike
        The file, for messages.

    Returns
    -------
    The value, or None if absent.
    """
    if key not in values:
        return None
    value = values[key]
    ok = {"string": isinstance(value, str),
          "integer": isinstance(value, int) and not isinstance(value, bool),
          "number": isinstance(value, int | float) and not isinstance(value, bool)
          and math.isfinite(value)}[kind]
    if not ok:
        shown = f"an array of shape {value.shape}" if isinstance(value, np.ndarray) else repr(value)
        raise InputError(f"attribute {where}.{key} is {shown}, expected one {kind}", path)
    return value

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
from perception.io.files import input_file
from perception.limits import MAX_HDF5_VALUES

__all__ = ["check_dataset", "check_schema", "decode_attrs", "open_hdf5", "read_dataset",
           "scalar_attr"]

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
    if not os.path.lexists(p) or not p.exists():
        raise InputError("no such file", p)
    input_file(p, what, empty=False)  # a FIFO or device would block or never end
    try:
        return h5py.File(p, "r")
    except OSError:
        raise InputError(f"not an HDF5 file (or unreadable; expected a {what})", p) from None


def check_dataset(fh, name: str, kind: str, ndim: int, path: str | os.PathLike, *,
                  max_values: int = MAX_HDF5_VALUES):
    """Dataset ``name``, checked to be a hard-linked array of ``kind`` and ``ndim``; not read.

    Its shape is what the file *claims*: checked against ``max_values``
    before anything is read, so a file claiming a billion rows costs nothing.

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
    max_values : int
        Most elements it may hold.

    Returns
    -------
    h5py.Dataset
    """
    import h5py

    where = f"/{fh.name.strip('/')}/{name}".replace("//", "/")
    link = fh.get(name, getlink=True)
    if link is None:
        raise InputError("missing dataset", path, field=where)
    if not isinstance(link, h5py.HardLink):
        raise InputError(f"is a {type(link).__name__}, not a dataset stored in the file", path,
                         field=where)
    obj = fh[name]
    if not isinstance(obj, h5py.Dataset):
        raise InputError("is a group, not a dataset", path, field=where)
    dtype = obj.dtype
    if dtype.fields is not None or dtype.kind not in _KINDS[kind]:
        raise InputError(f"has dtype {dtype}, expected {kind}s", path, field=where)
    if obj.ndim != ndim:
        raise InputError(f"has {obj.ndim} dimensions, expected {ndim}", path,
                         field=where)
    size = math.prod(int(n) for n in obj.shape)
    if size > max_values:
        raise InputError(f"claims shape {tuple(obj.shape)} ({size:.3g} values), more "
                         f"than the {max_values:.3g} a file of this kind may hold", path,
                         field=where)
    return obj


def read_dataset(fh, name: str, kind: str, ndim: int, path: str | os.PathLike, *,
                 max_values: int = MAX_HDF5_VALUES) -> np.ndarray:
    """The whole of dataset ``name``, checked by :func:`check_dataset` before it is read.

    ``fh``, ``name``, ``kind``, ``ndim``, ``path`` and ``max_values`` are
    those of :func:`check_dataset`.
    """
    obj = check_dataset(fh, name, kind, ndim, path, max_values=max_values)
    where = obj.name
    try:
        return obj[()]
    except (OSError, ValueError, TypeError) as exc:  # corrupt chunks, a bad filter
        raise InputError(f"cannot be read: {exc}", path, field=where) from None
    except MemoryError:
        raise InputError("too large to read", path, field=where) from None


def _plain(value: Any, key: str, where: str, path: str | os.PathLike) -> Any:
    if isinstance(value, bytes):
        try:
            return value.decode("utf-8")
        except UnicodeDecodeError:
            raise InputError("not UTF-8 text", path, field=f"{where}.{key}") from None
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        if value.dtype.fields is not None or value.dtype.kind not in "biufSOU":
            raise InputError(f"has dtype {value.dtype}", path, field=f"{where}.{key}")
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
        raise InputError(f"unreadable attributes: {exc}", path, field=where) from None
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
        raise InputError(f"is {shown}, expected one {kind}", path, field=f"{where}.{key}")
    return value


def check_schema(root: dict[str, Any], schema: str, version: int, what: str,
                 path: str | os.PathLike, remedy: str = "") -> None:
    """Refuse a file whose root ``schema`` or ``schema_version`` attribute is not ours.

    Parameters
    ----------
    root : dict
        The root's attributes, from :func:`decode_attrs`.
    schema, version : str, int
        What they must be.
    what : str
        The kind of file, for messages (``"tracks file"``).
    path : str or os.PathLike
        The file, for messages.
    remedy : str
        Said after an unsupported version (``"; rebuild it"``).

    Raises
    ------
    InputError
        Another schema, or another version of ours.
    """
    found = scalar_attr(root, "schema", "string", "/", path)
    if found != schema:
        raise InputError(f"not a hammer-mv {what} (schema {found!r}, expected {schema!r})",
                         path)
    number = scalar_attr(root, "schema_version", "integer", "/", path)
    if number != version:
        raise InputError(f"{what.split()[0]} schema_version {number!r} is not supported (this "
                         f"hammer-mv reads version {version}){remedy}", path)

"""The repertoire file: HDF5 storage of HAMMER-MV models (docs/repertoire-format.md).

Layout (schema ``hammer-mv/repertoire``, version 1)::

    /                attrs: schema, schema_version, software_version, config (JSON)
    /models/<name>   attrs: order, kind, task (JSON), scene (JSON), substeps, dt
    /models/<name>/<arm|finger|thumb>
                     datasets A, B, H, K, L, P, x0; attrs: l1, l2, base, elbow
    /models/<name>/calibration          (optional; files before it lack it)
                     dataset misfit; attrs: frame_period, params (JSON)

This module knows the layout and nothing of what the models mean: it writes
and reads plain records (:class:`StoredModel`); :mod:`perception.recognition`
turns them into models.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from perception import __version__
from perception.errors import InputError
from perception.io.atomic import atomic_hdf5
from perception.io.hdf5 import decode_attrs, open_hdf5, read_dataset, scalar_attr

__all__ = ["SCHEMA", "SCHEMA_VERSION", "StoredCalibration", "StoredChain", "StoredModel",
           "read_repertoire", "write_repertoire"]

SCHEMA = "hammer-mv/repertoire"
SCHEMA_VERSION = 1
ROLES = ("arm", "finger", "thumb")
ARRAYS = ("A", "B", "H", "K", "L", "P", "x0")
#: Large, smooth arrays: compressed on disk.
_COMPRESSED = ("K", "L")


@dataclass(frozen=True)
class StoredChain:
    """One chain of a stored model.

    Attributes
    ----------
    arrays : mapping of str to array
        ``A, B, H, K, L, P, x0``.
    l1, l2 : float
        Link lengths, m.
    base : (2,) array
        First joint, m.
    elbow : int
        +1 or -1.
    """

    arrays: Mapping[str, np.ndarray]
    l1: float
    l2: float
    base: np.ndarray
    elbow: int


@dataclass(frozen=True)
class StoredCalibration:
    """A model's familiarity calibration as stored.

    Attributes
    ----------
    misfit : (K,) array
        Misfits of the model's own demonstrations.
    frame_period : float
        Their frame period, s.
    params : dict
        How the demonstrations were made (JSON in the file).
    """

    misfit: np.ndarray
    frame_period: float
    params: dict


@dataclass(frozen=True)
class StoredModel:
    """One model as stored: its name, kind, task and scene, and its chains.

    Attributes
    ----------
    name, kind : str
        Model name and kind.
    task, scene : dict
        The task fields and the scene the model was planned for (JSON in the file).
    substeps : int
        Model steps per video frame.
    dt : float
        Model time step, s.
    chains : mapping of str to StoredChain
        ``arm``, ``finger``, ``thumb``.
    calibration : StoredCalibration or None
        The familiarity calibration (None in files written before it existed).
    """

    name: str
    kind: str
    task: dict
    scene: dict
    substeps: int
    dt: float
    chains: Mapping[str, StoredChain] = field(repr=False)
    calibration: StoredCalibration | None = field(default=None, repr=False)


def write_repertoire(path: str | os.PathLike, config: Mapping[str, Any],
                     models: Sequence[StoredModel]) -> Path:
    """Write a repertoire file atomically; return its path.

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    config : mapping
        The configuration the repertoire was built from (stored as JSON).
    models : sequence of StoredModel
        The models, in order.
    """

    path = Path(path)
    with atomic_hdf5(path) as f:
        f.attrs["schema"] = SCHEMA
        f.attrs["schema_version"] = SCHEMA_VERSION
        f.attrs["software_version"] = __version__
        f.attrs["config"] = json.dumps(config)
        g = f.create_group("models")
        for i, m in enumerate(models):
            mg = g.create_group(m.name)
            mg.attrs.update(order=i, kind=m.kind, task=json.dumps(m.task),
                            scene=json.dumps(m.scene), substeps=m.substeps, dt=m.dt)
            for role in ROLES:
                c = m.chains[role]
                cg = mg.create_group(role)
                for key in ARRAYS:
                    cg.create_dataset(key, data=c.arrays[key],
                                      compression="gzip" if key in _COMPRESSED else None)
                cg.attrs.update(l1=c.l1, l2=c.l2, base=c.base, elbow=c.elbow)
            if m.calibration is not None:
                cal = mg.create_group("calibration")
                cal.create_dataset("misfit", data=np.asarray(m.calibration.misfit, dtype=float))
                cal.attrs.update(frame_period=m.calibration.frame_period,
                                 params=json.dumps(m.calibration.params))
    return path


def _read_chain(cg, path: Path) -> StoredChain:
    arrays = {k: np.asarray(read_dataset(cg, k, "number", _NDIM[k], path), dtype=float)
              for k in ARRAYS}
    attrs = decode_attrs(cg.attrs, cg.name, path)
    base = np.asarray(attrs.get("base"), dtype=float) if "base" in attrs else None
    if base is None or base.shape != (2,):
        raise InputError(f"attribute {cg.name}.base must be 2 numbers", path)
    return StoredChain(arrays=arrays, l1=scalar_attr(attrs, "l1", "number", cg.name, path),
                       l2=scalar_attr(attrs, "l2", "number", cg.name, path), base=base,
                       elbow=scalar_attr(attrs, "elbow", "integer", cg.name, path))


def _read_calibration(mg, path: Path) -> StoredCalibration | None:
    """The model's calibration group, or None in a file written before it existed."""
    import h5py

    if "calibration" not in mg:
        return None
    cal = mg["calibration"]
    if not isinstance(cal, h5py.Group):
        raise InputError(f"{cal.name} is not a group", path)
    misfit = np.asarray(read_dataset(cal, "misfit", "number", 1, path), dtype=float)
    attrs = decode_attrs(cal.attrs, cal.name, path)
    period = scalar_attr(attrs, "frame_period", "number", cal.name, path)
    if period is None or not period > 0:
        raise InputError(f"attribute {cal.name}.frame_period must be a positive time, "
                         f"got {period!r}", path)
    params = _json_attr(attrs, "params", cal.name, path)
    if not isinstance(params, dict):
        raise InputError(f"attribute {cal.name}.params must be a JSON object", path)
    return StoredCalibration(misfit=misfit, frame_period=period, params=params)


def _json_attr(attrs: dict, key: str, where: str, path: Path):
    text = scalar_attr(attrs, key, "string", where, path)
    try:
        return json.loads(text)
    except (TypeError, ValueError):
        raise InputError(f"attribute {where}.{key} is not JSON", path) from None


def _read_model(name: str, mg, path: Path) -> StoredModel:
    import h5py

    if not isinstance(mg, h5py.Group):
        raise InputError(f"/models/{name} is not a group", path)
    a = decode_attrs(mg.attrs, mg.name, path)
    for role in ROLES:
        if role not in mg or not isinstance(mg.get(role, getlink=True), h5py.HardLink):
            raise InputError(f"missing group {mg.name}/{role}", path)
    dt = scalar_attr(a, "dt", "number", mg.name, path)
    if dt is None or dt <= 0:
        raise InputError(f"attribute {mg.name}.dt must be a positive time step, got {dt!r}",
                         path)
    return StoredModel(name=name, kind=scalar_attr(a, "kind", "string", mg.name, path),
                       task=_json_attr(a, "task", mg.name, path),
                       scene=_json_attr(a, "scene", mg.name, path),
                       substeps=scalar_attr(a, "substeps", "integer", mg.name, path), dt=dt,
                       chains={role: _read_chain(mg[role], path) for role in ROLES},
                       calibration=_read_calibration(mg, path))


def _read_file(f, path: Path) -> tuple[dict, list[StoredModel]]:
    root = decode_attrs(f.attrs, "/", path)
    schema = scalar_attr(root, "schema", "string", "/", path)
    if schema != SCHEMA:
        raise InputError(f"not a hammer-mv repertoire (schema {schema!r}, "
                         f"expected {SCHEMA!r})", path)
    version = scalar_attr(root, "schema_version", "integer", "/", path)
    if version != SCHEMA_VERSION:
        raise InputError(f"repertoire schema version {version} is not supported "
                         f"(this is version {SCHEMA_VERSION}); rebuild it", path)
    config = _json_attr(root, "config", "/", path) if "config" in root else {}
    if "models" not in f:
        raise InputError("missing group /models", path)
    groups = list(f["models"].items())
    order = [scalar_attr(decode_attrs(g.attrs, g.name, path), "order", "integer", g.name,
                         path) for _, g in groups]
    ranked = sorted(range(len(groups)), key=lambda i: (order[i] if order[i] is not None else i))
    return config, [_read_model(*groups[i], path) for i in ranked]


#: Dimensions of each stored chain array.
_NDIM = {"A": 2, "B": 2, "H": 2, "K": 3, "L": 3, "P": 3, "x0": 1}


def read_repertoire(path: str | os.PathLike) -> tuple[dict, list[StoredModel]]:
    """Read a repertoire file: its config and its models in order.

    Parameters
    ----------
    path : str or os.PathLike
        The HDF5 file.

    Raises
    ------
    InputError
        If the file is missing, not HDF5, of another schema or version, or corrupt.
    """

    path = Path(path)
    try:
        with open_hdf5(path, "repertoire") as f:
            config, models = _read_file(f, path)
    except InputError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as exc:  # a corruption we did not foresee
        raise InputError(f"corrupt or unreadable repertoire: {exc}", path) from None
    if not models:
        raise InputError("repertoire holds no models", path)
    return config, models

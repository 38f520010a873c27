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
from perception.io.hdf5 import check_schema, decode_attrs, open_hdf5, read_dataset, scalar_attr
from perception.limits import MAX_FPS, MAX_GAIN, MAX_SUBSTEPS

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
        f.attrs.update(schema=SCHEMA, schema_version=SCHEMA_VERSION,
                       software_version=__version__, config=json.dumps(config))
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


#: Largest link length or base offset of a chain, m (an arm is under a metre).
_MAX_LENGTH_M = 10.0


def _read_chain(cg, path: Path) -> StoredChain:
    arrays = {k: np.asarray(read_dataset(cg, k, "number", _NDIM[k], path), dtype=float)
              for k in ARRAYS}
    for key, value in arrays.items():
        where = f"{cg.name}/{key}"
        if not np.all(np.isfinite(value)):
            raise InputError("has non-finite values", path, field=where)
        if value.size and np.abs(value).max() > MAX_GAIN:
            raise InputError(f"has values up to {np.abs(value).max():.3g}, beyond the "
                             f"{MAX_GAIN:.0e} of any planned model: a corrupt repertoire "
                             "(rebuild it)", path, field=where)
    _check_covariance(arrays["P"], f"{cg.name}/P", path)
    attrs = decode_attrs(cg.attrs, cg.name, path)
    base = np.asarray(attrs.get("base"), dtype=float) if "base" in attrs else None
    if (base is None or base.shape != (2,) or not np.all(np.isfinite(base))
            or np.abs(base).max() > _MAX_LENGTH_M):
        raise InputError(f"must be 2 finite numbers within {_MAX_LENGTH_M:g} m", path,
                         field=f"{cg.name}.base")
    lengths = {}
    for key in ("l1", "l2"):
        value = scalar_attr(attrs, key, "number", cg.name, path)
        if value is None or not 0 < value <= _MAX_LENGTH_M:
            raise InputError(f"must be a link length in (0, {_MAX_LENGTH_M:g}] m, got {value!r}",
                             path, field=f"{cg.name}.{key}")
        lengths[key] = value
    elbow = scalar_attr(attrs, "elbow", "integer", cg.name, path)
    if elbow not in (1, -1):
        raise InputError(f"must be +1 or -1, got {elbow!r}", path, field=f"{cg.name}.elbow")
    return StoredChain(arrays=arrays, base=base, elbow=elbow, **lengths)


def _check_covariance(P: np.ndarray, where: str, path: Path) -> None:
    """``P`` (T+1, 2, 2): symmetric positive semi-definite covariances, not all zero."""
    if P.ndim != 3 or P.shape[1:] != (2, 2):
        return  # the shape is ChainModel's to report, with the others
    scale = float(np.abs(P).max()) if P.size else 0.0
    # a reach model's grip is planned without noise: its digits' covariances are
    # rounding noise around zero (1e-17 rad^2), of either sign
    tol = 1e-9 * scale + 1e-15
    if np.abs(P - np.swapaxes(P, 1, 2)).max() > tol:
        raise InputError("covariances are not symmetric: a corrupt repertoire (rebuild it)",
                         path, field=where)
    diagonal = np.diagonal(P, axis1=1, axis2=2)
    if diagonal.min() < -tol or np.linalg.eigvalsh(0.5 * (P + np.swapaxes(P, 1, 2))).min() < -tol:
        raise InputError("covariances are not positive semi-definite (a negative variance): "
                         "a corrupt repertoire (rebuild it)", path, field=where)


def _read_calibration(mg, path: Path) -> StoredCalibration | None:
    """The model's calibration group, or None in a file written before it existed."""
    import h5py

    if "calibration" not in mg:
        return None
    cal = mg["calibration"]
    if not isinstance(cal, h5py.Group):
        raise InputError("is not a group", path, field=cal.name)
    misfit = np.asarray(read_dataset(cal, "misfit", "number", 1, path), dtype=float)
    if np.isinf(misfit).any() or (misfit[np.isfinite(misfit)] < 0).any():
        raise InputError("misfits must be non-negative numbers", path,
                         field=f"{cal.name}/misfit")
    attrs = decode_attrs(cal.attrs, cal.name, path)
    period = scalar_attr(attrs, "frame_period", "number", cal.name, path)
    if period is None or not 1 / MAX_FPS <= period <= 1:
        raise InputError(f"must be a frame period of {1 / MAX_FPS:g} to 1 s, got {period!r}",
                         path, field=f"{cal.name}.frame_period")
    params = _json_attr(attrs, "params", cal.name, path)
    if not isinstance(params, dict):
        raise InputError("must be a JSON object", path, field=f"{cal.name}.params")
    return StoredCalibration(misfit=misfit, frame_period=period, params=params)


def _json_attr(attrs: dict, key: str, where: str, path: Path):
    text = scalar_attr(attrs, key, "string", where, path)
    try:
        return json.loads(text)
    except (TypeError, ValueError, RecursionError):
        raise InputError("is not JSON", path, field=f"{where}.{key}") from None


def _read_model(name: str, mg, path: Path) -> StoredModel:
    import h5py

    if not isinstance(mg, h5py.Group):
        raise InputError("is not a group", path, field=f"/models/{name}")
    a = decode_attrs(mg.attrs, mg.name, path)
    for role in ROLES:
        if role not in mg or not isinstance(mg.get(role, getlink=True), h5py.HardLink):
            raise InputError("missing group", path, field=f"{mg.name}/{role}")
    dt = scalar_attr(a, "dt", "number", mg.name, path)
    if dt is None or not 0 < dt <= 1:
        raise InputError(f"must be a positive time step of at most 1 s, got {dt!r}", path,
                         field=f"{mg.name}.dt")
    substeps = scalar_attr(a, "substeps", "integer", mg.name, path)
    if substeps is None or not 1 <= substeps <= MAX_SUBSTEPS:
        raise InputError(f"must be a whole number of model steps per frame, 1 to "
                         f"{MAX_SUBSTEPS}, got {substeps!r}", path, field=f"{mg.name}.substeps")
    task = _json_attr(a, "task", mg.name, path)
    scene = _json_attr(a, "scene", mg.name, path)
    for key, value in (("task", task), ("scene", scene)):
        if not isinstance(value, dict):
            raise InputError("must be a JSON object", path, field=f"{mg.name}.{key}")
    chains = {role: _read_chain(mg[role], path) for role in ROLES}
    if not np.any(chains["arm"].arrays["P"]):
        raise InputError("every covariance of the transport is zero: a corrupt repertoire "
                         "(rebuild it)", path, field=f"{mg.name}/arm/P")
    return StoredModel(name=name, kind=scalar_attr(a, "kind", "string", mg.name, path),
                       task=task, scene=scene, substeps=substeps, dt=dt, chains=chains,
                       calibration=_read_calibration(mg, path))


def _read_file(f, path: Path) -> tuple[dict, list[StoredModel]]:
    root = decode_attrs(f.attrs, "/", path)
    check_schema(root, SCHEMA, SCHEMA_VERSION, "repertoire", path, "; rebuild it")
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

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
from perception.io.atomic import atomic_path

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
    import h5py

    path = Path(path)
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
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


def _read_chain(cg) -> StoredChain:
    arrays = {k: np.asarray(cg[k][()], dtype=float) for k in ARRAYS}
    return StoredChain(arrays=arrays, l1=float(cg.attrs["l1"]), l2=float(cg.attrs["l2"]),
                       base=np.asarray(cg.attrs["base"], dtype=float),
                       elbow=int(cg.attrs["elbow"]))


def _read_calibration(mg) -> StoredCalibration | None:
    if "calibration" not in mg:
        return None
    cal = mg["calibration"]
    return StoredCalibration(misfit=np.asarray(cal["misfit"][()], dtype=float),
                             frame_period=float(cal.attrs["frame_period"]),
                             params=json.loads(cal.attrs["params"]))


def _read_model(name: str, mg) -> StoredModel:
    return StoredModel(name=name, kind=str(mg.attrs["kind"]), task=json.loads(mg.attrs["task"]),
                       scene=json.loads(mg.attrs["scene"]), substeps=int(mg.attrs["substeps"]),
                       dt=float(mg.attrs["dt"]),
                       chains={role: _read_chain(mg[role]) for role in ROLES},
                       calibration=_read_calibration(mg))


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
    import h5py

    path = Path(path)
    if not path.is_file():
        raise InputError("repertoire file not found", path)
    try:
        with h5py.File(path, "r") as f:
            schema = f.attrs.get("schema")
            if schema != SCHEMA:
                raise InputError(f"not a hammer-mv repertoire (schema {schema!r}, "
                                 f"expected {SCHEMA!r})", path)
            version = int(f.attrs.get("schema_version", -1))
            if version != SCHEMA_VERSION:
                raise InputError(f"repertoire schema version {version} is not supported "
                                 f"(this is version {SCHEMA_VERSION}); rebuild it", path)
            config = json.loads(f.attrs.get("config", "{}"))
            groups = sorted(f["models"].items(), key=lambda kv: kv[1].attrs["order"])
            models = [_read_model(name, mg) for name, mg in groups]
    except InputError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise InputError(f"corrupt or unreadable repertoire: {exc}", path) from None
    if not models:
        raise InputError("repertoire holds no models", path)
    return config, models

"""The HAMMER-MV repertoire: an ordered set of stored inverse/forward model pairs.

Plans depend on the scene (distance to the object, its size, the hand's size,
the frame rate), so each stored model records the scene it was planned for
(:class:`~perception.recognition.models.SceneSpec`). A clip whose scene
matches uses the stored gains as they are; a clip whose scene differs gets
the same models re-planned for its scene (:meth:`Repertoire.for_scene`) —
from the clip's first frames only, never from later frames. A repertoire is
built once (:meth:`Repertoire.build`, :meth:`Repertoire.from_config`) and
stored in HDF5 (:mod:`perception.io.repertoire`).
"""

from __future__ import annotations

import dataclasses
import logging
import tomllib
from collections.abc import Iterable, Iterator
from pathlib import Path

from perception.errors import InputError
from perception.io.repertoire import (
    StoredCalibration,
    StoredChain,
    StoredModel,
    read_repertoire,
    write_repertoire,
)
from perception.recognition.calibration import calibrate
from perception.recognition.models import CHAIN_ARRAYS, ChainModel, ModelSpec, MotorModel, SceneSpec
from perception.recognition.planning import DEFAULT_DURATIONS, build_model, default_specs
from perception.recognition.verdict import Calibration, CalibrationParams

__all__ = ["Repertoire"]

log = logging.getLogger(__name__)


class Repertoire:
    """An ordered set of :class:`MotorModel` with HDF5 persistence.

    Parameters
    ----------
    models : iterable of MotorModel
        The models, in report order; names must be unique.
    config : dict, optional
        The configuration the repertoire was built from (stored in the file).

    Every model gets a familiarity calibration
    (:mod:`perception.recognition.calibration`) if it has none: once, here.
    """

    def __init__(self, models: Iterable[MotorModel], config: dict | None = None):
        self.models = list(models)
        names = [m.name for m in self.models]
        if len(set(names)) != len(names):
            raise ValueError(f"repertoire: duplicate model names in {names}")
        if not self.models:
            raise ValueError("repertoire: needs at least one model")
        bare = [m for m in self.models if m.calibration is None]
        if bare:
            log.info("calibrating %d model(s) on their own demonstrations", len(bare))
            done = dict(zip([m.name for m in bare], calibrate(bare)))
            self.models = [dataclasses.replace(m, calibration=done[m.name])
                           if m.name in done else m for m in self.models]
        self.config = config or {}
        self._replanned: dict[tuple, MotorModel] = {}

    def __iter__(self) -> Iterator[MotorModel]:
        return iter(self.models)

    def __len__(self) -> int:
        return len(self.models)

    @property
    def names(self) -> list[str]:
        """Model names in order."""
        return [m.name for m in self.models]

    @classmethod
    def build(cls, specs: Iterable[ModelSpec] | None = None,
              scene: SceneSpec | None = None) -> Repertoire:
        """Plan every model for a scene.

        Parameters
        ----------
        specs : iterable of ModelSpec, optional
            Models to plan (default: :func:`default_specs`).
        scene : SceneSpec, optional
            The scene (default: 0.25 m to a 0.10 m ball at 30 frames/s).
        """
        specs = default_specs() if specs is None else list(specs)
        scene = SceneSpec() if scene is None else scene
        config = {"scene": dataclasses.asdict(scene),
                  "models": [dataclasses.asdict(s) for s in specs]}
        return cls([build_model(s, scene) for s in specs], config)

    @classmethod
    def from_config(cls, path: str | Path) -> Repertoire:
        """Build from a TOML file with a ``[scene]`` table and ``[[model]]`` entries.

        Parameters
        ----------
        path : str or Path
            The configuration file.
        """
        path = Path(path)
        try:
            cfg = tomllib.loads(path.read_text())
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"cannot read repertoire config: {exc}", path) from None
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"not valid TOML: {exc}", path) from None
        try:
            scene = SceneSpec(**cfg.get("scene", {}))
            entries = cfg.get("model") or []
            if entries:
                specs = [ModelSpec(e["name"], e.get("kind", "grasp"),
                                   {k: v for k, v in e.items() if k not in ("name", "kind")})
                         for e in entries]
            else:
                specs = default_specs(cfg.get("durations", DEFAULT_DURATIONS))
            return cls.build(specs, scene)
        except (TypeError, KeyError) as exc:
            raise InputError(f"bad repertoire config: {exc}", path) from None
        except ValueError as exc:
            raise InputError(str(exc), path) from None

    def for_scene(self, scene: SceneSpec) -> list[MotorModel]:
        """The models, re-planned for ``scene`` where their stored scene differs.

        Parameters
        ----------
        scene : SceneSpec
            The scene of the clip being scored.
        """
        out = []
        grid = scene.quantized()
        for m in self.models:
            if m.scene.matches(scene):
                out.append(m)
                continue
            key = (m.name, grid)
            if key not in self._replanned:
                log.info("re-planning %s for distance %.3f m, object %.3f m, hand %.3f m, "
                         "%.1f frames/s", m.name, grid.distance, grid.object_size,
                         grid.tip_start, 1 / grid.frame_period)
                # familiarity transfers across scenes (docs/recognition.md)
                self._replanned[key] = dataclasses.replace(build_model(m.spec, grid),
                                                           calibration=m.calibration)
            out.append(self._replanned[key])
        return out

    # -- persistence -------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write the repertoire to HDF5 at ``path`` (atomically; docs/repertoire-format.md).

        Parameters
        ----------
        path : str or Path
            Output file.
        """
        return write_repertoire(path, self.config, [_stored(m) for m in self.models])

    @classmethod
    def load(cls, path: str | Path) -> Repertoire:
        """Read a repertoire written by :meth:`save`.

        Parameters
        ----------
        path : str or Path
            The HDF5 file.

        A file written before familiarity calibrations were stored is
        calibrated as it is loaded (the file is not changed).

        Raises
        ------
        InputError
            If the file is missing, not HDF5, of another schema or version, or corrupt.
        """
        config, stored = read_repertoire(path)
        try:
            return cls([_model(s) for s in stored], config)
        except (KeyError, ValueError, TypeError) as exc:
            raise InputError(f"corrupt or unreadable repertoire: {exc}", path) from None


def _stored(m: MotorModel) -> StoredModel:
    chains = {c.role: StoredChain(arrays={k: getattr(c, k) for k in CHAIN_ARRAYS}, l1=c.l1,
                                  l2=c.l2, base=c.base, elbow=c.elbow) for c in m.chains}
    cal = m.calibration
    stored_cal = None if cal is None else StoredCalibration(
        misfit=cal.misfit, frame_period=cal.frame_period, params=dataclasses.asdict(cal.params))
    return StoredModel(name=m.name, kind=m.kind, task=m.spec.task,
                       scene=dataclasses.asdict(m.scene), substeps=m.substeps, dt=m.dt,
                       chains=chains, calibration=stored_cal)


def _model(s: StoredModel) -> MotorModel:
    chains = {role: ChainModel(role=role, l1=c.l1, l2=c.l2, base=c.base, elbow=c.elbow,
                               **c.arrays) for role, c in s.chains.items()}
    try:
        spec = ModelSpec(s.name, s.kind, s.task)
    except ValueError as exc:
        raise ValueError(f"model '{s.name}': {exc}") from None
    cal = s.calibration
    calibration = None if cal is None else Calibration(
        cal.misfit, cal.frame_period, CalibrationParams(**cal.params))
    return MotorModel(spec=spec, scene=SceneSpec(**s.scene), substeps=s.substeps, dt=s.dt,
                      calibration=calibration, **chains)

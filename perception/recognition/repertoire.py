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
import functools
import hashlib
import json
import logging
import os
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path

from perception.boundary import expect
from perception.errors import InputError, PlanningError
from perception.io.atomic import owner_gone, owner_tag
from perception.io.repertoire import (
    StoredCalibration,
    StoredChain,
    StoredModel,
    read_repertoire,
    write_repertoire,
)
from perception.recognition.calibration import calibrate
from perception.recognition.models import CHAIN_ARRAYS, ChainModel, ModelSpec, MotorModel, SceneSpec
from perception.recognition.planning import DEFAULT_DURATIONS, build_models, default_specs
from perception.recognition.verdict import Calibration, CalibrationParams

__all__ = ["LazyRepertoire", "PlanCache", "Repertoire"]

log = logging.getLogger(__name__)


class Repertoire:
    """An ordered set of :class:`MotorModel` with HDF5 persistence.

    Parameters
    ----------
    models : iterable of MotorModel
        The models, in report order; names must be unique.
    config : dict, optional
        The configuration the repertoire was built from (stored in the file).

    :meth:`build` calibrates every model's familiarity
    (:mod:`perception.recognition.calibration`) and :meth:`save` stores it; a
    model without one (loaded from an older file, or of the :meth:`default`
    repertoire) is calibrated when a verdict first needs it (:meth:`calibrated`).
    """

    def __init__(self, models: Iterable[MotorModel], config: dict | None = None):
        self._models: list[MotorModel] | None = list(models)
        names = [m.name for m in self.models]
        if len(set(names)) != len(names):
            raise ValueError(f"repertoire: duplicate model names in {names}")
        if not self.models:
            raise ValueError("repertoire: needs at least one model")
        self.config = config or {}
        self._replanned: dict[tuple, MotorModel] = {}
        self._calibrations: dict[tuple, Calibration] = {}

    @classmethod
    def default(cls) -> Repertoire:
        """The default repertoire (:meth:`build` with no arguments), planned when needed.

        Its models are planned the first time they are asked for; a clip
        scored first (:meth:`for_scene`) gets them planned for its own scene
        directly, not for the default scene and then again for its own. The
        models a clip is scored against are those of ``build()`` either way.
        """
        return LazyRepertoire()

    @property
    def models(self) -> list[MotorModel]:
        """The models, planned for the repertoire's own scene."""
        return self._models

    def __iter__(self) -> Iterator[MotorModel]:
        return iter(self.models)

    def __len__(self) -> int:
        return len(self.models)

    def __repr__(self) -> str:
        # names only: asking for the models would plan a lazy repertoire's
        names = self.names
        shown = ", ".join(names[:4]) + (f", ... {names[-1]}" if len(names) > 4 else "")
        count = f"{len(names)} model" + ("s" if len(names) != 1 else "")
        return f"<{type(self).__name__}: {count} ({shown})>"

    @property
    def names(self) -> list[str]:
        """Model names in order."""
        return [m.name for m in self.models]

    def reference(self) -> tuple[SceneSpec, tuple[float, float]]:
        """Where the verdict judges a movement's shape (:mod:`perception.recognition.shape`).

        The scene most of the models were planned (and calibrated) for, and
        the shortest and longest movement time of the grasp models (of all
        models if none grasps), s.
        """
        scenes = [m.scene for m in self.models]
        scene = max(scenes, key=scenes.count)
        times = [m.duration for m in self.models if m.kind == "grasp"]
        times = times or [m.duration for m in self.models]
        return scene, (float(min(times)), float(max(times)))

    def wrist_offset(self) -> float:
        """Where the grasp models' wrists stop short of the object centre, m: their tasks'
        own ``wrist_offset`` (the most common; :class:`minvar.GraspTask`'s by default).
        The reference scale scales a transport about it (:mod:`perception.recognition.shape`)."""
        return _wrist_offset(m.spec for m in self.models)

    @classmethod
    def build(cls, specs: Iterable[ModelSpec] | None = None,
              scene: SceneSpec | None = None, *, task: dict | None = None) -> Repertoire:
        """Plan every model for a scene and calibrate its familiarity.

        Parameters
        ----------
        specs : iterable of ModelSpec, optional
            Models to plan (default: :func:`default_specs`).
        scene : SceneSpec, optional
            The scene (default: 0.25 m to a 0.10 m ball at 30 frames/s).
        task : dict, optional
            :class:`minvar.GraspTask` fields given to every model that does not set
            them itself, e.g. the thesis's model and weights ``{"r": 0.002,
            "w_v": 0.1, "w_f": 0.01, "form": "thesis"}`` (default: none, the
            models' own settings; docs/thesis.md).

        Raises
        ------
        PlanningError
            A model cannot be planned in ``scene`` (out of reach, too short).
        TypeError
            An argument of another type (``task='x'``), said on entry.
        """
        # each refused here, not as a TypeError from deep in the planner
        expect(scene, SceneSpec, "Repertoire.build(scene=)", optional=True)
        expect(task, Mapping, "Repertoire.build(task=)", optional=True,
               hint="GraspTask fields by name")
        if specs is not None:
            if isinstance(specs, (str, bytes, Mapping)) or not isinstance(specs, Iterable):
                raise TypeError(f"Repertoire.build(specs=): expected ModelSpec objects, got "
                                f"{type(specs).__name__} {specs!r:.40}")
            for spec in (specs := list(specs)):
                expect(spec, ModelSpec, "Repertoire.build(specs=[...])")
        specs = default_specs() if specs is None else list(specs)
        if task:
            specs = [ModelSpec(s.name, s.kind, {**task, **s.task}) for s in specs]
        scene = SceneSpec() if scene is None else scene
        config = {"scene": dataclasses.asdict(scene),
                  "models": [dataclasses.asdict(s) for s in specs]}
        return cls(_calibrated(build_models(specs, scene)), config)

    @classmethod
    def from_config(cls, path: str | Path) -> Repertoire:
        """Build from a TOML file with a ``[scene]`` table and ``[[model]]`` entries.

        Parameters
        ----------
        path : str or Path
            The configuration file.

        Raises
        ------
        InputError
            The file is unreadable or its tables, keys or values are wrong.
        PlanningError
            A model cannot be planned in the file's scene (named with the file).
        """
        from perception.io.config import check_keys, read_toml

        path = Path(path)
        cfg = read_toml(path, "repertoire config")
        try:
            check_keys(cfg, ("scene", "model", "durations"), "the top level")
            if not isinstance(cfg.get("scene", {}), dict):
                raise ValueError("[scene] must be a table")
            check_keys(cfg.get("scene", {}), [f.name for f in dataclasses.fields(SceneSpec)],
                       "[scene]")
            scene = SceneSpec(**cfg.get("scene", {}))
            entries = cfg.get("model") or []
            if entries:
                specs = [ModelSpec(e["name"], e.get("kind", "grasp"),
                                   {k: v for k, v in e.items() if k not in ("name", "kind")})
                         for e in entries]
            else:
                specs = default_specs(cfg.get("durations", DEFAULT_DURATIONS))
            names = [s.name for s in specs]
            if not names:
                raise ValueError("no models: give [[model]] entries or durations")
            if len(set(names)) != len(names):
                raise ValueError(f"duplicate model names in {names}")
        except (TypeError, KeyError) as exc:
            raise InputError(f"bad repertoire config: {exc}", path) from None
        except ValueError as exc:
            raise InputError(str(exc), path) from None
        try:
            return cls.build(specs, scene)
        except PlanningError as exc:  # a model the config's scene cannot hold
            raise PlanningError(exc.problem, path, field=exc.field) from None

    def for_scene(self, scene: SceneSpec, cache: PlanCache | None = None, *,
                  threads: int | None = None) -> list[MotorModel]:
        """The models, re-planned for ``scene`` where their stored scene differs.

        Parameters
        ----------
        scene : SceneSpec
            The scene of the clip being scored.
        cache : PlanCache, optional
            Plans shared with other processes (a batch's workers): models
            another process has re-planned for this scene are read, not planned.
        threads : int, optional
            Threads that plan (see :func:`~perception.recognition.planning.build_models`).
        """
        return self._for_scene(self.models, scene, cache, threads)

    def _for_scene(self, models: list[MotorModel], scene: SceneSpec,
                   cache: PlanCache | None, threads: int | None = None) -> list[MotorModel]:
        grid = scene.quantized()
        todo = [m for m in models
                if not m.scene.matches(scene) and (m.name, grid) not in self._replanned]
        if todo:
            def plan() -> list[MotorModel]:
                log.info("re-planning %d models for distance %.3f m, object %.3f m, hand "
                         "%.3f m, %.1f frames/s", len(todo), grid.distance, grid.object_size,
                         grid.tip_start, 1 / grid.frame_period)
                # a re-planned model keeps its source's calibration (it transfers
                # across scenes: docs/recognition.md)
                return _calibrated(build_models([m.spec for m in todo], grid, threads=threads),
                                   [getattr(m, "calibration", None) for m in todo],
                                   compute=False)

            planned = plan() if cache is None else cache.get(grid, [m.spec for m in todo], plan)
            for m, new in zip(todo, planned):
                self._replanned[(m.name, grid)] = new
        return [self._known(m if m.scene.matches(scene) else self._replanned[(m.name, grid)])
                for m in models]

    def _known(self, m: MotorModel) -> MotorModel:
        """``m`` with the calibration :meth:`calibrated` made for it, if any."""
        cal = None if m.calibration is not None else self._calibrations.get((m.name, m.scene))
        return m if cal is None else dataclasses.replace(m, calibration=cal)

    def calibrated(self, models: list[MotorModel], index: int) -> list[MotorModel]:
        """``models`` with model ``index`` calibrated: once per model and scene, then kept.

        A repertoire built or loaded carries every model's calibration, and
        models re-planned from it keep theirs; the default repertoire planned
        for a clip's scene (:meth:`default`) calibrates only the models the
        verdict asks for, here.

        Parameters
        ----------
        models : list of MotorModel
            Models from :meth:`for_scene`.
        index : int
            The one to calibrate.
        """
        m = models[index]
        if m.calibration is not None:
            return models
        key = (m.name, m.scene)
        if key not in self._calibrations:
            log.info("calibrating %s on its own demonstrations", m.name)
            self._calibrations[key] = calibrate([m])[0]
        done = dataclasses.replace(m, calibration=self._calibrations[key])
        return [*models[:index], done, *models[index + 1:]]

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

        A file written before familiarity calibrations were stored loads as
        it is; its models are calibrated when a verdict first needs them
        (:meth:`calibrated`; the file is not changed).

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


#: The default models' verdict calibrations at the default scene
#: (``tools/calibrate_default.py`` makes it).
DEFAULT_CALIBRATION = Path(__file__).with_name("default_calibration.json")


@functools.cache
def _shipped_calibrations() -> dict[str, Calibration]:
    """The default models' calibrations, if the shipped file is present and readable.

    Without it, the default models are calibrated when a verdict needs them
    (the same numbers, computed: about half a second a model and scene).
    """
    try:
        data = json.loads(DEFAULT_CALIBRATION.read_text())
        params = CalibrationParams(**data["params"])
        return {name: Calibration(misfit, float(data["frame_period"]), params)
                for name, misfit in data["models"].items()}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        log.warning("no shipped calibration of the default models (%s): calibrating "
                    "them when needed", exc)
        return {}


def _wrist_offset(specs: Iterable[ModelSpec]) -> float:
    """The most common ``wrist_offset`` of the grasp specs' tasks (of all, if none grasps)."""
    from minvar.grasp_task import GraspTask

    specs = list(specs)
    grasp = [s for s in specs if s.kind == "grasp"] or specs
    offsets = [float(s.task.get("wrist_offset", GraspTask.wrist_offset)) for s in grasp]
    return max(offsets, key=offsets.count) if offsets else float(GraspTask.wrist_offset)


class LazyRepertoire(Repertoire):
    """The default repertoire (:meth:`Repertoire.default`), planned on first use.

    Its models are planned when first asked for (:attr:`models`), or directly
    for a clip's scene (:meth:`for_scene`); their verdict is calibrated by the
    shipped calibration, and a model without one is calibrated in an explicit
    step, when a verdict asks for it (:meth:`~Repertoire.calibrated`).
    """

    def __init__(self):
        self._specs = default_specs()
        self._scene = SceneSpec()
        self._models: list[MotorModel] | None = None
        self.config = {"scene": dataclasses.asdict(self._scene),
                       "models": [dataclasses.asdict(s) for s in self._specs]}
        self._replanned = {}
        self._calibrations = {}

    @property
    def models(self) -> list[MotorModel]:
        return self._planned()

    def _planned(self, threads: int | None = None) -> list[MotorModel]:
        if self._models is None:
            shipped = _shipped_calibrations()
            self._models = _calibrated(build_models(self._specs, self._scene, threads=threads),
                                       [shipped.get(s.name) for s in self._specs],
                                       compute=False)  # any other calibrated when asked
        return self._models

    @property
    def names(self) -> list[str]:
        return [s.name for s in self._specs]

    def reference(self) -> tuple[SceneSpec, tuple[float, float]]:
        # without planning the default scene's models
        times = [float(s.task["duration"]) for s in self._specs if s.kind == "grasp"]
        return self._scene, (min(times), max(times))

    def wrist_offset(self) -> float:
        return _wrist_offset(self._specs)

    def __len__(self) -> int:
        return len(self._specs)

    def for_scene(self, scene: SceneSpec, cache: PlanCache | None = None, *,
                  threads: int | None = None) -> list[MotorModel]:
        if self._models is None and not self._scene.matches(scene):
            # the stored (default-scene) plans would all be re-planned: plan the
            # clip's scene only, as the placeholder models below stand for
            stand_ins = [_Unplanned(s, self._scene) for s in self._specs]
            return self._for_scene(stand_ins, scene, cache, threads)
        return self._for_scene(self._planned(threads), scene, cache, threads)


@dataclasses.dataclass(frozen=True)
class _Unplanned:
    """A default model not planned yet: what :meth:`Repertoire.for_scene` reads of it."""

    spec: ModelSpec
    scene: SceneSpec

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def calibration(self) -> Calibration | None:
        """The shipped calibration, which the model planned for a clip's scene keeps."""
        return _shipped_calibrations().get(self.spec.name)


class PlanCache:
    """Models re-planned for a scene, on disk, shared by the processes of a batch.

    One file per scene and set of models (``<key>.h5`` in ``folder``), keyed by
    everything that changes a plan: the scene on the 5 mm grid and its frame
    period, each model's specification, and the software version. Files are
    written under a temporary name and renamed, so a reader never sees half a
    file. The first process to need a scene takes a lock file and plans it;
    another that needs it meanwhile waits for the file (up to ``wait_s``, or
    until the lock is older than ``stale_s`` — its owner died), then plans it
    itself rather than wait longer. Unreadable files are planned again.

    Parameters
    ----------
    folder : str or os.PathLike
        Where the plans are kept (e.g. ``REPORT_DIR/.plans``).
    wait_s : float
        Longest wait for a scene another process is planning.
    stale_s : float
        Age after which a lock without its plan is ignored.
    """

    def __init__(self, folder: str | os.PathLike, *, wait_s: float = 60.0,
                 stale_s: float = 120.0):
        self.folder = Path(folder)
        self.wait_s = wait_s
        self.stale_s = stale_s
        self.planned = 0  # scenes this process planned (the rest it read)

    def key(self, scene: SceneSpec, specs: list[ModelSpec]) -> str:
        """The file key of ``specs`` planned for ``scene`` (already on the grid)."""
        from perception.provenance import code_digest

        payload = json.dumps({"scene": dataclasses.asdict(scene),
                              "models": [dataclasses.asdict(s) for s in specs],
                              "code": code_digest()}, sort_keys=True, default=str)
        return hashlib.sha256(payload.encode()).hexdigest()[:24]

    def get(self, scene: SceneSpec, specs: list[ModelSpec],
            plan: Callable[[], list[MotorModel]]) -> list[MotorModel]:
        """The models of ``specs`` for ``scene``: read if planned, else ``plan()`` and stored."""
        key = self.key(scene, specs)
        path = self.folder / f"{key}.h5"
        lock = self.folder / f"{key}.lock"
        self.folder.mkdir(parents=True, exist_ok=True)
        deadline = time.monotonic() + self.wait_s
        while True:
            models = self._read(path, specs)
            if models is not None:
                return models
            try:
                fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            except FileExistsError:
                if self._abandoned(lock):
                    continue
                if time.monotonic() < deadline and not self._stale(lock):
                    time.sleep(0.05)
                    continue
                return plan()  # the owner is slow or gone: plan here, leave its lock
            os.write(fd, owner_tag().encode())  # so a killed owner's lock is known stale
            os.close(fd)
            try:
                models = self._read(path, specs)  # written between our read and our lock
                if models is None:
                    models = plan()
                    self.planned += 1
                    Repertoire(models, {"plan_cache": key}).save(path)
                return models
            finally:
                lock.unlink(missing_ok=True)

    def _stale(self, lock: Path) -> bool:
        try:
            return time.time() - lock.stat().st_mtime > self.stale_s
        except FileNotFoundError:
            return False

    @staticmethod
    def _abandoned(lock: Path) -> bool:
        """Remove ``lock`` if the process that took it has ended (killed mid-plan)."""
        try:
            gone = owner_gone(lock.read_text(errors="replace"))
        except OSError:
            return False
        if gone:
            lock.unlink(missing_ok=True)
        return gone

    @staticmethod
    def _read(path: Path, specs: list[ModelSpec]) -> list[MotorModel] | None:
        if not path.is_file():
            return None
        try:
            models = Repertoire.load(path).models
        except (InputError, OSError):
            return None
        if [m.name for m in models] != [s.name for s in specs]:
            return None  # the key says the rest
        return models


def _calibrated(models: list[MotorModel], sources: list[Calibration | None] | None = None,
                *, compute: bool = True) -> list[MotorModel]:
    """``models`` with a calibration each: their own, the one in ``sources``, else (with
    ``compute``) a new one."""
    sources = sources or [None] * len(models)
    given = [m.calibration or src for m, src in zip(models, sources)]
    bare = [m for m, cal in zip(models, given) if cal is None]
    if bare and not compute:
        return [m if cal is None else dataclasses.replace(m, calibration=cal)
                for m, cal in zip(models, given)]
    if bare:
        log.info("calibrating %d model(s) on their own demonstrations", len(bare))
        new = iter(calibrate(bare))
        given = [cal if cal is not None else next(new) for cal in given]
    return [m if m.calibration is cal else dataclasses.replace(m, calibration=cal)
            for m, cal in zip(models, given)]


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
    # files written before these variations existed were made without them
    made = {"transport_skew": 0.0, "noise_spread": 0.0, **(cal.params if cal else {})}
    calibration = None if cal is None else Calibration(
        cal.misfit, cal.frame_period, CalibrationParams(**made))
    return MotorModel(spec=spec, scene=SceneSpec(**s.scene), substeps=s.substeps, dt=s.dt,
                      calibration=calibration, **chains)

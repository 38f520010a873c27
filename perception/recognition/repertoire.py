"""The HAMMER-MV repertoire: stored inverse/forward model pairs.

An inverse model is the gains ``(L_t, K_t)`` of one movement plan; its forward
model is ``(A, B)`` (thesis 5.2.1). A reach-to-grasp model is a hierarchy:
grasp -> transport (the arm chain, moving the wrist) + grip (the finger and
thumb chains). Each chain is a leaf with its own joint-space plan.

Plans depend on the scene (distance to the object, its size, the frame
rate), so each stored model records the scene it was planned for. Scoring a
clip whose scene matches uses the stored gains as they are; a clip whose
scene differs gets the same model re-planned for its scene (see
:meth:`Repertoire.for_scene`) — never parameters taken from later frames of
the clip.

File layout (HDF5, schema ``hammer-mv/repertoire``)::

    /                attrs: schema, schema_version, software_version, config (JSON)
    /models/<name>   attrs: kind, task (JSON of GraspTask fields), substeps, dt
    /models/<name>/<arm|finger|thumb>
                     A, B, H, K, L, P (T+1, 2, 2), x0; attrs: l1, l2, base, elbow
"""

from __future__ import annotations

import dataclasses
import json
import logging
import re
import tomllib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from minvar import GraspTask, PointMassPlant, plan_grasp
from minvar.lqg import estimation_error_covariance

from perception import __version__
from perception.io.atomic import atomic_path
from perception.errors import InputError

__all__ = [
    "ChainModel",
    "MotorModel",
    "Repertoire",
    "SceneSpec",
    "ModelSpec",
    "DEFAULT_DURATIONS",
    "model_substeps",
    "build_model",
]

log = logging.getLogger(__name__)

SCHEMA = "hammer-mv/repertoire"
SCHEMA_VERSION = 1
ROLES = ("arm", "finger", "thumb")
KINDS = ("grasp", "reach")
#: Movement-time variants of the default repertoire, s.
DEFAULT_DURATIONS = (0.8, 0.9, 1.0, 1.1, 1.2)
#: Model time step the plans aim for, s (the thesis's 10 ms).
TARGET_DT = 0.01
#: GraspTask fields a repertoire entry may not set: the scene and the kind supply them.
SCENE_FIELDS = frozenset({"object_size", "distance", "tip_start", "reach_only", "plant"})
GRIP_VIA_KEYS = frozenset({"half_aperture", "height", "fraction"})


def model_substeps(frame_period: float) -> int:
    """Model steps per video frame: the frame period split into steps near 10 ms.

    Parameters
    ----------
    frame_period : float
        Time between frames, s.
    """
    return max(1, int(round(frame_period / TARGET_DT)))


@dataclass(frozen=True, eq=False)
class ChainModel:
    """Inverse and forward model of one two-link chain (a leaf of the hierarchy).

    Attributes
    ----------
    role : str
        ``arm``, ``finger`` or ``thumb``.
    l1, l2 : float
        Link lengths, m.
    base : (2,) array
        First joint: in the model frame for the arm, relative to the wrist for digits.
    elbow : int
        Branch (+1 or -1) used to turn observed positions into joint angles.
    A : (n, n) array
        Forward model dynamics.
    B : (n, m) array
        Forward model control input.
    H : (k, n) array
        Observation matrix of the plan (rows 0-1 observe the joint angles).
    K : (T, n, k) array
        Kalman filter gains (inverse model).
    L : (T, m, n) array
        Control gains (inverse model).
    P : (T+1, 2, 2) array
        The plan's own covariance of the joint-angle prediction error, rad^2.
    x0 : (n,) array
        Planned initial state (start angles, rest, the constant 1s).
    """

    role: str
    l1: float
    l2: float
    base: np.ndarray
    elbow: int
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    H: np.ndarray = field(repr=False)
    K: np.ndarray = field(repr=False)
    L: np.ndarray = field(repr=False)
    P: np.ndarray = field(repr=False)
    x0: np.ndarray = field(repr=False)

    @property
    def horizon(self) -> int:
        """Number of planned steps T."""
        return self.L.shape[0]


@dataclass(frozen=True)
class SceneSpec:
    """The scene a model is planned for.

    Parameters
    ----------
    distance : float
        Wrist start to object centre, m.
    object_size : float
        Object diameter, m.
    frame_period : float
        Video frame period, s (the plan steps a sub-multiple of it).
    tip_start : float
        How far ahead of the wrist the touching digit tips rest, m: the
        demonstrator's hand size, from the first frames.
    """

    distance: float = 0.25
    object_size: float = 0.10
    frame_period: float = 1 / 30
    tip_start: float = 0.06

    def __post_init__(self):
        for name in ("distance", "object_size", "frame_period", "tip_start"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and np.isfinite(value) and value > 0):
                raise ValueError(f"scene {name}: expected a positive number, got {value!r}")

    def matches(self, other: SceneSpec, *, tol_m: float = 0.01, tol_rel_dt: float = 0.02) -> bool:
        """Whether plans for ``other`` may be reused here (within ``tol_m``, ``tol_rel_dt``)."""
        return (
            abs(self.distance - other.distance) <= tol_m
            and abs(self.object_size - other.object_size) <= tol_m / 2
            and abs(self.tip_start - other.tip_start) <= tol_m / 2
            and abs(self.frame_period - other.frame_period) <= tol_rel_dt * self.frame_period
        )

    def quantized(self) -> SceneSpec:
        """This scene rounded to a 5 mm grid (frame period kept), so that
        re-planned models are shared by clips of nearly the same scene."""
        def q(v):
            return max(0.005, round(v / 0.005) * 0.005)

        return SceneSpec(distance=q(self.distance), object_size=q(self.object_size),
                         frame_period=self.frame_period, tip_start=q(self.tip_start))


@dataclass(frozen=True)
class ModelSpec:
    """One entry of a repertoire: a kind of movement and its task parameters.

    Parameters
    ----------
    name : str
        Unique model name.
    kind : str
        ``grasp`` (transport + grip) or ``reach`` (transport, grip kept closed).
    task : dict
        :class:`minvar.GraspTask` fields other than the scene (e.g. ``duration``,
        ``viapoint_offset``, ``grip_via``); the scene supplies distance and size.
    """

    name: str
    kind: str
    task: dict = field(default_factory=dict)

    def __post_init__(self):
        if not (isinstance(self.name, str) and re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._+-]*",
                                                             self.name)):
            raise ValueError(f"model name {self.name!r}: use letters, digits and . _ + - only")
        if self.kind not in KINDS:
            raise ValueError(f"model '{self.name}': kind must be one of {KINDS}, got {self.kind!r}")
        known = {f.name for f in dataclasses.fields(GraspTask)} - SCENE_FIELDS
        bad = set(self.task) - known
        if bad:
            raise ValueError(f"model '{self.name}': unknown task fields {sorted(bad)} "
                             f"(the scene sets {sorted(SCENE_FIELDS)}; a model may set "
                             f"{sorted(known)})")
        vias = self.task.get("grip_via")
        if vias is not None:
            if not isinstance(vias, list | tuple):
                raise ValueError(f"model '{self.name}': grip_via must be a list of "
                                 "{half_aperture, height, fraction} tables")
            for i, v in enumerate(vias):
                if not (isinstance(v, dict) and set(v) == GRIP_VIA_KEYS):
                    raise ValueError(f"model '{self.name}': grip_via[{i}] must have exactly "
                                     f"the keys {sorted(GRIP_VIA_KEYS)}, got {v!r}")
        self.grasp_task(SceneSpec())  # every other check of the task, before any planning

    def grasp_task(self, scene: SceneSpec) -> GraspTask:
        """The :class:`minvar.GraspTask` of this model in ``scene``."""
        k = model_substeps(scene.frame_period)
        plant = PointMassPlant(dt=scene.frame_period / k)
        params = dict(self.task)
        if "grip_via" in params and params["grip_via"] is not None:
            from minvar import GripVia

            params["grip_via"] = tuple(GripVia(**g) if isinstance(g, dict) else g
                                       for g in params["grip_via"])
        return GraspTask(object_size=scene.object_size, distance=scene.distance,
                         tip_start=scene.tip_start, reach_only=self.kind == "reach",
                         plant=plant, **params)


@dataclass(frozen=True, eq=False)
class MotorModel:
    """A reach-to-grasp (or reach-only) model: the hierarchy's root.

    Attributes
    ----------
    spec : ModelSpec
        Name, kind and task parameters.
    scene : SceneSpec
        The scene the gains were planned for.
    substeps : int
        Model steps per video frame.
    dt : float
        Model time step, s.
    arm, finger, thumb : ChainModel
        The leaves: transport (arm) and grip (finger, thumb).
    """

    spec: ModelSpec
    scene: SceneSpec
    substeps: int
    dt: float
    arm: ChainModel = field(repr=False)
    finger: ChainModel = field(repr=False)
    thumb: ChainModel = field(repr=False)

    @property
    def name(self) -> str:
        """Model name."""
        return self.spec.name

    @property
    def kind(self) -> str:
        """``grasp`` or ``reach``."""
        return self.spec.kind

    @property
    def duration(self) -> float:
        """Planned movement time, s."""
        return self.arm.horizon * self.dt

    @property
    def chains(self) -> tuple[ChainModel, ChainModel, ChainModel]:
        """The leaves (arm, finger, thumb)."""
        return self.arm, self.finger, self.thumb


def _check_chain_arrays(where: str, a: dict) -> None:
    """Raise ValueError unless a stored chain's arrays fit together."""
    n = a["A"].shape[0] if a["A"].ndim == 2 else -1
    T = a["L"].shape[0] if a["L"].ndim == 3 else -1
    m = a["B"].shape[1] if a["B"].ndim == 2 else -1
    k = a["H"].shape[0] if a["H"].ndim == 2 else -1
    want = {"A": (n, n), "B": (n, m), "H": (k, n), "K": (T, n, k), "L": (T, m, n),
            "P": (T + 1, 2, 2), "x0": (n,)}
    for key, shape in want.items():
        if a[key].shape != shape or min(shape) < 1:
            raise ValueError(f"{where}: {key} has shape {a[key].shape}, expected {shape}")
        if not np.all(np.isfinite(a[key])):
            raise ValueError(f"{where}: {key} has non-finite values")


def _chain_model(role: str, chain_plan) -> ChainModel:
    problem, solution = chain_plan.problem, chain_plan.solution
    P = estimation_error_covariance(problem, solution.K, solution.L)[:, :2, :2]
    q_ref = np.asarray(chain_plan.q_goal, dtype=float)
    chain = chain_plan.chain
    return ChainModel(
        role=role,
        l1=float(chain.l1),
        l2=float(chain.l2),
        base=np.asarray(chain.base, dtype=float),
        elbow=1 if q_ref[1] >= 0 else -1,
        A=np.asarray(problem.A),
        B=np.asarray(problem.B),
        H=np.asarray(problem.H),
        K=np.asarray(solution.K),
        L=np.asarray(solution.L),
        P=P,
        x0=np.asarray(problem.X1),
    )


def build_model(spec: ModelSpec, scene: SceneSpec) -> MotorModel:
    """Plan ``spec`` in ``scene`` with the minimum variance grasp model.

    Parameters
    ----------
    spec : ModelSpec
        The movement.
    scene : SceneSpec
        Distance, object size and frame period.
    """
    task = spec.grasp_task(scene)
    plan = plan_grasp(task)
    return MotorModel(
        spec=spec,
        scene=scene,
        substeps=model_substeps(scene.frame_period),
        dt=task.plant.dt,
        arm=_chain_model("arm", plan.arm),
        finger=_chain_model("finger", plan.finger),
        thumb=_chain_model("thumb", plan.thumb),
    )


def default_specs(durations: Iterable[float] = DEFAULT_DURATIONS) -> list[ModelSpec]:
    """Grasp and reach-only models at each movement time.

    Parameters
    ----------
    durations : iterable of float
        Movement times, s.
    """
    specs = []
    for kind in KINDS:
        for d in durations:
            specs.append(ModelSpec(f"{kind}-{d:.1f}s", kind, {"duration": float(d)}))
    return specs


class Repertoire:
    """An ordered set of :class:`MotorModel` with HDF5 persistence.

    Parameters
    ----------
    models : iterable of MotorModel
        The models, in report order; names must be unique.
    config : dict, optional
        The configuration the repertoire was built from (stored in the file).
    """

    def __init__(self, models: Iterable[MotorModel], config: dict | None = None):
        self.models = list(models)
        names = [m.name for m in self.models]
        if len(set(names)) != len(names):
            raise ValueError(f"repertoire: duplicate model names in {names}")
        if not self.models:
            raise ValueError("repertoire: needs at least one model")
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
                self._replanned[key] = build_model(m.spec, grid)
            out.append(self._replanned[key])
        return out

    # -- persistence -------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write the repertoire to HDF5 at ``path`` (atomically)."""
        import h5py

        path = Path(path)
        with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
            f.attrs["schema"] = SCHEMA
            f.attrs["schema_version"] = SCHEMA_VERSION
            f.attrs["software_version"] = __version__
            f.attrs["config"] = json.dumps(self.config)
            g = f.create_group("models")
            for i, m in enumerate(self.models):
                mg = g.create_group(m.name)
                mg.attrs["order"] = i
                mg.attrs["kind"] = m.kind
                mg.attrs["task"] = json.dumps(m.spec.task)
                mg.attrs["scene"] = json.dumps(dataclasses.asdict(m.scene))
                mg.attrs["substeps"] = m.substeps
                mg.attrs["dt"] = m.dt
                for c in m.chains:
                    cg = mg.create_group(c.role)
                    for key in ("A", "B", "H", "K", "L", "P", "x0"):
                        cg.create_dataset(key, data=getattr(c, key),
                                          compression="gzip" if key in ("K", "L") else None)
                    cg.attrs.update(l1=c.l1, l2=c.l2, base=c.base, elbow=c.elbow)
        return path

    @classmethod
    def load(cls, path: str | Path) -> Repertoire:
        """Read a repertoire written by :meth:`save`.

        Parameters
        ----------
        path : str or Path
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
                models = []
                for name, mg in groups:
                    spec = ModelSpec(name, str(mg.attrs["kind"]), json.loads(mg.attrs["task"]))
                    chains = {}
                    for role in ROLES:
                        cg = mg[role]
                        arrays = {k: np.asarray(cg[k][()], dtype=float)
                                  for k in ("A", "B", "H", "K", "L", "P", "x0")}
                        _check_chain_arrays(f"model '{name}' {role}", arrays)
                        chains[role] = ChainModel(
                            role=role, l1=float(cg.attrs["l1"]), l2=float(cg.attrs["l2"]),
                            base=np.asarray(cg.attrs["base"], dtype=float),
                            elbow=int(cg.attrs["elbow"]), **arrays,
                        )
                    models.append(MotorModel(
                        spec=spec, scene=SceneSpec(**json.loads(mg.attrs["scene"])),
                        substeps=int(mg.attrs["substeps"]), dt=float(mg.attrs["dt"]), **chains))
        except InputError:
            raise
        except (OSError, KeyError, ValueError, TypeError) as exc:
            raise InputError(f"corrupt or unreadable repertoire: {exc}", path) from None
        if not models:
            raise InputError("repertoire holds no models", path)
        return cls(models, config)


"""HAMMER-MV models: the scene they are planned for, what they are, what they hold.

An inverse model is the gains ``(L_t, K_t)`` of one movement plan; its forward
model is ``(A, B)`` (thesis 5.2.1). A reach-to-grasp model (:class:`MotorModel`)
is a hierarchy: grasp -> transport (the arm chain, moving the wrist) + grip
(the finger and thumb chains). Each chain is a leaf (:class:`ChainModel`)
with its own joint-space plan. A :class:`ModelSpec` names a movement; a
:class:`SceneSpec` is what a plan depends on in the clip (distance to the
object, its size, the hand's size, the frame rate). Planning is in
:mod:`perception.recognition.planning`.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import AfterValidator

from minvar import GraspTask, GripVia, PointMassPlant, shoulder_for
from perception.errors import InputError, PlanningError
from perception.geometry import DEFAULT_OBJECT_DIAMETER, DEFAULT_TIP_START
from perception.validation import Positive, declared

if TYPE_CHECKING:
    from perception.observation import Observation
    from perception.recognition.verdict import Calibration

__all__ = [
    "ChainModel",
    "KINDS",
    "ModelSpec",
    "MotorModel",
    "ROLES",
    "SCENE_GRID",
    "SceneSpec",
    "model_substeps",
]

ROLES = ("arm", "finger", "thumb")
KINDS = ("grasp", "reach")
#: Model time step the plans aim for, s (the thesis's 10 ms).
TARGET_DT = 0.01
#: Grid of re-planned scenes, m: clips within a few mm share their plans.
SCENE_GRID = 0.005
#: GraspTask fields a repertoire entry may not set: the scene and the kind supply them.
SCENE_FIELDS = frozenset({"object_size", "distance", "tip_start", "reach_only", "plant"})
GRIP_VIA_KEYS = frozenset({"half_aperture", "height", "fraction"})
#: The arrays of a :class:`ChainModel`, as stored in a repertoire file.
CHAIN_ARRAYS = ("A", "B", "H", "K", "L", "P", "x0")


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

    def __post_init__(self) -> None:
        if self.role not in ROLES:
            raise ValueError(f"chain role: expected one of {ROLES}, got {self.role!r}")
        for key in CHAIN_ARRAYS:
            object.__setattr__(self, key, np.asarray(getattr(self, key), dtype=float))
        object.__setattr__(self, "base", np.asarray(self.base, dtype=float))
        a = {key: getattr(self, key) for key in CHAIN_ARRAYS}
        n = a["A"].shape[0] if a["A"].ndim == 2 else -1
        T = a["L"].shape[0] if a["L"].ndim == 3 else -1
        m = a["B"].shape[1] if a["B"].ndim == 2 else -1
        k = a["H"].shape[0] if a["H"].ndim == 2 else -1
        want = {"A": (n, n), "B": (n, m), "H": (k, n), "K": (T, n, k), "L": (T, m, n),
                "P": (T + 1, 2, 2), "x0": (n,)}
        for key, shape in want.items():
            if a[key].shape != shape or min(shape) < 1:
                raise ValueError(f"{self.role}: {key} has shape {a[key].shape}, "
                                 f"expected {shape}")
            if not np.all(np.isfinite(a[key])):
                raise ValueError(f"{self.role}: {key} has non-finite values")
        if (self.base.shape != (2,) or not (self.l1 > 0 and self.l2 > 0)
                or self.elbow not in (1, -1)):
            raise ValueError(f"{self.role}: expected positive link lengths, a (2,) base and "
                             f"elbow +1 or -1, got {self.l1}, {self.l2}, {self.base}, "
                             f"{self.elbow}")

    @property
    def horizon(self) -> int:
        """Number of planned steps T."""
        return self.L.shape[0]


@declared(error=PlanningError)
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

    distance: Positive = 0.25
    object_size: Positive = DEFAULT_OBJECT_DIAMETER
    frame_period: Positive = 1 / 30
    tip_start: Positive = DEFAULT_TIP_START

    @classmethod
    def of(cls, observation: Observation) -> SceneSpec:
        """The scene of a demonstration, from its first frames only.

        Parameters
        ----------
        observation : Observation
            The demonstration (start distance, object size, frame period and
            where the touching digit tips rest ahead of the wrist).
        """
        return cls(distance=observation.start_distance,
                   object_size=observation.object_diameter,
                   frame_period=observation.dt,
                   tip_start=float(observation.hand_offset[1]))

    def matches(self, other: SceneSpec, *, tol_m: float = 0.01, tol_rel_dt: float = 0.02) -> bool:
        """Whether plans for ``other`` may be reused here (within ``tol_m``, ``tol_rel_dt``)."""
        return (
            abs(self.distance - other.distance) <= tol_m
            and abs(self.object_size - other.object_size) <= tol_m / 2
            and abs(self.tip_start - other.tip_start) <= tol_m / 2
            and abs(self.frame_period - other.frame_period) <= tol_rel_dt * self.frame_period
        )

    def quantized(self) -> SceneSpec:
        """This scene rounded to the :data:`SCENE_GRID` (frame period kept), so
        that re-planned models are shared by clips of nearly the same scene."""
        def q(v):
            return max(SCENE_GRID, round(v / SCENE_GRID) * SCENE_GRID)

        return SceneSpec(distance=q(self.distance), object_size=q(self.object_size),
                         frame_period=self.frame_period, tip_start=q(self.tip_start))


def _model_name(name: str) -> str:
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._+-]*", name):
        raise InputError(f"model name {name!r}: use letters, digits and . _ + - only")
    return name


@declared
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

    name: Annotated[str, AfterValidator(_model_name)]
    kind: Literal[KINDS]
    task: dict = field(default_factory=dict)

    def __post_init__(self):
        known = {f.name for f in dataclasses.fields(GraspTask)} - SCENE_FIELDS
        bad = sorted(set(self.task) - known)
        if bad:
            from perception.io.config import suggest

            raise ValueError(f"model '{self.name}': unknown task field {bad[0]!r}"
                             f"{suggest(bad[0], known)} (the scene sets "
                             f"{sorted(SCENE_FIELDS)}; a model may set {sorted(known)})")
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
            params["grip_via"] = tuple(GripVia(**g) if isinstance(g, dict) else g
                                       for g in params["grip_via"])
        params.setdefault("shoulder_offset", shoulder_for(scene.distance, **{
            k: params[k] for k in ("wrist_offset", "arm_links") if k in params}))
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
    calibration : Calibration, optional
        How well the model's own demonstrations fit it
        (:mod:`perception.recognition.verdict`); a
        :class:`~perception.recognition.repertoire.Repertoire` gives every
        model one. None: no familiarity and no verdict.
    """

    spec: ModelSpec
    scene: SceneSpec
    substeps: int
    dt: float
    arm: ChainModel = field(repr=False)
    finger: ChainModel = field(repr=False)
    thumb: ChainModel = field(repr=False)
    calibration: Calibration | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if not (isinstance(self.substeps, int | np.integer) and not isinstance(self.substeps, bool)
                and self.substeps >= 1):
            raise ValueError(f"model '{self.spec.name}': substeps: expected a whole number of "
                             f"model steps per frame >= 1, got {self.substeps!r}")
        if not (isinstance(self.dt, int | float | np.floating) and np.isfinite(self.dt)
                and self.dt > 0):
            raise ValueError(f"model '{self.spec.name}': dt: expected a positive time step, "
                             f"got {self.dt!r}")

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

"""Generated grasps as a lab's 3D recordings of the tasks labs run, with their own truth.

Each generator draws a grasp in the model's world frame (2D, metres, object
at the origin): ``independent`` from published human kinematics without the
minimum variance model (:mod:`perception.synthetic.independent`, the one
never tuned on), ``minvar`` from the model itself
(:mod:`perception.synthetic.stimuli`). The grasp is then placed on a table
in a lab's 3D frame (mm, z up, the approach turned by a drawn angle, a few
centimetres of lift, 0.1 mm of marker noise) and embedded in a task:

* :func:`single_reach` — rest, the reach to grasp, the hand held on the object;
* :func:`pick_and_place` — then the object carried 15 cm sideways, released,
  and the hand's return (an object marker moves with the hand);
* :func:`session` — many grasps back to back, each followed by the hand's
  return with a closing grip, with rests between (thumb, index and one hand
  marker only, as a long session is often recorded).

Every recording carries where its reaches truly start and end (the field's
definition on the noise-free paths, :func:`reference`), for the evaluation in
``tools/evaluate_labs.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import find_peaks

from perception.io.mocap import MocapTrial
from perception.synthetic.independent import draw_independent, independent_paths
from perception.synthetic.scene import min_jerk

VERDICT = {"normal": ("normal", None), "delayed": ("abnormal", "delayed-opening"),
           "open-close-open": ("abnormal", "re-opening"),
           # a cup taken with extended fingers: honest is "not a precision grip"
           "whole-hand": ("unfamiliar", None)}


@dataclass
class Generated:
    """A generated recording and the truth of its reaches."""

    trial: MocapTrial
    truth: list[dict]  # per reach: condition, window (s), onset, end, mt, mga


def grasp(generator: str, condition: str, rng: np.random.Generator, rate: float,
          rest_after: float = 0.4):
    """(t, {wrist, finger, thumb}: (F, 2) m) of one grasp at ``rate``.

    A ``whole-hand`` grasp is a normal one whose digits rest 6-8 cm apart
    (a flat hand) and widen by only 8 % of the normal opening (about 1 cm).
    """
    if condition == "whole-hand":
        t, paths = grasp(generator, "normal", rng, rate, rest_after)
        f, th = paths["finger"], paths["thumb"]
        mid, axis = 0.5 * (f + th), f - th
        g = np.linalg.norm(axis, axis=1)
        unit = axis / np.maximum(g, 1e-9)[:, None]
        wide = rng.uniform(0.06, 0.08) + 0.08 * (g - g[0])
        return t, {**paths, "finger": mid + 0.5 * wide[:, None] * unit,
                   "thumb": mid - 0.5 * wide[:, None] * unit}
    if generator == "independent":
        p = draw_independent(condition, rng, rest_before=0.6, rest_after=rest_after)
        return independent_paths(p, rate, seed=rng)
    from perception.synthetic.stimuli import StimulusParams, stimulus_paths

    p = StimulusParams(condition=condition, rest_before=0.6, rest_after=rest_after)
    return stimulus_paths(p, rate, seed=int(rng.integers(1 << 30)))


def _lab_frame(rng: np.random.Generator):
    """A drawn placement of the world frame on a lab's table: world (x, y, lift) -> mm."""
    angle = rng.uniform(-math.pi, math.pi)
    c, s = math.cos(angle), math.sin(angle)
    origin = np.array([rng.uniform(-300, 300), rng.uniform(200, 600), rng.uniform(700, 900)])

    def place(xy: np.ndarray, lift: np.ndarray) -> np.ndarray:
        x, y = xy[:, 0], xy[:, 1]
        return origin + 1000 * np.stack([c * x - s * y, s * x + c * y, lift], axis=1)
    return place


def _lift(wrist: np.ndarray, start: np.ndarray, goal: np.ndarray, height: float) -> np.ndarray:
    """A few cm of arc over the table, highest midway along the path from start to goal."""
    along = np.clip((wrist - start) @ (goal - start) / max((goal - start) @ (goal - start),
                                                           1e-12), 0, 1)
    return height * np.sin(np.pi * along)


def _move(a: np.ndarray, b: np.ndarray, n: int) -> np.ndarray:
    return a + min_jerk(np.linspace(0, 1, n))[:, None] * (b - a)


def reference(t, transport, aperture, window) -> dict:
    """The field's definitions on noise-free paths, within ``window`` (s): onset, end, MT, MGA."""
    inside = (t >= window[0]) & (t <= window[1])
    tt, tr, g = t[inside], transport[inside], aperture[inside]
    v = np.linalg.norm(np.gradient(tr, tt, axis=0), axis=1)
    # the first movement that peaks above a third of the fastest (a generated grasp's
    # hand may be pulled back briefly as the digits close, faster than the reach)
    peaks = find_peaks(v, height=np.max(v) / 3)[0]
    p = int(peaks[0]) if len(peaks) else int(np.argmax(v))
    below = v < 0.05 * v[p]
    on = p - int(np.argmax(below[p::-1])) + 1
    end = p + int(np.argmax(below[p:])) - 1
    return {"onset": float(tt[on]), "end": float(tt[end]), "mt": float(tt[end] - tt[on]),
            "mga": float(np.max(g[on:end + 1]))}


def _compose(generator, conditions, rng, rate, *, carry: bool, returns: bool, rests,
             drink: bool = False):
    """Grasps one after another (each with its return), in the lab frame (mm)."""
    place = _lab_frame(rng)
    parts = {k: [] for k in ("wrist", "finger", "thumb", "object", "lift")}
    truth, t0 = [], 0.0
    # in a task the hand may go on with the object at once
    after = (0.0, 0.1) if carry or drink else (0.4, 0.4)
    drawn = [grasp(generator, condition, rng, rate, rng.uniform(*after))
             for condition in conditions]
    for k, (condition, (t, paths)) in enumerate(zip(conditions, drawn)):
        w, f, th = paths["wrist"], paths["finger"], paths["thumb"]
        # the return leads to where the next grasp starts
        nxt = drawn[k + 1][1] if k + 1 < len(drawn) else paths
        start, goal = w[0], w[-1]
        lift = _lift(w, start, goal, rng.uniform(0.02, 0.05))
        obj = np.zeros_like(w)
        seg = {"wrist": [w], "finger": [f], "thumb": [th], "object": [obj], "lift": [lift]}
        hand = {"wrist": w[-1], "finger": f[-1], "thumb": th[-1]}
        n_hold = int(rng.uniform(0.0, 0.15) * rate)  # the hand may flow on at once
        if carry:  # the object carried sideways, put down, released
            side = np.array([0.15, 0.0]) @ np.array([[0.0, 1.0], [-1.0, 0.0]])
            n = int(rng.uniform(0.45, 0.6) * rate)
            for name, at in hand.items():
                seg[name] += [np.repeat(at[None], n_hold, 0), _move(at, at + side, n)]
                hand[name] = at + side
            seg["object"] += [np.zeros((n_hold, 2)), _move(np.zeros(2), side, n)]
            seg["lift"] += [np.zeros(n_hold), 0.04 * np.sin(np.pi * np.linspace(0, 1, n))]
            opened = 0.5 * (hand["finger"] - hand["thumb"])
            n = int(0.15 * rate)
            unit = opened / max(np.linalg.norm(opened), 1e-9)
            widen = 0.0075 * unit
            for name, d in (("finger", widen), ("thumb", -widen)):
                seg[name].append(_move(hand[name], hand[name] + d, n))
                hand[name] = hand[name] + d
            seg["wrist"].append(np.repeat(hand["wrist"][None], n, 0))
            seg["object"].append(np.repeat(side[None], n, 0))
            seg["lift"].append(np.zeros(n))
        if drink:  # the cup lifted toward the mouth, held, and put back down
            up = np.array([0.0, -0.12])
            n = int(rng.uniform(0.7, 0.9) * rate)
            n_hold_mouth = int(rng.uniform(0.8, 1.5) * rate)
            for name, at in hand.items():
                seg[name] += [np.repeat(at[None], n_hold, 0), _move(at, at + up, n),
                              np.repeat((at + up)[None], n_hold_mouth, 0),
                              _move(at + up, at, n)]
            seg["object"] += [np.zeros((n_hold, 2)), _move(np.zeros(2), up, n),
                              np.repeat(up[None], n_hold_mouth, 0), _move(up, np.zeros(2), n)]
            arc = 0.15 * np.sin(0.5 * np.pi * np.linspace(0, 1, n))
            seg["lift"] += [np.zeros(n_hold), arc, np.full(n_hold_mouth, 0.15), arc[::-1]]
        if returns:  # back to the start, the grip closing to its rest
            n = int(rng.uniform(0.6, 0.8) * rate)
            for name in ("wrist", "finger", "thumb"):
                seg[name].append(_move(hand[name], nxt[name][0], n))
            seg["object"].append(np.repeat(seg["object"][-1][-1:], n, 0))
            seg["lift"].append(0.03 * np.sin(np.pi * np.linspace(0, 1, n)))
            n = int(rng.uniform(*rests) * rate)
            for name in ("wrist", "finger", "thumb", "object"):
                seg[name].append(np.repeat(seg[name][-1][-1:], n, 0))
            seg["lift"].append(np.zeros(n))
        for name in parts:
            parts[name].append(np.concatenate(seg[name]))
        n_grasp = len(t)
        truth.append({"condition": condition, "window": (t0, t0 + t[-1]), "n": n_grasp})
        t0 += len(parts["wrist"][-1]) / rate
    lab = {name: np.concatenate(parts[name]) for name in parts}
    time = np.arange(len(lab["wrist"])) / rate
    lift = lab.pop("lift")
    markers = {}
    for name in ("wrist", "finger", "thumb", "object"):
        # the digits ride with the hand's lift; the object only while carried
        z = lift if name != "object" else np.where(
            np.linalg.norm(np.gradient(lab["object"], axis=0), axis=1) > 0, lift, 0.0)
        markers[name] = place(lab[name], z)
    # the transport is the hand marker, as the evaluation maps it
    hand = markers["wrist"] / 1000
    g = np.linalg.norm(markers["finger"] - markers["thumb"], axis=1) / 1000
    for tr in truth:
        tr.update(reference(time, hand, g, tr["window"]))
    noisy = {m: xyz + rng.normal(0, 0.1, xyz.shape) for m, xyz in markers.items()}
    return time, noisy, truth


def single_reach(generator: str, condition: str, seed: int, rate: float = 100.0) -> Generated:
    """One reach to grasp, the hand then held on the object (thumb, index, hand, object)."""
    rng = np.random.default_rng(seed)
    t, m, truth = _compose(generator, [condition], rng, rate, carry=False, returns=False,
                           rests=(0, 0))
    return Generated(_trial(f"{generator}-{condition}-{seed}", t, m, rate), truth)


def pick_and_place(generator: str, condition: str, seed: int,
                   rate: float = 200.0) -> Generated:
    """A reach to grasp, the object carried 15 cm and released, the hand's return."""
    rng = np.random.default_rng(seed)
    t, m, truth = _compose(generator, [condition], rng, rate, carry=True, returns=True,
                           rests=(0.3, 0.5))
    return Generated(_trial(f"{generator}-pnp-{condition}-{seed}", t, m, rate), truth)


def drinking(generator: str, condition: str, seed: int, rate: float = 100.0) -> Generated:
    """A reach to a cup, the cup lifted toward the mouth, held, put back, the hand's return."""
    rng = np.random.default_rng(seed)
    t, m, truth = _compose(generator, [condition], rng, rate, carry=False, returns=True,
                           rests=(0.3, 0.5), drink=True)
    return Generated(_trial(f"{generator}-drink-{condition}-{seed}", t, m, rate), truth)


def session(generator: str, conditions, seed: int, rate: float = 120.0) -> Generated:
    """Grasps back to back, each with its return and a rest (thumb, index, hand only)."""
    rng = np.random.default_rng(seed)
    t, m, truth = _compose(generator, list(conditions), rng, rate, carry=False, returns=True,
                           rests=(0.8, 2.0))
    m.pop("object")
    return Generated(_trial(f"{generator}-session-{seed}", t, m, rate), truth)


def _trial(name, time, markers_mm, rate) -> MocapTrial:
    names = {"wrist": "hand", "finger": "index", "thumb": "thumb", "object": "object"}
    return MocapTrial(name, name, time, {names[k]: v / 1000 for k, v in markers_mm.items()},
                      rate, "mm")


def write_vicon(trial: MocapTrial, path) -> None:
    """The trial as Vicon Nexus writes a Trajectories export (mm, empty cells where lost)."""
    names = list(trial.markers)
    rate = round(trial.rate)
    lines = ["Trajectories", str(rate),
             ",," + ",".join(f"Subject01:{n},," for n in names).rstrip(","),
             "Frame,Sub Frame," + ",".join("X,Y,Z" for _ in names),
             ",," + ",".join("mm,mm,mm" for _ in names)]
    xyz = np.concatenate([trial.markers[n] * 1000 for n in names], axis=1)
    for i, row in enumerate(xyz):
        cells = ["" if not np.isfinite(v) else f"{v:.5f}" for v in row]
        lines.append(f"{i + 1},0," + ",".join(cells))
    with open(path, "w", newline="") as fh:
        fh.write("\r\n".join(lines) + "\r\n")


def write_headerless(trial: MocapTrial, path) -> tuple[str, ...]:
    """The trial as RTMocap writes one (whitespace, mm, no header); its markers' names."""
    names = tuple(trial.markers)
    np.savetxt(path, np.concatenate([trial.markers[n] * 1000 for n in names], axis=1),
               fmt="%.4f")
    return names

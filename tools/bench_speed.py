"""Benchmark: start-up, planning and one clip end to end, with same-run baselines.

Run ``python tools/bench_speed.py`` or ``make bench`` (``tools/bench.py`` picks
up this module's ``main`` as the ``speed`` section). Prints, asserts nothing:
start-up is measured here, at the command line, not forbidden imports in tests.

* start-up: ``hammer-mv --version`` / ``--help`` in fresh processes, against
  a bare interpreter and importing every command module (what the CLI did
  before it was lazy);
* planning: the default 10-model repertoire for a new scene, against the
  same code with the numpy passes (``MINVAR_KERNEL=numpy``);
* one clip: ``hammer-mv recognize clip.mp4 --no-figures`` (2 s 640x480 clip,
  new scene, default repertoire), whole process on 2 cores, uncached (tracked
  and planned afresh each run), against importing what it imports; with
  figures; its tracks reused; and whether figures (matplotlib) and statistics
  (statsmodels) stayed unloaded;
* each input kind (issue 45 item 4): ``recognize`` of a tracks file, a
  DeepLabCut csv and a Qualisys tsv without figures, and of a 2 s video with
  its figures, against ``python -c 'import numpy, scipy.signal'`` (the floor:
  the field's filters need scipy.signal) in the same rounds; with our packages
  compiled to bytecode (as installed; the targets are for this case) and from
  source (as under PYTHONDONTWRITEBYTECODE=1); and which of OpenCV, matplotlib
  and pandas each loaded.
"""

from __future__ import annotations

import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench import table  # also puts the project root on sys.path

ROOT = Path(__file__).resolve().parents[1]
HAMMER = [sys.executable, "-m", "hammer_mv"]


def _wall(cmd: list[str], repeat: int = 5, env: dict | None = None,
          before_each=None) -> float:
    """Median wall time of a fresh process running ``cmd``, s."""
    return _timed(cmd, repeat, env, before_each)[0]


#: The cores a timed process may use: the first two this one may (the targets are
#: for a 2-core machine).
CORES = sorted(os.sched_getaffinity(0))[:2] if hasattr(os, "sched_getaffinity") else None


def _on_two_cores() -> None:
    if CORES is not None:
        os.sched_setaffinity(0, CORES)


def _timed(cmd: list[str], repeat: int = 5, env: dict | None = None,
           before_each=None, cwd: Path = ROOT) -> tuple[float, float]:
    """Median wall time and median CPU time (user + system) of a fresh process on
    :data:`CORES`, s; ``before_each()`` runs before each, untimed."""
    walls, cpus = [], []
    for _ in range(repeat):
        if before_each is not None:
            before_each()
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True, cwd=cwd, env=env,
                       preexec_fn=_on_two_cores)
        walls.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return statistics.median(walls), statistics.median(cpus)


def _verdict(value: float, target: float) -> str:
    return "ok" if value <= target else "MISSED"


def startup_rows() -> list[tuple[str, str, str, str]]:
    from hammer_mv.cli import COMMANDS

    version = _wall([*HAMMER, "--version"], repeat=7)
    helptext = _wall([*HAMMER, "--help"])
    bare = _wall([sys.executable, "-c", "pass"])
    eager = _wall([sys.executable, "-c", "; ".join(f"import hammer_mv.cli.{c}"
                                                   for c in COMMANDS)], repeat=3)
    base = f"every command module imported {eager:.2f} s; bare python {bare:.2f} s"
    return [
        ("hammer-mv --version", f"{version:.2f} s", f"target <= 0.3 s; {base}",
         _verdict(version, 0.3)),
        ("hammer-mv --help", f"{helptext:.2f} s", "target <= 0.3 s", _verdict(helptext, 0.3)),
    ]


_PLAN = """
import sys, time
import minvar.grasp as G
from perception.recognition.repertoire import Repertoire
from perception.recognition.models import SceneSpec
rep = Repertoire.default()
rep.for_scene(SceneSpec(distance=0.2))  # imports and first calls, not timed
runs = []
for i in range(int(sys.argv[1])):  # median and fastest printed
    G._SOLVED.clear()  # every chain planned anew
    scene = SceneSpec(distance=0.26 + 0.01 * i, object_size=0.06 + 0.005 * i, tip_start=0.065)
    t0 = time.perf_counter()
    # what recognize does without --repertoire: plan for the clip's scene; the
    # verdict's calibration comes with the package (tools/calibrate_default.py)
    models = rep.for_scene(scene)
    runs.append(time.perf_counter() - t0)
    assert all(m.calibration is not None for m in models)
print(sorted(runs)[len(runs) // 2], min(runs))
"""


def _plan_time(kernel: str, repeat: int) -> float:
    env = {**os.environ, "MINVAR_KERNEL": kernel, "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-c", _PLAN, str(repeat)], check=True,
                         capture_output=True, text=True, cwd=ROOT, env=env)
    median, best = (float(v) for v in out.stdout.split()[-2:])
    return median, best


def planning_rows() -> list[tuple[str, str, str, str]]:
    fast, best = _plan_time("compiled", 9)
    slow, _ = _plan_time("numpy", 3)
    from perception.recognition.planning import default_specs

    return [(f"default repertoire ({len(default_specs())} models) for a new scene",
             f"{fast * 1e3:.0f} ms (best {best * 1e3:.0f})",
             f"target <= 150 ms; numpy passes {slow * 1e3:.0f} ms",
             f"{_verdict(fast, 0.150)}; {slow / fast:.1f}x faster")]


#: What ``recognize --no-figures`` imports: the floor its whole process cannot go below.
_RECOGNIZE_IMPORTS = ("import numpy, scipy.signal, scipy.stats, h5py, cv2, "
                      "hammer_mv.cli.recognize, perception.pipeline, perception.report.clip")

_LOADED = """
import sys
from hammer_mv.cli import main
main(sys.argv[1:])
print(*[m for m in ('matplotlib', 'statsmodels', 'pandas') if m in sys.modules] or ['none'])
"""


def clip_rows() -> list[tuple[str, str, str, str]]:
    from perception.synthetic.demos import render_demo_clip
    from perception.synthetic.scene import Scene

    work = Path(tempfile.mkdtemp(prefix="hammer-bench-clip-"))
    try:
        # a 2 s clip of a scene the default repertoire was not planned for
        scene = Scene.reach_to_grasp(60, 30.0, start=(0.0, -0.30), onset=0.3, duration=1.2,
                                     object_diameter=0.08)
        clip, _ = render_demo_clip(work, "clip.mp4", n=60, scene=scene, hand=True)
        out = work / "out"
        args = ["recognize", str(clip.video), "-o", str(out), "--quiet",
                "--object-diameter", "0.08"]

        def uncached():  # no tracks file to reuse: tracked and planned afresh
            shutil.rmtree(out, ignore_errors=True)

        floor = _wall([sys.executable, "-c", _RECOGNIZE_IMPORTS], repeat=5)
        nofig, nofig_cpu = _timed([*HAMMER, *args, "--no-figures"], repeat=5,
                                  before_each=uncached)
        fresh, fresh_cpu = _timed([*HAMMER, *args], repeat=3, before_each=uncached)
        reuse = _wall([*HAMMER, *args, "--no-figures"], repeat=3)  # tracks from the last run
        numpy_env = {**os.environ, "MINVAR_KERNEL": "numpy"}
        slow = _wall([*HAMMER, *args, "--no-figures"], repeat=3, env=numpy_env,
                     before_each=uncached)
        uncached()
        loaded = subprocess.run([sys.executable, "-c", _LOADED, *args, "--no-figures"],
                                check=True, capture_output=True, text=True, cwd=ROOT)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return [
        ("recognize --no-figures, 2 s clip, uncached (track + plan), 2 cores",
         f"{nofig:.2f} s", f"target <= 1.0 s; its imports alone {floor:.2f} s; CPU "
         f"{nofig_cpu:.2f} s; numpy passes {slow:.2f} s", _verdict(nofig, 1.0)),
        ("  same, its tracks file current (reused)", f"{reuse:.2f} s", "", _verdict(reuse, 1.0)),
        ("  same, with figures", f"{fresh:.2f} s", f"CPU {fresh_cpu:.2f} s", ""),
        ("  loaded by --no-figures of matplotlib, statsmodels, pandas",
         loaded.stdout.split("\n")[-2], "none (figures, statistics and tables stay lazy)",
         "ok" if loaded.stdout.split("\n")[-2] == "none" else "MISSED"),
    ]


#: The floor of a ``recognize`` process: the field's filters need scipy.signal (which
#: loads scipy.stats); issue 45 measures every start-up against it, in the same run.
_FLOOR = [sys.executable, "-c", "import numpy, scipy.signal"]

#: ``recognize`` run in-process, then which of OpenCV, matplotlib, pandas it loaded.
_WHICH = """
import sys
from hammer_mv.cli import main
try:
    main(sys.argv[1:])
finally:
    print(",".join(m for m in ('cv2', 'matplotlib', 'pandas') if m in sys.modules) or "none")
"""


def _project_copy(work: Path, bytecode: bool) -> Path:
    """The project's packages copied under ``work``: compiled (as a user's installed
    copy is, its ``.pyc`` files written) or without any ``.pyc`` (compiled from source at
    every start, as here, where PYTHONDONTWRITEBYTECODE=1 keeps our edits uncompiled)."""
    import compileall

    root = work / ("bytecode" if bytecode else "source")
    for package in ("hammer_mv", "perception", "minvar"):
        shutil.copytree(ROOT / package, root / package,
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    if bytecode:
        assert compileall.compile_dir(root, quiet=1, workers=1)
    return root


def _start_files(work: Path) -> dict[str, list[str]]:
    """The ``recognize`` arguments of each input kind, its files written under ``work``."""
    import numpy as np
    import pandas as pd

    from perception.synthetic.demos import demo_tracks, render_demo_clip
    from perception.synthetic.scene import Scene

    tracks = demo_tracks("normal", 0)[0]
    tracks_file = tracks.save(work / "grasp.tracks.h5")
    columns = pd.MultiIndex.from_product([["DLC_resnet50"], list(tracks.markers),
                                          ["x", "y", "likelihood"]],
                                         names=["scorer", "bodyparts", "coords"])
    xy_p = np.concatenate([tracks.position, tracks.likelihood[..., None]], axis=-1)
    pose_file = work / "grasp.csv"  # a DeepLabCut table of the same grasp
    pd.DataFrame(xy_p.reshape(len(xy_p), -1), columns=columns).to_csv(pose_file)
    scene = Scene.reach_to_grasp(60, 30.0, start=(0.0, -0.30), onset=0.3, duration=1.2,
                                 object_diameter=0.08)
    clip, _ = render_demo_clip(work, "clip.mp4", n=60, scene=scene, hand=True)
    return {
        "tracks file": [str(tracks_file), "--no-figures"],
        "pose file (DeepLabCut csv)": [str(pose_file), "--no-figures", "--fps", "30",
                                       "--object-diameter-px", "80"],
        "motion-capture file (Qualisys tsv)": [
            str(ROOT / "tests" / "data" / "mocap" / "qualisys-recording.tsv"), "--no-figures"],
        "2 s video, with figures": [str(clip.video), "--object-diameter", "0.08"],
    }


#: Target: a whole ``recognize`` within this of the floor, s (issue 45 item 4).
_MARGINS = {"2 s video, with figures": 0.8}


def file_startup_rows(repeat: int = 3) -> list[tuple[str, str, str, str]]:
    """``recognize`` of each input kind, whole processes, beside the floor of the same run.

    Rounds interleave the floor and every command (so a busy spell costs each alike);
    the median of ``repeat`` rounds each. Twice: with our packages compiled to bytecode
    (a user's installation; the targets are for this case) and compiled from source
    at every start (this machine's PYTHONDONTWRITEBYTECODE=1).
    """
    work = Path(tempfile.mkdtemp(prefix="hammer-bench-start-"))
    rows = []
    try:
        files = _start_files(work)
        for bytecode in (True, False):
            root = _project_copy(work, bytecode)
            env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}
            env.pop("PYTHONPYCACHEPREFIX", None)
            out = work / "out"


            def run(args, out=out, env=env, root=root):
                shutil.rmtree(out, ignore_errors=True)  # nothing reused: tracked, planned
                cmd = [sys.executable, "-m", "hammer_mv", "recognize", *args, "-o", str(out),
                       "--quiet"]
                return _timed(cmd, 1, env, cwd=root)

            times: dict[str, list[tuple[float, float]]] = {"floor": []}
            run(files["tracks file"])  # warm the disk cache
            for _ in range(repeat):
                times["floor"].append(_timed(_FLOOR, 1, env, cwd=root))
                for what, args in files.items():
                    times.setdefault(what, []).append(run(args))
            floor, floor_cpu = (statistics.median(t[i] for t in times["floor"]) for i in (0, 1))
            how = "bytecode" if bytecode else "from source"
            rows.append((f"floor: python -c 'import numpy, scipy.signal' ({how})",
                         f"{floor:.2f} s", f"CPU {floor_cpu:.2f} s; same rounds", ""))
            for what, args in files.items():
                shutil.rmtree(out, ignore_errors=True)
                loaded = subprocess.run(
                    [sys.executable, "-c", _WHICH, "recognize", *args, "-o", str(out),
                     "--quiet"], capture_output=True, text=True, cwd=root, env=env,
                    check=True).stdout.split()[-1]
                wall, cpu = (statistics.median(t[i] for t in times[what]) for i in (0, 1))
                margin = _MARGINS.get(what, 0.25)
                target = (f"floor + {margin:.2f} s (target for bytecode); CPU {cpu:.2f} s "
                          f"({cpu - floor_cpu:+.2f}); loaded of cv2,matplotlib,pandas: {loaded}")
                rows.append((f"  recognize, {what} ({how})", f"{wall:.2f} s ({wall - floor:+.2f})",
                             target, _verdict(wall - floor, margin) if bytecode else ""))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return rows


def main() -> None:
    """Print the start-up, planning and per-clip table."""
    table("hammer-mv: start-up, planning, one clip (whole processes, median)",
          startup_rows() + planning_rows() + clip_rows())
    table("hammer-mv recognize of each input kind against the floor (whole processes, "
          "median of 3)", file_startup_rows())


if __name__ == "__main__":
    main()
    sys.exit(0)

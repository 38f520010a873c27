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

``--phases N`` instead prints where ``recognize`` of the 2 s video with its figures
spends its wall and CPU time, step by step (imports, settings, repertoire, tracking,
scoring, the contact sheet, matplotlib's import, the figures, the exit), median of N
fresh processes beside the floor of the same rounds.
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


def _project_copy(work: Path, bytecode: bool, source: Path = ROOT, name: str = "") -> Path:
    """The project's packages (of ``source``, a checkout) copied under ``work``: compiled
    (as a user's installed copy is, its ``.pyc`` files written) or without any ``.pyc``
    (compiled from source at every start, as here, where PYTHONDONTWRITEBYTECODE=1 keeps
    our edits uncompiled)."""
    import compileall

    root = work / (("bytecode" if bytecode else "source") + name)
    for package in ("hammer_mv", "perception", "minvar"):
        shutil.copytree(source / package, root / package,
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


#: ``--kinds``' names of the input kinds (``_start_files``' keys).
KINDS = {"tracks": "tracks file", "pose": "pose file (DeepLabCut csv)",
         "mocap": "motion-capture file (Qualisys tsv)", "video": "2 s video, with figures"}


def file_startup_rows(repeat: int = 3, *, baseline: Path | None = None,
                      kinds: list[str] | None = None,
                      modes: tuple[bool, ...] = (True, False)) -> list[tuple[str, str, str, str]]:
    """``recognize`` of each input kind, whole processes, beside the floor of the same run.

    Rounds interleave the floor and every command (so a busy spell costs each alike);
    the median of ``repeat`` rounds each. Twice (``modes``): with our packages compiled
    to bytecode (a user's installation; the targets are for this case) and compiled from
    source at every start (this machine's PYTHONDONTWRITEBYTECODE=1). ``baseline``,
    another checkout (a worktree of the commit before a change), is timed in the same
    rounds, each of its commands right after ours; ``kinds`` (keys of :data:`KINDS`)
    limits the input kinds.
    """
    work = Path(tempfile.mkdtemp(prefix="hammer-bench-start-"))
    rows = []
    try:
        files = _start_files(work)
        if kinds:
            files = {KINDS[k]: files[KINDS[k]] for k in kinds}
        for bytecode in modes:
            roots = {"": _project_copy(work, bytecode)}
            if baseline is not None:
                roots[" baseline"] = _project_copy(work, bytecode, baseline, "-baseline")
            env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
            env.pop("PYTHONPYCACHEPREFIX", None)
            envs = {tag: {**env, "PYTHONPATH": str(root)} for tag, root in roots.items()}
            out = work / "out"

            def run(args, tag, out=out, envs=envs, roots=roots):
                shutil.rmtree(out, ignore_errors=True)  # nothing reused: tracked, planned
                cmd = [sys.executable, "-m", "hammer_mv", "recognize", *args, "-o", str(out),
                       "--quiet"]
                return _timed(cmd, 1, envs[tag], cwd=roots[tag])

            times: dict[tuple[str, str], list[tuple[float, float]]] = {("floor", ""): []}
            for tag in roots:
                run(next(iter(files.values())), tag)  # warm the disk cache
            for _ in range(repeat):
                times["floor", ""].append(_timed(_FLOOR, 1, envs[""], cwd=roots[""]))
                for what, args in files.items():
                    for tag in roots:
                        times.setdefault((what, tag), []).append(run(args, tag))
            floor, floor_cpu = (statistics.median(t[i] for t in times["floor", ""])
                                for i in (0, 1))
            how = "bytecode" if bytecode else "from source"
            rows.append((f"floor: python -c 'import numpy, scipy.signal' ({how})",
                         f"{floor:.2f} s", f"CPU {floor_cpu:.2f} s; same rounds", ""))
            for what, args in files.items():
                for tag, root in roots.items():
                    shutil.rmtree(out, ignore_errors=True)
                    loaded = subprocess.run(
                        [sys.executable, "-c", _WHICH, "recognize", *args, "-o", str(out),
                         "--quiet"], capture_output=True, text=True, cwd=root, env=envs[tag],
                        check=True).stdout.split()[-1]
                    wall, cpu = (statistics.median(t[i] for t in times[what, tag])
                                 for i in (0, 1))
                    margin = _MARGINS.get(what, 0.25)
                    target = (f"floor + {margin:.2f} s (target for bytecode); CPU {cpu:.2f} s "
                              f"({cpu - floor_cpu:+.2f}); loaded of cv2,matplotlib,pandas: "
                              f"{loaded}")
                    rows.append((f"  recognize, {what} ({how}){tag}",
                                 f"{wall:.2f} s ({wall - floor:+.2f})", target,
                                 _verdict(wall - floor, margin) if bytecode else ""))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return rows


#: ``--phases``' child: ``hammer-mv recognize`` (as ``python -m hammer_mv`` runs it) with
#: the wall and CPU time taken where each step returns; prints them as JSON. matplotlib
#: and scipy.stats are imported just before the steps that would import them, to count
#: them apart (scipy.stats is in the floor: scipy.signal loads it).
_PHASES = """
import gc, json, resource, sys, time
gc.disable()  # as hammer_mv/__main__.py
marks = [("interpreter, site", time.perf_counter(), time.process_time())]
def mark(name):
    marks.append((name, time.perf_counter(), time.process_time()))
def after(owner, attr, name):
    fn = getattr(owner, attr)
    def call(*args, **kwargs):
        if attr == "write_clip_report":
            import matplotlib.figure, matplotlib.backends.backend_agg
            mark("import matplotlib (the figures')")
        elif attr == "recognize_tracks":
            import scipy.stats
            mark("import scipy.stats (the verdict's; in the floor)")
        out = fn(*args, **kwargs)
        mark(name)
        return out
    setattr(owner, attr, call)
import hammer_mv.cli as cli
mark("import hammer_mv.cli")
run_command = cli._run
def wrapped(args):
    mark("imports of the command, parser")
    from hammer_mv.cli import options
    from perception import pipeline
    from perception.report import clip, tracking
    mark("imports of recognize.run")
    after(options, "recognition_settings", "settings")
    after(options, "load_repertoire", "repertoire")
    after(pipeline, "load_clip", "tracking the video (load_clip)")
    after(pipeline, "recognize_tracks", "scoring: planning, engine (recognize_tracks)")
    after(tracking, "write_tracking_report", "tracking report, contact sheet")
    after(clip, "write_clip_report", "three figures, CSV, JSON (write_clip_report)")
    return run_command(args)
cli._run = wrapped
sys.argv = ["hammer-mv", *sys.argv[1:]]
status = cli.entry()
mark("after the command")
print(json.dumps(marks))
"""


def phase_rows(repeat: int = 5) -> list[tuple[str, str, str, str]]:
    """Where ``recognize`` of a 2 s video with its figures spends its time (issue 45 item 4).

    Fresh processes (our packages compiled to bytecode, as installed), each step's wall
    and CPU time (all threads: planning and decoding run in threads) taken where it
    returns, beside the floor (``python -c 'import numpy, scipy.signal'``) in the same
    rounds; the median of ``repeat`` rounds each. The last row, the interpreter's exit,
    is the process's CPU time (``ru_utime + ru_stime``) after the last mark.
    """
    import json

    work = Path(tempfile.mkdtemp(prefix="hammer-bench-phases-"))
    try:
        clip = _start_files(work)["2 s video, with figures"]
        root = _project_copy(work, bytecode=True)
        env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}
        env.pop("PYTHONPYCACHEPREFIX", None)
        out = work / "out"
        steps: dict[str, list[tuple[float, float]]] = {}
        floors, wholes = [], []
        for _ in range(repeat):
            floors.append(_timed(_FLOOR, 1, env, cwd=root))
            shutil.rmtree(out, ignore_errors=True)  # tracked and planned afresh
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-c", _PHASES, "recognize", *clip, "-o",
                                   str(out), "--quiet"], check=True, capture_output=True,
                                  text=True, cwd=root, env=env, preexec_fn=_on_two_cores)
            wall = time.perf_counter() - t0
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
            wholes.append((wall, cpu))
            marks = json.loads(proc.stdout.splitlines()[-1])
            last_cpu = 0.0
            steps.setdefault(marks[0][0], []).append((0.0, marks[0][2]))  # its CPU only
            for (_, w_prev, c_prev), (name, w, c) in zip(marks, marks[1:]):
                steps.setdefault(name, []).append((w - w_prev, c - c_prev))
                last_cpu = c
            steps.setdefault("exit (modules torn down)", []).append((0.0, cpu - last_cpu))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    med = statistics.median
    floor_wall, floor_cpu = med(f[0] for f in floors), med(f[1] for f in floors)
    whole_wall, whole_cpu = med(w[0] for w in wholes), med(w[1] for w in wholes)
    rows = [(f"  {name}", f"{1e3 * med(v[0] for v in values):.0f} ms" if name not in (
                 "interpreter, site", "exit (modules torn down)") else "-",
             f"CPU {1e3 * med(v[1] for v in values):.0f} ms", "")
            for name, values in steps.items()]
    return [("floor: python -c 'import numpy, scipy.signal' (bytecode)", f"{floor_wall:.2f} s",
             f"CPU {floor_cpu:.2f} s; same rounds", ""),
            ("recognize, 2 s video, with figures (bytecode), whole process",
             f"{whole_wall:.2f} s ({whole_wall - floor_wall:+.2f})",
             f"CPU {whole_cpu:.2f} s ({whole_cpu - floor_cpu:+.2f}); its steps below", ""),
            *rows]


def main(argv: list[str] | None = None) -> None:
    """Print the start-up, planning and per-clip table (``--phases N``: only the steps of
    ``recognize`` of a 2 s video with its figures, median of N fresh processes;
    ``--baseline DIR`` or ``--kinds``: only the input kinds against the floor)."""
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--phases", type=int, metavar="N", default=0,
                    help="only the steps of recognize of a 2 s video, N fresh processes")
    ap.add_argument("--baseline", type=Path, metavar="DIR",
                    help="only the input kinds against the floor, and another checkout of "
                         "the project (e.g. a git worktree of HEAD) timed in the same rounds")
    ap.add_argument("--kinds", metavar="K,...",
                    help=f"only these input kinds against the floor: {','.join(KINDS)}")
    ap.add_argument("--rounds", type=int, default=3, metavar="N",
                    help="rounds of the input kinds against the floor (default 3)")
    ap.add_argument("--bytecode-only", action="store_true",
                    help="the input kinds only as installed (compiled to bytecode)")
    # called from tools/bench.py with that script's own arguments in sys.argv
    args = ap.parse_args([] if argv is None and __name__ != "__main__" else argv)
    kinds = args.kinds.split(",") if args.kinds else None
    if kinds and set(kinds) - set(KINDS):
        ap.error(f"--kinds: one or more of {','.join(KINDS)}")
    if args.baseline is not None and not (args.baseline / "perception").is_dir():
        ap.error(f"--baseline: {args.baseline} holds no checkout of the project")
    if args.phases:
        table("hammer-mv recognize of a 2 s video with its figures, step by step (fresh "
              f"processes, median of {args.phases}; wall and CPU of each step)",
              phase_rows(args.phases))
        return
    kinds_rows = ("hammer-mv recognize of each input kind against the floor (whole processes, "
                  f"median of {args.rounds})")
    modes = (True,) if args.bytecode_only else (True, False)
    if args.baseline is not None or kinds or args.bytecode_only:
        table(kinds_rows, file_startup_rows(args.rounds, baseline=args.baseline, kinds=kinds,
                                            modes=modes))
        return
    table("hammer-mv: start-up, planning, one clip (whole processes, median)",
          startup_rows() + planning_rows() + clip_rows())
    table(kinds_rows, file_startup_rows(args.rounds))


if __name__ == "__main__":
    main()
    sys.exit(0)

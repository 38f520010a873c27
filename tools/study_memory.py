"""The study part of ``tools/bench_recognition.py`` (``--only study``; issue 45): the
shipped Optotrak trials written as a lab's study and run through ``hammer-mv batch``
with its figures and report, its time and its memory (see that tool's docstring).
Not named ``bench_*.py``: ``tools/bench.py`` runs ``main()`` of each such module.
"""

from __future__ import annotations

import re
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


#: The study part's targets: seconds for a 10,000-trial study at ``--jobs 16``, and
#: bytes a trial the batch's own process may grow by (10,000 trials: 50 MB).
STUDY_SECONDS, STUDY_TRIALS = 120.0, 10_000
STUDY_BYTES_PER_TRIAL = 5_000


def make_study(folder: Path, participants: int, trials: int, conditions: int = 2) -> int:
    """Write the shipped Optotrak trials as a study: ``participants`` files
    (``P001.tsv``, ...) of ``trials`` trials each, the shipped four in turn.

    Each row gains a ``participant`` column (``P001``) and, with ``conditions``
    above 0, a ``condition`` column (``normal``, ``delayed``, ``c3``, ...: trial
    ``k`` of a participant is condition ``k % conditions``); trials are numbered
    through the study, so that no two files share a trial's number.

    Returns
    -------
    int
        The trials written.
    """
    from bench_mocap import SOURCE

    lines = SOURCE.read_text().splitlines()
    header, rows = lines[0].split("\t"), [line.split("\t") for line in lines[1:]]
    by_trial: dict[str, list[list[str]]] = {}
    for r in rows:
        by_trial.setdefault(r[0], []).append(r[1:])
    shipped = list(by_trial.values())
    names = ["normal", "delayed", *(f"c{k}" for k in range(3, conditions + 1))][:conditions]
    folder.mkdir(parents=True, exist_ok=True)
    head = ["participant", *(["condition"] if conditions else []), *header]
    for p in range(participants):
        who = f"P{p + 1:03d}"
        out = ["\t".join(head)]
        for k in range(trials):
            number = str(p * trials + k)
            cond = [names[k % conditions]] if conditions else []
            prefix = "\t".join([who, *cond, number])
            out += [f"{prefix}\t" + "\t".join(r) for r in shipped[k % len(shipped)]]
        (folder / f"{who}.tsv").write_text("\n".join(out) + "\n")
    return participants * trials


def _watched(cmd: list[str]) -> tuple[float, float, int, int]:
    """Run ``cmd``; its wall time (s), its own CPU time (s; its workers are the
    forkserver's children, not its own), and the peak resident memory of its whole
    process tree and of the process itself, bytes (psutil, every 0.1 s)."""
    import subprocess
    import tempfile

    import psutil

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    # stderr to a file: a pipe read only at the end fills (64 kB of "not scored" lines)
    # and blocks the command while this loop waits for it
    err_file = tempfile.TemporaryFile()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err_file, cwd=ROOT)
    watched = psutil.Process(proc.pid)
    tree_peak = own_peak = 0
    while proc.poll() is None:
        try:
            own = watched.memory_info().rss
            tree = own + sum(_rss(c) for c in watched.children(recursive=True))
            own = max(own, _high_water(proc.pid))
        except psutil.Error:  # it ended between the poll and the look
            break
        own_peak, tree_peak = max(own_peak, own), max(tree_peak, tree)
        time.sleep(0.1)
    status = proc.wait()
    err_file.seek(0)
    err = err_file.read().decode(errors="replace")
    err_file.close()
    if status not in (0, 1):  # 1: a trial not scored, said in the report
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{err[-2000:]}")
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, tree_peak, own_peak


def _high_water(pid: int) -> int:
    """A process's peak resident memory so far, bytes (Linux's VmHWM: the peak between
    two looks too; 0 elsewhere). Not ``ru_maxrss`` of the children: that is the
    largest of every process waited for, a batch's workers among them."""
    try:
        with open(f"/proc/{pid}/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def _rss(proc) -> int:
    import psutil

    try:
        return proc.memory_info().rss
    except psutil.Error:  # a worker that has just ended
        return 0


#: ``python -c`` running ``hammer-mv`` under tracemalloc (the batch's own process; its
#: workers are not traced): argv[1] is where it writes, as JSON, what the process held
#: when the clips were all in (``held``; ``held_lines``: its 400 largest source lines,
#: bytes), its peak until then (``clips_peak``), the report's peak (``report_peak``)
#: and the whole run's (``peak``), bytes of Python and numpy allocations.
TRACED = """
import json, sys, tracemalloc
tracemalloc.start()
import perception.batch as batch
marks = {}
finish = batch._finish
def lines():
    snap = tracemalloc.take_snapshot().filter_traces(
        [tracemalloc.Filter(False, tracemalloc.__file__)])
    return {f"{s.traceback[0].filename}:{s.traceback[0].lineno}": s.size
            for s in snap.statistics("lineno")[:400]}
def traced(*args, **kwargs):
    marks["held"], marks["clips_peak"] = tracemalloc.get_traced_memory()
    marks["held_lines"] = lines()
    tracemalloc.reset_peak()
    try:
        return finish(*args, **kwargs)
    finally:
        marks["report_peak"] = tracemalloc.get_traced_memory()[1]
batch._finish = traced
from hammer_mv.cli import entry
where = sys.argv.pop(1)
sys.argv[0] = "hammer-mv"
try:
    status = entry()
finally:
    marks["peak"] = max(marks.get("clips_peak", 0), marks.get("report_peak", 0))
    with open(where, "w") as f:
        json.dump(marks, f)
sys.exit(status)
"""


def _traced_marks(path: Path) -> dict[str, int]:
    import json

    return json.loads(path.read_text()) if path.exists() else {}


def study_rows(participants: int, trials: int, jobs: int, conditions: int = 2,
               traced: bool = False) -> list[tuple[str, str, str, str]]:
    """A study of ``participants`` x ``trials`` Optotrak trials through ``hammer-mv
    batch --jobs jobs`` (issue 45), and the same with a tenth of the participants (5 at
    least, where there are 6): wall, trials/s, peak memory and memory a trial; with
    ``traced``, the batch's own process under tracemalloc (slower), and what it held
    (:data:`TRACED`) a trial more."""
    from bench_mocap import RATE
    from bench_speed import HAMMER

    work = Path(tempfile.mkdtemp(prefix="hammer-bench-study-"))
    marks: dict[int, dict[str, int]] = {}
    try:
        runs = {}
        # a tenth, but 5 participants at least (where there are 6): the statistics'
        # mixed models (statsmodels' imports) in both runs, not in the larger alone
        small = max(participants // 10, min(5, participants - 1))
        for who in ([small] if small else []) + [participants]:
            folder = work / f"study{who}"
            n = make_study(folder, who, trials, conditions)
            args = ["batch", str(folder), "--rate", RATE, "-o", str(work / "out"),
                    "--jobs", str(jobs), "--quiet"]
            cmd = ([sys.executable, "-c", TRACED, str(work / "marks.json"), *args] if traced
                   else [*HAMMER, *args])
            runs[n] = _watched(cmd)
            if traced:
                marks[n] = _traced_marks(work / "marks.json")
                print(f"  traced: { {k: v for k, v in marks[n].items() if k != 'held_lines'} }",
                      flush=True)
            # said as it ends: a study stopped at a time limit still leaves the smaller run's
            print(f"study of {n} trials: {runs[n][0]:.1f} s, peak memory {runs[n][2] / 2**20:.0f}"
                  f" MB every process, {runs[n][3] / 2**20:.0f} MB its own", flush=True)
            shutil.rmtree(work / "out", ignore_errors=True)
            shutil.rmtree(folder, ignore_errors=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    n = participants * trials
    wall, cpu, tree, own = runs[n]
    mb = 1 << 20
    rows = [(f"study: {participants} participants x {trials} trials = {n} trials, "
             f"batch --jobs {jobs}, figures and report", "", "", ""),
            ("  wall, whole command", f"{wall:.1f} s ({n / wall:.1f} trials/s; the batch's "
             f"own process CPU {cpu:.0f} s)",
             f"target {STUDY_TRIALS} trials <= {STUDY_SECONDS:.0f} s at --jobs 16 "
             f"({STUDY_TRIALS / STUDY_SECONDS:.0f} trials/s)",
             ("ok" if wall <= STUDY_SECONDS else "MISSED") if n == STUDY_TRIALS and jobs >= 16
             else "(another size)"),
            ("  peak memory, every process", f"{tree / mb:.0f} MB",
             f"{tree / n / 1e3:.1f} kB a trial", ""),
            ("  peak memory, the batch's own process", f"{own / mb:.0f} MB",
             f"{own / n / 1e3:.1f} kB a trial", "")]
    if small:
        m = small * trials
        grown = (own - runs[m][3]) / (n - m)
        rows.append((f"  its growth a trial, {m} -> {n} trials",
                     f"{grown / 1e3:.1f} kB",
                     f"target <= {STUDY_BYTES_PER_TRIAL / 1e3:.0f} kB ({m} trials: peak "
                     f"{runs[m][3] / mb:.0f} MB, {runs[m][0]:.1f} s)",
                     "ok" if grown <= STUDY_BYTES_PER_TRIAL else "MISSED"))
        if marks.get(n) and marks.get(m):
            for key, what in (("held", "held when the clips were in"),
                              ("clips_peak", "traced peak while the clips ran"),
                              ("report_peak", "traced peak of the report"),
                              ("peak", "traced peak, whole run")):
                a, b = marks[m].get(key, 0), marks[n].get(key, 0)
                rows.append((f"  tracemalloc: {what}", f"{(b - a) / (n - m) / 1e3:.1f} kB a "
                             "trial", f"{m} trials {a / mb:.1f} MB, {n} trials {b / mb:.1f} MB",
                             "" if key != "peak" else
                             "ok" if (b - a) / (n - m) <= STUDY_BYTES_PER_TRIAL else "MISSED"))
            rows += _grown_lines(marks[m].get("held_lines", {}), marks[n].get("held_lines", {}),
                                 n - m)
    return rows


def _grown_lines(small: dict[str, int], large: dict[str, int], more: int,
                 top: int = 8) -> list[tuple[str, str, str, str]]:
    """The source lines whose allocations held when the clips were in grew most from the
    smaller study to the larger, bytes a trial more (``more`` trials): what the batch's
    own process keeps a trial (a line in one run's 400 largest alone counts from 0)."""
    grown = sorted(((large.get(k, 0) - small.get(k, 0)) / more, k) for k in {*small, *large})
    return [(f"    held a trial, {re.sub(r'.*/(site-packages|python3[.0-9]*)/', '', where)}"
             .replace(f"{ROOT}/", ""), f"{size:.0f} B", "", "")
            for size, where in reversed(grown[-top:]) if size > 0]

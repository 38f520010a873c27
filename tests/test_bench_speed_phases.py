"""tools/bench_speed.py --phases: the child that splits a ``recognize`` process into its
steps still finds every step it wraps (a step renamed in the command would vanish from
the table silently). Nothing here is timed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from _demos import demo_tracks

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import bench_speed  # noqa: E402

STEPS = ["interpreter, site", "import hammer_mv.cli", "imports of the command, parser",
         "imports of recognize.run", "settings", "repertoire", "tracking the video (load_clip)",
         "import scipy.stats (the verdict's; in the floor)",
         "scoring: planning, engine (recognize_tracks)", "tracking report, contact sheet",
         "import matplotlib (the figures')", "three figures, CSV, JSON (write_clip_report)",
         "after the command"]


def test_the_phase_child_marks_every_step_of_recognize_in_order(tmp_path):
    tracks = demo_tracks("normal", 0)[0].save(tmp_path / "grasp.tracks.h5")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [
        str(ROOT), os.environ.get("PYTHONPATH")]))}
    proc = subprocess.run([sys.executable, "-c", bench_speed._PHASES, "recognize", str(tracks),
                           "--no-figures", "-o", str(tmp_path / "out"), "--quiet"],
                          capture_output=True, text=True, env=env, cwd=ROOT, check=True)
    marks = json.loads(proc.stdout.splitlines()[-1])
    assert [name for name, _, _ in marks] == STEPS
    walls, cpus = ([m[i] for m in marks] for i in (1, 2))
    assert walls == sorted(walls) and cpus == sorted(cpus)  # clocks taken as the steps end
    assert (tmp_path / "out" / "grasp.recognition.json").is_file()  # the command ran whole

"""A reader that closes the console early (``| head``) cuts the console, not the work."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "tests" / "data" / "mocap" / "optotrak-trials.tsv"


def test_recognize_piped_to_head_writes_every_reach_and_the_trials_table(tmp_path):
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "hammer_mv", "recognize", str(TABLE), "--rate", "85",
         "--markers", "thumb=thumb", "finger=index", "-o", str(out), "--no-figures"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=ROOT)
    first = proc.stdout.readline()  # as `head -1`: one line, then the reader is gone
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 0, err
    assert first.startswith(b"optotrak-trials-trial0: ")
    assert "Broken pipe" not in err and "Traceback" not in err, err
    reports = sorted(out.glob("*.recognition.json"))
    assert len(reports) == 4  # the table's four trials, one reach each
    assert all(json.loads(r.read_text())["verdict"] for r in reports)
    rows = (out / "optotrak-trials.trials.csv").read_text().splitlines()
    assert len(rows) == 1 + 4


def test_a_console_without_a_descriptor_goes_quiet_too():
    """The console script's stdout replaced by one without a file descriptor (an embedding
    program's): a closed reader still silences it, not a traceback."""
    import io

    from hammer_mv.cli import _Console

    class Closed(io.StringIO):
        def write(self, text):
            raise BrokenPipeError

    console = _Console(Closed())
    assert console.write("a line\n") == len("a line\n")
    assert console.write("another\n") == len("another\n")  # devnull now
    console.flush()

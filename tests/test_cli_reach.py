import json
import subprocess
import sys

import pandas as pd

from hammer_mv.cli import main


def test_reach_writes_figures_and_table(tmp_path):
    out = tmp_path / "r"
    assert main(["reach", "--start", "-0.2", "0.5", "--goal", "-0.4", "0.2", "--duration", "1",
                 "--via", "-0.4", "0.4", "0.25", "--via", "-0.2", "0.3", "0.75",
                 "--trials", "20", "--seed", "1", "-o", str(out)]) == 0
    assert (out / "reach.png").stat().st_size > 10_000
    df = pd.read_csv(out / "trajectories.csv")
    assert df.trial.nunique() == 20 and df.step.max() == 100
    summary = json.loads((out / "summary.json").read_text())
    assert all(d < 0.01 for d in summary["via_point_closest_approach_m"])
    assert summary["solver"]["converged"]


def test_reach_sweep(tmp_path):
    assert main(["reach", "--sweep", "--durations", "0.5", "1.0", "--trials", "30",
                 "-o", str(tmp_path)]) == 0
    s = pd.read_csv(tmp_path / "speed_accuracy.csv")
    assert list(s.duration) == [0.5, 1.0]
    assert s.sd_total.iloc[0] > s.sd_total.iloc[1]
    assert (tmp_path / "speed_accuracy.png").exists()


def test_reach_bad_input_one_line_exit_2(tmp_path):
    for bad in (["--via", "0.3", "0.4", "1.5"], ["--duration", "0.01"], ["--trials", "0"],
                ["--sigma-u", "-1"], ["--start", "nan", "0"]):
        proc = subprocess.run([sys.executable, "-m", "hammer_mv", "reach", *bad,
                               "-o", str(tmp_path / "x")], capture_output=True, text=True)
        assert proc.returncode == 2, bad
        assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
        assert "Traceback" not in proc.stderr
        assert not (tmp_path / "x").exists() or not any((tmp_path / "x").iterdir())

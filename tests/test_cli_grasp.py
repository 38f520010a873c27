import json
import subprocess
import sys

import pandas as pd
import pytest

from hammer_mv.cli import main


def test_grasp_simulate_writes_figures_and_table(tmp_path):
    out = tmp_path / "g"
    assert main(["grasp", "simulate", "--object-size", "0.06", "--trials", "20",
                 "--seed", "1", "-o", str(out)]) == 0
    df = pd.read_csv(out / "trajectories.csv")
    assert df.trial.nunique() == 20 and df.step.max() == 100
    assert df[df.step == 100].finger_x.mean() == pytest.approx(0.03, abs=5e-4)
    info = json.loads((out / "summary.json").read_text())
    assert info["task"]["object_size"] == 0.06
    assert info["task"]["transport_distance"] == pytest.approx(0.20)  # thesis line 953
    assert info["summary"]["mga_mean"] == pytest.approx(0.0807, abs=0.002)
    assert all(c["converged"] for c in info["solver"].values())
    assert (out / "grasp.png").stat().st_size > 10_000
    assert (out / "setup.png").stat().st_size > 10_000


def test_grasp_tip_start_sets_where_the_closed_tips_start(tmp_path):
    assert main(["grasp", "simulate", "--tip-start", "0.05", "--trials", "3",
                 "-o", str(tmp_path)]) == 0
    df = pd.read_csv(tmp_path / "trajectories.csv")
    first = df[df.step == 0].iloc[0]
    assert first.finger_y - first.wrist_y == pytest.approx(0.05, abs=1e-9)
    assert json.loads((tmp_path / "summary.json").read_text())["task"]["tip_start"] == 0.05


def test_grasp_reach_only_and_time_step(tmp_path):
    assert main(["grasp", "simulate", "--reach-only", "--dt", "0.0333333", "--trials", "5",
                 "-o", str(tmp_path)]) == 0
    df = pd.read_csv(tmp_path / "trajectories.csv")
    assert df.step.max() == 30 and df.aperture.max() < 1e-9


def test_grasp_experiment_writes_tables_and_figures(tmp_path):
    assert main(["grasp", "experiment", "object-size", "--trials", "5", "-o",
                 str(tmp_path)]) == 0
    s = pd.read_csv(tmp_path / "object-size.csv")
    assert len(s) == 9 and s.mga_mean.is_monotonic_increasing
    stats = json.loads((tmp_path / "object-size_stats.json").read_text())
    assert 0.7 < stats["mga_slope"] < 1.0
    for f in ("object-size_trials.csv", "object-size_curves.csv",
              "fig4_9_object_size_paths.png", "fig4_10_object_size_mga.png"):
        assert (tmp_path / f).stat().st_size > 1000, f


@pytest.mark.parametrize("argv", [
    ["grasp", "simulate", "--object-size", "0.5"],
    ["grasp", "simulate", "--distance", "0.6"],
    ["grasp", "simulate", "--viapoint-time", "1.5"],
    ["grasp", "simulate", "--tip-start", "0.3"],
    ["grasp", "simulate", "--duration", "0"],
    ["grasp", "simulate", "--trials", "0"],
    ["grasp", "experiment", "movement-time", "--trials", "1"],
])
def test_grasp_bad_input_one_line_exit_2(tmp_path, capsys, argv):
    out = tmp_path / "x"
    assert main([*argv, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hammer-mv grasp: error:")
    assert not out.exists()


def test_grasp_bad_input_in_a_fresh_process(tmp_path):
    for bad in (["experiment", "nonsense"], ["simulate", "--object-size", "-1"]):
        proc = subprocess.run([sys.executable, "-m", "hammer_mv", "grasp", *bad,
                               "-o", str(tmp_path / "x")], capture_output=True, text=True)
        assert proc.returncode == 2, bad
        assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
        assert "Traceback" not in proc.stderr
    assert not (tmp_path / "x").exists()

"""Sizes and positions are bounded before anything is allocated (minvar.limits).

Library level: the tasks, the planner and the simulators refuse numbers beyond
the documented limits with a ValueError naming the field, the value and the
limit, and accept values just inside them. Command line: each refusal is one
line on stderr, exit status 2, nothing written, within seconds.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from minvar import limits
from minvar.execution import simulate
from minvar.grasp import GraspTask, GripVia, check_grasp_simulation, simulate_grasp
from minvar.grasp_experiments import check_trials
from minvar.limits import MAX_POSITION_M, MAX_STEPS, MAX_TRIALS, MEMORY_BUDGET
from minvar.lqg import solve
from minvar.plant import PointMassPlant
from minvar.task import ReachTask, ViaPoint, reach_problem

ROOT = Path(__file__).resolve().parents[1]
DT = PointMassPlant().dt


# -- steps -------------------------------------------------------------------------
def test_a_huge_duration_is_refused_by_steps_and_reach_problem():
    task = ReachTask((0.2, 0.2), (0.4, 0.5), 1e6)  # a task is cheap; its steps are not
    with pytest.raises(ValueError, match=r"ReachTask\.duration.*1e\+06 s.*MAX_STEPS"):
        task.steps(DT)
    with pytest.raises(ValueError, match="5000 steps"):
        reach_problem(task)


def test_the_step_limit_itself_is_accepted():
    assert ReachTask((0, 0), (0.1, 0), MAX_STEPS * DT).steps(DT) == MAX_STEPS
    with pytest.raises(ValueError, match="MAX_STEPS"):
        ReachTask((0, 0), (0.1, 0), (MAX_STEPS + 1) * DT).steps(DT)


def test_a_huge_grasp_duration_or_a_tiny_step_is_refused_at_construction():
    with pytest.raises(ValueError, match=r"GraspTask\.duration.*MAX_STEPS"):
        GraspTask(duration=1e5)
    with pytest.raises(ValueError, match=r"GraspTask\.duration.*1e-06 s"):
        GraspTask(plant=PointMassPlant(dt=1e-6))
    assert GraspTask(duration=MAX_STEPS * DT).steps == MAX_STEPS


def test_baselines_bound_their_samples():
    from minvar.baselines import minimum_jerk

    with pytest.raises(ValueError, match=r"minimum_derivative: duration.*MAX_STEPS"):
        minimum_jerk((0, 0), (0.2, 0), 1e6)


# -- repetitions and memory --------------------------------------------------------
@pytest.fixture(scope="module")
def reach():
    problem = reach_problem(ReachTask((0.2, 0.2), (0.4, 0.5), 0.05))  # short: quick at 10 000
    return problem, solve(problem)


def test_simulate_refuses_too_many_trials_before_allocating(reach, monkeypatch):
    problem, solution = reach
    allocated = []
    real_empty = np.empty
    monkeypatch.setattr(np, "empty", lambda *a, **k: allocated.append(a) or real_empty(*a, **k))
    with pytest.raises(ValueError, match=r"simulate: trials: 100000000 repetitions .*"
                                         r"would need about 141\.6 GiB.*MEMORY_BUDGET"):
        simulate(problem, solution, 100_000_000)
    assert allocated == []


def test_simulate_is_bounded_by_memory_not_by_the_command_line_limit(reach):
    # the Monte Carlo checks of the exact moments run 20 000 repetitions of a short movement
    problem, solution = reach
    assert simulate(problem, solution, 2 * MAX_TRIALS).states.shape[0] == 2 * MAX_TRIALS


def test_the_memory_budget_is_checked_on_the_estimate():
    need = limits.simulation_bytes(MAX_TRIALS, MAX_STEPS, 10)
    assert need > MEMORY_BUDGET  # both limits at once would not fit
    with pytest.raises(ValueError, match=r"--trials: .*would need about 11\.9 GiB.*2\.0 GiB"):
        limits.check_simulation(MAX_TRIALS, MAX_STEPS, 10, "--trials")
    assert limits.check_simulation(MAX_TRIALS, 50, 10, "--trials") == MAX_TRIALS


def test_a_plan_with_too_many_via_points_is_refused_before_q_is_allocated():
    vias = tuple(ViaPoint((0.1, 0.1), seconds=0.01 * (i + 1)) for i in range(600))
    task = ReachTask((0, 0), (0.2, 0.2), 50, vias)
    with pytest.raises(ValueError, match=r"ReachTask: a plan of 5000 steps x 1210 states.*GiB"):
        reach_problem(task)


def test_simulate_grasp_refuses_before_planning():
    long = GraspTask(duration=40.0)
    with pytest.raises(ValueError, match=r"simulate_grasp: trials: .*GiB.*MEMORY_BUDGET"):
        simulate_grasp(long, MAX_TRIALS)  # would take seconds to plan first
    with pytest.raises(ValueError, match="MAX_TRIALS"):
        check_grasp_simulation(GraspTask(), MAX_TRIALS + 1, "--trials", max_trials=MAX_TRIALS)
    assert check_grasp_simulation(GraspTask(duration=MAX_STEPS * DT), 500, "x") == 500


def test_check_trials_has_an_upper_bound():
    assert check_trials(MAX_TRIALS) == MAX_TRIALS
    with pytest.raises(ValueError, match=r"--trials: 10001 .*MAX_TRIALS"):
        check_trials(MAX_TRIALS + 1, name="--trials")


# -- positions -----------------------------------------------------------------------
@pytest.mark.parametrize("make, field", [
    (lambda v: ReachTask((v, 0), (0.4, 0.5), 0.5), r"ReachTask\.start"),
    (lambda v: ReachTask((0, 0), (0.4, v), 0.5), r"ReachTask\.goal"),
    (lambda v: ViaPoint((v, v), fraction=0.5), r"ViaPoint\.position"),
    (lambda v: GraspTask(distance=v), r"GraspTask\.distance"),
    (lambda v: GraspTask(object_size=v), r"GraspTask\.object_size"),
    (lambda v: GraspTask(viapoint_height=-v), r"GraspTask\.viapoint_height"),
    (lambda v: GraspTask(arm_links=(v, v)), r"GraspTask\.arm_links"),
    (lambda v: GripVia(v, 0.0, 0.5), r"GripVia\.half_aperture"),
])
def test_positions_beyond_the_table_are_refused(make, field):
    with pytest.raises(ValueError, match=field + r": expected .*within \+-10 m "
                       r"\(MAX_POSITION_M.*got .*1e\+300"):
        make(1e300)
    with pytest.raises(ValueError, match=field + ".*MAX_POSITION_M"):
        make(MAX_POSITION_M * 1.001)


def test_positions_at_the_limit_are_accepted():
    task = ReachTask((-MAX_POSITION_M, MAX_POSITION_M), (MAX_POSITION_M, 0.0), 0.5,
                     (ViaPoint((0.0, -MAX_POSITION_M), fraction=0.5),))
    assert task.start == (-MAX_POSITION_M, MAX_POSITION_M)
    assert GripVia(MAX_POSITION_M, -MAX_POSITION_M, 0.5).half_aperture == MAX_POSITION_M


# -- the command line ----------------------------------------------------------------
@pytest.mark.parametrize("argv, flag", [
    (["reach", "--duration", "1e6"], "--duration"),
    (["reach", "--trials", "100000000"], "--trials"),
    (["reach", "--start", "1e300", "0"], "--start"),
    (["reach", "--sweep", "--durations", "0.5", "1e6"], "--durations"),
    (["grasp", "simulate", "--duration", "1e5"], "--duration"),
    (["grasp", "simulate", "--duration", "40", "--trials", "10000"], "--trials"),
    (["repertoire", "build", "--durations", "1e6"], "duration"),
])
def test_the_cli_refuses_in_one_line_and_writes_nothing(tmp_path, argv, flag):
    out = tmp_path / ("x.h5" if argv[0] == "repertoire" else "out")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "hammer_mv", *argv, "-o", str(out)],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path, env=env)
    lines = proc.stderr.splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert flag in lines[0] and ("MAX_" in lines[0] or "MEMORY_BUDGET" in lines[0]), lines[0]
    assert list(tmp_path.iterdir()) == [], "something was written"

"""The plant and task builders against docs/model.md and the reference inputs."""

import numpy as np
import pytest

from minvar import PointMassPlant, ReachTask, ViaPoint, reach_problem

S_TASK = ReachTask(
    (-0.2, 0.5), (-0.4, 0.2), 1.0,
    (ViaPoint((-0.4, 0.4), fraction=0.25), ViaPoint((-0.2, 0.3), fraction=0.75)),
)


def test_builder_reproduces_reference_inputs_exactly(todorov):
    task = ReachTask((0.2, 0.2), (0.4, 0.5), 0.5, r=0.002, w_v=0.1, w_f=0.01)
    p = reach_problem(task)
    for name, value in todorov["inputs"].items():
        ref = np.array(value, dtype=float)
        ours = getattr(p, name)
        assert ours.shape == ref.reshape(ours.shape).shape, name
        assert np.array_equal(ours, ref.reshape(ours.shape)), name


def test_state_layout_and_cost_of_via_points():
    p = reach_problem(S_TASK)
    assert p.n_states == 14 and p.horizon == 100
    x = np.zeros(14)
    x[8:] = 1.0
    x[:2] = (-0.38, 0.43)  # 2 cm / 3 cm off the first via-point at step 25
    assert x @ p.Q[25] @ x == pytest.approx((0.02**2 + 0.03**2) / 5)
    x[:2] = (-0.2, 0.3)
    assert x @ p.Q[75] @ x == pytest.approx(0.0, abs=1e-15)
    assert np.count_nonzero([np.any(q) for q in p.Q]) == 3  # steps 25, 75, 100
    np.testing.assert_allclose(p.R, 2e-4 * 0.01 / 100 * np.eye(2))


def test_seconds_and_fraction_agree():
    a = reach_problem(ReachTask((0, 0), (0.1, 0), 0.8, (ViaPoint((0.05, 0.02), fraction=0.5),)))
    b = reach_problem(ReachTask((0, 0), (0.1, 0), 0.8, (ViaPoint((0.05, 0.02), seconds=0.4),)))
    assert np.array_equal(a.Q, b.Q)


def test_plant_discretisation():
    A, B = PointMassPlant(mass=2.0).dynamics(1)
    x = np.zeros(10)
    x[4] = 1.0  # 1 N of force on x
    assert (A @ x)[2] == pytest.approx(0.01 / 2.0)  # dv = dt f / m
    assert B[6, 0] == pytest.approx(0.25) and B[:6].sum() == 0


def test_thesis_form_step_response_is_the_printed_filter():
    """Lines 520-524: g' = a g + u, f' = a f + a g, a = exp(-dt/tau). A unit command
    held from rest gives g_k = (1 - a^k)/(1 - a) and
    f_k = (a (1 - a^k)/(1 - a) - k a^k)/(1 - a), rising to a/(1 - a)^2 = 15.9."""
    plant = PointMassPlant()
    A, B = plant.dynamics(1, form="thesis")
    a = np.exp(-0.01 / 0.04)
    x, u = np.zeros(10), np.array([1.0, 0.0])
    for k in range(1, 60):
        x = A @ x + B @ u
        g = (1 - a**k) / (1 - a)
        f = (a * (1 - a**k) / (1 - a) - k * a**k) / (1 - a)
        assert x[6] == pytest.approx(g, rel=1e-12) and x[4] == pytest.approx(f, rel=1e-12)
        assert x[7] == x[5] == 0.0
    assert f == pytest.approx(a / (1 - a) ** 2, rel=1e-3) and a / (1 - a) ** 2 == pytest.approx(
        15.92, abs=0.01)
    # the Euler form's steady force per unit command is 1
    A, B = plant.dynamics(1)
    x = np.zeros(10)
    for _ in range(400):
        x = A @ x + B @ u
    assert x[4] == pytest.approx(1.0, rel=1e-9)


def test_thesis_form_effort_is_r_over_the_number_of_steps():
    """Eq. 3.22 (line 558): R = r/T I, T the number of steps, so R halves when T doubles;
    the project's form is r dt/T, 100 times smaller at dt = 0.01 s."""
    for duration, T in ((0.5, 50), (1.0, 100)):
        task = ReachTask((0, 0), (0.1, 0), duration, r=0.002, form="thesis")
        np.testing.assert_allclose(reach_problem(task).R, 0.002 / T * np.eye(2), rtol=1e-15)
        ours = reach_problem(ReachTask((0, 0), (0.1, 0), duration, r=0.002))
        np.testing.assert_allclose(ours.R, 0.002 * 0.01 / T * np.eye(2), rtol=1e-15)
    thesis = reach_problem(ReachTask((0, 0), (0.1, 0), 0.5, form="thesis"))
    ours = reach_problem(ReachTask((0, 0), (0.1, 0), 0.5))
    # only A, B and R change: the cost of the task, the noise and the sensing are the same
    for name in ("Q", "H", "D0", "X1"):
        assert np.array_equal(getattr(thesis, name), getattr(ours, name)), name
    assert np.array_equal(thesis.B[6:8], np.eye(2))


def test_grasp_form_reaches_every_chain():
    from minvar import GraspTask, plan_grasp

    plan = plan_grasp(GraspTask(form="thesis", r=0.002, w_v=0.1))
    for chain in plan.chains.values():
        assert chain.task.form == "thesis"
        assert np.array_equal(chain.problem.B[6:8], np.eye(2))
        np.testing.assert_allclose(chain.problem.R, 0.002 / 100 * np.eye(2))


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: ReachTask((0, 0), (0.1, 0), 0.01).steps(0.01), "shorter than 2 steps"),
        (lambda: ReachTask((0, 0), (0.1, 0), -1.0), "duration"),
        (lambda: ReachTask((0, np.nan), (0.1, 0), 1.0), "start"),
        (lambda: ReachTask((0, 0), (0.1, 0, 3), 1.0), "goal"),
        (lambda: ViaPoint((0, 0)), "exactly one"),
        (lambda: ViaPoint((0, 0), fraction=0.5, seconds=0.2), "exactly one"),
        (lambda: reach_problem(ReachTask((0, 0), (1, 0), 1.0, (ViaPoint((0, 0), fraction=1.0),))),
         "outside the movement"),
        (lambda: reach_problem(ReachTask((0, 0), (1, 0), 1.0, (ViaPoint((0, 0), seconds=2.0),))),
         "outside the movement"),
        (lambda: PointMassPlant(sigma_u=-0.1), "sigma_u"),
        (lambda: PointMassPlant(sigma_s=np.inf), "sigma_s"),
        (lambda: PointMassPlant(dt=0.1), "dt"),
        (lambda: ReachTask((0, 0), (0.1, 0), 1.0, r=-1), "ReachTask.r"),
        (lambda: ReachTask((0, 0), (0.1, 0), 1.0, form="printed"), "ReachTask.form"),
        (lambda: PointMassPlant().dynamics(1, form="exact"), "dynamics"),
        (lambda: __import__("minvar").GraspTask(form="Thesis"), "GraspTask.form"),
        # a dict or None for the task, a string for the plant: not an AttributeError
        (lambda: reach_problem({"start": (0, 0)}), "reach_problem: task: expected a ReachTask"),
        (lambda: reach_problem(ReachTask((0, 0), (0.1, 0), 1.0), "fast"),
         "reach_problem: plant: expected a PointMassPlant, got str"),
        (lambda: __import__("minvar").simulate_reach(None, trials=2),
         "simulate_reach: task: expected a ReachTask, got NoneType"),
    ],
)
def test_bad_input_is_a_value_error_naming_the_argument(make, message):
    with pytest.raises(ValueError, match=message):
        make()

"""Size and range limits, checked before anything is allocated.

Every array of the model grows with a number a user gives: the steps of a
movement (its duration over the plant's ``dt``), the repetitions simulated,
the via-points (each adds two states). Unchecked, a slip of the keyboard
(``--duration 1e6``) asks numpy for terabytes and ends in a ``MemoryError``
traceback, or the kernel kills the process minutes later. So each size is
checked against a documented limit, or against an estimate of the memory it
needs, and refused with a ``ValueError`` that names the field (or command-line
flag), the value, the limit and what it would need. The command line prints
such an error as one line and exits with status 2. docs/model.md ("Limits")
tabulates the limits.

The values, and why:

``MAX_STEPS = 5000``
    Control steps of one movement: 50 s at the default 10 ms step (40-55 s
    at the 8-11 ms steps of the recognition's models). The thesis's
    movements last 0.5-1.2 s, the longest anywhere in the project 2 s; human
    reaches and grasps last about a second. Planning 5000 steps takes a few
    seconds, and the plan's arrays (``Q``, gains, per-step matrices: ``(T+1)
    x n x n``) take about 16 MB for one target.
``MAX_TRIALS = 10_000``
    Simulated repetitions of one movement (per setting of a sweep) that the
    commands and the grasp experiments (:func:`minvar.grasp_experiments.check_trials`)
    accept: twenty times the thesis's 500 per setting; at 10 000 the Monte
    Carlo error of a standard deviation is under 1 %. More only lengthens the
    run and the tables written (one CSV row per repetition and step). The
    simulators themselves (:func:`minvar.execution.simulate`,
    :func:`minvar.grasp.simulate_grasp`) are bounded by memory alone: checking
    the Monte Carlo against the exact moments takes 20 000 repetitions of a
    short movement, which is cheap.
``MEMORY_BUDGET = 2 GiB`` (2^31 bytes)
    The most memory a simulation's (or a plan's) arrays may take, estimated
    from their shapes before they are allocated: :func:`simulation_bytes` for
    :func:`minvar.execution.simulate`, :func:`problem_bytes` for a plan.
    Small enough for a laptop to hold with the interpreter, the figures and
    a table; large enough for 10 000 repetitions of a 5 s reach, or 500 of a
    grasp at the step limit.
``MAX_POSITION_M = 10.0``
    The largest coordinate, length or distance of a task, m. Arm movements
    happen on a table, within a metre of the shoulder; ten metres is generous
    and keeps the cost's ``target^2`` terms far from overflow (at ``1e300``
    the solver breaks down). The grasp's chains plan in joint space, where
    the same bound holds in rad: their inverse kinematics keeps every angle
    within ``2 pi`` (6.3 rad).
"""

from __future__ import annotations

import math

import numpy as np

from minvar.errors import ParameterError

__all__ = [
    "MAX_STEPS",
    "MAX_TRIALS",
    "MEMORY_BUDGET",
    "MAX_POSITION_M",
    "check_steps",
    "check_trials",
    "check_memory",
    "check_simulation",
    "check_problem",
    "check_position",
    "simulation_bytes",
    "problem_bytes",
]

#: Most control steps of one movement (50 s at the default 10 ms step).
MAX_STEPS = 5000
#: Most simulated repetitions of one movement (or one setting of a sweep).
MAX_TRIALS = 10_000
#: Most memory, in bytes, that a simulation's or a plan's arrays may take (2 GiB).
MEMORY_BUDGET = 2 * 1024**3
#: Largest coordinate, length or distance of a task, m (or rad in joint space).
MAX_POSITION_M = 10.0

#: Bytes of one float64.
_FLOAT = 8
#: (T+1) x n x n arrays a plan holds at once: the cost ``Q``, the solver's
#: ``A - K H`` per step, the closed loop of the mean path, and a margin for
#: the gains (``(T, n, 6)`` and ``(T, 2, n)``) and the solver's scratch.
_PROBLEM_ARRAYS = 4


def _error(what: str | tuple[str, ...], message: str) -> ParameterError:
    """A :class:`ParameterError` naming ``what``: a field or flag, or a location
    (``("GraspTask", "duration")``) that a reader renames to its own key or flag."""
    if isinstance(what, tuple):
        return ParameterError(message, location=what)
    return ParameterError(message, field=what)


def _gib(nbytes: float) -> str:
    """``nbytes`` in GiB (2^30 bytes), e.g. ``12.3 GiB``; small amounts with more digits."""
    gib = nbytes / 1024**3
    return f"{gib:.1f} GiB" if gib >= 0.1 else f"{gib:.2g} GiB"


def check_steps(duration: float, dt: float, what: str) -> int:
    """Check that a movement of ``duration`` s at step ``dt`` s has at most :data:`MAX_STEPS`.

    Parameters
    ----------
    duration : float
        Movement time, s (finite and positive: checked by the caller).
    dt : float
        Time step, s.
    what : str
        The field or flag to name in the message (e.g. ``"--duration"``).

    Returns
    -------
    int
        The number of steps.

    Raises
    ------
    ValueError
        If the movement has more than :data:`MAX_STEPS` steps.
    """
    ratio = float(duration) / float(dt)
    if not (math.isfinite(ratio) and ratio > 0):
        raise _error(what, f"expected a finite, positive time in s, got {duration!r}")
    if ratio > MAX_STEPS + 0.5:
        steps = f"{ratio:.0f}" if ratio < 1e9 else f"{ratio:.3g}"
        raise _error(
            what, f"{duration:g} s is {steps} steps of {dt:g} s, more than the "
            f"{MAX_STEPS} steps a movement may have (MAX_STEPS: {MAX_STEPS * dt:.3g} s at "
            f"this step; see docs/model.md, Limits)"
        )
    return int(round(ratio))


def check_trials(trials: int, what: str) -> int:
    """Check that ``trials`` repetitions are at most :data:`MAX_TRIALS`; return it as an int.

    Parameters
    ----------
    trials : int
        Repetitions (an integer >= 1: checked by the caller).
    what : str
        The field or flag to name in the message (e.g. ``"--trials"``).

    Raises
    ------
    ValueError
        If there are more than :data:`MAX_TRIALS`.
    """
    if trials > MAX_TRIALS:
        raise _error(
            what, f"{trials} repetitions are more than the {MAX_TRIALS} allowed "
            f"(MAX_TRIALS; see docs/model.md, Limits)"
        )
    return int(trials)


def check_memory(nbytes: float, what: str, detail: str = "",
                 hint: str = "use fewer repetitions or a shorter movement") -> None:
    """Refuse an allocation estimated at ``nbytes`` above :data:`MEMORY_BUDGET`.

    Parameters
    ----------
    nbytes : float
        Estimated bytes needed.
    what : str
        The field, flag or function to name in the message.
    detail : str, optional
        What the memory is for (e.g. ``"500 repetitions x 5001 states"``).
    hint : str, optional
        How to ask for less, ending the message.

    Raises
    ------
    ValueError
        If ``nbytes`` exceeds the budget; the message gives the GiB needed.
    """
    if nbytes > MEMORY_BUDGET:
        detail = f"{detail} " if detail else ""
        raise _error(
            what, f"{detail}would need about {_gib(nbytes)} of memory, more than the "
            f"{_gib(MEMORY_BUDGET)} allowed (MEMORY_BUDGET; see docs/model.md, Limits): {hint}"
        )


def simulation_bytes(trials: int, steps: int, n_states: int, n_controls: int = 2) -> int:
    """Estimated bytes of :func:`minvar.execution.simulate`'s arrays.

    The states and the Kalman estimates (``trials x (steps+1) x n_states``
    each), the commands (``trials x steps x n_controls``) and the realised
    cost's temporary, the size of the states: float64 throughout.

    Parameters
    ----------
    trials : int
        Repetitions.
    steps : int
        Control steps of the movement.
    n_states : int
        State dimension.
    n_controls : int
        Command dimension.
    """
    per_trial = 3 * (steps + 1) * n_states + steps * n_controls
    return _FLOAT * int(trials) * per_trial


def check_simulation(trials: int, steps: int, n_states: int, what: str,
                     n_controls: int = 2, *, max_trials: int | None = None) -> int:
    """Check a simulation's memory (and repetitions) before it allocates; return ``trials``.

    Parameters
    ----------
    trials : int
        Repetitions.
    steps : int
        Control steps of the movement.
    n_states : int
        State dimension.
    what : str
        The field, flag or function to name in the message.
    n_controls : int
        Command dimension.
    max_trials : int, optional
        Also refuse more repetitions than this (the commands pass
        :data:`MAX_TRIALS`).

    Raises
    ------
    ValueError
        If ``trials`` exceeds ``max_trials`` or the arrays would exceed
        :data:`MEMORY_BUDGET`; the message gives the memory needed.
    """
    need = simulation_bytes(trials, steps, n_states, n_controls)
    if max_trials is not None and trials > max_trials:
        raise _error(
            what, f"{trials} repetitions are more than the {max_trials} allowed "
            f"(MAX_TRIALS; they would need about {_gib(need)} of memory; see docs/model.md, "
            f"Limits)"
        )
    check_memory(need, what, f"{trials} repetitions x {steps + 1} time points x "
                             f"{n_states} states")
    return int(trials)


def problem_bytes(steps: int, n_states: int) -> int:
    """Estimated bytes of a plan: a few ``(steps+1) x n x n`` float64 arrays.

    Parameters
    ----------
    steps : int
        Control steps of the movement.
    n_states : int
        State dimension (8 plus 2 per positional target).
    """
    return _FLOAT * _PROBLEM_ARRAYS * (steps + 1) * n_states * n_states


def check_problem(steps: int, n_states: int, what: str) -> None:
    """Check the memory of a plan of ``steps`` steps and ``n_states`` states.

    The estimate is :func:`problem_bytes`.

    Parameters
    ----------
    steps : int
        Control steps of the movement.
    n_states : int
        State dimension.
    what : str
        The task or field to name in the message.

    Raises
    ------
    ValueError
        If the plan's arrays would exceed :data:`MEMORY_BUDGET`.
    """
    check_memory(problem_bytes(steps, n_states), what,
                 f"a plan of {steps} steps x {n_states} states",
                 "use fewer via-points or a shorter movement")


def check_position(value, what: str, unit: str = "m") -> None:
    """Check that every coordinate of ``value`` lies within :data:`MAX_POSITION_M`.

    Parameters
    ----------
    value : float or array_like
        A coordinate, a point or a length (finite: checked by the caller).
    what : str
        The field or flag to name in the message.
    unit : str
        Unit of the value for the message (``m``, or ``rad`` in joint space).

    Raises
    ------
    ValueError
        If a coordinate's magnitude exceeds :data:`MAX_POSITION_M`.
    """
    arr = np.abs(np.asarray(value, dtype=float))
    if arr.size and not np.all(arr <= MAX_POSITION_M):  # also catches nan
        flat = ", ".join(f"{v:g}" for v in np.ravel(np.asarray(value, dtype=float)))
        shown = flat if np.ndim(value) == 0 else f"({flat})"
        raise _error(
            what, f"{shown} {unit} lies beyond +-{MAX_POSITION_M:g} {unit}, the most a "
            f"position or length may be (MAX_POSITION_M: the metres of a table; see "
            f"docs/model.md, Limits)"
        )

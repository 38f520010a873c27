"""The independent demonstration generator: literature kinematics, no minimum variance model."""

import ast
import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from perception.observation import observe
from perception.synthetic.independent import (
    CONDITIONS,
    RANGES,
    IndependentParams,
    draw_independent,
    independent_aperture,
    independent_paths,
    independent_tracks,
)

MODULE = Path(__file__).resolve().parents[1] / "perception" / "synthetic" / "independent.py"


def test_it_does_not_use_the_minimum_variance_model():
    tree = ast.parse(MODULE.read_text())
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    assert not [m for m in imported if m and m.split(".")[0] == "minvar"]
    # the validation every parameter class shares is minvar's, but none of it is the model
    code = ("import sys\n"
            "NOT_THE_MODEL = {'minvar._version', 'minvar.errors', 'minvar.limits', "
            "'minvar.validation'}\n"
            "from perception.synthetic.independent import IndependentParams, independent_tracks\n"
            "independent_tracks(IndependentParams('open-close-open'), 1)\n"
            "used = [m for m in sys.modules\n"
            "        if m.startswith('minvar.') and m not in NOT_THE_MODEL]\n"
            "assert not used, used\n")
    subprocess.run([sys.executable, "-c", code], check=True)


def _speed(t, xy):
    return np.linalg.norm(np.gradient(xy, t, axis=0), axis=1)


def test_normal_grasp_follows_the_literature():
    p = IndependentParams(wobble=0.0)
    t, paths = independent_paths(p, 200.0)
    tau = (t - p.rest_before) / p.duration
    g = paths["aperture"]
    # maximum grip aperture: object + 2-3 cm at 60-75 % of the movement (Jeannerod 1984)
    assert 0.02 <= g.max() - p.object_size <= 0.03
    assert 0.60 <= tau[np.argmax(g)] <= 0.75
    assert g[-1] == pytest.approx(p.object_size)  # closes on the object
    # a skewed, single-peaked transport: speed peaks at 40 % of the movement, then a long
    # deceleration
    v = _speed(t, paths["wrist"])
    assert tau[np.argmax(v)] == pytest.approx(p.peak_velocity_time, abs=0.02)
    moving = (tau > 0) & (tau < 1)
    assert np.sum(np.diff(np.sign(np.diff(v[moving]))) < 0) == 1
    # the grip midpoint ends on the object's centre, the wrist hand_size short of it
    mid = 0.5 * (paths["finger"] + paths["thumb"])
    np.testing.assert_allclose(mid[-1], [0, 0], atol=1e-9)
    assert np.linalg.norm(paths["wrist"][-1]) == pytest.approx(p.hand_size, abs=0.012)


def test_min_jerk_when_the_speed_peaks_halfway():
    p = IndependentParams(peak_velocity_time=0.5, wobble=0.0)
    t, paths = independent_paths(p, 1000.0)
    tau = np.clip((t - p.rest_before) / p.duration, 0, 1)
    s = tau**3 * (10 - 15 * tau + 6 * tau**2)
    y = paths["wrist"][:, 1]
    np.testing.assert_allclose((y - y[0]) / (y[-1] - y[0]), s, atol=1e-9)


def test_the_abnormal_stimuli_differ_where_they_should():
    tau = np.linspace(0, 1, 1001)
    delayed = IndependentParams("delayed")
    g = independent_aperture(delayed, tau)
    assert np.all(g[tau <= delayed.delayed_onset] == 0)  # closed until the late opening
    assert tau[np.argmax(g)] == pytest.approx(delayed.delayed_mga_time, abs=0.002)
    oco = IndependentParams("open-close-open")
    g = independent_aperture(oco, tau)
    first = g[np.argmin(abs(tau - oco.oco_first_time))]
    dip = g[np.argmin(abs(tau - oco.oco_close_time))]
    assert dip == pytest.approx(oco.oco_depth * first)
    assert first == pytest.approx(oco.oco_first_fraction * oco.mga)
    assert g.max() == pytest.approx(oco.mga)
    reach = independent_aperture(IndependentParams("reach"), tau)
    assert np.all(reach == 0)


def test_draws_vary_within_the_ranges_and_are_reproducible():
    a = [draw_independent("normal", np.random.default_rng(s)) for s in range(30)]
    b = [draw_independent("normal", np.random.default_rng(s)) for s in range(30)]
    assert a == b
    for name, (lo, hi) in RANGES.items():
        values = np.array([getattr(p, name) for p in a])
        assert np.all((values >= lo) & (values <= hi)), name
        assert values.std() > 0.1 * (hi - lo), name


@pytest.mark.parametrize("condition", CONDITIONS)
def test_tracks_are_observed_like_a_clip(condition):
    p = draw_independent(condition, np.random.default_rng(4))
    tracks, truth = independent_tracks(p, 4)
    obs = observe(tracks)
    assert obs.start_distance == pytest.approx(p.distance, abs=0.01)
    # the tracked markers, their separation at rest taken off, give the generator's aperture
    raw = obs.raw["finger"] - obs.raw["thumb"]
    g_raw = np.linalg.norm(raw - raw[0] * obs.marker_separation / np.linalg.norm(raw[0]),
                           axis=1)
    np.testing.assert_allclose(g_raw, truth["aperture"][obs.frame], atol=0.0025)
    assert abs(obs.onset_frame - truth["onset_frame"]) <= 3


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="condition"):
        IndependentParams("wave")
    with pytest.raises(ValueError, match="increase"):
        IndependentParams("open-close-open", oco_close_time=0.3)
    with pytest.raises(ValueError, match="duration"):
        IndependentParams(duration=0)
    with pytest.raises(ValueError, match="fps"):
        independent_paths(IndependentParams(), 0)


def test_both_generators_name_the_same_conditions():
    from perception.synthetic import independent, stimuli

    assert independent.CONDITIONS == stimuli.CONDITIONS


@pytest.mark.parametrize("condition", CONDITIONS)
def test_the_digits_never_pass_through_the_object(condition):
    """A late grip holds the hand back at the surface; a reach touches it, ending there."""
    rng = np.random.default_rng(31)
    for _ in range(15):
        p = dataclasses.replace(draw_independent(condition, rng), wobble=0.0,
                                marker_offset=0.0)
        _, paths = independent_paths(p, 100.0)
        radius = p.object_size / 2
        depth = radius - min(np.linalg.norm(paths[d], axis=1).min() for d in ("finger", "thumb"))
        assert depth < 0.5e-3, f"{condition}: a digit {depth * 1e3:.1f} mm inside the object"
        if condition != "reach":  # a grasp still closes on the object (a grip axis turned
            # far from the approach can be held back a few mm as it closes)
            tips = (paths["finger"][-1] + paths["thumb"][-1]) / 2
            assert np.linalg.norm(tips) < 6e-3
        else:
            assert abs(np.linalg.norm(paths["finger"][-1]) - radius) < 1e-3

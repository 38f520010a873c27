"""A movement brought to the reference scale again (a stream at rest) is the one made afresh.

:func:`perception.recognition.shape.canonical` keeps what the last movements
became; the same movement again returns it, its arrays copies the caller may
change, and any change to what it reads (a path's bit, the noise, the scene)
makes it afresh.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from _demos import demo_tracks

from perception.observation import observe
from perception.recognition.models import SceneSpec
from perception.recognition.rules import VerdictRules
from perception.recognition.shape import _canonical, canonical

_FIELDS = ("time", "frame", "wrist", "finger", "thumb", "hand_offset")


def _fresh(obs, scene, durations, rules, wrist_offset=0.06):
    return _canonical(obs, scene, durations, rules, wrist_offset)


def _same(out, norm, want):
    arrays, want_norm = want
    assert norm == want_norm
    for name in _FIELDS:
        assert np.asarray(getattr(out, name)).tobytes() == arrays[name].tobytes(), name


def test_the_same_movement_again_is_the_fresh_one_and_its_own_copy():
    obs = observe(demo_tracks("normal", 1, duration=1.0)[0])
    scene, durations, rules = SceneSpec(), (0.8, 1.2), VerdictRules()
    first, norm1 = canonical(obs, scene, durations, rules, 0.06)
    again, norm2 = canonical(obs, scene, durations, rules, 0.06)
    _same(again, norm2, _fresh(obs, scene, durations, rules))
    assert again.noise == first.noise and again.dt == scene.frame_period and again.raw == {}
    assert again.start_distance == scene.distance
    for name in _FIELDS:
        assert getattr(again, name) is not getattr(first, name)
    first.wrist[:] = 0.0  # the caller's to change: the next result is not
    third, norm3 = canonical(obs, scene, durations, rules, 0.06)
    _same(third, norm3, _fresh(obs, scene, durations, rules))


def test_a_changed_movement_or_setting_is_made_afresh():
    obs = observe(demo_tracks("normal", 1, duration=1.0)[0])
    scene, durations, rules = SceneSpec(), (0.8, 1.2), VerdictRules()
    canonical(obs, scene, durations, rules, 0.06)
    wrist = obs.wrist.copy()
    wrist[5, 0] = np.nextafter(wrist[5, 0], np.inf)  # one bit
    for changed, sc, du in ((dataclasses.replace(obs, wrist=wrist), scene, durations),
                            (dataclasses.replace(obs, noise=obs.noise * 2), scene, durations),
                            (obs, dataclasses.replace(scene, distance=0.3), durations),
                            (obs, scene, (0.9, 1.2))):
        out, norm = canonical(changed, sc, du, rules, 0.06)
        _same(out, norm, _fresh(changed, sc, du, rules))
        assert out.noise == changed.noise * norm.distance_scale
    out, norm = canonical(obs, scene, durations, rules, 0.07)
    _same(out, norm, _fresh(obs, scene, durations, rules, 0.07))
    # other rules: made afresh under them (the movement time's span read at 0.7, not 0.8)
    canonical(obs, scene, durations, rules, 0.06)
    other = dataclasses.replace(rules, span_fraction=0.7)
    out, norm = canonical(obs, scene, durations, other, 0.06)
    _same(out, norm, _fresh(obs, scene, durations, other))
    assert norm.movement_time != canonical(obs, scene, durations, rules, 0.06)[1].movement_time

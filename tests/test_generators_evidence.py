"""The verdict's decisive evidence on both synthetic generators (issue 43).

Each condition is drawn where it is unambiguous (a delayed grasp that stays
closed until 60 % of its movement, an open-close-open grasp that closes by
half its first opening, mild marker noise at 60 frames/s), once from the
generator the rules are tuned on (:mod:`perception.synthetic.independent`)
and once from the one nobody tunes on
(:mod:`perception.synthetic.sigma_lognormal`): the landmark each rule reads
must carry the verdict on both. Where the generators stop agreeing (delayed
grasps opening where real healthy grips do, fast grasps under drifting
marker noise) docs/generators.md gives the figures.
"""

from __future__ import annotations

import numpy as np
import pytest
from _demos import default_repertoire

from perception.pipeline import recognize_tracks
from perception.recognition.rules import VerdictRules
from perception.synthetic import sigma_lognormal_clips as sl
from perception.synthetic.independent import draw_independent, independent_tracks

#: condition -> the fields that make it unambiguous (the sigma-lognormal generator's names)
PLAIN = {"normal": {}, "delayed": {"delayed_onset": 0.6}, "open-close-open": {"oco_depth": 0.5},
         "reach": {}}


def _tracks(generator: str, condition: str, seed: int):
    rng = np.random.default_rng(seed)
    if generator == "independent":
        return independent_tracks(draw_independent(condition, rng), seed)[0]
    clip = sl.draw_sigma_lognormal_clip(condition, rng, fps=60.0, jitter=0.0003, drift=0.0005,
                                        spike_rate=0.0, dropout_rate=0.0, **PLAIN[condition])
    return sl.clip_tracks(clip, seed)[0]


@pytest.fixture(scope="module")
def rep():
    return default_repertoire()


@pytest.mark.parametrize("generator", ["independent", "sigma-lognormal"])
@pytest.mark.parametrize("seed", [1, 2])
def test_each_condition_is_judged_on_its_own_landmark(rep, generator, seed):
    rules = VerdictRules()
    got = {}
    for condition in PLAIN:
        rec = recognize_tracks(_tracks(generator, condition, seed), rep, clip=condition)
        got[condition] = rec
    normal, delayed = got["normal"], got["delayed"]
    oco, reach = got["open-close-open"], got["reach"]
    # a healthy grasp opens once, early
    assert normal.verdict == "normal" and normal.landmarks[0].aperture_peaks == 1
    assert normal.landmarks[0].opening_time < rules.late_opening
    # a delayed grasp is abnormal because it starts to open late: the landmark, not the fit
    assert delayed.landmarks[0].opening_time > rules.late_opening
    assert (delayed.verdict, delayed.verdict_rule, delayed.verdict_detail) == (
        "abnormal", "grip-departs", "delayed-opening")
    # an open-close-open grasp because its aperture has two peaks
    assert oco.landmarks[0].aperture_peaks == 2
    assert (oco.verdict, oco.verdict_detail) == ("abnormal", "re-opening")
    assert "2 aperture peaks" in oco.verdict_reason
    # a reach keeps its digits closed and fits the reach models
    assert reach.verdict == "reach" and reach.landmarks[0].aperture_peaks == 0

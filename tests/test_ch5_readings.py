"""tools/thesis/ch5_readings.py: eqs. 5.1/5.7 under every reading the thesis allows."""

import sys
from pathlib import Path

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from perception.pipeline import RecognitionSettings, recognize_clip  # noqa: E402
from perception.recognition import HammerParams  # noqa: E402
from tools.thesis.ch5_readings import (  # noqa: E402
    ALLOWED,
    READINGS,
    balanced_ratio,
    oco_landmarks,
    reading_clip,
    reading_terms,
    survived,
)


@pytest.fixture(scope="module")
def recs():
    rep = default_repertoire()
    tracks = demo_tracks("open-close-open", 1)[0]
    return {sign: recognize_clip(tracks, rep, RecognitionSettings(
        hammer=HammerParams(thesis_sign=sign))) for sign in ("text", "printed")}


def test_text_and_printed_are_the_engines_own(recs):
    # the same predictions scored here give the engine's confidence under either sign
    for sign, rec in recs.items():
        d = reading_clip(rec, sign, 1.0, 2.0)
        for i, name in enumerate(rec.names):
            np.testing.assert_allclose(d["confidence"][name], rec.confidence[i], atol=1e-12)
            np.testing.assert_allclose(d["transport_confidence"][name],
                                       np.cumsum(rec.dC_r[i]), atol=1e-12)


def test_literal_and_consecutive_readings(recs):
    rec = recs["text"]
    text_r, text_g, path = reading_terms(rec, "text", 1.0, 2.0)
    printed_r, printed_g, _ = reading_terms(rec, "printed", 1.0, 2.0)
    literal_r, literal_g, _ = reading_terms(rec, "literal", 1.0, 2.0)
    # to the letter, the distance's sign is the opposite of line 1070's; the grip's the same
    np.testing.assert_allclose(literal_r, -printed_r)
    np.testing.assert_allclose(literal_g, printed_g)
    # every reading earns at most the prediction's path, one step at a time
    assert np.all(np.abs(text_r + text_g) <= path + 1e-15)
    # consecutive: the predicted change is between the model's own predictions
    cons_r, _, _ = reading_terms(rec, "consecutive", 1.0, 2.0)
    r_pred, r_obs = rec.predicted_r, rec.observation.r
    n = int(np.flatnonzero(rec.scored[0, 1:] & rec.scored[0, :-1])[5]) + 1
    dpred = r_pred[0, n] - r_pred[0, n - 1]
    dobs = r_obs[n] - r_obs[n - 1]
    assert cons_r[0, n] == pytest.approx(np.sign(dobs) * np.sign(dpred) * abs(dpred))
    with pytest.raises(ValueError, match="reading"):
        reading_terms(rec, "sideways", 1.0, 2.0)


def test_the_balancing_ratio_equalises_the_terms(recs):
    rec = recs["text"]
    model = "grasp-1.0s"
    ratio = balanced_ratio([rec], model)
    i = rec.names.index(model)
    dC_r, dC_g, _ = reading_terms(rec, "text", 2.0 * ratio, 2.0)
    assert np.abs(dC_r[i]).sum() == pytest.approx(np.abs(dC_g[i]).sum())


def test_a_claim_holds_only_under_every_allowed_reading():
    every = dict.fromkeys(READINGS, "agree")
    assert survived(every) == ("agree", "survives text, printed, literal, consecutive")
    # a reading the thesis does not allow cannot make or break a claim
    assert set(READINGS) - set(ALLOWED) == {"literal"}
    assert survived({**every, "literal": "differs"})[0] == "agree"
    verdict, words = survived({**every, "printed": "differs"})
    assert verdict == "conditional" and words == ("survives text, literal, consecutive; "
                                                  "not printed")
    assert survived({r: "differs" for r in READINGS})[0] == "differs"


def test_open_close_open_landmarks():
    phase = np.linspace(0, 1, 101)
    g = np.interp(phase, [0, 0.45, 0.68, 0.88, 1], [0.0, 0.1, 0.04, 0.125, 0.1])
    first, closed, again = oco_landmarks(phase, g)
    assert (first, closed, again) == pytest.approx((0.45, 0.68, 0.88))
    assert oco_landmarks(phase, np.interp(phase, [0, 0.7, 1], [0, 0.12, 0.1])) is None

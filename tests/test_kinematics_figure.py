"""The per-trial kinematics figure: speed and aperture with their landmarks, in every report."""

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

from perception.batch import ClipResult, summary_table
from perception.pipeline import recognize_clip
from perception.recognition.rules import Verdict
from perception.report import ClipSummary, write_batch_report, write_clip_report
from perception.report.clip import clip_figures, clip_outputs
from perception.report.kinematics import kinematic_traces, kinematics_figure, kinematics_title


@pytest.fixture(scope="module")
def recs():
    rep = default_repertoire()
    return {cond: recognize_clip(demo_tracks(cond, 0)[0], rep, clip=f"{cond}-0")
            for cond in ("normal", "delayed")}


def _gid(ax, gid):
    return [line for line in ax.get_lines() if line.get_gid() == gid]


def test_two_panels_sharing_time_titled_with_the_verdict(recs):
    for rec in recs.values():
        fig = kinematics_figure(rec)
        top, grip = fig.axes
        assert len(fig.axes) == 2
        assert top.get_shared_x_axes().joined(top, grip)
        assert "mm/s" in top.get_ylabel() and "mm" in grip.get_ylabel()
        assert "(s)" in grip.get_xlabel()
        title = fig.texts[0].get_text()
        verdict = rec.verdict + (f" ({rec.verdict_detail})" if rec.verdict_detail else "")
        assert title == f"{rec.clip}: {verdict}, familiarity {rec.decision.familiarity:.2f}"


def test_the_title_names_the_kind_of_an_abnormal_verdict():
    def rec(verdict, detail, familiarity):
        return SimpleNamespace(clip="c", winner="grasp-1.0s", verdict_detail=detail,
                               decision=Verdict(verdict, 0, familiarity, 1.0))

    assert kinematics_title(rec("abnormal", "delayed-opening", 0.004)) == (
        "c: abnormal (delayed-opening), familiarity 0.00")
    assert kinematics_title(rec("normal", None, 0.876)) == "c: normal, familiarity 0.88"
    assert kinematics_title(rec(None, None, math.nan)) == (
        "c: no verdict (winner grasp-1.0s), familiarity n/a")


def test_the_marks_sit_at_the_landmarks(recs):
    rec = recs["normal"]
    lm = rec.landmarks[0]
    fig = kinematics_figure(rec)
    top, grip = fig.axes
    t0 = rec.time_origin  # drawn on the recording's (the tracks') clock
    for ax in (top, grip):  # the movement's bounds cross both panels
        for gid, t in (("onset", lm.onset_time + t0), ("end", lm.end_time + t0)):
            (line,) = _gid(ax, gid)
            np.testing.assert_allclose(line.get_xdata(), [t, t])
    (mga,) = _gid(grip, "mga")
    assert mga.get_xdata()[0] == pytest.approx(
        lm.onset_time + t0 + lm.mga_time * lm.movement_time)
    assert abs(mga.get_ydata()[0] - lm.mga * 1000) < 1e-6
    assert any(t.get_text() == f"MGA {lm.mga * 1000:.0f} mm" for t in grip.texts)
    (peak,) = _gid(top, "peak_speed")
    assert peak.get_xdata()[0] == pytest.approx(
        lm.onset_time + t0 + lm.peak_speed_time * lm.movement_time)
    assert peak.get_ydata()[0] == pytest.approx(lm.peak_speed * 1000)
    (opening,) = _gid(grip, "opening")
    assert opening.get_xdata()[0] == pytest.approx(
        lm.onset_time + t0 + lm.opening_time * lm.movement_time)
    # the marks lie on the curves the landmarks are measured on
    time, speed, aperture = kinematic_traces(rec.observation)
    assert np.nanmax(speed) == pytest.approx(lm.peak_speed)
    assert np.interp(mga.get_xdata()[0], time + t0, aperture) * 1000 == pytest.approx(
        lm.mga * 1000, rel=1e-3)
    # the shaded movement
    spans = [p for p in top.patches if p.get_x() == pytest.approx(lm.onset_time + t0)]
    assert spans and spans[0].get_width() == pytest.approx(lm.end_time - lm.onset_time)


def test_what_was_not_measured_is_not_drawn(recs):
    rec = recs["normal"]
    nan = dataclasses.replace(rec.landmarks[0], onset_time=math.nan, mga=math.nan,
                              opening_time=math.nan)
    rec = dataclasses.replace(rec)
    rec.__dict__["landmarks"] = (nan, None)  # the cached property, replaced
    top, grip = kinematics_figure(rec).axes
    assert not _gid(top, "onset") and not _gid(grip, "mga") and not _gid(grip, "opening")
    assert not top.patches  # no movement to shade without its onset
    assert _gid(top, "end") and not _gid(top, "peak_speed")  # its time needs the onset


def test_an_observation_without_the_clip_arrays_uses_its_own(recs):
    rec = recs["normal"]
    old = dataclasses.replace(rec.observation, clip_time=None, clip_raw=None)
    time, speed, aperture = kinematic_traces(old)
    np.testing.assert_array_equal(time, old.time)
    assert speed.shape == aperture.shape == time.shape and np.isfinite(aperture).any()
    fig = kinematics_figure(dataclasses.replace(rec, observation=old))
    assert len(fig.axes) == 2


def test_the_clip_report_writes_it_and_the_batch_page_shows_it(recs, tmp_path):
    rec = recs["normal"]
    paths = write_clip_report(rec, tmp_path)
    png = paths["kinematics_png"]
    assert png == tmp_path / "normal-0.kinematics.png"
    assert png.read_bytes().startswith(b"\x89PNG")
    assert png in clip_figures(tmp_path, rec.clip)
    results = [ClipResult(rec.clip, "normal", "ok", summary=ClipSummary.from_recognition(rec))]
    write_batch_report(summary_table(results), {rec.clip: results[0].summary}, tmp_path)
    page = (tmp_path / "report.html").read_text()
    assert '<a href="normal-0.kinematics.png"><img class=thumb src="normal-0.kinematics.png"' \
        in page

    none = tmp_path / "none"
    write_clip_report(rec, none, figures=False)
    assert not clip_outputs(none, rec.clip)["kinematics_png"].exists()
    write_clip_report(rec, tmp_path, figures=False)  # an earlier run's figure goes
    assert not png.exists()


def test_the_curves_and_the_speed_bound_are_those_the_landmarks_were_measured_by():
    """A user's [verdict.landmarks] (cutoff, threshold) draws the figure, the JSON's
    traces and the batch's profiles, not the defaults."""
    from perception.landmarks import LandmarkParams
    from perception.pipeline import RecognitionSettings
    from perception.recognition.rules import VerdictRules
    from perception.report.clip import clip_traces

    own = LandmarkParams(cutoff=4.0, threshold=0.1)
    rec = recognize_clip(demo_tracks("normal", 0)[0], default_repertoire(),
                         RecognitionSettings(rules=VerdictRules(landmarks=own)), clip="own")
    time, speed, _ = kinematic_traces(rec.observation, own)
    _, default_speed, _ = kinematic_traces(rec.observation)
    assert np.nanmax(np.abs(speed - default_speed)) > 1e-3  # the cutoff matters here
    np.testing.assert_allclose(clip_traces(rec)["wrist_speed"], np.round(speed, 6))
    top, _ = kinematics_figure(rec).axes
    (drawn,) = [ln for ln in top.get_lines() if ln.get_label().endswith("speed")
                and len(ln.get_xdata()) > 2]
    np.testing.assert_allclose(drawn.get_ydata(), speed * 1000)
    (bound,) = _gid(top, "bound")
    np.testing.assert_allclose(bound.get_ydata()[0], 0.1 * rec.landmarks[0].peak_speed * 1000)

"""Honest labels (issue 44 item 6) and the figures' clocks (item 2): the transport point
named for what it is where no wrist was recorded, a synthesised wrist never drawn as
observed, and the kinematics figure's time axis saying which clock it is on."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

from perception.pipeline import recognize_tracks
from perception.recordings import MocapImport, read_reaches, recognize_reach
from perception.report.clip import ClipSummary
from perception.report.figures import paths_figure
from perception.report.kinematics import kinematics_figure
from perception.report.paper import condition_kinematics_figure

OPTOTRAK = Path(__file__).parent / "data" / "mocap" / "optotrak-trials.tsv"


@pytest.fixture(scope="module")
def mocap():
    """A real Optotrak reach: index and thumb markers only, no wrist."""
    reach = read_reaches(OPTOTRAK, MocapImport(rate=85))[0]
    assert reach.wrist is None
    return recognize_reach(reach, default_repertoire())[0]


@pytest.fixture(scope="module")
def video():
    """A clip whose wrist was tracked."""
    return recognize_tracks(demo_tracks("normal", 0)[0], default_repertoire())


def _texts(fig) -> list[str]:
    """Every axis label, legend entry, title and annotation of a figure."""
    out = [fig._suptitle.get_text()] if fig._suptitle is not None else []
    for ax in fig.axes:
        out += [ax.get_xlabel(), ax.get_ylabel(), ax.get_title()]
        out += [t.get_text() for t in ax.texts]
        if ax.get_legend() is not None:
            out += [t.get_text() for t in ax.get_legend().get_texts()]
    for legend in fig.legends:
        out += [t.get_text() for t in legend.get_texts()]
    return out


def test_the_observation_knows_a_synthesised_wrist(mocap, video):
    assert mocap.wrist_synthesised and mocap.transport_point == "grip midpoint"
    assert not video.wrist_synthesised and video.transport_point == "wrist"
    assert mocap.to_dict()["transport_point"] == "grip midpoint"
    assert ClipSummary.from_dict(mocap.to_dict()).transport_point == "grip midpoint"


def test_the_kinematics_figure_names_the_transport_point(mocap, video):
    """Before: "wrist speed" on a recording with no wrist marker."""
    texts = _texts(kinematics_figure(mocap))
    assert "grip midpoint speed (mm/s)" in texts and "grip midpoint speed" in texts
    assert not any("wrist" in t for t in texts), texts
    assert "wrist speed (mm/s)" in _texts(kinematics_figure(video))


def test_paths_png_does_not_draw_a_synthesised_wrist_as_observed(mocap, video):
    """Before: a solid "wrist observed" path placed 6 cm behind the grip."""
    fig = paths_figure(mocap)
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert "wrist observed" not in labels
    assert "finger observed" in labels and "thumb observed" in labels
    assert any("wrist not recorded" in t for t in _texts(fig))
    lines = {line.get_label(): line for line in paths_figure(video).axes[0].get_lines()}
    assert lines["wrist observed"].get_linestyle() == "-"


def test_the_condition_figure_names_the_transport_point(mocap, video):
    fig = condition_kinematics_figure([mocap], ["a"])
    assert "grip midpoint speed (mm/s)" in _texts(fig)
    mixed = _texts(condition_kinematics_figure([mocap, video], ["a", "a"]))
    assert "transport (wrist or grip midpoint) speed (mm/s)" in mixed


def test_the_kinematics_figure_says_which_clock_it_is_on(mocap):
    """Before: "time (s)" on the reach window's clock, whatever the recording's."""
    lm = mocap.landmarks[0]
    # recognize_reach knows the recording's clock: the reach's onset row in the file
    assert np.isfinite(mocap.time_origin)
    unknown = dataclasses.replace(mocap, time_origin=math.nan)
    fig = kinematics_figure(unknown)
    assert fig.axes[1].get_xlabel() == "time from the scored movement's start (s)"
    onset = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "onset"][0]
    assert onset.get_xdata()[0] == pytest.approx(lm.onset_time)
    # on the recording's clock where the recognition knows it: every mark moves with it
    shifted = dataclasses.replace(mocap, time_origin=12.5)
    fig = kinematics_figure(shifted)
    assert fig.axes[1].get_xlabel() == "time on the recording's clock (s)"
    onset = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "onset"][0]
    assert onset.get_xdata()[0] == pytest.approx(lm.onset_time + 12.5)
    peak = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "peak_speed"][0]
    assert peak.get_xdata()[0] == pytest.approx(
        lm.onset_time + lm.peak_speed_time * lm.movement_time + 12.5)
    speed = fig.axes[0].get_lines()[0].get_xdata()
    assert np.nanmin(speed) == pytest.approx(np.nanmin(mocap.observation.clip_time) + 12.5)
    assert any(f"onset {lm.onset_time + 12.5:.2f} s" == t for t in _texts(fig))
    assert unknown.to_dict()["time_origin"] is None
    assert shifted.to_dict()["time_origin"] == 12.5

"""Figures for a paper: per trial, per condition (mean ± SD, onset to end), every landmark;
PNG, SVG and PDF; ``--figure-format`` and ``--dpi``."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

from hammer_mv.cli import main
from perception.batch import ClipResult, summary_table
from perception.pipeline import recognize_tracks
from perception.report.clip import ClipSummary, clip_figures, clip_outputs, write_clip_report
from perception.report.figures import write_figure
from perception.report.kinematics import kinematic_traces, kinematics_figure
from perception.report.paper import (
    POINTS,
    condition_kinematics_figure,
    kinematic_profiles,
    landmark_strip_figure,
)

CONDITIONS = ("normal", "delayed")


@pytest.fixture(scope="module")
def trials():
    """2 conditions x 3 clips, and their conditions."""
    rep = default_repertoire()
    recs = [recognize_tracks(demo_tracks(cond, i)[0], rep, clip=f"{cond}-{i}")
            for cond in CONDITIONS for i in range(3)]
    return recs, [cond for cond in CONDITIONS for _ in range(3)]


def _gid(ax, gid):
    return [line for line in ax.get_lines() if line.get_gid() == gid]


def test_the_trial_figure_marks_its_landmarks_where_they_are(trials):
    rec = trials[0][0]
    lm = rec.landmarks[0]
    fig = kinematics_figure(rec)
    speed, grip = fig.axes
    # drawn on the recording's clock: the observation's times from the tracks' first row
    t0 = rec.time_origin
    assert np.isfinite(t0) and "recording" in speed.get_xlabel() + grip.get_xlabel()
    onset, end = lm.onset_time + t0, lm.end_time + t0
    for ax in (speed, grip):  # onset and end: vertical lines across both panels
        for gid, t in (("onset", onset), ("end", end)):
            (line,) = _gid(ax, gid)
            np.testing.assert_allclose(line.get_xdata(), [t, t])
    (peak,) = _gid(speed, "peak_speed")
    assert peak.get_xdata()[0] == pytest.approx(onset + lm.peak_speed_seconds)
    assert peak.get_ydata()[0] == pytest.approx(lm.peak_speed * 1000)  # mm/s
    (mga,) = _gid(grip, "mga")
    assert mga.get_xdata()[0] == pytest.approx(onset + lm.mga_seconds)
    assert mga.get_ydata()[0] == pytest.approx(lm.mga * 1000)  # mm
    labels = {t.get_text() for ax in fig.axes for t in ax.texts}
    assert {f"peak {lm.peak_speed * 1000:.0f} mm/s", f"MGA {lm.mga * 1000:.0f} mm",
            f"onset {onset:.2f} s", f"end {end:.2f} s"} <= labels
    assert "Fig." not in fig.get_suptitle()


def _resampled(rec, share):
    time, speed, aperture = kinematic_traces(rec.observation)
    lm = rec.landmarks[0]
    at = (time - lm.onset_time) / (lm.end_time - lm.onset_time)
    return (np.interp(share, at, speed * 1000, left=np.nan, right=np.nan),
            np.interp(share, at, aperture * 1000, left=np.nan, right=np.nan))


def test_the_condition_mean_is_the_mean_of_the_trials_onset_to_end(trials):
    recs, conds = trials
    fig = condition_kinematics_figure(recs, conds)
    speed, grip = fig.axes
    k = 37  # one point: 37 % of the movement
    share = np.linspace(0, 1, POINTS)
    for cond in CONDITIONS:
        curves = [_resampled(r, share) for r, c in zip(recs, conds) if c == cond]
        for ax, which in ((speed, 0), (grip, 1)):
            (line,) = _gid(ax, cond)
            values = np.array([c[which][k] for c in curves])
            assert line.get_xdata()[k] == pytest.approx(37.0)
            assert line.get_ydata()[k] == pytest.approx(values.mean())
            assert line.get_label() == f"{cond} (n=3)"
    prof = kinematic_profiles(recs, conds)
    row = prof[(prof["condition"] == "delayed")].iloc[k]
    grips = np.array([_resampled(r, share)[1][k] for r, c in zip(recs, conds) if c == "delayed"])
    assert row["aperture_sd"] == pytest.approx(grips.std(ddof=1))
    assert len(speed.collections) == len(grip.collections) == 2  # an SD band per condition
    assert "Fig." not in fig.get_suptitle()


def test_summaries_give_the_same_profiles_with_their_traces(trials):
    """A ClipSummary gives the Recognition's curves from its ``traces``; without them only
    its aperture (the report's) and no speed."""
    recs, conds = trials
    with_traces = []
    for rec in recs:
        time, speed, aperture = kinematic_traces(rec.observation)
        d = json.loads(json.dumps({**rec.to_dict(), "traces": {
            "time": time.tolist(), "wrist_speed": speed.tolist(), "aperture": aperture.tolist()}}))
        with_traces.append(ClipSummary.from_dict(d))
    a, b = kinematic_profiles(recs, conds), kinematic_profiles(with_traces, conds)
    np.testing.assert_allclose(a.drop(columns="condition").to_numpy(float),
                               b.drop(columns="condition").to_numpy(float))
    bare = [ClipSummary.from_dict(json.loads(json.dumps(r.to_dict()))) for r in recs]
    profiles = kinematic_profiles(bare, conds)
    assert (profiles["speed_n"] == 0).all() and (profiles["aperture_n"] == 3).all()
    speed, grip = condition_kinematics_figure(bare, conds).axes
    assert not speed.get_lines() and len(grip.get_lines()) == 2


def _points(ax) -> int:
    return sum(len(c.get_offsets()) for c in ax.collections if c.get_gid() == "trials")


def test_the_strip_plot_has_a_point_per_trial_and_landmark(trials):
    recs, conds = trials
    results = [ClipResult(r.clip, c, "ok", summary=ClipSummary.from_recognition(r))
               for r, c in zip(recs, conds)]
    summary = summary_table(results)
    fig = landmark_strip_figure(summary)
    titles = [ax.get_title() for ax in fig.axes]
    # summary.csv has no opening_time: its panel is left out
    assert titles == ["movement time", "peak speed", "time to peak speed", "MGA", "time to MGA"]
    assert [_points(ax) for ax in fig.axes] == [6] * 5
    assert "(ms)" in fig.axes[0].get_ylabel() and "(mm/s)" in fig.axes[1].get_ylabel()
    (mt,) = [c for c in fig.axes[0].collections if c.get_gid() == "trials"][:1]
    assert sorted(mt.get_offsets()[:, 1]) == pytest.approx(
        sorted(summary["movement_time"][:3] * 1000))

    # landmarks.csv's long form, with a participant: all six, coloured by participant
    rows = []
    for r, cond, who in zip(recs, conds, ["p1", "p2", "p3"] * 2):
        lm = r.landmarks[0]
        for name, scale in (("movement_time", 1e3), ("peak_speed", 1e3), ("mga", 1e3),
                            ("peak_speed_time", 100), ("mga_time", 100), ("opening_time", 100),
                            ("rest_aperture", 1e3)):
            rows.append({"clip": r.clip, "condition": cond, "participant": who,
                         "landmark": name, "value": getattr(lm, name) * scale, "unit": "",
                         "status": "complete"})  # the movement's, as landmarks.csv has it
    rows.append({"clip": "lost", "condition": conds[0], "participant": "p1",  # no reach in it
                 "landmark": "mga", "value": np.nan, "unit": "mm", "status": "no reach"})
    import pandas as pd

    fig = landmark_strip_figure(pd.DataFrame(rows))
    assert len(fig.axes) == 6 and [_points(ax) for ax in fig.axes] == [6] * 6
    colours = np.concatenate([c.get_facecolors() for c in fig.axes[3].collections
                              if c.get_gid() == "trials"])
    assert len({tuple(c) for c in colours}) == 3  # one per participant
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["p1", "p2", "p3"]

    # a study where only some trials name their participant: the others drawn grey, not
    # a report that fails (list.index of a NaN participant raised)
    some = pd.DataFrame(rows).assign(participant=lambda t: t["participant"].where(
        t["clip"] != recs[0].clip))
    fig = landmark_strip_figure(some)
    assert [_points(ax) for ax in fig.axes] == [6] * 6
    colours = {tuple(c) for c in np.concatenate([c.get_facecolors() for c in fig.axes[3].collections
                                                 if c.get_gid() == "trials"])}
    assert (0.6, 0.6, 0.6, 1.0) in colours and len(colours) == 4
    assert sorted(t.get_text() for t in fig.legends[0].get_texts()) == ["p1", "p2", "p3"]


@pytest.mark.parametrize("fmt", ["png", "svg", "pdf"])
def test_write_figure_writes_valid_files(trials, tmp_path, fmt):
    recs, conds = trials
    for name, fig in (("trial", kinematics_figure(recs[0])),
                      ("conditions", condition_kinematics_figure(recs, conds))):
        path = write_figure(fig, tmp_path / f"{name}.x", fmt, 150)
        assert path == tmp_path / f"{name}.x.{fmt}"
        data = path.read_bytes()
        if fmt == "png":
            assert data.startswith(b"\x89PNG\r\n\x1a\n")
            width = int.from_bytes(data[16:20], "big")
            assert width == round(fig.get_figwidth() * 150)
        elif fmt == "svg":
            root = ET.fromstring(data)
            ns = "{http://www.w3.org/2000/svg}"
            assert root.tag == f"{ns}svg"
            assert len(root.findall(f".//{ns}path")) > 10  # the lines, as vectors
            assert not root.findall(f".//{ns}image")  # no raster inside
            assert any(t.text and "mm" in t.text for t in root.iter(f"{ns}text"))  # text
        else:
            assert data.startswith(b"%PDF") and b"/Subtype /Image" not in data  # vector
        # the same figure is the same file: no date stamped (matplotlib writes the time)
        again = write_figure(fig, tmp_path / f"{name}.again", fmt, 150).read_bytes()
        assert again == data and b"<dc:date>" not in data and b"/CreationDate" not in data
    with pytest.raises(ValueError, match="png, svg, pdf"):
        write_figure(kinematics_figure(recs[0]), tmp_path / "x", "jpg", 100)
    with pytest.raises(ValueError, match="dpi"):
        write_figure(kinematics_figure(recs[0]), tmp_path / "x", fmt, 0)


def test_the_clip_report_follows_the_format_and_drops_another_format(trials, tmp_path):
    rec = trials[0][0]
    png = write_clip_report(rec, tmp_path)
    svg = write_clip_report(rec, tmp_path, figure_format="svg", dpi=200)
    for key in ("confidence_png", "paths_png", "kinematics_png"):
        assert svg[key].suffix == ".svg" and svg[key].exists() and not png[key].exists()
    assert clip_figures(tmp_path, rec.clip) == [svg[k] for k in (
        "confidence_png", "paths_png", "kinematics_png")]
    assert clip_outputs(tmp_path, rec.clip, "pdf")["paths_png"].name == "normal-0.paths.pdf"
    write_clip_report(rec, tmp_path, figures=False)
    assert not any(p.suffix in (".png", ".svg", ".pdf") for p in tmp_path.iterdir())


def test_recognize_writes_svgs_with_figure_format_and_dpi(tmp_path):
    rep = default_repertoire().save(tmp_path / "rep.h5")
    tracks = demo_tracks("normal", 0)[0].save(tmp_path / "n.tracks.h5")
    out = tmp_path / "out"
    assert main(["recognize", str(tracks), "-o", str(out), "--repertoire", str(rep),
                 "--figure-format", "svg", "--dpi", "200", "--quiet"]) == 0
    figures = sorted(p.name for p in out.iterdir() if p.suffix in (".png", ".svg", ".pdf"))
    assert figures == ["n.confidence.svg", "n.kinematics.svg", "n.paths.svg"]
    for name in figures:
        assert ET.parse(out / name).getroot().tag.endswith("svg")
    with pytest.raises(SystemExit):
        main(["recognize", str(tracks), "-o", str(out), "--dpi", "0"])


@pytest.mark.slow
def test_svg_and_png_figures_render_in_a_browser(trials, tmp_path):
    from test_report_browser import _chromium, _run

    browser = _chromium()
    recs, conds = trials
    write_figure(kinematics_figure(recs[0]), tmp_path / "trial", "svg")
    write_figure(condition_kinematics_figure(recs, conds), tmp_path / "conditions", "png")
    write_figure(condition_kinematics_figure(recs, conds), tmp_path / "conditions", "svg")
    probe = ("<script>window.addEventListener('load', () => { const i = "
             "Array.from(document.images); const p = document.createElement('pre'); "
             "p.id = 'probe'; p.textContent = i.map(x => x.complete && x.naturalWidth > 0 ? "
             "x.naturalWidth : 0).join(','); document.body.appendChild(p); });</script>")
    page = tmp_path / "page.html"
    page.write_text(f"<!doctype html><html><head>{probe}</head><body>"
                    '<img src="trial.svg"><img src="conditions.png"><img src="conditions.svg">'
                    "</body></html>")
    dom = _run(browser, tmp_path / "profile", "--dump-dom", page.as_uri())
    widths = [int(w) for w in dom.split('<pre id="probe">')[1].split("</pre>")[0].split(",")]
    assert len(widths) == 3 and all(w > 0 for w in widths), widths


def test_a_batch_writes_every_figure_in_its_format_and_shows_them(tmp_path):
    rep = default_repertoire().save(tmp_path / "rep.h5")
    src = tmp_path / "clips"
    src.mkdir()
    rows = ["clip,video,condition,participant"]
    for cond in CONDITIONS:
        for i in range(2):
            demo_tracks(cond, i)[0].save(src / f"{cond}-{i}.tracks.h5")
            rows.append(f"{cond}-{i},{cond}-{i}.tracks.h5,{cond},p{i}")
    (src / "manifest.csv").write_text("\n".join(rows) + "\n")
    out = tmp_path / "out"
    batch = ["kinematic_profiles", "landmark_strips", "aperture_profiles", "confidence_single",
             "confidence_all", "condition_profiles"]
    for fmt in ("svg", "pdf"):  # the second run's figures replace the first's
        assert main(["batch", str(src / "manifest.csv"), "-o", str(out), "--repertoire",
                     str(rep), "--figure-format", fmt, "--dpi", "90", "--quiet"]) == 0
        figures = {p.name for p in out.iterdir() if p.suffix in (".png", ".svg", ".pdf")}
        assert figures == {f"{s}.{fmt}" for s in batch} | {
            f"{c}-{i}.{k}.{fmt}" for c in CONDITIONS for i in range(2)
            for k in ("confidence", "paths", "kinematics")}
        page = (out / "report.html").read_text()
        if fmt == "svg":
            assert '<img src="kinematic_profiles.svg"' in page
            assert '<img class=thumb src="normal-0.kinematics.svg" loading="lazy"' in page
        else:  # no <img> shows a PDF: a link
            assert '<a href="landmark_strips.pdf">landmark_strips.pdf (PDF)</a>' in page
            assert "<img" not in page
    # rerun: every clip reused, its speed read back from its report's traces
    assert main(["batch", str(src / "manifest.csv"), "-o", str(out), "--repertoire", str(rep),
                 "--figure-format", "pdf", "--quiet"]) == 0
    import pandas as pd

    assert pd.read_csv(out / "summary.csv")["reused"].all()
    prof = pd.read_csv(out / "kinematic_profiles.csv")
    assert set(prof["condition"]) == set(CONDITIONS) and (prof["speed_n"] == 2).all()

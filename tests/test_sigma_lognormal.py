"""The second generator (sigma-lognormal strokes, grip pulses, marker noise): draws within their
declared distributions, conditions that differ as declared, reproducible seeds, a rendered clip
that the tracker turns into tracks, and no import of the minimum variance model or of the
generator the rules are tuned on."""

import ast
import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from perception.io.tracks import Tracks
from perception.synthetic.sigma_lognormal import (
    CONDITIONS,
    DISTRIBUTIONS,
    FAST_DURATION,
    FPS_CHOICES,
    SigmaLognormalParams,
    draw_sigma_lognormal,
    lognormal_stroke,
    sigma_lognormal_aperture,
    sigma_lognormal_paths,
)
from perception.synthetic.sigma_lognormal_clips import (
    FILMING,
    clip_tracks,
    draw_sigma_lognormal_clip,
    render_sigma_lognormal_set,
)

ROOT = Path(__file__).resolve().parents[1]
MODULES = [ROOT / "perception" / "synthetic" / name
           for name in ("sigma_lognormal.py", "sigma_lognormal_clips.py")]
TAU = np.linspace(0.0, 1.0, 2001)
QUIET = {"jitter": 0.0, "drift": 0.0, "spike_rate": 0.0, "dropout_rate": 0.0}


def test_it_imports_neither_the_model_nor_the_tuned_generator():
    trees = [ast.parse(m.read_text()) for m in MODULES]
    imported = {a.name for t in trees for n in ast.walk(t) if isinstance(n, ast.Import)
                for a in n.names}
    imported |= {n.module for t in trees for n in ast.walk(t) if isinstance(n, ast.ImportFrom)}
    banned = [m for m in imported if m and (m.split(".")[0] == "minvar" or m.startswith(
        ("perception.synthetic.independent", "perception.synthetic.population",
         "perception.synthetic.stimuli")))]
    assert not banned, banned
    # and at run time: drawing, tracks and the scene load none of them (minvar's shared
    # validation helpers are no part of the model)
    code = ("import sys, numpy as np\n"
            "NOT_THE_MODEL = {'minvar._version', 'minvar.errors', 'minvar.limits', "
            "'minvar.validation'}\n"
            "from perception.synthetic.sigma_lognormal_clips import draw_sigma_lognormal_clip, "
            "clip_tracks\n"
            "clip_tracks(draw_sigma_lognormal_clip('open-close-open', "
            "np.random.default_rng(1)), 1)\n"
            "used = [m for m in sys.modules if (m.startswith('minvar.') and m not in "
            "NOT_THE_MODEL) or m in ('perception.synthetic.independent', "
            "'perception.synthetic.population', 'perception.synthetic.stimuli')]\n"
            "assert not used, used\n")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_draws_stay_within_their_declared_distributions():
    seen_fps, durations = set(), []
    for seed in range(150):
        rng = np.random.default_rng(seed)
        p = draw_sigma_lognormal(CONDITIONS[seed % 4], rng)
        for name, (_, _, _, lo, hi) in DISTRIBUTIONS.items():
            value = getattr(p, name)
            if name in ("corrective", "aim_error") and value == 0.0:
                continue  # a movement without a corrective stroke
            assert lo <= value <= hi, (name, value)
        durations.append(p.duration)
        fast = draw_sigma_lognormal("normal", rng, fast=True)
        assert FAST_DURATION[0] <= fast.duration <= FAST_DURATION[1]
        clip = draw_sigma_lognormal_clip("normal", np.random.default_rng(seed))
        seen_fps.add(clip.fps)
        assert clip.camera.px_per_m <= FILMING["px_per_m"][1]
        assert FILMING["camera_angle_deg"][0] <= clip.camera.angle_deg <= \
            FILMING["camera_angle_deg"][1]
        assert clip.style.exposure <= FILMING["exposure_share"][1] / clip.fps + 1e-12
    assert seen_fps == set(FPS_CHOICES)
    # the healthy population's movement times spread over their range, not piled at a bound
    assert np.percentile(durations, 10) < 0.8 and np.percentile(durations, 90) > 1.0
    # a share of the movements carries a corrective stroke, the rest one stroke
    rng = np.random.default_rng(0)
    share = np.mean([draw_sigma_lognormal("normal", rng).corrective > 0 for _ in range(300)])
    assert 0.3 < share < 0.6


def test_every_drawn_clip_keeps_the_hand_in_its_frame():
    from perception.synthetic import sigma_lognormal_clips as clips

    for seed in range(120):
        for fast in (False, True):
            clip = draw_sigma_lognormal_clip(CONDITIONS[seed % 4], np.random.default_rng(seed),
                                             fast=fast)
            _, paths = sigma_lognormal_paths(clip.params, clip.fps, seed=seed)  # with noise
            assert clips._fits(paths, clip.camera, clip.style), (seed, fast)
    fixed = draw_sigma_lognormal_clip("normal", np.random.default_rng(1), fps=30.0,
                                      duration=0.5)
    drawn = draw_sigma_lognormal_clip("normal", np.random.default_rng(1))
    assert (fixed.fps, fixed.params.duration) == (30.0, 0.5)
    assert fixed.params.distance == drawn.params.distance  # every other draw the same


def test_seeds_are_reproducible_and_differ():
    a = draw_sigma_lognormal_clip("delayed", np.random.default_rng(11))
    b = draw_sigma_lognormal_clip("delayed", np.random.default_rng(11))
    c = draw_sigma_lognormal_clip("delayed", np.random.default_rng(12))
    assert a == b and a != c
    ta, tb = clip_tracks(a, 5)[0], clip_tracks(b, 5)[0]
    np.testing.assert_array_equal(ta.position, tb.position)
    assert not np.allclose(np.nan_to_num(clip_tracks(a, 6)[0].position),
                           np.nan_to_num(ta.position))


def test_a_lognormal_stroke_is_skewed_early_and_ends_exactly():
    u = np.linspace(-0.1, 1.1, 12001)
    for sigma in (0.10, 0.18, 0.26):
        s = lognormal_stroke(u, 0.0, 1.0, sigma)
        assert s[u <= 0].max() == 0 and s[u >= 1].min() == 1
        assert np.all(np.diff(s) >= 0)
        v = np.gradient(s, u)
        peak = u[np.argmax(v)]
        # the speed peaks in the first 28-41 % of the stroke, earlier the larger sigma
        # (a lognormal's mode, e^(mu - sigma^2), inside its +-3 sigma span)
        expected = (math.exp(-sigma**2) - math.exp(-3 * sigma)) / (2 * math.sinh(3 * sigma))
        assert peak == pytest.approx(expected, abs=0.002)
        assert 0.27 < peak < 0.42


def test_the_transport_reaches_the_object_with_or_without_a_corrective_stroke():
    for corrective, aim_error in ((0.0, 0.0), (0.08, 0.012)):
        p = SigmaLognormalParams(corrective=corrective, aim_error=aim_error, arc_deg=12.0,
                                 **QUIET)
        t, paths = sigma_lognormal_paths(p, 500.0)
        mid = 0.5 * (paths["clean"]["finger"] + paths["clean"]["thumb"])
        np.testing.assert_allclose(mid[-1], [0.0, 0.0], atol=1e-6)
        assert np.linalg.norm(paths["clean"]["wrist"][0]) == pytest.approx(p.distance, abs=0.01)
        speed = np.linalg.norm(np.gradient(paths["clean"]["wrist"], t, axis=0), axis=1)
        moving = (t > p.rest_before) & (t < p.rest_before + p.duration)
        assert speed[~moving].max() < 0.05 * speed.max()  # at rest before and after
        bumps = np.sum(np.diff(np.sign(np.diff(speed[moving]))) < 0)
        assert bumps == (1 if corrective == 0 else 2), bumps  # one peak per stroke


def test_the_conditions_differ_as_declared():
    rng = np.random.default_rng(3)
    for _ in range(40):
        for cond in CONDITIONS:
            p = draw_sigma_lognormal(cond, rng)
            g = sigma_lognormal_aperture(p, TAU)
            assert g[-1] == pytest.approx(0.0 if cond == "reach" else p.object_size, abs=1e-9)
            if cond == "reach":
                assert np.all(g == 0)
            elif cond == "delayed":
                # closed through the early transport (>= 40 % of the movement), then one
                # opening to the MGA late
                assert np.all(g[TAU <= p.delayed_onset] == 0) and p.delayed_onset >= 0.40
                assert TAU[np.argmax(g)] == pytest.approx(p.delayed_mga_time, abs=0.01)
            elif cond == "normal":
                # opens early, one maximum; the wobble never closes the grip by 3 mm or more
                assert np.all(g[TAU > 0.3] > 0)
                assert TAU[np.argmax(g)] == pytest.approx(p.mga_time, abs=0.02)
                before = g[TAU <= TAU[np.argmax(g)]]
                drop = np.max(np.maximum.accumulate(before) - before)
                assert drop < 0.003
            else:
                # a first opening, a closing to at most oco_depth of it, a re-opening to the MGA
                first = float(sigma_lognormal_aperture(p, p.oco_first_time))
                assert first == pytest.approx(p.oco_first_fraction * p.mga, rel=1e-9)
                assert g[TAU < p.oco_close_time].max() == pytest.approx(first, abs=1e-5)
                between = (TAU > p.oco_first_time) & (TAU < p.oco_reopen_time)
                assert sigma_lognormal_aperture(p, p.oco_close_time) == pytest.approx(
                    p.oco_depth * first)  # the deepest point, between samples of TAU
                assert g[between].min() <= p.oco_depth * first + 2e-4
                assert first - g[between].min() >= 0.3 * first
                assert g.max() == pytest.approx(p.mga, abs=1.5e-3)  # the first pulse's tail adds
                assert TAU[np.argmax(g)] > p.oco_close_time


@pytest.mark.parametrize("condition", CONDITIONS)
def test_the_digits_stay_out_of_the_object_and_a_reach_touches_it(condition):
    rng = np.random.default_rng(17)
    for _ in range(8):
        p = dataclasses.replace(draw_sigma_lognormal(condition, rng), marker_offset=0.0,
                                **QUIET)
        _, paths = sigma_lognormal_paths(p, 100.0)
        radius = p.object_size / 2
        depth = radius - min(np.linalg.norm(paths["clean"][d], axis=1).min()
                             for d in ("finger", "thumb"))
        assert depth < 0.5e-3, f"a digit {1e3 * depth:.1f} mm inside the object"
        if condition == "reach":
            assert abs(np.linalg.norm(paths["clean"]["finger"][-1]) - radius) < 1e-3


def test_the_noise_is_what_it_declares():
    p = SigmaLognormalParams(jitter=0.001, drift=0.0, spike_rate=0.0, dropout_rate=0.05)
    t, paths = sigma_lognormal_paths(p, 60.0, seed=2)
    residual = paths["finger"] - paths["clean"]["finger"]
    assert residual.std() == pytest.approx(0.001, rel=0.2)
    assert paths["dropped"]["finger"].mean() == pytest.approx(0.05, abs=0.04)
    assert not paths["dropped"]["wrist"].any()  # the wrist band is never dropped
    spiky = SigmaLognormalParams(spike_rate=0.05, spike_size=0.01, **{
        k: v for k, v in QUIET.items() if k != "spike_rate"})
    _, sp = sigma_lognormal_paths(spiky, 60.0, seed=2)
    jump = np.linalg.norm(sp["thumb"] - sp["clean"]["thumb"], axis=1)
    assert set(np.round(jump[jump > 0], 6)) == {0.01}
    tracks = clip_tracks(draw_sigma_lognormal_clip("normal", np.random.default_rng(0)), 0)[0]
    lost = ~np.isfinite(tracks.position).all(axis=-1)
    assert (tracks.status[lost] == 2).all() and (tracks.likelihood[lost] == 0).all()


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="condition"):
        SigmaLognormalParams("wave")
    with pytest.raises(ValueError, match="increase"):
        SigmaLognormalParams("open-close-open", oco_close_time=0.3)
    with pytest.raises(ValueError, match="corrective"):
        SigmaLognormalParams(corrective=0.05, corrective_start=0.8)
    with pytest.raises(ValueError, match="fps"):
        sigma_lognormal_paths(SigmaLognormalParams(), 0)


def test_a_rendered_clip_is_tracked_into_a_tracks_file(tmp_path):
    """One short clip (seed 6: a 0.47 s grasp at 25 frames/s) through the colour tracker."""
    from perception.tracking.video_tracks import track_video

    manifest = render_sigma_lognormal_set(tmp_path, {"normal": 1}, seed=6, fast=True)
    assert list(pd.read_csv(tmp_path / "manifest.csv")["clip"]) == ["normal-01"]
    for column in ("movement_time", "fps", "px_per_m", "peak_velocity_time", "parameters"):
        assert column in manifest.columns
    row = manifest.iloc[0]
    assert row["fps"] == 25.0 and FAST_DURATION[0] <= row["movement_time"] <= FAST_DURATION[1]
    tracks = Tracks.load(track_video(tmp_path / row["video"], tmp_path / "c.tracks.h5"))
    truth = Tracks.load(tmp_path / row["truth"])
    assert tracks.n_frames == truth.n_frames
    for marker in ("finger", "thumb", "wrist"):
        j, k = tracks.markers.index(marker), truth.markers.index(marker)
        err = np.linalg.norm(tracks.position[:, j] - truth.position[:, k], axis=1)
        found = np.isfinite(err)
        assert found.mean() >= 0.8, marker
        assert np.median(err[found]) < 4.0, marker


# -- the evaluation tools on the second generator ------------------------------------

def _tool(name):
    sys.path.insert(0, str(ROOT / "tools"))
    import importlib

    return importlib.import_module(name)


def test_evaluate_verdict_gives_its_tables_on_either_generator_from_tracks(tmp_path):
    ev = _tool("evaluate_verdict")
    args = ev.build_parser().parse_args(["-o", "x"])
    assert (args.generator, args.source) == ("independent", "video")  # defaults unchanged
    for generator in ev.GENERATORS:
        out = tmp_path / generator
        assert ev.main(["--generator", generator, "--source", "tracks", "--quick", "--jobs",
                        "1", "-o", str(out), "--quiet"]) == 0
        result = __import__("json").loads((out / "evaluation.json").read_text())
        assert (result["generator"], result["source"]) == (generator, "tracks")
        assert result["groups"]["all"]["n"] == 4
        assert f"of the `{generator}` generator" in (out / "evaluation.md").read_text()
        assert {c["condition"] for c in result["clips"]} == set(CONDITIONS)
        assert all(c["verdict"] != ev.FAILED for c in result["clips"])


def test_the_tracks_of_a_set_are_the_movements_its_video_shows():
    """Clip k of a set draws from seed first_seed + k whether rendered or kept as tracks."""
    ev = _tool("evaluate_verdict")
    tracks, row = ev.clip_tracks("sigma-lognormal", "fast-dev", "delayed", 20003)
    clip = draw_sigma_lognormal_clip("delayed", np.random.default_rng(20003), fast=True)
    assert row == clip.row() and FAST_DURATION[0] <= row["movement_time"] <= FAST_DURATION[1]
    assert tracks.time[1] == pytest.approx(1 / clip.fps)
    _, independent_row = ev.clip_tracks("independent", "dev", "normal", 1000)
    assert independent_row["fps"] in (25.0, 30.0, 60.0)


def test_online_settling_is_fed_the_held_out_clips_of_the_second_generator(capsys):
    online = _tool("evaluate_online_demos")
    ev = _tool("evaluate_verdict")
    clips = list(online.set_clips("sigma-lognormal", counts={"normal": 1,
                                                              "open-close-open": 2}))
    assert [c for c, _ in clips] == ["normal", "open-close-open", "open-close-open"]
    # clip k of the held-out set: seed 9000 + k, as tools/evaluate_verdict.py draws it
    third = ev.clip_tracks("sigma-lognormal", "heldout", "open-close-open", 9002)[0]
    np.testing.assert_array_equal(clips[2][1].position, third.position)
    fast = next(online.set_clips("sigma-lognormal", fast=True, counts={"reach": 1}))[1]
    assert fast.time[-1] < 0.65 + 2 * 0.5 + 0.05  # a fast grasp and its rests
    online.report({"reach": [("reach", True, 0.5, True), ("reach", False, 1.0, True)]})
    assert "settled before the end 1/2, decision_fraction median 0.75, settled = offline 2/2" \
        in capsys.readouterr().out

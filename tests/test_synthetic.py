"""Stimuli derived from the grasp model, recipes and `hammer-mv synth`."""

import numpy as np
import pytest

from hammer_mv.cli import main
from perception.errors import InputError
from perception.io.tracks import Tracks
from perception.synthetic.recipes import StimulusParams, load_recipe, stimulus_paths


def _aperture(cond, seed=0):
    p = StimulusParams(condition=cond, rest_before=0.0, rest_after=0.0, marker_offset=0.0)
    t, paths = stimulus_paths(p, 100, seed=seed)
    return t / p.duration, np.linalg.norm(paths["finger"] - paths["thumb"], axis=1)


def test_stimulus_apertures_have_their_shapes():
    phase, g = _aperture("normal")
    assert 0.55 <= phase[np.argmax(g)] <= 0.85 and g.max() > 0.11  # MGA above the 10 cm ball
    phase, g = _aperture("delayed")
    assert g[phase <= 0.5].max() < 0.02  # still closed through the first half
    assert phase[np.argmax(g)] > 0.8  # maximal aperture markedly late
    phase, g = _aperture("open-close-open")
    peaks = [i for i in range(1, len(g) - 1) if g[i] > g[i - 1] and g[i] >= g[i + 1]]
    assert len(peaks) == 2
    assert g[peaks[0]:peaks[1]].min() < g[peaks[0]] - 0.06  # a deep unexpected closing
    assert 0.3 < phase[peaks[0]] < 0.6
    phase, g = _aperture("reach")
    assert g.max() < 0.005


def test_recipes_in_datasets_load():
    for name in ("smoke", "gangitano"):
        r = load_recipe(f"datasets/{name}.toml")
        assert set(r.counts) == {"normal", "delayed", "open-close-open"}
    assert load_recipe("datasets/gangitano.toml").n_clips == 30


@pytest.mark.parametrize("text, message", [
    ("[conditions]\nwave = 2\n", "unknown"),
    ("[conditions]\nnormal = 1\n[render]\nfps = -3\n", "fps"),
    ("[conditions]\nnormal = 1\n[scene]\nwobble = 1\n", "wobble"),
    ("not toml [", "TOML"),
])
def test_bad_recipes(tmp_path, text, message):
    path = tmp_path / "r.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=message) as exc:
        load_recipe(path)
    assert str(path) in str(exc.value)


def test_synth_cli_is_reproducible_and_labels_truth(tmp_path):
    recipe = tmp_path / "tiny.toml"
    recipe.write_text("[conditions]\nnormal = 1\ndelayed = 1\n[scene]\nrest_before = 0.1\n"
                      "rest_after = 0.1\n[render]\nwidth = 320\nheight = 240\n")
    for out in ("a", "b"):
        assert main(["synth", str(recipe), "-o", str(tmp_path / out), "--seed", "4",
                     "--quiet"]) == 0
    man_a = (tmp_path / "a" / "manifest.csv").read_text()
    assert man_a == (tmp_path / "b" / "manifest.csv").read_text()
    truth = Tracks.load(tmp_path / "a" / "delayed-01.truth.h5")
    assert truth.attrs["label"] == "delayed"
    again = Tracks.load(tmp_path / "b" / "delayed-01.truth.h5")
    assert np.array_equal(truth.position, again.position)
    assert (tmp_path / "a" / "normal-01.mp4").stat().st_size > 1000


@pytest.mark.parametrize("text, message", [
    ("conditions = 3\n", r"\[conditions\]: expected a table"),
    ("[conditions]\nnormal = 1.7\n", r"\[conditions\] normal: expected an integer"),
    ("[conditions]\nnormal = 1\n[scene]\nmarker_offset = -0.5\n", "marker_offset"),
    ("[conditions]\nnormal = 1\n[variation]\nduration_sd = -0.1\n", "duration_sd"),
    ("[conditions]\nnormal = 3\n[scene]\nduration = 0.15\n[variation]\nduration_sd = 0.3\n",
     "clip normal-0"),
])
def test_recipe_problems_are_found_before_rendering(tmp_path, text, message):
    path = tmp_path / "r.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        load_recipe(path)


def test_a_clip_does_not_depend_on_other_conditions_counts():
    from perception.synthetic.recipes import Recipe, clip_plans

    one = {p[0]: p[2] for p in clip_plans(Recipe("r", {"normal": 1, "delayed": 1},
                                                 duration_sd=0.05), seed=3)}
    two = {p[0]: p[2] for p in clip_plans(Recipe("r", {"normal": 4, "delayed": 2},
                                                 duration_sd=0.05), seed=3)}
    assert one["delayed-01"] == two["delayed-01"] and one["normal-01"] == two["normal-01"]
    assert two["normal-01"] != two["normal-02"]

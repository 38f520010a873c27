"""Setup, colour and recipe files: every value checked at the boundary, naming file and field.

Also: a FIFO named as a setup or colours file is refused at once (not read
for ever), and a clip whose object is hidden in frames 5-9 is observed.
"""

import os
import sys
import threading

import numpy as np
import pytest
from _demos import demo_tracks

from perception.errors import InputError
from perception.io.config import Spec, check_value
from perception.observation import observe
from perception.synthetic.recipes import load_recipe
from perception.tracking.markers import load_markers
from perception.tracking.params import LIMITS, TrackerParams
from perception.tracking.setup import TrackingSetup, load_setup, write_setup

BAD_SETUPS = [
    # tables that are not tables
    ("setup = []\n", "[setup]"),
    ("sizes = 3\n", "[sizes]"),
    ("tracker = \"fast\"\n", "[tracker]"),
    ("markers = 5\n", "[markers]"),
    ("[markers]\nthumb = 3\n", "[markers.thumb]"),
    # [setup]
    ("[setup]\nframes = inf\n", "[setup] frames"),
    ("[setup]\nframes = -1\n", "[setup] frames"),
    ("[setup]\nframes = 2.5\n", "[setup] frames"),
    ("[setup]\nsource = 3\n", "[setup] source"),
    # [tracker]: negative, NaN, huge, out of int32, strings for numbers
    ("[tracker]\nsearch_scale = -1\n", "[tracker] search_scale"),
    ("[tracker]\nalpha = nan\n", "[tracker] alpha"),
    ("[tracker]\nbeta = inf\n", "[tracker] beta"),
    ("[tracker]\nmin_area_px = -5\n", "[tracker] min_area_px"),
    ("[tracker]\nvelocity_margin = 1e300\n", "[tracker] velocity_margin"),
    ("[tracker]\nstill_jump_px = -1e300\n", "[tracker] still_jump_px"),
    ("[tracker]\nterm_max_iter = 9223372036854775807\n", "[tracker] term_max_iter"),
    ("[tracker]\nterm_max_iter = 2147483648\n", "[tracker] term_max_iter"),
    ("[tracker]\nterm_eps_px = 0\n", "[tracker] term_eps_px"),
    ("[tracker]\ninit_candidates = 1000\n", "[tracker] init_candidates"),
    ("[tracker]\nsearch_scale = \"2\"\n", "[tracker] search_scale"),
    ("[tracker]\nsize_tolerance = \"3.0\"\n", "[tracker] size_tolerance"),
    ("[tracker]\nsearch_tries = 2.0\n", "[tracker] search_tries"),
    ("[tracker]\nsearch_tries = true\n", "[tracker] search_tries"),
    ("[tracker]\nstill_markers = \"object\"\n", "[tracker] still_markers"),
    ("[tracker]\nband_elongation = [1.4]\n", "[tracker] band_elongation"),
    ("[tracker]\nmerged_likelihood = 0.5\n", "[tracker] merged_likelihood"),
    ("[tracker]\nlost_ratio = 0.9\nreacquire_ratio = 0.5\n", "[tracker] lost_ratio"),
    # [sizes]
    ("[sizes]\nobject_diameter = nan\n", "[sizes] object_diameter"),
    ("[sizes]\nmarker_diameter = 1e300\n", "[sizes] marker_diameter"),
    ("[sizes]\nband_size = [0.07, -0.02]\n", "[sizes] band_size"),
    ("[sizes]\nband_size = \"wide\"\n", "[sizes] band_size"),
    # [markers.NAME]
    ("[markers.thumb]\nsat_min = 1e300\n", "[markers.thumb] sat_min"),
    ("[markers.thumb]\nval_min = -1\n", "[markers.thumb] val_min"),
    ("[markers.thumb]\nbgr = [1, 2, \"3\"]\n", "[markers.thumb] bgr"),
    ("[markers.thumb]\nrgb = [1, 2, 300]\n", "[markers.thumb] rgb"),
    ("[markers.thumb]\nhue = [[1, 2, 3]]\n", "[markers.thumb] hue"),
    ("[markers.thumb]\nhue = \"red\"\n", "[markers.thumb] hue"),
]


@pytest.mark.parametrize("text, field", BAD_SETUPS)
def test_bad_setup_value_names_file_and_field(tmp_path, text, field):
    path = tmp_path / "lab-setup.toml"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        load_setup(path)
    assert str(err.value).startswith(f"{path}: {field}: "), str(err.value)
    assert err.value.field == field and err.value.path == str(path)


def test_every_tracker_field_has_a_range_and_the_defaults_are_in_it(tmp_path):
    names = {f for f in TrackerParams.__dataclass_fields__}
    assert set(LIMITS) == names
    for name, spec in LIMITS.items():
        default = getattr(TrackerParams(), name)
        assert check_value(list(default) if isinstance(default, tuple) else default,
                           spec) is None, name
        assert f"{name} : {spec.describe()}" in TrackerParams.__doc__
    # a written setup reads back: everything calibrate writes is within range
    path = write_setup(tmp_path / "s.toml", TrackingSetup(source="clip", frames=5))
    assert load_setup(path).frames == 5


def test_tracker_params_from_python_are_checked_too():
    for kwargs in ({"search_scale": -1}, {"alpha": float("nan")}, {"min_area_px": -5},
                   {"term_max_iter": 2**63 - 1}, {"size_tolerance": "3"}):
        with pytest.raises(InputError, match=f"TrackerParams.{next(iter(kwargs))}"):
            TrackerParams(**kwargs)


def test_integers_fit_int32_even_without_an_upper_bound():
    assert check_value(2**31 - 1, Spec(int)) is None
    assert check_value(2**31, Spec(int)) is not None
    assert check_value(float("inf"), Spec(float)) is not None
    assert check_value(True, Spec(int)) is not None


def _load_within(load, path, seconds=1.0):
    """``load(path)``'s exception, or fail if it does not return within ``seconds``."""
    box = {}

    def run():
        try:
            box["value"] = load(path)
        except BaseException as exc:  # noqa: BLE001 - handed to the test thread
            box["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        # unblock the reader so the daemon thread ends
        fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
        os.close(fd)
        pytest.fail(f"{load.__name__} still reading the FIFO after {seconds} s")
    return box.get("error")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
@pytest.mark.parametrize("load, name", [
    (load_setup, "setup.toml"), (load_markers, "colours.toml"), (load_markers, "colours.json"),
    (load_recipe, "recipe.toml"),
])
def test_a_fifo_is_refused_at_once(tmp_path, load, name):
    fifo = tmp_path / name
    os.mkfifo(fifo)
    error = _load_within(load, fifo)
    assert isinstance(error, InputError), error
    assert str(fifo) in str(error) and "not a regular file" in str(error)


@pytest.mark.parametrize("text, field", [
    ("[conditions]\nnormal = \"2\"\n", "[conditions] normal"),
    ("[conditions]\nnormal = -1\n", "[conditions] normal"),
    ("scene = [1]\n[conditions]\nnormal = 1\n", "[scene]"),
    ("[conditions]\nnormal = 1\n[scene]\ndistance = 1e300\n", "[scene] distance"),
    ("[conditions]\nnormal = 1\n[scene]\nduration = nan\n", "[scene] duration"),
    ("[conditions]\nnormal = 1\n[scene]\nobject_size = \"big\"\n", "[scene] object_size"),
    ("[conditions]\nnormal = 1\n[variation]\ncamera_angle_deg = [1]\n",
     "[variation] camera_angle_deg"),
    ("[conditions]\nnormal = 1\n[variation]\ndistance_sd = inf\n", "[variation] distance_sd"),
    ("[conditions]\nnormal = 1\n[render]\nwidth = \"640\"\n", "[render] width"),
    ("[conditions]\nnormal = 1\n[render]\nnoise_sd = -3\n", "[render] noise_sd"),
    ("[conditions]\nnormal = 1\n[render]\nmotion_samples = 2147483648\n",
     "[render] motion_samples"),
    ("[conditions]\nnormal = 1\n[render]\nhand = 1\n", "[render] hand"),
    ("[conditions]\nnormal = 1\n[render]\nsleeve = \"scarf\"\n", "[render] sleeve"),
    ("[conditions]\nnormal = 1\n[render]\ndistractors = 5\n", "[render] distractors"),
    ("[conditions]\nnormal = 1\n[[render.distractors]]\ncolour = \"thumb\"\n"
     "start = [0, 1e300]\n", "[[render.distractors]] #1 start"),
    ("[conditions]\nnormal = 1\n[[render.distractors]]\ncolour = \"thumb\"\n",
     "[[render.distractors]] #1 start"),
    ("[conditions]\nnormal = 1\n[[render.occlusions]]\nmarker = \"nose\"\nstart = 1\nstop = 2\n",
     "[[render.occlusions]] #1 marker"),
])
def test_bad_recipe_value_names_file_and_field(tmp_path, text, field):
    path = tmp_path / "my-recipe.toml"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        load_recipe(path)
    assert str(err.value).startswith(f"{path}: {field}: "), str(err.value)


@pytest.mark.parametrize("name, text, field", [
    ("c.toml", "[thumb]\nsat_min = nan\n", "thumb.sat_min"),
    ("c.toml", "thumb = 3\n", "thumb"),
    ("c.json", '{"thumb": {"val_min": 1e400}}', "thumb.val_min"),
    ("c.json", "[1, 2]", None),
])
def test_bad_colours_value_names_file_and_field(tmp_path, name, text, field):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(InputError) as err:
        load_markers(path)
    assert str(err.value).startswith(str(path))
    assert err.value.field == field


@pytest.mark.parametrize("hidden", [slice(5, 10), slice(5, 6), slice(9, 10)])
def test_object_hidden_in_frames_5_to_9_is_observed(hidden):
    tracks, truth = demo_tracks("normal", 0, noise_px=0.0)
    pos = tracks.position.copy()
    pos[hidden, tracks.markers.index("object")] = np.nan
    seen = observe(tracks)
    obs = observe(tracks.replace(position=pos))
    np.testing.assert_allclose(obs.scene.origin_px, seen.scene.origin_px)
    assert obs.onset_frame == seen.onset_frame


def test_object_never_seen_names_the_tracks_file_and_field(tmp_path):
    from perception.io.tracks import Tracks

    tracks, _ = demo_tracks("normal", 0)
    path = tracks.save(tmp_path / "clip-7.tracks.h5")
    loaded = Tracks.load(path)
    pos = loaded.position.copy()
    pos[:, loaded.markers.index("object")] = np.nan
    with pytest.raises(InputError) as err:
        observe(loaded.replace(position=pos))
    assert err.value.field == "object" and "clip-7.tracks.h5" in str(err.value)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-q"]))

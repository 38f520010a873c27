"""Setup, colour and recipe files: every value checked at the boundary, naming file and field.

One table of bad values per kind of file; each row must end in an InputError whose
message starts "PATH: FIELD: " and whose ``path`` and ``field`` are the file and the
field. TrackerParams built in Python is checked the same way; and a clip whose object
is hidden in frames 5-9 is observed.
"""

import dataclasses
import re
import sys

import numpy as np
import pytest
from _demos import demo_tracks
from _faults import refused

from perception.observation import observe
from perception.synthetic.recipes import load_recipe
from perception.tracking.markers import load_markers
from perception.tracking.params import TrackerParams
from perception.tracking.setup import TrackingSetup, load_setup, write_setup


def _keys(load, name, tables, head=""):
    """A case per ``(key, value)`` of each table: ``[table] key = value``, naming "[table] key"."""
    return [pytest.param(load, name, f"{head}[{t}]\n{k} = {v}\n", f"[{t}] {k}",
                         id=f"{name} [{t}] {k} = {v}")
            for t, rows in tables.items() for k, v in rows]


def _texts(load, name, rows):
    """A case per ``(whole file, field it names)``."""
    return [pytest.param(load, name, text, field, id=f"{name} {text!r}") for text, field in rows]


SETUP = "lab-setup.toml"
RECIPE = "my-recipe.toml"
ONE_CLIP = "[conditions]\nnormal = 1\n"
CASES = [
    # setup: tables that are not tables
    *_texts(load_setup, SETUP, [
        ("setup = []\n", "[setup]"), ("sizes = 3\n", "[sizes]"), ("markers = 5\n", "[markers]"),
        ("tracker = \"fast\"\n", "[tracker]"), ("[markers]\nthumb = 3\n", "[markers.thumb]")]),
    # each field's range is tests/test_declared_fields.py's (generated): here one value out
    # of range per table (the file and the key named), and what no range says (a float or
    # a bool for an integer, a string for a tuple, a tuple's member, two fields together)
    *_keys(load_setup, SETUP, {
        "setup": [("frames", "-1"), ("frames", "2.5"), ("source", "3")],
        "tracker": [("search_scale", "-1"), ("search_tries", "2.0"), ("search_tries", "true"),
                    ("still_markers", "\"object\""), ("band_elongation", "[1.4]"),
                    ("lost_ratio", "0.9\nreacquire_ratio = 0.5")],  # above reacquire_ratio
        "sizes": [("object_diameter", "nan"), ("band_size", "[0.07, -0.02]"),
                  ("band_size", "\"wide\"")],
        "markers.thumb": [("val_min", "-1"), ("bgr", "[1, 2, \"3\"]"), ("rgb", "[1, 2, 300]"),
                          ("hue", "[[1, 2, 3]]"), ("hue", "\"red\"")],
    }),
    *_texts(load_recipe, RECIPE, [
        ("[conditions]\nnormal = \"2\"\n", "[conditions] normal"),
        ("[conditions]\nnormal = -1\n", "[conditions] normal"),
        ("scene = [1]\n" + ONE_CLIP, "[scene]"),
        (ONE_CLIP + "[[render.distractors]]\ncolour = \"thumb\"\nstart = [0, 1e300]\n",
         "[[render.distractors]] #1 start"),
        (ONE_CLIP + "[[render.distractors]]\ncolour = \"thumb\"\n",
         "[[render.distractors]] #1 start"),
        (ONE_CLIP + "[[render.occlusions]]\nmarker = \"nose\"\nstart = 1\nstop = 2\n",
         "[[render.occlusions]] #1 marker")]),
    *_keys(load_recipe, RECIPE, head=ONE_CLIP, tables={
        "scene": [("distance", "1e300"), ("object_size", "\"big\"")],
        "variation": [("camera_angle_deg", "[1]")],
        "render": [("width", "\"640\""), ("noise_sd", "-3"), ("hand", "1"),
                   ("sleeve", "\"scarf\""), ("distractors", "5")],
    }),
    *_texts(load_markers, "c.toml", [("[thumb]\nsat_min = nan\n", "thumb.sat_min"),
                                     ("thumb = 3\n", "thumb")]),
    *_texts(load_markers, "c.json", [('{"thumb": {"val_min": 1e400}}', "thumb.val_min"),
                                     ("[1, 2]", None)]),
]


@pytest.mark.parametrize("load, name, text, field", CASES)
def test_bad_value_names_file_and_field(tmp_path, load, name, text, field):
    path = tmp_path / name
    path.write_text(text)
    error = refused(load, path, path=path, field=field)
    assert str(error).startswith(f"{path}: {field}: " if field else f"{path}: "), str(error)


def _beyond(default):
    """Values below and above any range, of the kind of ``default``."""
    if isinstance(default, tuple):
        return [(3,)] if isinstance(default[0], str) else [(-1e300,) * 2, (1e300,) * 2]
    big = 2**30 if isinstance(default, int) else 1e300
    return [-big, big]


def test_every_tracker_field_has_a_range_and_the_defaults_are_in_it(tmp_path):
    defaults = TrackerParams()
    for name in (f.name for f in dataclasses.fields(TrackerParams)):
        for bad in _beyond(getattr(defaults, name)):
            refused(lambda: TrackerParams(**{name: bad}), match=f"TrackerParams.{name}")  # noqa: B023
        assert re.search(rf"\b{name}\b", TrackerParams.__doc__), f"{name} not documented"
    # a written setup reads back: everything calibrate writes is within range
    path = write_setup(tmp_path / "s.toml", TrackingSetup(source="clip", frames=5))
    assert load_setup(path).frames == 5


def test_tracker_params_from_python_are_checked_too():
    # (each range: tests/test_declared_fields.py) a bool is no integer
    refused(lambda: TrackerParams(search_tries=True), match="TrackerParams.search_tries")
    assert TrackerParams(min_area_px=10_000_000).min_area_px == 10_000_000  # its upper bound


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

    loaded = Tracks.load(demo_tracks("normal", 0)[0].save(tmp_path / "clip-7.tracks.h5"))
    pos = loaded.position.copy()
    pos[:, loaded.markers.index("object")] = np.nan
    error = refused(observe, loaded.replace(position=pos), field="object")
    assert "clip-7.tracks.h5" in str(error)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-q"]))

import cv2
import numpy as np
import pytest

from perception.errors import InputError
from perception.synthetic.render import SKIN_BGR, TABLE_BGR
from perception.tracking.markers import (
    MARKER_NAMES,
    MarkerColour,
    default_markers,
    load_markers,
)


def test_default_set_order_and_render_colours_pass_their_own_gate():
    markers = default_markers()
    assert markers.names == MARKER_NAMES == ("thumb", "finger", "wrist", "object")
    for m in markers:
        assert m.matches(m.bgr), m.name
        # No marker's colour passes another marker's gate.
        for other in markers:
            if other is not m:
                assert not other.matches(m.bgr), (m.name, other.name)


def test_skin_and_table_fail_every_gate_though_skin_hue_is_near_red():
    markers = default_markers()
    skin_hue = cv2.cvtColor(np.array([[SKIN_BGR]], np.uint8), cv2.COLOR_BGR2HSV)[0, 0, 0]
    assert abs(int(skin_hue) - markers["thumb"].hsv[0]) <= 12  # the hard case is real
    for m in markers:
        assert not m.matches(SKIN_BGR), m.name
        assert not m.matches(TABLE_BGR), m.name


def test_red_hue_range_wraps_through_zero():
    thumb = default_markers()["thumb"]
    hsv = np.array([[[178, 200, 200], [2, 200, 200], [90, 200, 200], [2, 50, 200]]], np.uint8)
    assert thumb.backproject(hsv).tolist() == [[255, 255, 0, 0]]


def test_toml_override_changes_only_given_fields(tmp_path):
    f = tmp_path / "colours.toml"
    f.write_text("[thumb]\nhue = [[170, 8]]\nsat_min = 120\n[object]\nrgb = [250, 220, 20]\n")
    markers = load_markers(f)
    assert markers["thumb"].hue == ((170, 8),)
    assert markers["thumb"].sat_min == 120
    assert markers["thumb"].val_min == default_markers()["thumb"].val_min
    assert markers["object"].bgr == (20, 220, 250)
    assert markers["finger"] == default_markers()["finger"]


def test_json_override(tmp_path):
    f = tmp_path / "colours.json"
    f.write_text('{"wrist": {"hue": [100, 130], "val_min": 30}}')
    assert load_markers(f)["wrist"].hue == ((100, 130),)


@pytest.mark.parametrize(
    "text, expected",
    [
        ("[thumb]\nhue = [200, 5]\n", "thumb.hue"),
        ("[thumb]\nsat_min = 300\n", "thumb.sat_min"),
        ("[thumb]\ncolor = 1\n", "marker 'thumb': unknown key 'color'"),
        ("[index]\nhue = [1, 2]\n", "unknown key 'index'"),
        ("[thumb]\nbgr = [1, 2]\n", "thumb.bgr"),
        ("[thumb\n", "not valid TOML"),
    ],
)
def test_bad_colours_file_names_file_and_field(tmp_path, text, expected):
    f = tmp_path / "colours.toml"
    f.write_text(text)
    with pytest.raises(InputError) as err:
        load_markers(f)
    assert str(err.value).startswith(str(f))
    assert expected in str(err.value)


@pytest.mark.parametrize(
    "name, text, hint",
    [
        ("c.toml", "[thum]\nhue = [[170, 8]]\n", "'thumb'"),
        ("c.toml", "[thumb]\nsat_mn = 120\n", "'sat_min'"),
        ("c.toml", "[finger]\nval_minn = 40\n", "'val_min'"),
        ("c.json", '{"wrist": {"hues": [100, 130]}}', "'hue'"),
        ("c.json", '{"objet": {"hue": [20, 34]}}', "'object'"),
    ],
)
def test_misspelt_marker_or_field_is_refused_naming_the_nearest(tmp_path, name, text, hint):
    f = tmp_path / name
    f.write_text(text)
    with pytest.raises(InputError, match=f"did you mean {hint}") as err:
        load_markers(f)
    assert str(err.value).startswith(str(f))


def test_missing_colours_file(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_markers(tmp_path / "nope.toml")


def test_marker_colour_validates_at_construction():
    with pytest.raises(ValueError, match="hue"):
        MarkerColour("x", (1, 2, 3), hue=((0, 180),))

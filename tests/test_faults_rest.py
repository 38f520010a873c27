"""Issue 46's remaining faults: the rules file, the online stream, the batch and the types.

Each case ends in one named error (an InputError: one line, exit 2 on the command
line; a TypeError for an object of the wrong type given in Python), never a
traceback from deep inside.
"""

from __future__ import annotations

import math
import typing

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks
from _faults import one_line, refused

from hammer_mv.cli import main
from perception.online import OnlineRecognizer
from perception.recognition.rules import VerdictRules, judge


@pytest.fixture(scope="module")
def rep():
    return default_repertoire()


@pytest.fixture(scope="module")
def tracks():
    return demo_tracks("normal", 0)[0]


# -- 1. the rules file: a table where a table is meant ----------------------------------
@pytest.mark.parametrize("text, field", [
    ("[[verdict]]\nlate_opening = 0.5\n", "[verdict]"),
    ("verdict = 3\n", "[verdict]"),
    ("[verdict]\nlate_opening = 0.5\n[[verdict.landmarks]]\nopening_level = 0.2\n",
     "[verdict.landmarks]"),
    ("[verdict]\nlandmarks = [1, 2]\n", "[verdict.landmarks]"),
])
def test_a_rules_table_of_the_wrong_kind_is_one_line(tmp_path, tracks, capsys, text, field):
    path = tracks.save(tmp_path / "n.tracks.h5")
    rules = tmp_path / "rules.toml"
    rules.write_text(text)
    assert main(["recognize", str(path), "-o", str(tmp_path / "o"), "--no-figures",
                 "--verdict-rules", str(rules)]) == 2
    line = one_line(capsys.readouterr().err, "rules.toml", field, "expected a table")
    assert "bug" not in line
    refused(VerdictRules.from_dict, [{"late_opening": 0.5}], rules, path=rules,
            field="[verdict]")


# -- 2. the online stream's times ---------------------------------------------------------
def _stream(rep, tracks, n):
    rec = OnlineRecognizer(rep, markers=tracks.markers, tracker_attrs=dict(tracks.tracker))
    for i in range(n):
        rec.update(tracks.position[i], tracks.time[i])
    return rec


@pytest.mark.parametrize("frames", [0, 5, "mid"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_time_that_is_not_finite_is_refused_at_update(rep, tracks, frames, bad):
    n = tracks.n_frames // 2 if frames == "mid" else frames
    rec = _stream(rep, tracks, n)
    err = refused(rec.update, tracks.position[n], bad, field="t", match="not finite")
    assert str(bad) in str(err)
    rec.update(tracks.position[n], tracks.time[n])  # the stream goes on from the refused frame


@pytest.mark.parametrize("frames", [1, 5, "mid"])
@pytest.mark.parametrize("step", [0.0, -0.01])
def test_a_repeated_or_backward_time_is_refused_at_update(rep, tracks, frames, step):
    n = tracks.n_frames // 2 if frames == "mid" else frames
    rec = _stream(rep, tracks, n)
    last = float(tracks.time[n - 1])
    err = refused(rec.update, tracks.position[n], last + step, field="t")
    assert f"{last + step:g} s comes after {last:g} s" in str(err)
    refused(rec.update, tracks.position[n], "soon", field="t", match="expected a time")


# -- 3. a batch of nothing ----------------------------------------------------------------
@pytest.mark.parametrize("items", [[], (), iter([])])
def test_a_batch_of_no_clips_says_so(rep, tmp_path, items):
    from perception.batch import run_batch

    refused(run_batch, items, tmp_path / "out", rep, field="items", match="no clips found")
    assert not (tmp_path / "out").exists()  # refused before anything is written


# -- 5. objects of the wrong type, said at the boundary -----------------------------------
def _batch_of(rep, tmp_path, **kw):
    from perception.batch import run_batch

    return lambda: run_batch([object()], tmp_path / "out", **{"repertoire": rep, **kw})


@pytest.mark.parametrize("call, expected", [
    (lambda rep, tmp: judge(None), "expected Evidence, got NoneType"),
    (lambda rep, tmp: judge({"kinds": []}), "expected Evidence, got dict"),
    (lambda rep, tmp: judge(_evidence(), {"late_opening": 0.5}),
     "expected VerdictRules, got dict"),
    (lambda rep, tmp: OnlineRecognizer(None), "expected a Repertoire"),
    (lambda rep, tmp: OnlineRecognizer("default.repertoire.h5"), "got str"),
    (lambda rep, tmp: OnlineRecognizer(rep, settings={}), "expected RecognitionSettings"),
    (lambda rep, tmp: OnlineRecognizer(rep, settle=0.5), "expected a SettleRule"),
    (lambda rep, tmp: _batch_of(None, tmp)(), "expected a Repertoire"),
    (lambda rep, tmp: _batch_of(rep, tmp, settings="fast")(), "expected RecognitionSettings"),
])
def test_an_object_of_the_wrong_type_is_a_type_error_that_says_what_was_expected(
        rep, tmp_path, call, expected):
    with pytest.raises(TypeError, match=expected):
        call(rep, tmp_path)
    assert not (tmp_path / "out").exists()


def _evidence():
    from perception.recognition.rules import Evidence

    return Evidence(["grasp"], np.zeros(1), np.full(1, 0.5))


# -- 4. every rule within what it can mean ------------------------------------------------
# (every rule's range, in Python: tests/test_declared_fields.py, generated; here a rules
# file's value is named by its file and key)
@pytest.mark.parametrize("field, value", [
    ("familiarity_threshold", 1.0), ("grasp_rest_frames", 10**9), ("min_transport", 1e308),
])
def test_a_rule_out_of_its_range_in_a_rules_file_names_file_and_key(tmp_path, field, value):
    rules = tmp_path / "rules.toml"
    rules.write_text(f"[verdict]\n{field} = {value!r}\n")
    refused(lambda: VerdictRules.from_dict({field: value}, rules), path=rules,
            field=f"[verdict] {field}")


def test_every_rule_has_a_declared_range_that_holds_its_default():
    import dataclasses

    from pydantic import TypeAdapter

    hints = typing.get_type_hints(VerdictRules, include_extras=True)
    for f in dataclasses.fields(VerdictRules):
        if f.name == "landmarks":
            continue
        meta = [m for a in getattr(hints[f.name], "__metadata__", ())
                for m in getattr(a, "metadata", [a])]
        bounds = {type(m).__name__ for m in meta}
        assert bounds & {"Gt", "Ge"} and bounds & {"Lt", "Le"}, f.name
        TypeAdapter(hints[f.name]).validate_python(getattr(VerdictRules(), f.name))

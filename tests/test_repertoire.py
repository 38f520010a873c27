"""The repertoire: planning, HDF5 round trip, schema checks, configs, CLI."""

import subprocess
import sys

import h5py
import numpy as np
import pytest
from _demos import default_repertoire

from hammer_mv.cli import main
from perception.errors import InputError
from perception.recognition import ModelSpec, Repertoire, SceneSpec, build_model
from perception.recognition.models import model_substeps


def test_default_repertoire_has_both_kinds_and_ten_models():
    rep = default_repertoire()
    assert len(rep) >= 10
    assert {m.kind for m in rep} == {"grasp", "reach"}
    m = rep.models[rep.names.index("grasp-1.0s")]
    assert m.substeps == model_substeps(1 / 30) == 3
    assert m.duration == pytest.approx(1.0, abs=m.dt)
    # the reach-only model keeps the digits where they start
    r = rep.models[rep.names.index("reach-1.0s")]
    assert np.allclose(r.finger.x0[8:10], 1.0)


def test_a_repertoire_shows_its_models_in_a_notebook():
    lazy = Repertoire.default()
    assert repr(lazy) == ("<LazyRepertoire: 16 models (grasp-0.5s, grasp-0.6s, grasp-0.7s, "
                          "grasp-0.8s, ... reach-1.2s)>")
    assert lazy._models is None  # shown without planning a model
    one = Repertoire(default_repertoire().models[:1])
    assert repr(one) == "<Repertoire: 1 model (grasp-0.5s)>"


def test_round_trip_is_exact(tmp_path):
    rep = Repertoire.build([ModelSpec("g", "grasp", {"duration": 0.9}),
                            ModelSpec("r", "reach", {"duration": 0.9})])
    path = rep.save(tmp_path / "rep.h5")
    back = Repertoire.load(path)
    assert back.names == ["g", "r"]
    for a, b in zip(rep, back):
        assert a.kind == b.kind and a.scene == b.scene and a.dt == b.dt
        for ca, cb in zip(a.chains, b.chains):
            for key in ("A", "B", "H", "K", "L", "P", "x0", "base"):
                assert np.array_equal(getattr(ca, key), getattr(cb, key)), key
            assert (ca.l1, ca.l2, ca.elbow) == (cb.l1, cb.l2, cb.elbow)


def test_stored_gains_are_the_plans(tmp_path):
    from minvar import plan_grasp

    spec = ModelSpec("g", "grasp", {"duration": 1.0})
    scene = SceneSpec()
    model = build_model(spec, scene)
    plan = plan_grasp(spec.grasp_task(scene))
    np.testing.assert_array_equal(model.arm.L, plan.arm.solution.L)
    np.testing.assert_array_equal(model.finger.K, plan.finger.solution.K)


def test_scene_matching_and_replanning():
    rep = Repertoire.build([ModelSpec("g", "grasp", {"duration": 1.0})])
    same = rep.for_scene(SceneSpec(distance=0.255))
    assert same[0] is rep.models[0]
    other = rep.for_scene(SceneSpec(distance=0.20, frame_period=1 / 25))
    assert other[0] is not rep.models[0] and other[0].substeps == 4
    assert rep.for_scene(SceneSpec(distance=0.20, frame_period=1 / 25))[0] is other[0]  # cached


def test_wrong_schema_and_corrupt_files(tmp_path):
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f.attrs["schema"] = "hammer-mv/tracks"
    with pytest.raises(InputError, match="not a hammer-mv repertoire"):
        Repertoire.load(tmp_path / "other.h5")
    good = Repertoire.build([ModelSpec("g", "grasp", {"duration": 0.9})]).save(tmp_path / "r.h5")
    with h5py.File(good, "a") as f:
        f.attrs["schema_version"] = 99
    with pytest.raises(InputError, match="version 99"):
        Repertoire.load(good)
    (tmp_path / "junk.h5").write_bytes(b"not hdf5 at all")
    with pytest.raises(InputError, match="not an HDF5 file"):
        Repertoire.load(tmp_path / "junk.h5")
    with pytest.raises(InputError, match="no such file"):
        Repertoire.load(tmp_path / "missing.h5")


def test_config_file(tmp_path):
    cfg = tmp_path / "rep.toml"
    cfg.write_text('[scene]\ndistance = 0.22\n\n[[model]]\nname = "slow"\nkind = "grasp"\n'
                   'duration = 1.2\nviapoint_offset = 0.02\n\n[[model]]\nname = "late"\n'
                   'kind = "grasp"\nduration = 1.0\ngrip_via = [{half_aperture = 0.003, '
                   'height = 0.0, fraction = 0.5}, {half_aperture = 0.07, height = 0.0, '
                   'fraction = 0.85}]\n')
    rep = Repertoire.from_config(cfg)
    assert rep.names == ["slow", "late"] and rep.models[0].scene.distance == 0.22
    assert rep.models[1].finger.A.shape[0] == 8 + 2 * 3  # two via-points and the goal
    cfg.write_text('[[model]]\nname = "x"\nkind = "dance"\n')
    with pytest.raises(InputError, match="ModelSpec.kind: expected 'grasp' or 'reach'"):
        Repertoire.from_config(cfg)
    cfg.write_text('[[model]]\nname = "x"\nwobble = 3\n')
    with pytest.raises(InputError, match="unknown task field"):
        Repertoire.from_config(cfg)


def test_cli_build_and_info(tmp_path, capsys):
    out = tmp_path / "rep.h5"
    assert main(["repertoire", "build", "-o", str(out), "--durations", "0.9", "1.1"]) == 0
    assert main(["repertoire", "info", str(out)]) == 0
    text = capsys.readouterr().out
    assert "grasp-0.9s" in text and "reach-1.1s" in text
    proc = subprocess.run([sys.executable, "-m", "hammer_mv", "repertoire", "info",
                           str(tmp_path / "nope.h5")], capture_output=True, text=True)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("entry, message", [
    ('name = "x"\ndistance = 0.3', "the scene sets"),
    ('name = "x"\nreach_only = true', "the scene sets"),
    ('name = "x"\ngrip_via = [{half = 0.01}]', "grip_via\\[0\\] must have exactly"),
    ('name = "x"\ngrip_via = 3', "grip_via must be a list"),
    ('name = "a/b"', "use letters, digits"),
    ('name = "x"\nduration = -1', "duration"),
])
def test_bad_model_entries_are_one_line(tmp_path, entry, message):
    cfg = tmp_path / "rep.toml"
    cfg.write_text(f"[[model]]\n{entry}\n")
    with pytest.raises(InputError, match=message) as exc:
        Repertoire.from_config(cfg)
    assert str(cfg) in str(exc.value)


def test_truncated_gains_are_refused(tmp_path):
    path = Repertoire.build([ModelSpec("g", "grasp", {"duration": 0.9})]).save(tmp_path / "r.h5")
    with h5py.File(path, "a") as f:
        K = f["models/g/finger/K"][()]
        del f["models/g/finger/K"]
        f["models/g/finger/K"] = K[:5]
    with pytest.raises(InputError, match="finger: K has shape"):
        Repertoire.load(path)

"""Real DeepLabCut output of a non-human movement is never called `normal` or `reach`.

The file is DeepLabCut's own predictions table of a head-fixed mouse reaching
for a joystick and pulling it (Mathis lab), shipped in the source distribution
of ``dlc2kinematics`` 0.0.7 on PyPI and fetched by ``tests/_real_pose.py``
(pinned by version and sha256; docs/pose-files.md, "Tested on real files").

A mouse's paw is not a human hand closing on a ball: hammer-mv may refuse the
clip in one line, or score it `abnormal`, but must not pass it as a familiar
grasp or reach. The table carries no frame rate and no metric scale, so the
verdict is checked over a range of both: frame rates a reach of about 15
frames could have (100 to 200 frames/s), and 3000 to 4000 px/m (the forearm,
elbow to wrist, is about 38 px and a mouse's about 1 cm; the paw, digit 1 to 4
base, about 16 px for 4 mm).
"""

import json
import subprocess
import sys

import pandas as pd
import pytest
from _real_pose import real_pose_file

movement = pytest.importorskip("movement", reason="the 'pose' extra (make test installs it)")
from movement.io import load_poses  # noqa: E402

NAME = "dlc-mouse-reach"
#: the paw's digits play the thumb and index finger; the joystick is the object
DIGITS_1_2 = ("thumb=R_Finger1_Tip", "finger=R_Finger2_Tip", "wrist=Right_wrist",
              "object=joystick")
DIGITS_1_4 = ("thumb=R_Finger1_Tip", "finger=R_Finger4_Tip", "wrist=Right_wrist",
              "object=joystick")


@pytest.fixture(scope="module")
def mouse_reach(request):
    cache = getattr(request.config, "cache", None)  # None under -p no:cacheprovider
    return real_pose_file(NAME, cache.mkdir("hammer-mv-real-pose") if cache else None)


def test_the_file_is_deeplabcut_output_that_movement_reads(mouse_reach):
    ds = load_poses.from_dlc_file(mouse_reach)
    assert ds.attrs["source_software"] == "DeepLabCut"
    assert ds.sizes == {"time": 800, "space": 2, "keypoints": 33, "individuals": 1}
    keypoints = set(ds.keypoints.values.tolist())
    assert {"R_Finger1_Tip", "R_Finger2_Tip", "R_Finger4_Tip", "Right_wrist",
            "joystick", "nose"} <= keypoints
    # DeepLabCut's own scores: a network's likelihoods, not a hand-made table
    confidence = ds.confidence.values
    assert 0.0 <= confidence.min() < 0.01 and confidence.max() <= 1.0
    table = pd.read_hdf(mouse_reach, "df_with_missing")
    assert table.columns.names == ["scorer", "bodyparts", "coords"]
    assert table.columns.get_level_values("scorer")[0].startswith("DeepCut_resnet50_")


def _recognize(path, out, keypoints, fps, px_per_m):
    return subprocess.run(
        [sys.executable, "-m", "hammer_mv", "recognize", str(path), "-o", str(out),
         "--no-figures", "--keypoints", *keypoints, "--fps", str(fps),
         "--px-per-m", str(px_per_m)],
        capture_output=True, text=True, timeout=600)


@pytest.mark.slow
@pytest.mark.parametrize(("keypoints", "fps", "px_per_m"), [
    pytest.param(DIGITS_1_2, 100, 4000, id="digits1-2-100fps-4000pxm"),
    pytest.param(DIGITS_1_2, 200, 4000, id="digits1-2-200fps-4000pxm"),
    pytest.param(DIGITS_1_2, 100, 3000, id="digits1-2-100fps-3000pxm"),
    pytest.param(DIGITS_1_2, 200, 3000, id="digits1-2-200fps-3000pxm"),
    pytest.param(DIGITS_1_4, 100, 4000, id="digits1-4-100fps-4000pxm"),
])
def test_a_mouse_reaching_for_a_joystick_is_not_normal_or_reach(
        mouse_reach, tmp_path, keypoints, fps, px_per_m):
    out = tmp_path / "out"
    done = _recognize(mouse_reach, out, keypoints, fps, px_per_m)
    assert "Traceback" not in done.stderr, done.stderr
    assert done.returncode in (0, 2), done.stderr
    report = out / f"{mouse_reach.stem}.recognition.json"
    if done.returncode == 2:
        # an honest refusal: one error naming the file ...
        lines = done.stderr.strip().splitlines()
        errors = [line for line in lines if "error:" in line]
        assert len(errors) == 1 and mouse_reach.name in errors[0], done.stderr
        assert not report.exists()
        # ... and nothing else: a refusal is one line
        assert lines == errors, f"a refusal in more than one line:\n{done.stderr}"
        return
    result = json.loads(report.read_text())
    assert result["verdict"] not in ("normal", "reach"), (
        f"a mouse reaching for a joystick was called {result['verdict']!r} "
        f"(winner {result['winner']}, familiarity {result['familiarity']:.3f}, "
        f"threshold {result['familiarity_threshold']})")

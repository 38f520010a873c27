"""Clip names come from the outside world: manifests and file names are data."""

import subprocess
import sys

import pytest

from perception.discovery import check_clip_name, discover
from perception.errors import InputError


def _manifest(tmp_path, rows):
    path = tmp_path / "manifest.csv"
    path.write_text("clip,video,condition\n" + "".join(f"{c},{v},normal\n" for c, v in rows))
    return path


@pytest.mark.parametrize("name", ["../escape", "a/b", "..", ".hidden", "", "x\ty",
                                  "x" * 201])
def test_names_that_would_leave_the_report_folder_are_refused(name):
    with pytest.raises(InputError, match="cannot name report files"):
        check_clip_name(name, "manifest.csv row 2")


@pytest.mark.parametrize("name", ["normal-01", "a b", "50% #1?", 'a" onerror="x', "émile"])
def test_odd_but_harmless_names_are_kept(name):
    assert check_clip_name(name, "here") == name


def test_a_manifest_row_escaping_the_output_is_refused_before_any_work(tmp_path):
    (tmp_path / "v.mp4").write_bytes(b"")
    man = _manifest(tmp_path, [("ok", "v.mp4"), ("../escape", "v.mp4")])
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "hammer_mv", "batch", str(man), "-o",
                           str(out), "--quiet"], capture_output=True, text=True)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert "row 3" in proc.stderr and "../escape" in proc.stderr
    assert not (tmp_path / "escape.recognition.json").exists() and not out.exists()


def test_duplicate_manifest_rows_are_named(tmp_path):
    man = _manifest(tmp_path, [("a", "1.mp4"), ("b", "2.mp4"), ("a", "3.mp4")])
    with pytest.raises(InputError, match=r"'a' appears twice \(rows 2 and 4\)"):
        discover(man)


def test_a_manifest_clip_name_that_looks_like_a_number_stays_text(tmp_path):
    man = _manifest(tmp_path, [("007", "a.mp4"), ("1e3", "b.mp4")])
    assert [i.clip for i in discover(man)] == ["007", "1e3"]


def test_stem_collisions_are_both_processed_under_their_file_names(tmp_path):
    for name in ("dup.avi", "dup.mp4", "solo.mp4", "t.mp4", "t.tracks.h5", "p.csv", "p.mp4",
                 "u.tracks.h5"):
        (tmp_path / name).write_bytes(b"")
    items = {i.clip: (i.path.name, i.kind) for i in discover(tmp_path)}
    assert items == {"dup.avi": ("dup.avi", "video"), "dup.mp4": ("dup.mp4", "video"),
                     "solo": ("solo.mp4", "video"), "t": ("t.mp4", "video"),
                     "u": ("u.tracks.h5", "tracks"),
                     "p": ("p.csv", "pose")}

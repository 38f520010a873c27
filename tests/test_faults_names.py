"""Any clip name gives a report: undecodable, long, non-Latin; bad output folders are one line."""

import errno
import os

import pytest
from _demos import default_repertoire, demo_tracks
from PIL import Image

from perception.batch import ClipResult, summary_table
from perception.errors import InputError
from perception.io import atomic
from perception.io.atomic import atomic_path, write_text
from perception.io.names import NAME_MAX, output_folder, output_stem, printable
from perception.pipeline import recognize_clip
from perception.report import ClipSummary, write_batch_report, write_clip_report
from perception.report.clip import clip_outputs
from perception.report.tracking import write_tracking_report

UNDECODABLE = os.fsdecode(b"clip\xff")
NON_LATIN = ("حركة", "मुट्ठी", "握る")


@pytest.fixture(scope="module")
def tracks():
    return demo_tracks("normal", 0)[0]


@pytest.fixture(scope="module")
def rep():
    return default_repertoire()


def _utf8(name: str) -> bool:
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


@pytest.fixture
def renames(monkeypatch):
    """Every (temporary, final) name pair atomic writes rename."""
    seen = []
    real = os.replace

    def replace(src, dst, *args, **kwargs):
        seen.append((os.path.basename(os.fspath(src)), os.path.basename(os.fspath(dst))))
        return real(src, dst, *args, **kwargs)

    monkeypatch.setattr(atomic.os, "replace", replace)
    return seen


def _report(rec, out, tracks):
    extra = {"tracking": write_tracking_report(tracks, out, rec.clip, sheet=False)}
    return write_clip_report(rec, out, extra=extra)


@pytest.mark.parametrize("name", [UNDECODABLE, *NON_LATIN], ids=["undecodable", *NON_LATIN])
def test_any_clip_name_gives_a_report_with_utf8_names_and_figures(tracks, rep, tmp_path, name):
    rec = recognize_clip(tracks, rep, clip=name)
    paths = _report(rec, tmp_path, tracks)
    names = os.listdir(tmp_path)
    assert all(_utf8(n) for n in names) and not [n for n in names if ".part" in n], names
    for path in paths.values():
        assert path.is_file() and path.stat().st_size > 0
    assert Image.open(paths["confidence_png"]).size[0] > 100
    for key in ("confidence_png", "paths_png"):  # the name drawn in the figures
        assert paths[key].name.startswith(name if _utf8(name) else output_stem(name))
        assert Image.open(paths[key]).format == "PNG"
    # the batch report and its table show the name (escaped), in valid UTF-8
    results = [ClipResult(rec.clip, "normal", "ok", summary=ClipSummary.from_recognition(rec))]
    write_batch_report(summary_table(results), {rec.clip: results[0].summary}, tmp_path,
                       models=rep.models)
    assert printable(name) in (tmp_path / "report.html").read_bytes().decode("utf-8")
    assert printable(name) in (tmp_path / "summary.csv").read_bytes().decode("utf-8")
    assert Image.open(tmp_path / "confidence_single.png").format == "PNG"
    assert not [n for n in os.listdir(tmp_path) if ".part" in n or not _utf8(n)]


def test_a_contact_sheet_is_encoded_by_us_and_written_under_a_utf8_name(tracks, tmp_path,
                                                                       monkeypatch):
    import cv2
    import numpy as np

    from perception.io.frame_sample import FrameSample

    def refuse(*args, **kwargs):
        raise AssertionError("cv2.imwrite handed a path (a non-UTF-8 one crashes it)")

    monkeypatch.setattr(cv2, "imwrite", refuse)
    frames = FrameSample()
    frames.frames = {int(i): np.zeros((240, 320, 3), np.uint8) for i in tracks.frame}
    quality = write_tracking_report(tracks, tmp_path, UNDECODABLE, frames=frames)
    sheet = tmp_path / quality["contact_sheet"]
    assert _utf8(sheet.name) and Image.open(sheet).format == "PNG"
    assert [n for n in os.listdir(tmp_path) if ".part" in n] == []


@pytest.mark.parametrize("length", [225, 245])
def test_long_clip_names_fit_every_output_and_temporary_name(tracks, rep, tmp_path, renames,
                                                             length):
    clip = "g" * length
    rec = recognize_clip(tracks, rep, clip=clip)
    paths = _report(rec, tmp_path, tracks)
    for path in paths.values():
        assert path.is_file() and len(os.fsencode(path.name)) <= NAME_MAX
    assert len(renames) == 5  # JSON, CSV and three figures
    for tmp, final in renames:
        assert len(os.fsencode(final)) <= NAME_MAX
        assert len(os.fsencode(tmp)) <= len(os.fsencode(final)), (tmp, final)
    assert not [n for n in os.listdir(tmp_path) if ".part" in n]
    # two long names alike but for their end get different files
    other = clip_outputs(tmp_path, clip[:-1] + "h")
    assert {p.name for p in other.values()}.isdisjoint({p.name for p in paths.values()})


def test_a_final_name_that_fits_gets_a_temporary_name_that_fits(tmp_path, renames):
    final = tmp_path / ("x" * 235 + ".recognition.json")  # 252 bytes
    write_text(final, "{}")
    assert final.read_text() == "{}"
    ((tmp, name),) = renames
    assert name == final.name and len(tmp) <= len(name)


def test_a_killed_writers_long_temporary_file_is_removed_by_the_next_write(tmp_path):
    final = tmp_path / ("y" * 230 + ".json")
    with atomic_path(final) as tmp:
        tmp.write_text("{")
        os.replace(tmp, tmp_path / tmp.name.replace(atomic.owner_tag(),
                                                    atomic.owner_tag().split("p")[0]
                                                    + "p999999"))
        tmp.write_text("{}")  # what the writer finishes
    dead = [n for n in os.listdir(tmp_path) if ".part" in n]
    assert len(dead) == 1
    write_text(final, "{}")
    assert [n for n in os.listdir(tmp_path) if ".part" in n] == []


def test_output_stems_are_utf8_short_and_distinct():
    assert output_stem("plain-01") == "plain-01" and output_stem("握る") == "握る"
    stems = {output_stem(n) for n in (UNDECODABLE, "clip_", os.fsdecode(b"clip\xfe"),
                                      "a/b", "a\nb", "é" * 150, "é" * 149 + "e")}
    assert len(stems) == 7
    for s in stems:
        assert _utf8(s) and "/" not in s and "\n" not in s and len(s.encode()) <= 200
    assert printable(UNDECODABLE) == "clip\\xff" and printable("a\nb") == "a\\nb"


def test_a_read_only_output_folder_is_one_error_naming_it(tracks, rep, tmp_path, monkeypatch):
    import tempfile

    def read_only(*args, dir=None, **kwargs):
        raise OSError(errno.EROFS, "Read-only file system", dir)

    monkeypatch.setattr(tempfile, "mkstemp", read_only)
    rec = recognize_clip(tracks, rep, clip="ro")
    with pytest.raises(OSError) as caught:
        write_clip_report(rec, tmp_path)
    message = str(caught.value)
    assert str(tmp_path) in message and "Read-only" in message and "\n" not in message
    assert os.listdir(tmp_path) == []


def test_stale_figures_in_a_read_only_folder_are_one_error_or_none(tracks, rep, tmp_path,
                                                                   monkeypatch):
    from pathlib import Path

    rec = recognize_clip(tracks, rep, clip="ro")
    write_clip_report(rec, tmp_path)

    def read_only(self, *args, **kwargs):  # as a read-only file system answers, even if absent
        raise OSError(errno.EROFS, "Read-only file system", str(self))

    monkeypatch.setattr(Path, "unlink", read_only)
    with pytest.raises(OSError, match=r"cannot remove .*ro\.confidence\.png"):
        write_clip_report(rec, tmp_path, figures=False)
    for p in tmp_path.iterdir():
        os.unlink(p)
    # no figure to remove: nothing is asked of the folder, the report is written
    paths = write_clip_report(rec, tmp_path, figures=False)
    assert paths["json"].is_file() and not paths["confidence_png"].exists()


def test_an_output_subfolder_linked_outside_is_refused(tmp_path):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "tracks").symlink_to(elsewhere)
    with pytest.raises(InputError, match="outside the output folder") as caught:
        output_folder(out, "tracks")
    assert str(out / "tracks") in str(caught.value) and "\n" not in str(caught.value)
    (out / "inside").mkdir()
    (out / "plans").symlink_to(out / "inside")
    assert output_folder(out, "plans") == out / "plans"
    assert output_folder(out, "absent") == out / "absent"

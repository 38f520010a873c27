"""Batches never hang, never reuse a stale result, and never end on one bad clip.

Every case here was once measured broken: a FIFO or a link to /dev/zero in a
batch folder hung it (the clip was hashed before it was checked), a tracks
file of another clip beside a video was trusted, a change to the code reused
every old report, a silent scheduler hung the command, and a failure while
recording a failure ended the batch without its summary.
"""

from __future__ import annotations

import html
import json
import os
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest
from _demos import default_repertoire, demo_tracks
from _faults import one_line

from perception.batch import discover, find_clips, run_batch
from perception.cluster import SCHEDULER_TIMEOUT_S
from perception.discovery import SUBFOLDER
from perception.provenance import code_digest
from perception.recognition.repertoire import Repertoire
from perception.synthetic.recipes import Recipe, StimulusParams, synthesize

ROOT = Path(__file__).resolve().parents[1]


#: Seconds after which a batch is taken to hang: the bound of a bug, not a speed (no test
#: here asserts how fast a batch runs; a busy machine runs them more slowly)
HANG = 600


def _batch(src, out, *extra, env=None, timeout=HANG, cwd=None):
    return subprocess.run([sys.executable, "-m", "hammer_mv", "batch", str(src), "-o", str(out),
                           "--quiet", *extra], capture_output=True, text=True, timeout=timeout,
                          env=env, cwd=cwd)


def _main(*args) -> int:
    """``hammer-mv *args``' exit status, run in this process: for a test of what the
    command decides and writes, where a subprocess would only add its imports (4 s of
    CPU a batch). Hangs, crashes and exit messages stay in subprocesses (:func:`_batch`)."""
    from hammer_mv.cli import main

    return main([str(a) for a in args])


@pytest.fixture(scope="module")
def repfile(tmp_path_factory):
    return default_repertoire().save(tmp_path_factory.mktemp("rep") / "rep.h5")


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    out = tmp_path_factory.mktemp("clips")
    recipe = Recipe(name="f", counts={"normal": 1, "delayed": 1},
                    stimulus=StimulusParams(rest_before=0.3, rest_after=0.2))
    synthesize(recipe, out, seed=5)
    return out


@pytest.fixture()
def tracks_folder(tmp_path):
    """Two demonstrations as tracks files (no video: fast)."""
    src = tmp_path / "src"
    src.mkdir()
    for cond in ("normal", "delayed"):
        demo_tracks(cond, 0)[0].save(src / f"{cond}.tracks.h5")
    return src


def test_a_subfolder_is_listed_as_skipped_not_passed_over(tracks_folder):
    # a lab's P01/, P02/ folders of recordings: their files are not read, and that is
    # said (it was silent: exit 0, the trials missing from the report without a word)
    (tracks_folder / "P01").mkdir()
    demo_tracks("normal", 1)[0].save(tracks_folder / "P01" / "normal.tracks.h5")
    (tracks_folder / "report").mkdir()  # a batch report written inside the input
    (tracks_folder / "report" / "batch.json").write_text("{}")
    found = find_clips(tracks_folder)
    assert [i.clip for i in found.items] == ["delayed", "normal"]
    assert dict(found.skipped) == {"P01": SUBFOLDER}
    assert "not those of its subfolders" in SUBFOLDER


def test_fifos_devices_and_notes_in_a_folder_are_skipped_not_opened(tracks_folder, repfile,
                                                                     tmp_path):
    os.mkfifo(tracks_folder / "x.mp4")
    (tracks_folder / "z.mp4").symlink_to("/dev/zero")
    (tracks_folder / "notes.txt").write_text("not a clip")
    (tracks_folder / "setup.toml").write_text("[tracker]\n")
    found = find_clips(tracks_folder)
    assert [i.clip for i in found.items] == ["delayed", "normal"]
    assert dict(found.skipped).keys() == {"x.mp4", "z.mp4", "notes.txt", "setup.toml"}
    assert "regular file" in dict(found.skipped)["x.mp4"]
    out = tmp_path / "out"
    proc = _batch(tracks_folder, out, "--repertoire", str(repfile))
    assert proc.returncode == 0, proc.stderr
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["clip"]) == ["delayed", "normal"] and (summary["status"] == "ok").all()
    skipped = json.loads((out / "batch.json").read_text())["skipped"]
    assert {s["file"] for s in skipped} == {"x.mp4", "z.mp4", "notes.txt", "setup.toml"}
    # and on the page, each with why (the page said nothing of them)
    page = (out / "report.html").read_text()
    assert "4 file(s) of the input not read" in page and "Files not read (4)" in page
    for s in skipped:
        assert f"<td>{s['file']}</td><td>{html.escape(s['reason'])}</td>" in page


def test_a_manifest_row_naming_a_device_fails_that_clip_at_once(tracks_folder, repfile,
                                                                 tmp_path):
    manifest = tracks_folder / "manifest.csv"
    manifest.write_text("clip,condition,video\nnormal,normal,normal.tracks.h5\n"
                        "noise,normal,/dev/urandom\n")
    proc = _batch(manifest, tmp_path / "out", "--repertoire", str(repfile))
    assert proc.returncode == 1, proc.stderr
    s = pd.read_csv(tmp_path / "out" / "summary.csv").set_index("clip")
    assert s.loc["normal", "status"] == "ok"
    assert s.loc["noise", "status"] == "failed"
    # refused as no regular file, before a byte is read: reading the device would never
    # end (a hang, caught by HANG), not take a little longer
    assert "/dev/urandom" in s.loc["noise", "error"] and "regular file" in s.loc["noise", "error"]


def test_tracks_of_another_clip_beside_a_video_are_not_trusted(clips, repfile, tmp_path):
    alone = tmp_path / "alone"
    alone.mkdir()
    shutil.copy(clips / "normal-01.mp4", alone)
    assert _main("batch", alone, "-o", tmp_path / "ref", "--quiet", "--repertoire", repfile) == 0
    ref = json.loads((tmp_path / "ref" / "normal-01.recognition.json").read_text())

    src = tmp_path / "src"
    src.mkdir()
    shutil.copy(clips / "normal-01.mp4", src)
    # the delayed grasp's tracks, under the normal clip's name
    shutil.copy(tmp_path / "ref" / "tracks" / "normal-01.tracks.h5", tmp_path / "keep.h5")
    assert _main("track", clips / "delayed-01.mp4", "-o", src / "normal-01.tracks.h5",
                 "--quiet") == 0
    out = tmp_path / "out"
    assert _main("batch", src, "-o", out, "--quiet", "--repertoire", repfile) == 0
    got = json.loads((out / "normal-01.recognition.json").read_text())
    for key in ("verdict", "winner", "familiarity", "margin"):
        assert got[key] == ref[key], key
    assert (out / "tracks" / "normal-01.tracks.h5").exists()  # tracked afresh

    # its own current tracks beside it are reused, not tracked again
    shutil.copy(tmp_path / "keep.h5", src / "normal-01.tracks.h5")
    out2 = tmp_path / "out2"
    assert _main("batch", src, "-o", out2, "--quiet", "--repertoire", repfile) == 0
    assert not (out2 / "tracks" / "normal-01.tracks.h5").exists()
    got = json.loads((out2 / "normal-01.recognition.json").read_text())
    assert got["verdict"] == ref["verdict"] and got["familiarity"] == ref["familiarity"]


def _code_copy(root: Path, change: str | None) -> Path:
    """The packages copied to ``root``; ``change`` appended to the scoring module."""
    for pkg in ("minvar", "perception", "hammer_mv"):
        shutil.copytree(ROOT / pkg, root / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    if change:
        with open(root / "perception" / "recognition" / "scoring.py", "a") as fh:
            fh.write(change)
    return root


def test_a_change_to_the_scoring_code_recomputes_every_report(tracks_folder, repfile, tmp_path):
    out = tmp_path / "out"
    same = _code_copy(tmp_path / "same", None)
    changed = _code_copy(tmp_path / "changed", "\n_UNUSED_SCORING_CONSTANT = 1.0\n")
    # run from tmp_path: "python -m" puts the working folder (the checkout) first
    env = {**os.environ, "PYTHONPATH": str(same)}
    for _ in range(2):
        assert _batch(tracks_folder, out, "--repertoire", str(repfile), env=env,
                      cwd=tmp_path).returncode == 0
    assert pd.read_csv(out / "summary.csv")["reused"].all()
    env = {**os.environ, "PYTHONPATH": str(changed)}
    proc = _batch(tracks_folder, out, "--repertoire", str(repfile), env=env, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert not pd.read_csv(out / "summary.csv")["reused"].any()
    code = "from perception.provenance import code_digest; print(code_digest())"
    digests = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env={**os.environ, "PYTHONPATH": str(p)}, cwd=tmp_path).stdout.strip()
               for p in (same, changed)]
    assert digests[0] == code_digest() != digests[1]


def test_a_silent_scheduler_fails_in_bounded_time(tracks_folder, repfile, tmp_path):
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)
    held = []
    stop = threading.Event()

    def accept():  # accepts and says nothing
        server.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(server.accept()[0])
            except OSError:
                continue

    threading.Thread(target=accept, daemon=True).start()
    try:
        start = time.monotonic()
        proc = _batch(tracks_folder, tmp_path / "out", "--repertoire", str(repfile),
                      "--scheduler", f"tcp://127.0.0.1:{server.getsockname()[1]}")
        elapsed = time.monotonic() - start
    finally:
        stop.set()
        for c in held:
            c.close()
        server.close()
    # bounded by its own limit, whatever the machine's speed: it waited that long for an
    # answer (not refused for another reason) and gave up on it, saying so (a wait with no
    # bound would hang, caught by HANG)
    assert proc.returncode == 2 and elapsed >= SCHEDULER_TIMEOUT_S
    one_line(proc.stderr, "--scheduler")
    assert f"within {SCHEDULER_TIMEOUT_S:g} s (TimeoutError" in proc.stderr, proc.stderr


def test_a_failure_while_recording_a_failure_does_not_end_the_batch(tracks_folder, tmp_path,
                                                                     monkeypatch):
    import perception.batch as batch
    import perception.batch_clip as batch_clip

    def broken(out, clip, *figure_format):
        raise OSError(36, "File name too long")

    (tracks_folder / "empty.tracks.h5").write_bytes(b"")  # fails: its error handler runs
    monkeypatch.setattr(batch_clip, "clip_outputs", broken)
    items = discover(tracks_folder)
    summary = batch.summary_table([batch_clip._guarded(i, tmp_path / "out",
                                                       repertoire=default_repertoire(),
                                                       settings=batch.RecognitionSettings(),
                                                       repertoire_id="")
                                   for i in items if i.clip == "empty"])
    assert summary.loc[0, "status"] == "failed"


def test_a_bug_in_one_clip_is_kept_with_its_traceback(tracks_folder, tmp_path, monkeypatch):
    import perception.batch_clip as batch_clip

    real = batch_clip.recognize_tracks

    def buggy(tracks, *args, clip=None, **kwargs):
        if clip == "delayed":
            raise ZeroDivisionError("a bug")
        return real(tracks, *args, clip=clip, **kwargs)

    monkeypatch.setattr(batch_clip, "recognize_tracks", buggy)
    out = tmp_path / "out"
    summary = run_batch(discover(tracks_folder), out, default_repertoire(), quiet=True)
    s = summary.set_index("clip")
    assert s.loc["normal", "status"] == "ok" and s.loc["delayed", "status"] == "failed"
    assert "unexpected ZeroDivisionError" in s.loc["delayed", "error"]
    log = (out / "errors.log").read_text()
    assert "Traceback" in log and "ZeroDivisionError: a bug" in log and "== delayed" in log
    # a later clean run removes the stale log
    monkeypatch.setattr(batch_clip, "recognize_tracks", real)
    run_batch(discover(tracks_folder), out, default_repertoire(), quiet=True)
    assert not (out / "errors.log").exists()


def test_a_tracks_subfolder_linked_outside_the_report_is_refused(tracks_folder, repfile,
                                                                  tmp_path):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "tracks").symlink_to(elsewhere)
    proc = _batch(tracks_folder, out, "--repertoire", str(repfile))
    assert proc.returncode == 2
    one_line(proc.stderr, "outside the output folder")
    assert not any(elsewhere.iterdir())


def test_a_video_whose_name_is_not_utf8_is_tracked_and_reported(clips, repfile, tmp_path):
    # OpenCV crashed the whole process (a segfault) opening such a name
    src = tmp_path / "src"
    src.mkdir()
    name = os.fsdecode(b"grasp\xff.mp4")
    shutil.copy(clips / "normal-01.mp4", src / name)
    out = tmp_path / "out"
    for _ in range(2):
        proc = _batch(src, out, "--repertoire", str(repfile))
        assert proc.returncode == 0, proc.stderr
    summary = pd.read_csv(out / "summary.csv")
    assert (summary["status"] == "ok").all() and summary["reused"].all()
    for path in [*out.iterdir(), *(out / "tracks").iterdir()]:
        os.fsencode(path.name).decode("utf-8")  # every output name is valid UTF-8


def test_a_cluster_batch_leaves_the_workers_as_it_found_them(tracks_folder, tmp_path):
    import cv2
    from dask.distributed import LocalCluster

    before = cv2.getNumThreads()
    cv2.setNumThreads(3)
    env = dict(os.environ)
    try:
        # workers in this very process: what the batch's plugin changes, we can see
        with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                          dashboard_address=None) as cluster:
            summary = run_batch(discover(tracks_folder), tmp_path / "out", default_repertoire(),
                                quiet=True, scheduler=cluster.scheduler_address)
        assert (summary["status"] == "ok").all()
        assert cv2.getNumThreads() == 3
        assert dict(os.environ) == env
    finally:
        cv2.setNumThreads(before)


class _CrashesInAWorker(Repertoire):
    """Kills the worker process that plans a clip's models (as a crash in a library would)."""

    def for_scene(self, scene, cache=None, **kwargs):
        os._exit(3)


def test_clips_that_kill_every_worker_fail_in_one_clear_line_and_the_batch_ends(tracks_folder,
                                                                               tmp_path):
    rep = _CrashesInAWorker(default_repertoire().models)
    out = tmp_path / "out"
    summary = run_batch(discover(tracks_folder), out, rep, quiet=True, jobs=2)
    assert (summary["status"] == "failed").all()
    for clip, error in zip(summary["clip"], summary["error"]):
        assert error.startswith(str(tracks_folder / f"{clip}.tracks.h5"))
        assert "worker process running it died" in error and "rerun" in error
    assert json.loads((out / "batch.json").read_text())["failed"] == 2
    assert not list(out.glob("*.recognition.json"))

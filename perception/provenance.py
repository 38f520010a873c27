"""What made a result: a digest of the code that computes it.

A cached or reused result (a batch report, a tracks file found beside a
video, a scene's re-planned models) is current only if the code that would
make it now is the code that made it. ``__version__`` cannot say that: it
stays the same across many changes. :func:`code_digest` hashes the installed
packages' own files instead — every source file and shipped data file of
``minvar`` and ``perception`` (the default verdict calibration among them) —
so any change to scoring, tracking, planning or calibration makes every
result keyed on it stale.
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

__all__ = ["code_digest", "DIGEST_SUFFIXES"]

#: Files of the packages that decide results: source, the compiled kernel's
#: source, shipped data (calibration).
DIGEST_SUFFIXES = (".py", ".c", ".json", ".toml")


def _package_files(root: Path):
    for path in sorted(root.rglob("*")):
        if path.suffix in DIGEST_SUFFIXES and "__pycache__" not in path.parts and path.is_file():
            yield path


@functools.cache
def code_digest() -> str:
    """SHA-256 (hex, 16 characters) of the source and data files of ``minvar`` and ``perception``.

    Computed once per process (about 5 ms: some 200 small files). Paths
    enter the hash relative to their package, so the same code installed in
    another place gives the same digest.
    """
    import minvar
    import perception

    h = hashlib.sha256()
    for package in (minvar, perception):
        root = Path(package.__file__).resolve().parent
        for path in _package_files(root):
            rel = f"{package.__name__}/{path.relative_to(root).as_posix()}"
            data = path.read_bytes()
            h.update(f"{rel}\0{len(data)}\0".encode())
            h.update(data)
    return h.hexdigest()[:16]

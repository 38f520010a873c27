"""Shared test helpers for reports: JSON compared value by value, a disk that fills up."""

import math


def assert_json_close(a, b, *, rel: float, abs_: float, path: str = "") -> None:
    """Equal JSON values, floats to ``rel`` relative (or ``abs_``); the path names a difference."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            assert_json_close(a[k], b[k], rel=rel, abs_=abs_, path=f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            assert_json_close(x, y, rel=rel, abs_=abs_, path=f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        assert math.isclose(a, b, rel_tol=rel, abs_tol=abs_), (path, a, b)
    else:
        assert a == b, path


def disk_full_at(monkeypatch, name: str) -> None:
    """Make writing the output file called ``name`` fail as on a full disk (ENOSPC)."""
    import errno
    from pathlib import Path

    from perception.io import atomic

    real = atomic.atomic_path

    def full_disk(path, **kwargs):
        if Path(path).name == name:
            raise OSError(errno.ENOSPC, f"cannot write {path}: No space left on device")
        return real(path, **kwargs)

    monkeypatch.setattr(atomic, "atomic_path", full_disk)

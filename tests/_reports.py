"""Compare parsed JSON reports value by value."""

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

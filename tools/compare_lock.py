"""Print how the packages installed in this environment differ from the lock.

Used by ``make test-latest``: run with the interpreter of an unpinned
environment, it lists each package whose installed version is not the one
``requirements-lock.txt`` pins (and packages that only one side has).
Exits 0 whatever it finds: it reports, the test run decides nothing here.

    python tools/compare_lock.py requirements-lock.txt
"""

from __future__ import annotations

import argparse
from importlib import metadata

from packaging.requirements import InvalidRequirement, Requirement
from packaging.utils import canonicalize_name


def pinned(path: str) -> dict[str, str]:
    """``name -> version`` of the ``name==version`` lines of a constraints file."""
    out = {}
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            try:
                req = Requirement(line)
            except InvalidRequirement:
                continue
            exact = [s.version for s in req.specifier if s.operator == "=="]
            if exact:
                out[canonicalize_name(req.name)] = exact[0]
    return out


def installed() -> dict[str, str]:
    """``name -> version`` of every distribution in this environment but hammer-mv."""
    return {canonicalize_name(d.metadata["Name"]): d.version for d in metadata.distributions()
            if canonicalize_name(d.metadata["Name"]) != "hammer-mv"}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("constraints", help="the lock (requirements-lock.txt)")
    args = parser.parse_args(argv)
    lock, now = pinned(args.constraints), installed()
    rows = [(name, lock.get(name, "-"), now.get(name, "-")) for name in sorted(lock | now)
            if lock.get(name) != now.get(name)]
    if not rows:
        print("test-latest: the newest versions are the locked ones")
        return 0
    print(f"test-latest: {len(rows)} package(s) differ from the lock (locked -> newest):")
    for name, old, new in rows:
        print(f"test-latest:   {name} {old} -> {new}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The shape of the code: data flows one way and no module imports itself round a cycle.

The import graph is read from the source (every ``import`` statement,
top-level or inside a function, except those under ``if TYPE_CHECKING:``),
so a cycle hidden in a lazy import is caught too.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("minvar", "perception", "hammer_mv")


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))}


def _type_checking_blocks(tree: ast.AST) -> set[int]:
    """ids of import nodes under ``if TYPE_CHECKING:``."""
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for inner in ast.walk(node):
                skip.add(id(inner))
    return skip


def _imports(name: str, path: Path, known: set[str]) -> set[str]:
    """Project modules imported by module ``name`` (resolved to the deepest known module)."""
    tree = ast.parse(path.read_text())
    skip = _type_checking_blocks(tree)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")
                parent = parent[: len(parent) - (node.level - 1)]
                base = ".".join(parent + ([base] if base else []))
            # "from pkg import sub" imports the submodule pkg.sub when there is one
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base
                       for a in node.names]
        for target in targets:
            while target and target not in known:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    modules = _modules()
    known = set(modules)
    # Importing pkg.sub runs pkg/__init__ first, but a package that gathers
    # its submodules' names is the usual facade, not a cycle: only explicit
    # imports are edges.
    return {name: _imports(name, path, known) for name, path in modules.items()}


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


def test_no_import_cycle(graph):
    cycle = _cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_the_cycle_finder_finds_cycles():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


@pytest.mark.parametrize("library, forbidden", [
    ("minvar", ("perception", "hammer_mv")),
    ("perception", ("hammer_mv",)),
])
def test_libraries_never_import_the_application(graph, library, forbidden):
    bad = {(m, dep) for m, deps in graph.items() if m.split(".")[0] == library
           for dep in deps if dep.split(".")[0] in forbidden}
    assert not bad, f"{library} imports {sorted(bad)}"


def test_io_knows_nothing_of_what_it_stores(graph):
    """perception.io reads and writes files; recognition, tracking and reports sit above it."""
    above = ("perception.recognition", "perception.tracking", "perception.report",
             "perception.batch", "perception.pipeline", "perception.synthetic",
             "perception.workers", "perception.cluster")
    bad = {(m, dep) for m, deps in graph.items() if m.startswith("perception.io")
           for dep in deps if dep.startswith(above)}
    assert not bad, sorted(bad)


def test_the_facade_exposes_what_users_call():
    import perception

    for name in ("track_video", "Tracks", "observe", "Repertoire", "recognize_clip",
                 "run_batch", "render_clip"):
        assert getattr(perception, name) is getattr(importlib.import_module("perception.api"),
                                                    name)
    with pytest.raises(AttributeError):
        perception.no_such_thing  # noqa: B018


def test_importing_a_topic_module_stays_light():
    """``import perception.io.tracks`` must not pull in OpenCV, matplotlib or dask."""
    import subprocess
    import sys

    code = ("import sys, perception.io.tracks, perception.geometry\n"
            "heavy = [m for m in ('cv2', 'matplotlib', 'dask') if m in sys.modules]\n"
            "assert not heavy, heavy\n")
    subprocess.run([sys.executable, "-c", code], check=True)


#: Worker initialisers: the only library code that may set process-wide state,
#: in a worker process that the library itself started (or, on a dask worker,
#: for as long as the batch's plugin is registered, which puts it back).
WORKER_INITIALISERS = {"perception.workers.init_worker",
                       "perception.cluster.OneThreadPerWorker.setup",
                       "perception.cluster.OneThreadPerWorker.teardown"}
#: Calls that change a whole process: thread pools, the allocator, the environment,
#: how multiprocessing starts its children.
_PROCESS_WIDE = {"setNumThreads", "mallopt", "putenv", "unsetenv", "set_start_method",
                 "set_forkserver_preload"}
_ENVIRON_WRITES = {"update", "pop", "popitem", "setdefault", "clear", "__setitem__",
                   "__delitem__"}


def _is_environ(node: ast.AST) -> bool:
    return (isinstance(node, ast.Attribute) and node.attr == "environ") or (
        isinstance(node, ast.Name) and node.id == "environ")


def _process_wide_changes(module: str, source: str) -> list[str]:
    """``module.function: call`` of each change to process-wide state outside
    :data:`WORKER_INITIALISERS`."""
    found = []

    def visit(node: ast.AST, where: str) -> None:
        for child in ast.iter_child_nodes(node):
            inner = where
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                inner = f"{where}.{child.name}"
            bad = None
            if isinstance(child, ast.Call):
                func = child.func
                name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
                if name in _PROCESS_WIDE:
                    bad = name
                elif (isinstance(func, ast.Attribute) and name in _ENVIRON_WRITES
                      and _is_environ(func.value)):
                    bad = f"os.environ.{name}"
            elif isinstance(child, (ast.Assign, ast.AugAssign, ast.Delete)):
                targets = child.targets if isinstance(child, (ast.Assign, ast.Delete)) \
                    else [child.target]
                if any(isinstance(t, ast.Subscript) and _is_environ(t.value) for t in targets):
                    bad = "os.environ[...]"
            if bad and inner not in WORKER_INITIALISERS:
                found.append(f"{inner}: {bad}")
            visit(child, inner)

    visit(ast.parse(source), module)
    return found


def test_libraries_leave_process_wide_state_to_the_application():
    """No library code sets thread counts, the allocator or the environment behind its
    caller's back: only hammer_mv's entry points and worker initialisers do."""
    bad = [change for name, path in _modules().items() if name.split(".")[0] != "hammer_mv"
           for change in _process_wide_changes(name, path.read_text())]
    assert not bad, bad


def test_the_process_wide_check_finds_each_kind_of_change():
    source = """
import os, cv2, ctypes
def a():
    cv2.setNumThreads(1)
def b():
    os.environ["X"] = "1"
def c():
    os.environ.update(X="1")
class D:
    def e(self):
        ctypes.CDLL(None).mallopt(-1, 0)
def f():
    del os.environ["X"]
def g():
    return os.environ.get("X"), cv2.getNumThreads()  # reading is fine
"""
    assert _process_wide_changes("m", source) == [
        "m.a: setNumThreads", "m.b: os.environ[...]", "m.c: os.environ.update",
        "m.D.e: mallopt", "m.f: os.environ[...]"]
    assert _process_wide_changes("perception.workers",
                                 "def init_worker():\n    cv2.setNumThreads(1)\n") == []

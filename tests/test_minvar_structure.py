"""The shape of the minvar package: one-way imports, lazy submodules, results before figures."""

import ast
import inspect
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import minvar
from minvar import grasp_stats
from minvar.grasp_experiments import EXPERIMENTS, check_trials

PACKAGE = Path(minvar.__file__).parent


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _runtime_imports(tree: ast.AST):
    """Import nodes that run at import or call time: not those under ``if TYPE_CHECKING:``."""
    stack = [tree]
    while stack:
        node = stack.pop()
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                stack.extend(child.orelse)
                continue
            if isinstance(child, ast.Import | ast.ImportFrom):
                yield child
            stack.append(child)


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _graph() -> dict[str, set[str]]:
    """minvar module -> the minvar modules it imports (at module or function level)."""
    files = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph = {name: set() for name in files}
    for name, path in files.items():
        is_package = path.name == "__init__.py"
        for node in _runtime_imports(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                target = _resolve(name, is_package, node)
                # "from . import x" / "from .pkg import mod" may name submodules
                targets = [target] + [f"{target}.{a.name}" for a in node.names]
            graph[name] |= {t for t in targets if t in files and t != name}
    return graph


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


def test_no_import_cycle_among_minvar_modules():
    graph = _graph()
    assert "minvar.plotting.grasp_experiments" in graph["minvar.grasp_experiments"]
    # the root package imports its re-exported modules; none imports it back
    cyclic = _cycle({k: v - {"minvar"} for k, v in graph.items()})
    assert cyclic is None, " -> ".join(cyclic)


def test_only_plot_methods_reach_into_plotting():
    graph = _graph()
    for name, deps in graph.items():
        if name.startswith("minvar.plotting") or name == "minvar":
            continue
        for dep in deps:
            assert not dep.startswith("minvar.plotting") or name == "minvar.grasp_experiments", (
                f"{name} imports {dep}")


def test_plotting_imports_result_classes_for_type_checking_only():
    # a task is an input a figure may default to; results are duck-typed
    allowed = {"GraspTask"}
    for path in (PACKAGE / "plotting").glob("*.py"):
        for node in _runtime_imports(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom) or node.level < 2:
                continue
            module = sys.modules.get(f"minvar.{node.module}") or __import__(
                f"minvar.{node.module}", fromlist=["_"])
            for alias in node.names:
                obj = getattr(module, alias.name)
                assert not inspect.isclass(obj) or alias.name in allowed, (
                    f"{path.name} imports {alias.name} at run time")


def test_import_minvar_is_light_and_exposes_its_submodules():
    code = (
        "import sys, minvar\n"
        "heavy = [m for m in ('matplotlib', 'pandas', 'scipy') if m in sys.modules]\n"
        "assert not heavy, heavy\n"
        "for name in ('analysis', 'baselines', 'grasp', 'grasp_experiments', 'grasp_stats',\n"
        "             'kinematics', 'lqg', 'plant', 'reach', 'similarity', 'task',\n"
        "             'viapoints', 'execution'):\n"
        "    assert getattr(minvar, name).__name__ == 'minvar.' + name, name\n"
        "assert callable(minvar.simulate)  # the function, exported since the start\n"
        "import minvar.reach  # imports minvar.execution: minvar.simulate stays the function\n"
        "assert callable(minvar.simulate) and minvar.solve.__module__ == 'minvar.lqg'\n"
        "assert 'matplotlib' not in sys.modules\n"
        "assert callable(minvar.plotting.new_figure)\n"
        "assert 'grasp_experiments' in dir(minvar)\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
    with pytest.raises(AttributeError, match="nonsense"):
        minvar.nonsense  # noqa: B018


def test_plotting_exposes_every_figure_function_and_loads_them_on_use():
    code = (
        "import sys\n"
        "from minvar.plotting import new_figure\n"
        "assert 'scipy.stats' not in sys.modules and 'minvar.viapoints' not in sys.modules\n"
        "import minvar.plotting as p\n"
        "for name in p.__all__:\n"
        "    assert callable(getattr(p, name)) or name == 'EXPERIMENT_FIGURES', name\n"
        "assert set(p.__all__) <= set(dir(p)) and p.viapoints.__name__.endswith('viapoints')\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
    import minvar.plotting

    with pytest.raises(AttributeError, match="nonsense"):
        minvar.plotting.nonsense  # noqa: B018


def test_every_experiment_has_its_thesis_figures():
    from minvar.plotting import EXPERIMENT_FIGURES

    assert list(EXPERIMENT_FIGURES) == list(EXPERIMENTS)
    for name, builders in EXPERIMENT_FIGURES.items():
        assert len(builders) == 2 and all(s.startswith("fig4_") for s in builders), name


def test_experiment_figures_reject_an_unknown_experiment():
    from minvar.plotting import experiment_figures

    class Custom:  # duck-typed: only the name is read before any drawing
        name = "my-sweep"

    with pytest.raises(ValueError, match="my-sweep"):
        experiment_figures(Custom())


def test_grasp_result_measures_are_the_grasp_stats_functions():
    g = minvar.simulate_grasp(minvar.GraspTask(), 8, seed=3)
    mga, when = grasp_stats.max_grip_aperture(g.aperture, g.relative_time)
    np.testing.assert_array_equal(g.mga, mga)
    np.testing.assert_array_equal(g.mga_time, when)
    np.testing.assert_array_equal(g.wrist_sd, grasp_stats.path_sd(g.wrist))
    np.testing.assert_array_equal(g.aperture_sd, grasp_stats.path_sd(g.aperture))
    np.testing.assert_array_equal(g.aperture, grasp_stats.grip_aperture(g.finger, g.thumb))
    # the same numbers as the formulas they replaced
    np.testing.assert_array_equal(g.mga, g.aperture.max(axis=1))
    np.testing.assert_array_equal(g.aperture_sd, g.aperture.std(axis=0, ddof=1))
    np.testing.assert_array_equal(g.wrist_sd, np.sqrt(g.wrist.var(axis=0, ddof=1).sum(-1)))


@pytest.mark.parametrize("bad", [1, 0, -3, 2.0, True, "5", None])
def test_check_trials_rejects_non_integers_and_fewer_than_two(bad):
    with pytest.raises(ValueError, match="--trials"):
        check_trials(bad, name="--trials")


def test_check_trials_accepts_numpy_integers():
    assert check_trials(np.int64(2)) == 2 and type(check_trials(np.int64(2))) is int

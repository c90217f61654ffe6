"""The code base's own rules, checked on its source: no import cycles between tumble's modules, no test that
asserts nothing (a test that cannot fail proves nothing), and no ``@kernel`` that only compiled code calls (its
Python wrapper would cost compile time for nothing: that is an ``@inline``)."""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "src"


def _module(path: Path) -> str:
    parts = list(path.relative_to(SOURCE).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, modules) -> set[str]:
    """The tumble modules of ``modules`` that ``path`` imports, at its top or inside a function (a lazy import is
    still a dependency). ``from . import module`` imports that module; ``from .control import name``, the package."""
    module = _module(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            base = package.split(".")[: len(package.split(".")) - (node.level - 1)] if node.level else []
            target = ".".join(base + ([node.module] if node.module else []))
            found.update(f"{target}.{a.name}" if f"{target}.{a.name}" in modules else target for a in node.names)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return {m for m in found if m in modules and m != module}


def _import_graph() -> dict[str, set[str]]:
    """Module -> the modules it imports. Packages' ``__init__`` files only gather their modules' names for users,
    so an import of a package is left out (else every module of it would sit in a circle with its package)."""
    paths = {_module(p): p for p in (SOURCE / "tumble").rglob("*.py")}
    packages = {name for name, p in paths.items() if p.name == "__init__.py"}
    return {name: _imports(p, paths) - packages for name, p in paths.items() if name not in packages}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan 1972), iteratively."""
    index, low, on_stack, stack, components = {}, {}, set(), [], []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            for nxt in edges:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        components.append(sorted(component))
    return components


def test_the_cycle_finder_finds_a_circle_and_only_it():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert _cycles(graph) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_module_of_tumble_imports_itself_through_others():
    graph = _import_graph()
    assert {"tumble._validate", "tumble.rotation", "tumble.handles", "tumble.joints"} <= set(graph)
    assert _cycles(graph) == []


def test_validation_helpers_import_nothing_of_tumble():
    assert _import_graph()["tumble._validate"] == set()


# --- the engine's layers (issue 45) ---------------------------------------------------------------------------

# The engine (the World and its rooms, the runner, the step), and what sits on top of it that it must not import:
# vehicles, controllers and trajectories, environments, model and scene files, the command line.
ENGINE = ("tumble.world", "tumble.world_building", "tumble.world_stepping", "tumble.runner", "tumble.controllers",
          "tumble.pipeline", "tumble.dynamics", "tumble.geometry")  # fmt: skip
ABOVE_ENGINE = ("tumble.control", "tumble.vehicles", "tumble.envs", "tumble.models", "tumble.scene_file", "tumble.cli")
# Circles that remain, outside the engine: the test fails when one goes (take it off this list) or another comes.
KNOWN_CIRCLES = [
    ["tumble.articulation", "tumble.models.build", "tumble.models.mjcf", "tumble.models.mjcf.springs",
     "tumble.models.urdf", "tumble.models.urdf.reader"],
]  # fmt: skip


def _within(module: str, prefixes) -> bool:
    return any(module == p or module.startswith(p + ".") for p in prefixes)


def _graph_with_packages() -> dict[str, set[str]]:
    """Module -> the modules it imports, packages included: a package's ``__init__`` that holds code (``control``'s
    names, the root's) is a module like any other, reached by ``from .control import SE3Controller``."""
    paths = {_module(p): p for p in (SOURCE / "tumble").rglob("*.py")}
    return {name: _imports(path, paths) for name, path in paths.items()}


def _engine_imports_above(graph: dict[str, set[str]]) -> set[tuple[str, str]]:
    return {(m, t) for m, targets in graph.items() if _within(m, ENGINE) for t in targets if _within(t, ABOVE_ENGINE)}


def test_the_layer_scan_sees_a_function_level_import_of_a_package():
    graph = _graph_with_packages()
    assert "tumble.models.build" in graph["tumble.articulation"]  # imported inside articulation.from_mjcf
    assert _engine_imports_above({"tumble.world": {"tumble.cli", "tumble.state"}}) == {("tumble.world", "tumble.cli")}


def test_no_import_circles_counting_packages_and_function_level_imports():
    assert sorted(_cycles(_graph_with_packages())) == sorted(KNOWN_CIRCLES)


def test_the_engine_imports_no_vehicle_controller_model_file_scene_file_or_cli():
    assert _engine_imports_above(_graph_with_packages()) == set()


# --- tests that assert something ------------------------------------------------------------------------------

_CHECKING_CALLS = ("raises", "warns", "fail", "deprecated_call", "importorskip", "skip", "xfail")


def _checks(function: ast.AST, helpers: set[str]) -> bool:
    """Whether ``function`` can fail: an assert or raise, pytest.raises/warns/fail, an ``assert*``/``check*``/
    ``expect*`` call (numpy.testing's included), or a call of a helper of its file that itself checks."""
    for node in ast.walk(function):
        if isinstance(node, (ast.Assert, ast.Raise)):
            return True
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in _CHECKING_CALLS or name in helpers or name.lstrip("_").startswith(("assert", "check", "expect")):
                return True
    return False


def _tests_that_check_nothing(source: str) -> list[str]:
    functions = [n for n in ast.walk(ast.parse(source)) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
    helpers: set[str] = set()
    for _ in range(4):  # helpers that call helpers
        helpers |= {f.name for f in functions if not f.name.startswith("test") and _checks(f, helpers)}
    return [f.name for f in functions if f.name.startswith("test") and not _checks(f, helpers)]


def test_the_scan_tells_a_test_that_checks_from_one_that_does_not():
    source = (
        "def helper(x):\n    assert x\n"
        "def test_a():\n    helper(1)\n"
        "def test_b():\n    print('timing')\n"
        "def test_c():\n    with pytest.raises(ValueError):\n        int('x')\n"
    )
    assert _tests_that_check_nothing(source) == ["test_b"]


def test_every_test_asserts_something():
    silent = [
        f"{path.relative_to(REPO)}::{name}"
        for path in sorted((REPO / "tests").rglob("test_*.py"))
        for name in _tests_that_check_nothing(path.read_text(encoding="utf-8"))
    ]
    assert silent == []


# --- kernels that Python calls ----------------------------------------------------------------------------------


def _decorators(function: ast.FunctionDef) -> set[str]:
    names = set()
    for node in function.decorator_list:
        target = node.func if isinstance(node, ast.Call) else node
        names.add(getattr(target, "id", getattr(target, "attr", "")))
    return names


def _kernels_python_never_names(sources: dict[str, str]) -> list[str]:
    """``@kernel`` functions of ``sources`` (name -> text) that no code outside a compiled function names: a call, a
    reference or an attribute of that name in plain Python (a module, a test, a benchmark)."""
    trees = {name: ast.parse(text) for name, text in sources.items()}
    kernels = {
        f.name
        for name, tree in trees.items()
        if name.startswith("src/")
        for f in ast.walk(tree)
        if isinstance(f, ast.FunctionDef) and "kernel" in _decorators(f)
    }
    compiled = {"kernel", "inline"}
    named: set[str] = set()
    for tree in trees.values():
        outside = [n for n in tree.body if not (isinstance(n, ast.FunctionDef) and _decorators(n) & compiled)]
        for top in outside:
            for node in ast.walk(top):
                if isinstance(node, ast.FunctionDef) and _decorators(node) & compiled:
                    continue  # a kernel nested in a test module's helper is still compiled code
                if isinstance(node, ast.Name):
                    named.add(node.id)
                elif isinstance(node, ast.Attribute):
                    named.add(node.attr)
    return sorted(kernels - named)


def test_the_kernel_scan_tells_a_kernel_python_calls_from_one_it_does_not():
    sources = {
        "src/m.py": "@kernel\ndef hot(a):\n    return helper(a)\n@kernel\ndef helper(a):\n    return a\n",
        "tests/t.py": "def test_x():\n    assert m.hot(1)\n",
    }
    assert _kernels_python_never_names(sources) == ["helper"]


def test_every_kernel_is_called_from_python():
    paths = [*(SOURCE / "tumble").rglob("*.py"), *(REPO / "tests").rglob("*.py"), *(REPO / "benchmarks").rglob("*.py")]
    sources = {path.relative_to(REPO).as_posix(): path.read_text(encoding="utf-8") for path in paths}
    assert _kernels_python_never_names(sources) == []


def test_world_is_a_facade_over_its_rooms():
    """World delegates building, stepping, queries and I/O to the modules named for them (issue 45, part 3)."""
    lines = (SOURCE / "tumble" / "world.py").read_text(encoding="utf-8").count("\n")
    assert lines < 600, f"world.py has {lines} lines; move what it does into world_building, world_stepping, ..."

"""Layering: softarm.analytic and softarm.statics never import each other.

They are two independent routes to the same equilibria and the tests compare them, so neither
may reach the other, directly or through a module that imports it. Two checks: the import
statements of every module of each package, read with ast (direct imports, whatever the code
path), and a fresh interpreter that loads one package without softarm/__init__.py (which
imports both) and lists what it pulled in (indirect imports, at import time).
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

import softarm

PACKAGE = Path(softarm.__file__).resolve().parent
ROUTES = {"analytic": "statics", "statics": "analytic"}
# Modules that import both routes (the public package and the dispatcher): off limits too.
BRIDGES = ("softarm", "softarm.dispatch")


def _imported_modules(path: Path) -> set[str]:
    """Absolute names of every module an import statement of ``path`` may load."""
    parts = ["softarm", *path.relative_to(PACKAGE).with_suffix("").parts]
    parts.pop()  # the package relative imports start from (a package's own, for __init__)
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = parts[: len(parts) - node.level + 1] if node.level else []
            module = ".".join([*base, *([node.module] if node.module else [])])
            # `from . import x` may load the submodule module.x; where every x is one, a
            # relative `from .. import x` reads nothing of the package (an enclosing one of
            # this module, loaded before it)
            submodules = {f"{module}.{alias.name}" for alias in node.names}
            names.update(submodules)
            if node.module or not node.level or not all(map(_is_module, submodules)):
                names.add(module)
    return names


def _is_module(name: str) -> bool:
    path = PACKAGE.joinpath(*name.split(".")[1:])
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file()


def _reaches(name: str, target: str) -> bool:
    return name in BRIDGES or name == f"softarm.{target}" or \
        name.startswith(f"softarm.{target}.")


@pytest.mark.parametrize("route", sorted(ROUTES))
def test_no_import_statement_reaches_the_other_route(route):
    other = ROUTES[route]
    files = sorted((PACKAGE / route).rglob("*.py"))
    assert len(files) >= 2  # the package and at least one module were found
    offending = {
        str(path.relative_to(PACKAGE)): sorted(n for n in _imported_modules(path)
                                               if _reaches(n, other))
        for path in files
    }
    assert {k: v for k, v in offending.items() if v} == {}


def test_the_import_statement_reader_sees_relative_imports():
    # dispatch.py imports both routes with relative imports: the reader must flag it.
    names = _imported_modules(PACKAGE / "dispatch.py")
    assert any(_reaches(n, "analytic") for n in names)
    assert any(_reaches(n, "statics") for n in names)


_LOAD_ONE_ROUTE = """
import importlib.util, json, sys, types
spec = importlib.util.find_spec("softarm")
bare = types.ModuleType("softarm")  # the package without its __init__ (which imports both)
bare.__path__ = list(spec.submodule_search_locations)
sys.modules["softarm"] = bare
importlib.import_module("softarm." + sys.argv[1])
print(json.dumps(sorted(name for name in sys.modules if name.startswith("softarm."))))
"""


@pytest.mark.parametrize("route", sorted(ROUTES))
def test_importing_one_route_does_not_load_the_other(route):
    completed = subprocess.run([sys.executable, "-c", _LOAD_ONE_ROUTE, route],
                               capture_output=True, text=True, timeout=300, check=False)
    assert completed.returncode == 0, completed.stderr
    loaded = json.loads(completed.stdout)
    assert f"softarm.{route}" in loaded and "softarm.model" in loaded  # it did load something
    assert [name for name in loaded if _reaches(name, ROUTES[route])] == []


# --------------------------------------------------------------------------------------------
# The house: no import circle, and imports flow one way (docs/conventions.md, "Layers")
# --------------------------------------------------------------------------------------------

#: The layers, lowest first: a module imports its own layer or lower ones, never a higher one.
#: Sub-packages count as one module (``softarm.statics.solver`` is ``statics``); the top
#: package ``softarm`` (its ``__init__`` re-exports, and holds ``__version__``) is not a layer.
LAYERS = (
    ("errors", "_validate", "_threads", "_jit", "_files"),  # helpers that know no physics
    ("lie",),
    ("model",),
    ("routing",),
    ("loads",),
    ("contact",),
    ("geometry", "view"),  # pictures from arrays: numpy (plotly when a page is written)
    ("equilibrium", "_admissible"),  # the result type both routes build, and the model's
    # limits both routes check it against
    ("kernels",),  # the compiled kernels (numba; imported lazily: importing them loads nothing)
    ("analytic", "statics"),  # two independent routes (see the tests above)
    ("dispatch",),
    ("stability", "control", "dynamics"),
    ("_sweep_table", "_simulate_table"),  # the plain data of a [sweep], [simulate] table
    ("_schema",),
    ("_keypath",),
    ("case",),
    ("sweep",),
    ("io", "plot", "app", "cli", "validation", "warmup", "__main__"),  # the front ends
)
#: What a module below the front ends may import inside a function: the compiled kernels
#: (numba compiles them on first use) and the viewer (Equilibrium.show, which needs plotly).
LAZY = ("softarm.analytic._compiled", "softarm.view")
FRONT_ENDS = LAYERS[-1]


def _modules(package: Path = PACKAGE, name: str = "softarm") -> dict[str, Path]:
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = (name, *path.relative_to(package).with_suffix("").parts)
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def _runtime_imports(tree: ast.AST):
    """(import node, inside a function) for every import statement, except those under
    ``if TYPE_CHECKING:`` (type hints only: never imported at run time)."""
    stack = [(tree, False)]
    while stack:
        node, in_function = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node, in_function
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                stack.extend((c, in_function) for c in child.orelse)
                continue
            stack.append((child, in_function or isinstance(
                node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))))


def _edges(modules: dict[str, Path]) -> dict[str, dict[str, bool]]:
    """module -> {imported softarm module: only inside functions}; importing a package's own
    parent package (``from . import x`` inside it) or the top package is no dependency."""
    edges: dict[str, dict[str, bool]] = {m: {} for m in modules}
    for module, path in modules.items():
        base = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
        for node, in_function in _runtime_imports(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            else:
                head = base[: len(base) - node.level + 1] if node.level else []
                target = ".".join([*head, *([node.module] if node.module else [])])
                targets = [f"{target}.{alias.name}" if f"{target}.{alias.name}" in modules
                           else target for alias in node.names]
            for target in targets:
                while target and target not in modules:
                    target = target.rpartition(".")[0]
                if not target or target in ("softarm", module) or \
                        module.startswith(target + "."):
                    continue
                edges[module][target] = edges[module].get(target, True) and in_function
    return edges


def _circles(edges: dict[str, dict[str, bool]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(edges[w]))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    component = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        component.append(w)
                        if w == v:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return found


def _layer(module: str) -> int | None:
    """The index in LAYERS of ``module`` (a sub-package's modules take the package's)."""
    if module == "softarm":
        return None
    head = module.split(".")[1]
    for k, names in enumerate(LAYERS):
        if head in names:
            return k
    raise AssertionError(f"{module} is in no layer of LAYERS: put it in one")


def test_no_import_circle():
    """No circle among softarm's modules, counting imports inside functions (they hide a
    circle from Python's loader, not from a reader)."""
    edges = _edges(_modules())
    assert len(edges) > 50 and edges["softarm.dispatch"]  # the reader found the house
    circles = _circles(edges)
    assert circles == [], "\n".join(
        f"circle of {len(c)}: " + "; ".join(f"{a} -> {b}" for a in c for b in sorted(edges[a])
                                             if b in c) for c in circles)


def test_imports_flow_one_way():
    """Every import, inside a function or not, goes to the module's own layer or a lower one;
    below the front ends, an import inside a function is only for the compiled kernels or
    the viewer (LAZY), never to break a circle."""
    modules = _modules()
    upward, lazy = [], []
    for module, targets in _edges(modules).items():
        own = _layer(module)
        for target, in_function in sorted(targets.items()):
            if own is not None and _layer(target) > own:
                upward.append(f"{module} -> {target}")
            if in_function and target not in LAZY and module != "softarm" and \
                    module.split(".")[1] not in FRONT_ENDS:
                lazy.append(f"{module} -> {target}")
    assert upward == []
    assert lazy == []


def test_the_house_checks_see_a_circle_and_an_upward_import(tmp_path):
    """The checks themselves, on a made-up package: a circle through a function-level import
    is found, an import under `if TYPE_CHECKING:` is not an import."""
    package = tmp_path / "softarm"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "loads.py").write_text("def f():\n    from .case import x\n")
    (package / "case.py").write_text("from .loads import f\nfrom typing import TYPE_CHECKING\n"
                                     "if TYPE_CHECKING:\n    from .sweep import y\n")
    (package / "sweep.py").write_text("from . import case\n")
    edges = _edges(_modules(package))
    assert edges["softarm.loads"] == {"softarm.case": True}
    assert edges["softarm.case"] == {"softarm.loads": False}
    assert edges["softarm.sweep"] == {"softarm.case": False}
    assert _circles(edges) == [["softarm.case", "softarm.loads"]]
    assert _layer("softarm.loads") < _layer("softarm.case")

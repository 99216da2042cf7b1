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
            names.add(module)
            # `from . import x` may load the submodule module.x
            names.update(f"{module}.{alias.name}" for alias in node.names)
    return names


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

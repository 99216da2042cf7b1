"""The compiled kernels' cache rule (softarm/kernels/__init__.py, "The cache rule").

numba keys a function's on-disk cache on its own source file: a caller compiled in one file
keeps the code of a callee from another file after that file changes. The kernels are one
module per capability, calling each other, so each is cached under a stamp of its file and
of every file of the package it imports (``softarm._jit.jit(..., key_on_imports=True)``).
Checked here on a made-up package in fresh processes with a numba cache of their own: the
callee's file changes between two runs, and the caller must return the new value (plain
numba, the same package without the rule, returns the stale one: the reason for the rule).
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import subprocess
import sys
import textwrap

import pytest

from softarm import _jit, kernels

CALLEE = "from softarm._jit import jit\n\n\n@jit({rule})\ndef value():\n    return {value}\n"
MIDDLE = "from .callee import value\n"  # imports the callee, compiles nothing of its own
CALLER = textwrap.dedent("""\
    from softarm._jit import jit

    from . import middle


    @jit({rule})
    def twice():
        return 2.0 * middle.value()
    """)


def _run(tmp_path, package: str) -> float:
    done = subprocess.run(
        [sys.executable, "-c", f"from {package}.caller import twice; print(twice())"],
        cwd=tmp_path, capture_output=True, text=True, timeout=300,
        env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
                 SOFTARM_COMPILE_NOTICE="0", PYTHONPATH=str(tmp_path)))
    assert done.returncode == 0, done.stderr
    return float(done.stdout)


def _package(tmp_path, name: str, rule: str, value: float) -> None:
    folder = tmp_path / name
    folder.mkdir(exist_ok=True)
    (folder / "__init__.py").write_text("")
    (folder / "callee.py").write_text(CALLEE.format(rule=rule, value=value))
    (folder / "middle.py").write_text(MIDDLE)
    (folder / "caller.py").write_text(CALLER.format(rule=rule))


@pytest.mark.parametrize("rule, stale", [("key_on_imports=True", False), ("", True)])
def test_a_changed_callee_in_another_file_recompiles_its_caller(tmp_path, rule, stale):
    _package(tmp_path, "pkg", rule, 1.5)
    assert _run(tmp_path, "pkg") == 3.0  # compiled, cached
    assert _run(tmp_path, "pkg") == 3.0  # loaded from the cache
    _package(tmp_path, "pkg", rule, 4.0)  # the callee's file changes, the caller's does not
    assert _run(tmp_path, "pkg") == (3.0 if stale else 8.0)


def test_the_stamp_covers_what_a_file_imports_and_nothing_else(tmp_path):
    """imports_stamp: the file and the package files it imports, through others too; not a
    file it does not import, nor the file that imports it."""
    _package(tmp_path, "pkg", "key_on_imports=True", 1.5)
    (tmp_path / "pkg" / "other.py").write_text("X = 1\n")
    caller, callee = str(tmp_path / "pkg" / "caller.py"), str(tmp_path / "pkg" / "callee.py")
    before = _jit.imports_stamp(caller), _jit.imports_stamp(callee)
    _jit._file_digest.cache_clear()
    (tmp_path / "pkg" / "other.py").write_text("X = 2\n")
    assert (_jit.imports_stamp(caller), _jit.imports_stamp(callee)) == before
    _jit._file_digest.cache_clear()
    (tmp_path / "pkg" / "caller.py").write_text(CALLER.format(rule="") + "\n")
    assert _jit.imports_stamp(callee) == before[1]
    assert _jit.imports_stamp(caller) != before[0]
    _jit._file_digest.cache_clear()
    (tmp_path / "pkg" / "callee.py").write_text(CALLEE.format(rule="", value=2.0))
    assert _jit.imports_stamp(callee) != before[1]
    _jit._file_digest.cache_clear()


def test_every_kernel_is_cached_under_the_rule():
    """Every compiled function of softarm.kernels (its entry points and the functions they
    call) carries the stamp of its imports; the dynamics' stamp does not cover shooting."""
    from numba.core.registry import CPUDispatcher

    modules = [importlib.import_module(f"softarm.kernels.{info.name}")
               for info in pkgutil.iter_modules(kernels.__path__)]
    dispatchers = {f"{m.__name__}.{n}": v for m in modules for n, v in vars(m).items()
                   if isinstance(v, CPUDispatcher) and v.__module__ == m.__name__}
    assert len(dispatchers) > 130
    unruled = [name for name, d in dispatchers.items()
               if not isinstance(d._cache, _jit._ImportsKeyedCache)]
    assert unruled == []
    assert set(_jit._sibling_imports(sys.modules["softarm.kernels.dynamics"].__file__)) == {
        "_compile", "layout", "linear", "rod"}

"""``softarm compile`` pays the first solve ahead; ``softarm compile --all`` every capability.

In a fresh numba cache: ``softarm compile``, then a first passive solve, ``softarm compile``
again, ``softarm compile --all`` in the same cache (it compiles what the first left out, as it
would after a user's ``softarm compile``), then every capability a user can call. The module
fixture runs them all (about 7 minutes of compiling: the longest piece of ``pytest -m slow``);
the tests read its outcome.

Design note, for the slow run's wall time only: the fixture runs in the setup of the first of
three tests in this file. pytest-xdist (``--dist loadfile``) hands a worker another file only
once two or fewer of its tests are left, so no file waits behind the compile on this worker
while the other worker runs everything else; tests/conftest.py puts this file first.
"""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from _cold_cache import PASSIVE_SOLVE, cache_env, python_with, softarm_with


def _compiled_files(cache: Path) -> dict[Path, int]:
    """numba's index and data files in ``cache``: a compile writes or rewrites them."""
    return {path: path.stat().st_mtime_ns for path in cache.rglob("*")
            if path.suffix in (".nbi", ".nbc")}


@dataclass
class _Runs:
    """The commands in their order, each a CompletedProcess, and numba's cache files before
    and after the last."""

    compile: subprocess.CompletedProcess
    solve: subprocess.CompletedProcess
    again: subprocess.CompletedProcess
    compile_all: subprocess.CompletedProcess
    every: subprocess.CompletedProcess
    before: dict
    after: dict


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> _Runs:
    cache = tmp_path_factory.mktemp("numba-cache")
    first = softarm_with("compile", cache=cache)
    solve = python_with(PASSIVE_SOLVE, "_steps", cache=cache)
    again = softarm_with("compile", cache=cache, notice=False)
    compile_all = softarm_with("compile", "--all", cache=cache)
    before = _compiled_files(cache)
    every = subprocess.run([sys.executable, str(Path(__file__).parent / "_every_capability.py")],
                           capture_output=True, text=True, timeout=1800,
                           env=cache_env(cache, notice=True))
    return _Runs(first, solve, again, compile_all, every, before, _compiled_files(cache))


@pytest.mark.slow
def test_softarm_compile_pays_the_first_solve_ahead(runs):
    """``softarm compile`` compiles the passive solver with its verdict and the closed forms,
    showing its own progress; a first passive solve after it compiles nothing (no notice)."""
    assert runs.compile.returncode == 0, runs.compile.stderr
    lines = runs.compile.stdout.splitlines()
    assert lines[0].startswith(" 1/2 the solver and its stability verdict for passive arms: ")
    assert lines[1].startswith(" 2/2 the closed forms: ")
    assert "kernels compiled in" in lines[-1]
    assert "softarm: compiling" not in runs.compile.stderr
    assert runs.solve.returncode == 0, runs.solve.stderr
    assert "compiling" not in runs.solve.stderr
    assert runs.solve.stdout.splitlines()[0] == "{'_steps': 0}"  # numba's cache: no miss


@pytest.mark.slow
def test_softarm_compile_again_finds_everything_cached(runs):
    assert runs.again.returncode == 0, runs.again.stderr
    assert runs.again.stdout.splitlines()[-1] == \
        "every kernel was already compiled (numba's cache)"


@pytest.mark.slow
def test_after_compile_all_no_capability_compiles_anything(runs):
    """After ``softarm compile --all``, every capability a user can call
    (tests/_every_capability.py: statics passive, actuated, magnetic and touching, single and
    multiple shooting with and without Jacobians and the verdict, closed forms and their
    verdict in tension too, inverse statics, critical loads and continuation, dynamics with
    and without contact and actuation, case files) compiles nothing: no compile notice, and
    numba's cache gets no new file. Found before: the stiff closed forms' verdict, multiple
    shooting without the verdict or with Jacobians, actuated critical loads and dynamics from
    an equilibrium, with contact, with a moving base, all compiled on first use after
    compile --all."""
    assert runs.compile_all.returncode == 0, runs.compile_all.stderr
    assert runs.every.returncode == 0, runs.every.stdout + runs.every.stderr
    assert len(runs.every.stdout.splitlines()) >= 40, runs.every.stdout
    assert "compiling" not in runs.every.stderr, runs.every.stderr
    assert runs.after == runs.before

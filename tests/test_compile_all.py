"""``softarm compile`` pays the first solve ahead; ``softarm compile --all`` every capability.

In a fresh numba cache: ``softarm compile``, then a first passive solve, then ``softarm
compile`` again. Then, in the cache the tests use, ``softarm compile --all`` and every
capability a user can call, each listing the kernel versions it used (compiled or loaded:
tests/_touched.py): every version a capability uses must be one that ``compile --all``
compiled or loaded. The module fixture runs them all; the tests read its outcome.

Design note, for the slow run's wall time: ``compile --all`` in a fresh cache of its own
compiled every kernel once more than the rest of the run (566 s of a 892-s ``pytest -m slow``,
with a core of its own). In the tests' cache it compiles only what no test compiled before it
(after a cold default run: 8 kernels, 173 s on a quiet machine), and the tests after it load
what it compiled. (Under the slow run's load the fixture was not shorter for it: 738-832 s in
.ci/run, its compiles beside the other worker's of the same slow-only kernels.) What a user's
fresh cache would give, "after ``compile --all`` nothing compiles", is the same statement as
"every version a capability uses is one that ``compile --all`` used", and only the second holds
in a cache that other tests share (one compiled there first, or lost to two processes writing
its index at once, says nothing about ``compile --all``). The fixture runs in the setup of the
first of three tests in this file; tests/conftest.py puts this file first.
"""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from _cold_cache import PASSIVE_SOLVE, cache_env, python_with, softarm_with

HERE = Path(__file__).parent


@dataclass
class _Runs:
    """The commands in their order, each a CompletedProcess, and the kernel versions that
    ``compile --all`` and every capability used (tests/_touched.py)."""

    compile: subprocess.CompletedProcess
    solve: subprocess.CompletedProcess
    again: subprocess.CompletedProcess
    compile_all: subprocess.CompletedProcess
    every: subprocess.CompletedProcess
    compile_all_used: dict
    every_used: dict


def _used(out: Path, *command: str) -> tuple[subprocess.CompletedProcess, dict]:
    """``command`` run by tests/_touched.py in the tests' numba cache: (the process, the
    kernel versions it used)."""
    run = subprocess.run([sys.executable, str(HERE / "_touched.py"), str(out), *command],
                         capture_output=True, text=True, timeout=1800,
                         env=cache_env(None, notice=True))
    return run, json.loads(out.read_text()) if out.exists() else {}


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> _Runs:
    cache = tmp_path_factory.mktemp("numba-cache")
    first = softarm_with("compile", cache=cache)
    solve = python_with(PASSIVE_SOLVE, "_steps", cache=cache)
    again = softarm_with("compile", cache=cache, notice=False)
    used = tmp_path_factory.mktemp("used")
    compile_all, compile_all_used = _used(used / "compile_all.json", "-m", "softarm",
                                          "compile", "--all")
    every, every_used = _used(used / "every.json", str(HERE / "_every_capability.py"))
    return _Runs(first, solve, again, compile_all, every, compile_all_used, every_used)


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
    """``softarm compile --all`` compiles every kernel version that a capability a user can
    call uses (tests/_every_capability.py: statics passive, actuated, magnetic and touching,
    single and multiple shooting with and without Jacobians and the verdict, closed forms and
    their verdict in tension too, inverse statics, critical loads and continuation, dynamics
    with and without contact and actuation, case files): in a user's fresh cache, nothing
    compiles after it. Found before: the stiff closed forms' verdict, multiple shooting
    without the verdict or with Jacobians, actuated critical loads and dynamics from an
    equilibrium, with contact, with a moving base, all compiled on first use after
    compile --all."""
    assert runs.compile_all.returncode == 0, runs.compile_all.stderr
    assert runs.every.returncode == 0, runs.every.stdout + runs.every.stderr
    assert len(runs.every.stdout.splitlines()) >= 40, runs.every.stdout
    # the kernels of the statics, the dynamics and the closed forms, in several versions
    assert {"softarm.kernels.shooting.solve_cases", "softarm.kernels.dynamics.dynamic_steps",
            "softarm.analytic._compiled.solve"} <= set(runs.every_used)
    assert sum(map(len, runs.every_used.values())) >= 30, runs.every_used
    missed = {kernel: sorted(set(versions) - set(runs.compile_all_used.get(kernel, ())))
              for kernel, versions in runs.every_used.items()}
    assert not {kernel: versions for kernel, versions in missed.items() if versions}

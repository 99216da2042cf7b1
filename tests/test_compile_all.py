"""``softarm compile`` pays the first solve ahead; ``softarm compile --all`` every capability.

One test, in its own file so that pytest-xdist runs it beside tests/test_compile.py (its
cold compiles are the longest test of ``pytest -m slow``): ``softarm compile`` in a fresh
numba cache, then ``softarm compile --all`` in the same cache (it compiles what the first left
out, as it would after a user's ``softarm compile``), then every capability.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from _cold_cache import PASSIVE_SOLVE, cache_env, python_with, softarm_with


def _compiled_files(cache: Path) -> dict[Path, int]:
    """numba's index and data files in ``cache``: a compile writes or rewrites them."""
    return {path: path.stat().st_mtime_ns for path in cache.rglob("*")
            if path.suffix in (".nbi", ".nbc")}


@pytest.mark.slow
def test_softarm_compile_pays_the_first_solve_ahead_and_compile_all_everything(tmp_path):
    """After ``softarm compile`` a first passive solve compiles nothing. After ``softarm
    compile --all``, every capability a user can call (tests/_every_capability.py: statics
    passive, actuated, magnetic and touching, single and multiple shooting with and without
    Jacobians and the verdict, closed forms and their verdict in tension too, inverse statics,
    critical loads and continuation, dynamics with and without contact and actuation, case
    files) compiles nothing: no compile notice, and numba's cache gets no new file. Found
    before: the stiff closed forms' verdict, multiple shooting without the verdict or with
    Jacobians, actuated critical loads and dynamics from an equilibrium, with contact, with a
    moving base, all compiled on first use after compile --all."""
    cache = tmp_path / "cache"
    run = softarm_with("compile", cache=cache)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0].startswith(" 1/2 the solver and its stability verdict for passive arms: ")
    assert lines[1].startswith(" 2/2 the closed forms: ")
    assert "kernels compiled in" in lines[-1]
    assert "softarm: compiling" not in run.stderr  # the command shows its own progress
    # then a first solve compiles nothing: no notice
    solve = python_with(PASSIVE_SOLVE, "_steps", cache=cache)
    assert solve.returncode == 0, solve.stderr
    assert "compiling" not in solve.stderr
    # and the command again: everything cached
    again = softarm_with("compile", cache=cache, notice=False)
    assert again.returncode == 0
    assert again.stdout.splitlines()[-1] == "every kernel was already compiled (numba's cache)"

    done = softarm_with("compile", "--all", cache=cache)
    assert done.returncode == 0, done.stderr
    before = _compiled_files(cache)
    every = subprocess.run([sys.executable, str(Path(__file__).parent / "_every_capability.py")],
                           capture_output=True, text=True, timeout=1800,
                           env=cache_env(cache, notice=True))
    assert every.returncode == 0, every.stdout + every.stderr
    assert len(every.stdout.splitlines()) >= 40 and "compiling" not in every.stderr, every.stderr
    assert _compiled_files(cache) == before

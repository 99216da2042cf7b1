"""The first minute: compiled per capability, announced once, paid ahead with ``softarm compile``.

Each test here starts processes with an empty numba cache of their own (a cold start, as on a
new machine), so the kernels really compile: a passive solve must compile the solver and the
verdict for passive arms and nothing of the actuated law, the Jacobians' input columns, the
chained starts or inverse statics; the notice must come once per capability with an estimate
that, once measured, is this machine's own figure.
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

_PASSIVE_SOLVE = """
import sys, numpy as np, softarm
from softarm.statics.solver import _kernels
silicone = softarm.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)
arm = softarm.Arm(0.2, softarm.Circle(0.01), silicone)
eq = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=[0.0, 0.01, 0.0])],
                   method="numeric")
k = _kernels()
# what this process compiled: numba's cache misses per kernel (a load from the cache is a hit)
print({name: sum(getattr(k, name).stats.cache_misses.values()) for name in sys.argv[1:]})
print(repr(eq.tip_position.tolist()))
"""

#: kernels of other capabilities: a passive solve from the unloaded arm compiles none
_NOT_PASSIVE = ("_law", "_dipole", "_actuator_rates", "_ldl_substitute", "_implicit_function",
                "inverse_newton", "box_least_squares", "shoot", "sweep_point",
                "solve_stiff_cases", "_band_factor", "_ms_evaluate", "dynamic_steps",
                "_node_rates", "_dyn_newton", "_contact", "_nearest", "_pressure",
                "_moving_contact")


def _python(code: str, *args: str, cache: Path, notice: bool = True, prefetch: bool = False):
    """``python -c code args`` with its own numba cache, the compile notice on or off, and
    the verdict's compile on another core (statics/_prefetch.py) or in the process."""
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          timeout=900, env=_env(cache, notice, prefetch))


def _softarm(*args: str, cache: Path, notice: bool = True):
    return subprocess.run([sys.executable, "-m", "softarm", *args], capture_output=True,
                          text=True, timeout=900, env=_env(cache, notice))


def _env(cache: Path, notice: bool, prefetch: bool = False) -> dict:
    return dict(os.environ, NUMBA_CACHE_DIR=str(cache),
                SOFTARM_COMPILE_NOTICE="1" if notice else "0",
                SOFTARM_PREFETCH="1" if prefetch else "0")


@pytest.fixture(scope="module")
def first_solve(tmp_path_factory):
    """(cache, process): a passive solve in a process with an empty cache."""
    cache = tmp_path_factory.mktemp("numba-cache")
    return cache, _python(_PASSIVE_SOLVE, *_NOT_PASSIVE, "_steps", cache=cache)


@pytest.mark.slow
def test_a_passive_solve_compiles_its_capability_alone_and_says_so_once(first_solve):
    cache, run = first_solve
    assert run.returncode == 0, run.stderr
    compiled = ast.literal_eval(run.stdout.splitlines()[0])
    assert compiled.pop("_steps") == 1  # the RK4 step: one version, for passive arms
    assert compiled == dict.fromkeys(_NOT_PASSIVE, 0)
    notices = [line for line in run.stderr.splitlines() if line.startswith("softarm:")]
    assert [line.split(",")[0] for line in notices] == [
        "softarm: compiling the solver for passive arms",
        "softarm: compiling the stability verdict for passive arms"]
    assert all("on this machine" in line and "about " in line for line in notices)
    # the times were measured and recorded beside the compiled code
    records = list(cache.rglob("softarm-compile-seconds.json"))
    assert len(records) == 1
    record = json.loads(records[0].read_text())
    assert set(record) == {"solve", "verdict"} and all(v > 0 for v in record.values())

    # a second process loads everything from the cache: no notice, the same answer
    again = _python(_PASSIVE_SOLVE, "_steps", cache=cache)
    assert again.returncode == 0, again.stderr
    assert "compiling" not in again.stderr
    assert ast.literal_eval(again.stdout.splitlines()[0]) == {"_steps": 0}
    assert again.stdout.splitlines()[1] == run.stdout.splitlines()[1]


@pytest.mark.slow
def test_the_estimate_is_this_machines_measurement_once_there_is_one(first_solve):
    # the time recorded by the first compile is what the next estimate says; a capability
    # not yet compiled here is estimated (the reference machine's time, scaled)
    cache, first = first_solve
    assert first.returncode == 0, first.stderr
    code = """
from softarm._jit import compile_seconds
from softarm.statics.solver import _kernels
print(compile_seconds("solve", _kernels().solve_cases))
print(compile_seconds("solve+jacobians", _kernels().solve_cases))
"""
    run = _python(code, cache=cache)
    assert run.returncode == 0, run.stderr
    measured, unmeasured = (ast.literal_eval(line) for line in run.stdout.splitlines())
    record = json.loads(next(cache.rglob("softarm-compile-seconds.json")).read_text())
    assert measured == (record["solve"], True)
    assert unmeasured[1] is False and unmeasured[0] > 0


@pytest.mark.slow
def test_softarm_compile_pays_the_first_solve_ahead(tmp_path):
    cache = tmp_path / "cache"
    run = _softarm("compile", cache=cache)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0].startswith(" 1/2 the solver and its stability verdict for passive arms: ")
    assert lines[1].startswith(" 2/2 the closed forms: ")
    assert "kernels compiled in" in lines[-1]
    assert "softarm: compiling" not in run.stderr  # the command shows its own progress
    # then a first solve compiles nothing: no notice
    solve = _python(_PASSIVE_SOLVE, "_steps", cache=cache)
    assert solve.returncode == 0, solve.stderr
    assert "compiling" not in solve.stderr
    # and the command again: everything cached
    again = _softarm("compile", cache=cache, notice=False)
    assert again.returncode == 0
    assert again.stdout.splitlines()[-1] == "every kernel was already compiled (numba's cache)"


@pytest.mark.slow
@pytest.mark.skipif((len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                     else os.cpu_count() or 1) < 2,
                    reason="the verdict compiles beside the solver only with 2 usable cores")
def test_a_cold_first_solve_compiles_its_verdict_on_another_core(tmp_path):
    run = _python(_PASSIVE_SOLVE, "stability_cases", "_record", "solve_cases", cache=tmp_path,
                  prefetch=True)
    assert run.returncode == 0, run.stderr
    # this process compiled the solver's path; the output pass and the verdict it loaded
    # from the cache, where the other process had put them
    assert ast.literal_eval(run.stdout.splitlines()[0]) == {
        "stability_cases": 0, "_record": 0, "solve_cases": 1}
    notices = [line for line in run.stderr.splitlines() if line.startswith("softarm:")]
    assert len(notices) == 1 and notices[0].startswith(
        "softarm: compiling the solver for passive arms (its output pass and stability "
        "verdict on another core), once (about ")
    # the times are this process's: the other one's include what this one compiled too
    record = json.loads(next(tmp_path.rglob("softarm-compile-seconds.json")).read_text())
    assert set(record) == {"solve"}

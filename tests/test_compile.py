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

import pytest
from _cold_cache import PASSIVE_SOLVE, cache_env, python_with

#: kernels of other capabilities: a passive solve from the unloaded arm compiles none
_NOT_PASSIVE = ("_law", "_dipole", "_actuator_rates", "_ldl_substitute", "_implicit_function",
                "inverse_newton", "box_least_squares", "shoot", "sweep_point",
                "solve_stiff_cases", "_band_factor", "_ms_evaluate", "dynamic_steps",
                "_node_rates", "_dyn_newton", "_contact", "_nearest", "_pressure",
                "_moving_contact")


@pytest.fixture(scope="module")
def first_solve(tmp_path_factory):
    """(cache, process): a passive solve in a process with an empty cache."""
    cache = tmp_path_factory.mktemp("numba-cache")
    return cache, python_with(PASSIVE_SOLVE, *_NOT_PASSIVE, "_steps", cache=cache)


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
    # a first compile here: it says so, with the reference machine's time, and that it varies
    assert all(", once: a first compile on this machine (it varies with the machine and its "
               "load; about " in line and "on a quiet 2-core reference machine" in line
               for line in notices)
    assert "\r" not in run.stderr  # not a terminal: no elapsed time drawn
    # the times were measured and recorded beside the compiled code
    records = list(cache.rglob("softarm-compile-seconds.json"))
    assert len(records) == 1
    record = json.loads(records[0].read_text())  # per capability, per compiled version
    assert set(record) == {"solve", "verdict"}
    assert all(len(v) == 1 and min(min(t) for t in v.values()) > 0 for v in record.values())

    # a second process loads everything from the cache: no notice, the same answer
    again = python_with(PASSIVE_SOLVE, "_steps", cache=cache)
    assert again.returncode == 0, again.stderr
    assert "compiling" not in again.stderr
    assert ast.literal_eval(again.stdout.splitlines()[0]) == {"_steps": 0}
    assert again.stdout.splitlines()[1] == run.stdout.splitlines()[1]


@pytest.mark.slow
def test_the_estimate_is_this_machines_measurement_once_there_is_one(first_solve):
    # the time recorded by the first compile is what the next estimate says; for a capability
    # not yet compiled here, the reference machine's time (not scaled: not a measurement)
    cache, first = first_solve
    assert first.returncode == 0, first.stderr
    code = """
from softarm._jit import compile_seconds
from softarm import kernels
print(compile_seconds("solve", kernels.solve_cases))
print(compile_seconds("solve+jacobians", kernels.solve_cases))
"""
    run = python_with(code, cache=cache)
    assert run.returncode == 0, run.stderr
    measured, unmeasured = (ast.literal_eval(line) for line in run.stdout.splitlines())
    record = json.loads(next(cache.rglob("softarm-compile-seconds.json")).read_text())
    assert measured == (sum(wall for wall, _ in record["solve"].values()), True)
    from softarm._jit import REFERENCE_SECONDS

    assert unmeasured == (REFERENCE_SECONDS["solve+jacobians"], False)


@pytest.mark.slow
@pytest.mark.skipif((len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                     else os.cpu_count() or 1) < 2,
                    reason="the verdict compiles beside the solver only with 2 usable cores")
def test_a_cold_first_solve_compiles_its_verdict_on_another_core(tmp_path):
    run = python_with(PASSIVE_SOLVE, "stability_cases", "_record", "solve_cases", cache=tmp_path,
                  prefetch=True)
    assert run.returncode == 0, run.stderr
    # this process compiled the solver's path; the output pass and the verdict it loaded
    # from the cache, where the other process had put them
    assert ast.literal_eval(run.stdout.splitlines()[0]) == {
        "stability_cases": 0, "_record": 0, "solve_cases": 1}
    notices = [line for line in run.stderr.splitlines() if line.startswith("softarm:")]
    assert len(notices) == 1 and notices[0].startswith(
        "softarm: compiling the solver for passive arms (its output pass and stability "
        "verdict on another core), once: a first compile on this machine (")
    # the times are this process's: the other one's include what this one compiled too
    record = json.loads(next(tmp_path.rglob("softarm-compile-seconds.json")).read_text())
    assert set(record) == {"solve"}


def test_the_notice_says_what_was_measured_and_nothing_else():
    from softarm import _jit

    measured = _jit.announcement("the closed forms", 63.4, True, True)
    assert measured == ("softarm: compiling the closed forms, once (it took about 65 s on this "
                        "machine the last time; later runs load it from the cache)")
    first = _jit.announcement("the closed forms", 3.0, False, True)
    assert first == ("softarm: compiling the closed forms, once: a first compile on this "
                     "machine (it varies with the machine and its load; about 3 s on a quiet "
                     "2-core reference machine, more on a busy one; later runs load it from "
                     "the cache)")
    unknown = _jit.announcement("the closed forms", None, False, True)
    assert "reference" not in unknown and "a first compile on this machine" in unknown
    assert "every process compiles it" in _jit.announcement("x", 3.0, False, False)


class _Stream:
    def __init__(self, tty: bool):
        self.tty, self.text = tty, ""

    def isatty(self) -> bool:
        return self.tty

    def write(self, text: str) -> None:
        self.text += text

    def flush(self) -> None:
        pass


def test_the_elapsed_time_of_a_compile_is_drawn_on_a_terminal_only():
    import time

    from softarm._jit import Elapsed

    tty = _Stream(True)
    shown = Elapsed(tty, after=0.5, every=0.05).start()
    time.sleep(0.1)
    assert tty.text == ""  # not before `after` seconds (a margin for a busy machine)
    time.sleep(0.8)
    shown.stop()
    drawn = tty.text.split("\r")[1:]
    assert len(drawn) >= 3 and drawn[0] in ("  compiling... 0 s", "  compiling... 1 s")
    assert drawn[-1] == "\x1b[K"  # erased at the end
    quick = _Stream(True)
    Elapsed(quick, after=1.0).start().stop()  # a compile shorter than `after`: nothing
    assert quick.text == ""
    pipe = _Stream(False)
    hidden = Elapsed(pipe, after=0.0, every=0.01).start()
    time.sleep(0.1)
    hidden.stop()
    assert pipe.text == "" and hidden.thread is None


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="a pseudo-terminal")
def test_a_compile_on_a_terminal_shows_its_elapsed_time_then_the_measurement(tmp_path):
    """A first compile of the closed forms with stderr on a pseudo-terminal draws its elapsed
    time in place (from PROGRESS_AFTER on, here 0.2 s) and erases it; a later compile of the
    same capability on this machine (numba's cache gone, as after an upgrade; the record
    kept) quotes the time measured the first time, read from the record."""
    import pty
    import shutil

    code = """
import softarm, softarm._jit as jit
jit.PROGRESS_AFTER = 0.2
arm = softarm.Arm(0.2, softarm.Circle(0.01), softarm.Material(1.5e6, poisson_ratio=0.49))
softarm.solve(arm, [softarm.TipLoad(force=[0.0, 0.0, -0.05])], method="analytic",
              stability=False)  # (the verdict is another capability, compiled apart)
"""
    cache = tmp_path / "cache"
    master, slave = pty.openpty()
    try:
        process = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.DEVNULL,
                                   stdout=subprocess.DEVNULL, stderr=slave,
                                   env=cache_env(cache, notice=True))
        os.close(slave)
        drawn = b""
        while True:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # the child closed the terminal
                break
            if not chunk:
                break
            drawn += chunk
        process.wait(timeout=900)
    finally:
        os.close(master)
    assert process.returncode == 0, drawn
    text = drawn.decode()
    assert "softarm: compiling the closed forms" in text and "a first compile" in text
    assert "\r  compiling... " in text and text.rstrip("\n").endswith("\r\x1b[K")
    # (each compiled module's cache folder has its own record: the closed forms' is the one)
    records = {path: json.loads(path.read_text())
               for path in cache.rglob("softarm-compile-seconds.json")}
    [record_file] = [path for path, record in records.items() if "closed forms" in record]
    seconds = sum(wall for wall, _ in records[record_file]["closed forms"].values())
    again = tmp_path / "again"
    (again / record_file.parent.relative_to(cache)).mkdir(parents=True)
    shutil.copy(record_file, again / record_file.relative_to(cache))
    run = python_with(code, cache=again)
    assert run.returncode == 0, run.stderr
    from softarm._jit import _about

    assert (f"softarm: compiling the closed forms' kernels, once (it took about "
            f"{_about(seconds)} on this machine the last time;") in run.stderr


def test_a_version_never_compiled_here_is_a_first_compile(tmp_path):
    """The record holds each compiled version's seconds: a version recorded is quoted with the
    sum of its capability's versions (a recompile after an upgrade); another version of the
    same capability (other argument types) is a first compile, quoted from the reference."""
    from types import SimpleNamespace

    from softarm import _jit

    dispatcher = SimpleNamespace(_cache=SimpleNamespace(cache_path=str(tmp_path)),
                                 py_func=test_a_version_never_compiled_here_is_a_first_compile)
    _jit._write_record(dispatcher, "dynamics", "dynamic_steps:aaa", 20.0, 19.0)
    _jit._write_record(dispatcher, "dynamics", "dynamic_steps:bbb", 5.5, 5.0)
    record = json.loads((tmp_path / "softarm-compile-seconds.json").read_text())
    assert record == {"dynamics": {"dynamic_steps:aaa": [20.0, 19.0],
                                   "dynamic_steps:bbb": [5.5, 5.0]}}
    assert _jit.compile_seconds("dynamics", dispatcher, "dynamic_steps:bbb") == (25.5, True)
    assert _jit.compile_seconds("dynamics", dispatcher) == (25.5, True)
    assert _jit.compile_seconds("dynamics", dispatcher, "dynamic_steps:ccc") == (
        _jit.REFERENCE_SECONDS["dynamics"], False)
    assert _jit.compile_seconds("solve", dispatcher) == (_jit.REFERENCE_SECONDS["solve"], False)
    # the same argument types name the same version in every process
    assert _jit._variant(dispatcher, ("a", 1)) == _jit._variant(dispatcher, ("a", 1)) != \
        _jit._variant(dispatcher, ("a", 2))


def test_every_capability_of_softarm_compile_has_a_reference_time():
    from softarm._jit import REFERENCE_SECONDS
    from softarm.warmup import STEPS

    keys = {key for step in STEPS for key in step.keys}
    assert keys == set(REFERENCE_SECONDS)


def test_the_verdict_compiles_beside_only_where_a_core_is_idle(monkeypatch):
    """kernels/_prefetch.py launches the other process where the 1-minute load average
    leaves the second core free (2 cores: load < 1), or always with SOFTARM_PREFETCH=1, never
    with 0 (a cold demo on a 2-core machine: 19.4 s with it, 26.9 s without at load 0.8;
    46.0 s and 33.5 s at load 1.5-2.5; 104 s and 64 s at load 6.7)."""
    from types import SimpleNamespace

    from softarm.kernels import _prefetch

    launched = []

    class Popen:
        def __init__(self, *args, **kwargs):
            launched.append(args)

        def poll(self):
            return 0

    monkeypatch.setattr(_prefetch.subprocess, "Popen", Popen)
    monkeypatch.setattr(_prefetch, "_usable_cores", lambda: 2)
    monkeypatch.setattr(_prefetch, "_RUNNING", {})
    dispatcher = SimpleNamespace(_cache=SimpleNamespace(cache_path="/nowhere"))
    for load, wanted, launches in [(0.2, None, True), (0.9, None, True), (1.0, None, False),
                                   (1.5, None, False), (6.7, None, False), (6.7, "1", True),
                                   (0.2, "0", False)]:
        monkeypatch.setattr(_prefetch.os, "getloadavg", lambda load=load: (load, 0.0, 0.0))
        if wanted is None:
            monkeypatch.delenv("SOFTARM_PREFETCH", raising=False)
        else:
            monkeypatch.setenv("SOFTARM_PREFETCH", wanted)
        _prefetch._RUNNING.clear()
        launched.clear()
        said = _prefetch.start("passive", dispatcher)
        assert bool(launched) is launches and (said is not None) is launches, (load, wanted)


def test_compile_all_shares_its_steps_among_processes_by_their_reference_times():
    """softarm compile --all --jobs N: every step in exactly one share, the first step (the
    passive solver) in this process's, and no share over the largest step's time beyond an
    even split (the greedy bound: a share exceeds total/N by at most one step)."""
    from softarm._jit import REFERENCE_SECONDS
    from softarm.warmup import STEPS, _shares, compile_kernels

    def cost(step):
        return sum(REFERENCE_SECONDS.get(key, 5.0) for key in step.keys)

    steps = list(STEPS)
    for jobs in (1, 2, 3):
        shares = _shares(steps, jobs)
        assert len(shares) == jobs and shares[0][0] is steps[0]
        assert sorted(s.name for share in shares for s in share) == sorted(s.name for s in steps)
        total = sum(cost(s) for s in steps)
        assert max(sum(cost(s) for s in share) for share in shares) <= \
            total / jobs + max(cost(s) for s in steps)
    with pytest.raises(ValueError, match="jobs must be a positive integer, got 0"):
        compile_kernels(all=True, jobs=0)

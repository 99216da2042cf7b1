"""A cold first solve compiles its output pass and its verdict on another core.

A first solve on a machine compiles the solver (``solve_cases``, with the output pass
``_record`` inside it) and then the stability verdict (``stability_cases``), one after the
other in one process (numba compiles under one lock, mostly in Python). When the solver's
compile starts cold (numba's event, the moment the cache misses), :func:`start` launches a
Python process running ``softarm.statics.solver.compile_beside(KIND)``: it compiles the
output pass and the verdict of the same kind of arm (passive, or actuated/magnetic) into
numba's cache, on the second core, while this process compiles the solver's path. numba
looks a callee up in its cache when the caller first needs it: the solver finds the output
pass there, and :func:`wait`, before the first verdict, waits for the process so that the
verdict is found there too. A cache miss (the process slower, or failed) compiles it here
as before: nothing depends on the process but the time. On a 2-core machine a cold
``softarm demo`` took 29 s with everything in one process, 21 s so (docs/performance.md;
tests/test_compile.py checks that the solver's process compiled neither).

Not launched with one usable core, where numba cannot write its cache, with
``SOFTARM_PREFETCH=0``, or inside such a process itself; nor, unless ``SOFTARM_PREFETCH=1``,
on a busy machine, whose 1-minute load average reaches the usable cores less one (other work
keeps a core's worth busy): there the second core is not free, and the other process's work
(its own imports, what this one may compile again, the wait for it) costs more than it saves.
Measured on a 2-core machine (benchmarks/cold_compile.py, a cold ``softarm demo``, one run
each, with / without the other process): 19.4 / 26.9 s wall at load 0.8 (2026-12-01);
46.0 / 33.5 s at load 1.5-2.5, 44.1 / 29.1 s at load 2.9-3.6 and 104 / 64 s at load 6.7
(2026-12-06): from a load of 1.5 on it only cost time.
"""

from __future__ import annotations

import atexit
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

__all__ = ["kind", "start", "wait"]

#: The verdict compiles launched by this process: kind -> Popen
_RUNNING: dict[str, subprocess.Popen] = {}
_LOCK = threading.Lock()
#: The longest wait for a launched compile (it takes a few seconds to half a minute)
_PATIENCE = 300.0


def _usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _busy() -> bool:
    """Whether no second core is free: the 1-minute load average at or above the usable
    cores less one (False where there is no load average)."""
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):  # not on this platform
        return False
    return load >= _usable_cores() - 1.0


def start(kind: str, dispatcher) -> str | None:
    """Launch the verdict's compile for ``kind`` ("passive" or "actuated") in another
    process, unless one ran already or it cannot help (see the module docstring: not on a
    busy machine unless ``SOFTARM_PREFETCH=1``); says so
    (for the compile notice), or None. ``dispatcher``: a kernel whose cache folder is the one
    to fill (where numba can cache)."""
    wanted = os.environ.get("SOFTARM_PREFETCH", "auto")
    if (wanted == "0" or _usable_cores() < 2 or (wanted != "1" and _busy())
            or getattr(getattr(dispatcher, "_cache", None), "cache_path", None) is None):
        return None
    with _LOCK:
        if kind in _RUNNING:
            return None
        package = Path(__file__).resolve().parents[2]  # the folder holding softarm/
        path = os.pathsep.join(filter(None, [str(package), os.environ.get("PYTHONPATH")]))
        env = dict(os.environ, PYTHONPATH=path, SOFTARM_PREFETCH="0",
                   SOFTARM_COMPILE_NOTICE="0", SOFTARM_COMPILE_RECORD="0",
                   SOFTARM_NUM_THREADS="1")
        try:
            _RUNNING[kind] = subprocess.Popen(
                [sys.executable, "-c", "import sys; from softarm.statics.solver import "
                 "compile_beside; compile_beside(sys.argv[1])", kind],
                env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL)
        except OSError:  # no process can be started here: compile as before
            _RUNNING[kind] = None
            return None
    return "its output pass and stability verdict on another core"


def kind(arm) -> str:
    """"passive" or "actuated": the kind of the kernel's (arm, act) pair."""
    return "passive" if arm[1] is None else "actuated"


def wait(kind: str) -> None:
    """Wait for the verdict compile of ``kind`` launched by :func:`start`, if any (a verdict
    call costs this one dictionary lookup when none was launched)."""
    process = _RUNNING.get(kind)
    if process is None:
        return
    deadline = time.monotonic() + _PATIENCE
    while process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    if process.poll() is None:  # hung: this process compiles for itself from now on
        process.kill()
    _RUNNING[kind] = None  # done: never waited for again (start() sees it was launched)


@atexit.register
def _stop() -> None:
    """A process that ends before its launched compiles do takes them with it (numba writes
    its cache atomically: an interrupted compile leaves nothing behind)."""
    for process in _RUNNING.values():
        if process is not None and process.poll() is None:
            process.kill()

"""``jit``: numba's ``njit(cache=True)`` with a fallback where the cache cannot be written, and
a notice on stderr when softarm compiles one of its capabilities.

Imported only by compiled modules, on first use: ``import softarm`` does not import numba.

Design note: compiled per capability, announced once. Each compiled *entry point* (a kernel
that Python calls: the solver's ``solve_cases``, the stability sweep, the closed forms, ...)
is registered with a ``capability`` function that names, from the argument types of a
compile, what is being compiled ("the solver for passive arms", "... with Jacobians": the
solver is compiled per capability, statics/README.md). numba's event API reports every
compile that misses the cache (``numba:compile``; a cache hit is no event), so a listener
prints one line the first time a capability compiles in a process, with the time it takes
on this machine, and afterwards records how long it took. The record lives in numba's cache
folder beside the compiled code it describes (``softarm-compile-seconds.json``), so the next
estimate on this machine is a measurement; before any, it is the reference machine's time
(:data:`REFERENCE_SECONDS`, ``python benchmarks/cold_compile.py``) scaled by a 20-ms probe of this
machine's single-core speed. ``SOFTARM_COMPILE_NOTICE=0`` silences the notice.
"""

from __future__ import annotations

import json
import os
import sys
import threading
import time
import warnings
from collections.abc import Callable

from numba import njit
from numba.core import event

__all__ = ["COMPILED", "REFERENCE_SECONDS", "compile_seconds", "jit", "notices",
           "on_cold_compile"]

_WARNED = set()

#: Cold compile of each capability, seconds, on the reference machine (2 cores, AMD EPYC, the
#: machine of docs/performance.md), each after those before it in softarm.warmup.STEPS (what
#: a user meets who adds capabilities one by one; a capability used first compiles what it
#: shares with the others too): ``python benchmarks/cold_compile.py``, 2026-12-01.
REFERENCE_SECONDS = {
    "solve": 17.0,
    "verdict": 6.0,
    "closed forms": 3.0,
    "solve+jacobians": 7.0,
    "solve+chained": 7.0,
    "actuated": 26.0,
    "verdict+actuated": 5.0,
    "actuated+jacobians": 8.0,
    "actuated+chained": 9.0,
    "actuated+chained+jacobians": 11.0,
    "inverse": 13.0,
    "bounded": 2.0,
    "shoot": 1.0,
    "shoot+actuated": 2.0,
    "branch": 4.0,
    "branch+actuated": 5.0,
    # multiple shooting (stiff problems): a fresh install's first hanging-hose solve after a
    # passive one, 42.2 s beside "solve" 21.9 s, scaled by that run's 17/21.9 (not yet
    # measured by benchmarks/cold_compile.py; the actuated one estimated alike)
    "stiff+verdict": 33.0,
    "stiff+actuated+verdict": 40.0,
    # dynamics (softarm.simulate): in a fresh cache after a passive solve (53.3 s there
    # against 23 s here: a loaded machine), 26.5 s, and the actuated one after an actuated
    # solve 16.4 s; scaled by 23/53.3
    "dynamics": 11.5,
    "dynamics+actuated": 7.0,
}
#: The probe's time on the reference machine, seconds (:func:`_probe`, best of 5)
_REFERENCE_PROBE = 0.0158
#: The file of measured compile times, in numba's cache folder of the compiled module.
_RECORD = "softarm-compile-seconds.json"

#: compiled entry points: Python function -> capability(argument types) -> (key, text)
_ENTRIES: dict[Callable, Callable] = {}
#: entry points' Python function -> callbacks(argument types) at the start of a cold compile
_ON_COLD: dict[Callable, list[Callable]] = {}
_ANNOUNCED: set[str] = set()
_STATE = threading.local()
_LOCK = threading.Lock()
_PROBE: list[float] = []
#: The capabilities compiled in this process, in order: (key, text, seconds)
COMPILED: list[tuple[str, str, float]] = []
#: Whether compile times are recorded (not in statics/_prefetch.py's process, whose times
#: include what the solver's process compiles beside it)
_RECORD_TIMES = os.environ.get("SOFTARM_COMPILE_RECORD", "1") != "0"
#: Whether a compile prints its notice (``softarm compile`` draws a progress bar instead)
notices = os.environ.get("SOFTARM_COMPILE_NOTICE", "1") != "0"


def jit(function=None, *, what: str = "softarm's compiled kernels", capability=None,
        **options):
    """``njit(cache=True, **options)``, or without the cache where numba has nowhere to write.

    Numba stores its cache beside the source file or in a user cache directory; with a
    read-only package and no writable cache directory (a service user, a container) it raises
    at decoration time. The function is then compiled in memory on first use, and a
    RuntimeWarning naming ``what`` says so once per ``what``. Usable as ``@jit`` or
    ``@jit(error_model="numpy")``.

    ``capability``: for an entry point (a kernel called from Python), a function of the
    argument types of a compile returning (key, text): the capability being compiled, a key
    of :data:`REFERENCE_SECONDS` and the words of the notice ("the solver for passive arms").
    """
    if function is None:
        return lambda f: jit(f, what=what, capability=capability, **options)
    try:
        dispatcher = njit(cache=True, **options)(function)
    except RuntimeError as error:
        if "cannot cache" not in str(error):
            raise
        if what not in _WARNED:
            _WARNED.add(what)
            warnings.warn(
                f"softarm: numba cannot cache {what} here (read-only package and no writable "
                "cache directory); they compile on first use in every process. Set "
                "NUMBA_CACHE_DIR to a writable directory to cache them"
                + (f" (now {os.environ['NUMBA_CACHE_DIR']!r})"
                   if "NUMBA_CACHE_DIR" in os.environ else ""),
                RuntimeWarning, stacklevel=2)
        dispatcher = njit(cache=False, **options)(function)
    if capability is not None:
        _ENTRIES[function] = capability
    return dispatcher


def on_cold_compile(dispatcher, callback: Callable) -> None:
    """Call ``callback(argument types)`` when the entry point ``dispatcher`` starts a compile
    that missed numba's cache (statics/_prefetch.py starts the verdict's compile then); what
    it returns, if not None, is added to the notice."""
    _ON_COLD.setdefault(getattr(dispatcher, "py_func", dispatcher), []).append(callback)


def compile_seconds(key: str, dispatcher=None) -> tuple[float, bool]:
    """(seconds, measured): how long capability ``key`` takes to compile on this machine, as
    last measured here (in the cache folder of ``dispatcher``'s module), else the reference
    machine's time scaled by this machine's speed (``measured`` False)."""
    recorded = _read_record(dispatcher).get(key) if dispatcher is not None else None
    if isinstance(recorded, (int, float)) and recorded > 0:
        return float(recorded), True
    return REFERENCE_SECONDS.get(key, 20.0) * _speed_ratio(), False


def _speed_ratio() -> float:
    """This machine's time for the probe over the reference machine's, in [0.25, 8]."""
    if not _PROBE:
        _PROBE.append(min(_probe() for _ in range(3)))
    return min(8.0, max(0.25, _PROBE[0] / _REFERENCE_PROBE))


def _probe() -> float:
    """About 20 ms of what a compile does most (Python objects: dicts, tuples, strings) on
    one core."""
    start = time.perf_counter()
    table = {}
    for i in range(40_000):
        key = ("v", i % 977, str(i))
        table[key] = table.get(key, 0) + len(key[2])
    sorted(table.items(), key=lambda item: item[0][2])
    return time.perf_counter() - start


def _record_path(dispatcher) -> str | None:
    cache = getattr(dispatcher, "_cache", None)
    path = getattr(cache, "cache_path", None)
    return os.path.join(path, _RECORD) if isinstance(path, str) else None


def _read_record(dispatcher) -> dict:
    path = _record_path(dispatcher)
    try:
        with open(path, encoding="utf-8") as file:
            record = json.load(file)
        return record if isinstance(record, dict) else {}
    except (OSError, TypeError, ValueError):
        return {}


def _write_record(dispatcher, key: str, seconds: float) -> None:
    """Store the measured time (atomically: a concurrent process loses nothing but its own
    figure); nothing if the cache folder cannot be written."""
    path = _record_path(dispatcher)
    if path is None:
        return
    with _LOCK:
        record = _read_record(dispatcher)
        record[key] = round(seconds, 2)
        temporary = f"{path}.{os.getpid()}.tmp"
        try:
            with open(temporary, "w", encoding="utf-8") as file:
                json.dump(record, file, indent=1, sort_keys=True)
            os.replace(temporary, path)
        except OSError:
            try:
                os.unlink(temporary)
            except OSError:
                pass


class _Notice(event.Listener):
    """Announces the compile of a capability (an entry point's compile that misses numba's
    cache and is not nested in another entry point's), then records its time."""

    def on_start(self, ev):
        stack = _STATE.__dict__.setdefault("stack", [])
        dispatcher = ev.data["dispatcher"]
        capability = _ENTRIES.get(getattr(dispatcher, "py_func", None))
        if capability is None or any(stack):
            stack.append(None)
            return
        key, text = capability(ev.data["args"])
        stack.append((key, text, dispatcher, time.perf_counter()))
        extra = [callback(ev.data["args"]) for callback in _ON_COLD.get(dispatcher.py_func, ())]
        text += "".join(f" ({more})" for more in extra if more)
        with _LOCK:
            first = key not in _ANNOUNCED
            _ANNOUNCED.add(key)
        if first and notices:
            seconds, _ = compile_seconds(key, dispatcher)
            cached = _record_path(dispatcher) is not None
            print(f"softarm: compiling {text}{', once' if cached else ''} (about "
                  f"{_about(seconds)} on this machine; " + (
                      "later runs load it from the cache)" if cached else
                      "not cached here: every process compiles it; set NUMBA_CACHE_DIR)"),
                  file=sys.stderr, flush=True)

    def on_end(self, ev):
        stack = _STATE.__dict__.setdefault("stack", [])
        entry = stack.pop() if stack else None
        # (not ev.is_failed: numba 0.68's is_failed is inverted, True for a success)
        if entry is not None and getattr(ev, "_exc_details", None) is None:
            key, text, dispatcher, start = entry
            seconds = time.perf_counter() - start
            COMPILED.append((key, text, seconds))
            if _RECORD_TIMES:  # (several entry points of one capability: their sum)
                _write_record(dispatcher, key, sum(t for k, _, t in COMPILED if k == key))


def _about(seconds: float) -> str:
    if seconds < 10:
        return f"{max(1, round(seconds))} s"
    if seconds < 100:
        return f"{5 * round(seconds / 5)} s"
    return f"{round(seconds / 60)} min"


event.register("numba:compile", _Notice())

"""``jit``: numba's ``njit(cache=True)`` with a fallback where the cache cannot be written, and
a notice on stderr when softarm compiles one of its capabilities.

Imported only by compiled modules, on first use: ``import softarm`` does not import numba.

Design note: compiled per capability, announced once. Each compiled *entry point* (a kernel
that Python calls: the solver's ``solve_cases``, the stability sweep, the closed forms, ...)
is registered with a ``capability`` function that names, from the argument types of a
compile, what is being compiled ("the solver for passive arms", "... with Jacobians": the
solver is compiled per capability, statics/README.md). numba's event API reports every
compile that misses the cache (``numba:compile``; a cache hit is no event), so a listener
prints one line the first time a capability compiles in a process and afterwards records how
long it took. The record lives in numba's cache folder beside the compiled code it describes
(``softarm-compile-seconds.json``): per capability, the seconds of each compiled version (an
entry point and its argument types; a capability may compile several: other argument types,
or several entry points).

The notice says only what was measured: the time this capability took on this machine the
last time this version of it compiled here (after an upgrade of softarm or numba, whose
cache then misses: the sum of its recorded versions), or, for a first compile here (of this
version), that it is one, with the time it took on the reference machine
(:data:`REFERENCE_SECONDS`, ``python benchmarks/cold_compile.py``) and that it varies with the
machine and its load. (A guess from a speed probe of this machine was off by 0.5-5x: a
compile's time follows the load of the machine more than its speed.) On a
terminal, a compile that runs longer than :data:`PROGRESS_AFTER` seconds also shows its
elapsed time, redrawn in place each second and erased at its end; nothing more is written
when stderr is not a terminal. ``SOFTARM_COMPILE_NOTICE=0`` silences both.
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import json
import os
import re
import sys
import threading
import time
import warnings
from collections.abc import Callable

from numba import njit
from numba.core import event
from numba.core.caching import CompileResultCacheImpl, FunctionCache

__all__ = ["COMPILED", "PROGRESS_AFTER", "REFERENCE_SECONDS", "compile_seconds", "jit",
           "notices", "on_cold_compile"]

_WARNED = set()

#: Cold compile of each capability, seconds, on the reference machine (2 cores, AMD EPYC, the
#: machine of docs/performance.md), each after those before it in softarm.warmup.STEPS (what
#: a user meets who adds capabilities one by one; a capability used first compiles what it
#: shares with the others too); the first version of a capability that compiles several (the
#: dynamics from rest; from an equilibrium or with contact, 3-5 s more each). Measured by
#: ``python benchmarks/cold_compile.py``: wall seconds on the quiet machine (load < 1.5),
#: 2026-12-01; the keys marked * were first measured on 2026-12-06 on the same machine busy
#: (load 5-6): there its CPU seconds (the wall seconds of a quiet machine: the keys measured
#: both ways agree to 0-27 %, the CPU seconds above).
REFERENCE_SECONDS = {
    "solve": 17.0,
    "verdict": 6.0,
    "closed forms": 3.0,
    "solve+jacobians": 7.0,
    "solve+chained": 7.0,
    "solve+chained+jacobians": 9.4,  # *
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
    "branch+actuated": 5.3,  # *
    # multiple shooting (stiff problems, contact), and a stiff closed form's verdict
    "stiff+verdict": 36.6,  # *
    "stiff": 5.3,  # *
    "stiff+jacobians+verdict": 17.3,  # *
    "stiff+jacobians": 6.2,  # *
    "verdict+given": 6.8,  # *
    "stiff+actuated+verdict": 43.1,  # *
    "stiff+actuated": 6.7,  # *
    "stiff+actuated+jacobians+verdict": 22.7,  # *
    "stiff+actuated+jacobians": 8.0,  # *
    # dynamics (softarm.simulate, Simulator)
    "dynamics": 10.4,  # *
    "dynamics+actuated": 13.4,  # *
}
#: On a terminal, the elapsed time of a compile is shown from this many seconds on
PROGRESS_AFTER = 3.0
#: The file of measured compile times, in numba's cache folder of the compiled module.
_RECORD = "softarm-compile-seconds.json"

#: compiled entry points: Python function -> capability(argument types) -> (key, text)
_ENTRIES: dict[Callable, Callable] = {}
#: entry points' Python function -> callbacks(argument types) at the start of a cold compile
_ON_COLD: dict[Callable, list[Callable]] = {}
_ANNOUNCED: set[str] = set()
_STATE = threading.local()
_LOCK = threading.Lock()
#: The capabilities compiled in this process, in order: (key, text, seconds)
COMPILED: list[tuple[str, str, float]] = []
#: Whether compile times are recorded (not in kernels/_prefetch.py's process, whose times
#: include what the solver's process compiles beside it)
_RECORD_TIMES = os.environ.get("SOFTARM_COMPILE_RECORD", "1") != "0"
#: Whether a compile prints its notice (``softarm compile`` draws a progress bar instead)
notices = os.environ.get("SOFTARM_COMPILE_NOTICE", "1") != "0"


def jit(function=None, *, what: str = "softarm's compiled kernels", capability=None,
        key_on_imports: bool = False, **options):
    """``njit(cache=True, **options)``, or without the cache where numba has nowhere to write.

    Numba stores its cache beside the source file or in a user cache directory; with a
    read-only package and no writable cache directory (a service user, a container) it raises
    at decoration time. The function is then compiled in memory on first use, and a
    RuntimeWarning naming ``what`` says so once per ``what``. Usable as ``@jit`` or
    ``@jit(error_model="numpy")``.

    ``capability``: for an entry point (a kernel called from Python), a function of the
    argument types of a compile returning (key, text): the capability being compiled, a key
    of :data:`REFERENCE_SECONDS` and the words of the notice ("the solver for passive arms").

    ``key_on_imports``: the cache is keyed on the function's file *and* every file of its
    package that the file imports, directly or through others (:func:`imports_stamp`), not
    on its own file only (numba's rule, under which a caller keeps a changed callee's old
    code): for functions that call compiled functions of other files (softarm/kernels).
    """
    if function is None:
        return lambda f: jit(f, what=what, capability=capability,
                             key_on_imports=key_on_imports, **options)
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
    else:
        if key_on_imports:
            dispatcher._cache = _ImportsKeyedCache(function)
    if capability is not None:
        _ENTRIES[function] = capability
    return dispatcher


class _ImportsKeyedCache(FunctionCache):
    """numba's on-disk cache of a function, its source stamp extended by
    :func:`imports_stamp` (``jit(..., key_on_imports=True)``)."""

    class _impl_class(CompileResultCacheImpl):
        def __init__(self, py_func):
            super().__init__(py_func)
            self._locator = _StampedLocator(self._locator, imports_stamp(
                inspect.getfile(py_func)))


class _StampedLocator:
    """numba's cache locator of a function (where its cache lives, its own file's stamp),
    with ``stamp`` added to that stamp: a cached index whose stamp differs is not loaded
    (numba compiles again and overwrites it)."""

    def __init__(self, locator, stamp: str):
        self._locator, self._stamp = locator, stamp

    def get_source_stamp(self):
        return self._locator.get_source_stamp(), self._stamp

    def __getattr__(self, name):
        return getattr(self._locator, name)


def imports_stamp(path: str) -> str:
    """A digest of the Python file ``path`` and of every file of its folder (its package)
    that it imports by a relative import (``from .rod import ...``, ``from . import x``),
    directly or through those files: what a function compiled in ``path`` may link. Imports
    from outside the folder (``from .._jit import``, numpy) are not compiled code of it."""
    folder, name = os.path.split(os.path.abspath(path))
    seen, todo = set(), [name.removesuffix(".py")]
    while todo:
        module = todo.pop()
        if module not in seen and os.path.isfile(os.path.join(folder, f"{module}.py")):
            seen.add(module)
            todo.extend(_sibling_imports(os.path.join(folder, f"{module}.py")))
    digest = hashlib.sha256()
    for module in sorted(seen):
        digest.update(module.encode("utf-8") + b"\0")
        digest.update(_file_digest(os.path.join(folder, f"{module}.py")))
    return digest.hexdigest()


#: A relative import of a sibling: ``from .rod import ...`` (group 1) or ``from . import x,
#: y`` (group 2: the names, up to the line's end or a parenthesised list's)
_SIBLING_IMPORT = re.compile(r"^[ \t]*from \.(?!\.)(\w*)[\w.]* import[ \t]*(\([^)]*\)|[^\n]*)",
                             re.MULTILINE)


@functools.cache
def _sibling_imports(path: str) -> tuple[str, ...]:
    """The modules of its own folder that the file ``path`` imports (relative, level 1), read
    from the import statements' text (``ast.parse`` of the kernels took 0.24 s at the first
    kernel's import: a start-up cost of every process that solves)."""
    with open(path, encoding="utf-8") as file:
        text = file.read()
    names = []
    for module, listed in _SIBLING_IMPORT.findall(text):
        if module:
            names.append(module)
        else:
            listed = re.sub(r"#[^\n]*", "", listed).strip().strip("()")  # (comments)
            names += [name.split(" as ")[0].strip() for name in listed.split(",")
                      if name.strip()]
    return tuple(names)


@functools.cache
def _file_digest(path: str) -> bytes:
    with open(path, "rb") as file:
        return hashlib.sha256(file.read()).digest()


def on_cold_compile(dispatcher, callback: Callable) -> None:
    """Call ``callback(argument types)`` when the entry point ``dispatcher`` starts a compile
    that missed numba's cache (kernels/_prefetch.py starts the verdict's compile then); what
    it returns, if not None, is added to the notice."""
    _ON_COLD.setdefault(getattr(dispatcher, "py_func", dispatcher), []).append(callback)


def compile_seconds(key: str, dispatcher=None, variant: str | None = None
                    ) -> tuple[float | None, bool]:
    """(seconds, measured): how long capability ``key`` took to compile on this machine the
    last time, every compiled version of it recorded in the cache folder of ``dispatcher``'s
    module (``measured`` True), else on the reference machine (``measured`` False; None for
    a key it has no time for). With ``variant`` (see :func:`_variant`), measured only if that
    version is among them: a version never compiled here (other argument types: a moving
    base, read-only arrays, ...) is a first compile, whatever the others took."""
    recorded = _read_record(dispatcher).get(key) if dispatcher is not None else None
    if isinstance(recorded, dict) and recorded and (variant is None or variant in recorded):
        seconds = sum(_wall(v) for v in recorded.values())
        if seconds > 0:
            return float(seconds), True
    return REFERENCE_SECONDS.get(key), False


def _wall(version) -> float:
    """A recorded version's wall seconds: [wall, CPU] (0 for anything else)."""
    if isinstance(version, list) and version and isinstance(version[0], (int, float)):
        return float(version[0])
    return 0.0


def _variant(dispatcher, args) -> str:
    """The compiled version of an entry point: its name and a digest of its argument types
    (the same in every process, unlike hash())."""
    digest = hashlib.sha1(repr(tuple(args)).encode("utf-8")).hexdigest()[:12]
    return f"{getattr(getattr(dispatcher, 'py_func', None), '__name__', 'kernel')}:{digest}"


def announcement(text: str, seconds: float | None, measured: bool, cached: bool) -> str:
    """The notice of a first compile of capability ``text`` in this process: what was
    measured, and nothing else (the module docstring)."""
    if not cached:
        return (f"softarm: compiling {text} (not cached here: every process compiles it; set "
                "NUMBA_CACHE_DIR to a writable folder)")
    if measured:
        return (f"softarm: compiling {text}, once (it took about {_about(seconds)} on this "
                "machine the last time; later runs load it from the cache)")
    reference = "" if seconds is None else \
        f"; about {_about(seconds)} on a quiet 2-core reference machine, more on a busy one"
    return (f"softarm: compiling {text}, once: a first compile on this machine (it varies "
            f"with the machine and its load{reference}; later runs load it from the cache)")


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


def _write_record(dispatcher, key: str, variant: str, seconds: float, cpu: float) -> None:
    """Store the measured time of one compiled version of capability ``key``, [wall, CPU]
    seconds (this process's CPU time: on a quiet machine, the wall time; what
    benchmarks/cold_compile.py reports for :data:`REFERENCE_SECONDS`), atomically (a
    concurrent process loses nothing but its own figure); nothing if the cache folder cannot
    be written."""
    path = _record_path(dispatcher)
    if path is None:
        return
    with _LOCK:
        record = _read_record(dispatcher)
        versions = record.get(key)
        record[key] = versions = versions if isinstance(versions, dict) else {}
        versions[variant] = [round(seconds, 2), round(cpu, 2)]
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
        variant = _variant(dispatcher, ev.data["args"])
        stack.append((key, text, dispatcher, (time.perf_counter(), time.process_time()),
                      variant))
        extra = [callback(ev.data["args"]) for callback in _ON_COLD.get(dispatcher.py_func, ())]
        text += "".join(f" ({more})" for more in extra if more)
        with _LOCK:
            first = key not in _ANNOUNCED
            _ANNOUNCED.add(key)
        if first and notices:
            seconds, measured = compile_seconds(key, dispatcher, variant)
            cached = _record_path(dispatcher) is not None
            print(announcement(text, seconds, measured, cached), file=sys.stderr, flush=True)
            stack[-1] += (Elapsed(sys.stderr).start(),)

    def on_end(self, ev):
        stack = _STATE.__dict__.setdefault("stack", [])
        entry = stack.pop() if stack else None
        if entry is not None and len(entry) > 5:
            entry[5].stop()
        # (not ev.is_failed: numba 0.68's is_failed is inverted, True for a success)
        if entry is not None and getattr(ev, "_exc_details", None) is None:
            key, text, dispatcher, (start, cpu), variant = entry[:5]
            seconds = time.perf_counter() - start
            COMPILED.append((key, text, seconds))
            if _RECORD_TIMES:
                _write_record(dispatcher, key, variant, seconds, time.process_time() - cpu)


class Elapsed:
    """On a terminal (``stream.isatty()``), the elapsed time of a running compile, from
    ``after`` seconds on: ``  compiling... 12 s`` redrawn in place every ``every`` seconds by
    a daemon thread (numba releases the GIL in LLVM's C code: the thread gets its turn), and
    erased by :meth:`stop`. Elsewhere nothing."""

    def __init__(self, stream, after: float | None = None, every: float = 1.0):
        self.stream, self.every = stream, every
        self.after = PROGRESS_AFTER if after is None else after
        self.done = threading.Event()
        self.thread = None
        self.shown = False

    def start(self) -> Elapsed:
        try:
            tty = self.stream.isatty()
        except (AttributeError, ValueError, OSError):
            tty = False
        if tty:
            self.begin = time.perf_counter()
            self.thread = threading.Thread(target=self._run, daemon=True,
                                           name="softarm-compile-elapsed")
            self.thread.start()
        return self

    def _run(self) -> None:
        if self.done.wait(self.after):
            return
        while not self.done.is_set():
            self._write(f"\r  compiling... {time.perf_counter() - self.begin:.0f} s")
            self.shown = True
            self.done.wait(self.every)

    def stop(self) -> None:
        self.done.set()
        if self.thread is not None:
            self.thread.join()
            if self.shown:
                self._write("\r\x1b[K")  # (erase the line: the notice said the rest)

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text)
            self.stream.flush()
        except (ValueError, OSError):  # stderr closed
            pass


def _about(seconds: float) -> str:
    if seconds < 10:
        return f"{max(1, round(seconds))} s"
    if seconds < 100:
        return f"{5 * round(seconds / 5)} s"
    return f"{round(seconds / 60)} min"


event.register("numba:compile", _Notice())

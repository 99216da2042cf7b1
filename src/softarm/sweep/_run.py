"""Running a sweep design: chunks of cases solved in-process, on a process pool or a Dask
cluster, written to a resumable Zarr store (:mod:`softarm.sweep._store`; private, the public
names are in :mod:`softarm.sweep`).

The unit of work is a *chunk*: consecutive cases of the design. :func:`solve_chunk`, a
module-level function (a Dask scheduler and a process pool pickle it by name), builds the
chunk's arms and loads (:class:`softarm.sweep._design.Plan`), solves them in batched calls of
the same code as :func:`softarm.solve`, and either returns the arrays (no store) or writes
them to the chunk's own region of the store, then sets the chunk's done flag. Every chunk is
aligned with the store's chunks along ``case``, so no two writers touch the same file.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import os
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import dispatch
from .._sweep_table import Design, Parameter
from .._validate import check_allocation, count, format_value
from ..case import parse_case
from ..errors import ConvergenceError
from ..lie import so3
from ..statics import Solver
from ..statics.solver import check_tol
from ._design import Plan
from ._store import (
    DEFAULT_FIELDS,
    FAILED,
    FIELDS,
    INVALID,
    MESSAGE_WIDTH,
    SOLVED,
    allocate,
    case_text,
    dataset_attrs,
    dataset_coords,
    dims,
    need_store_packages,
    open_sweep,
    prepare_store,
    recorded_options,
    variable_attrs,
    write_chunk,
)

__all__ = ["ChunkResult", "Spec", "Task", "design_of", "process_pool", "run", "solve_chunk"]

# --------------------------------------------------------------------------------------------
# What a worker receives
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Spec:
    """Everything a worker needs to solve any chunk (picklable, small)."""

    case_data: dict
    source: str | None
    design: Design
    method: str
    stations: int
    tol: float
    fields: tuple[str, ...]
    dtype: str
    chunk: int
    out: str | None
    chained: bool = False
    single_thread: bool = False

    @functools.cached_property
    def key(self) -> str:
        """Fingerprint of what the store holds (the case, design and options; computed once,
        and carried to the workers with the spec)."""
        text = json.dumps({"case": self.case_data, "design": self.design.to_dict(),
                           "method": self.method, "stations": self.stations, "tol": self.tol,
                           "fields": list(self.fields), "dtype": self.dtype,
                           "chunk": self.chunk, "chained": self.chained},
                          sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:32]


@dataclass(frozen=True)
class Task:
    """One chunk: cases ``start`` .. ``stop - 1`` with their parameter ``values``."""

    spec: Spec
    index: int
    start: int
    stop: int
    values: np.ndarray


@dataclass(frozen=True)
class ChunkResult:
    index: int
    start: int
    stop: int
    solved: int
    failed: int
    data: dict | None = None  # the arrays, when there is no store


_WORKER: dict = {}  # spec key -> (plan, {arm: Solver}); one per process


def _state(spec: Spec):
    key = spec.key
    if key not in _WORKER:
        _WORKER.clear()
        case = parse_case(spec.case_data, spec.source)
        _WORKER[key] = (Plan(case, spec.design), {})
    return _WORKER[key]


def solve_chunk(task: Task) -> ChunkResult:
    """Solve one chunk and write it to the store (or return its arrays).

    The task function of every engine: ``map(solve_chunk, tasks)``. A failed case is recorded
    (status, NaN outputs, the reason), never raised.
    """
    spec = task.spec
    if spec.single_thread:
        os.environ["SOFTARM_NUM_THREADS"] = "1"
    plan, solvers = _state(spec)
    data = _compute(plan, solvers, spec, task.values)
    status = data["status"]
    result = ChunkResult(task.index, task.start, task.stop, int(np.sum(status == SOLVED)),
                         int(np.sum(status != SOLVED)))
    if spec.out is None:
        return dataclasses.replace(result, data=data)
    write_chunk(spec, task, data)
    return result


# --------------------------------------------------------------------------------------------
# Solving a chunk
# --------------------------------------------------------------------------------------------


_CASE_WHERE = re.compile(r" for load case \([^)]*\)")


def _reason(error: Exception) -> str:
    return _CASE_WHERE.sub("", str(error))[:MESSAGE_WIDTH]


def _compute(plan: Plan, solvers: dict, spec: Spec, values: np.ndarray) -> dict:
    data = allocate(spec, len(values))
    for group in plan.groups(values):
        if group.error:
            data["status"][group.rows] = INVALID
            data["message"][group.rows] = group.error[:MESSAGE_WIDTH]
            continue
        solver = _solver(solvers, group.arm, spec)
        if isinstance(solver, str):
            data["status"][group.rows] = INVALID
            data["message"][group.rows] = solver[:MESSAGE_WIDTH]
            continue
        data["length"][group.rows] = group.arm.length
        if spec.chained:
            _solve_path(plan, solver, spec, group, values, data)
        else:
            _solve_rows(plan, solver, spec, group, group.rows, group.loads, values, data)
    return data


def _solver(solvers: dict, arm, spec: Spec):
    if arm not in solvers:
        if len(solvers) > 32:
            solvers.clear()
        try:
            solvers[arm] = Solver(arm, s=spec.stations, tol=spec.tol)
        except (ValueError, TypeError) as error:
            solvers[arm] = str(error)
    return solvers[arm]


def _solve_rows(plan, solver, spec, group, rows, loads, values, data) -> None:
    """Solve ``rows`` (batched ``loads``); on a failure, halve until the failed cases are
    alone (every case is independent of the others, so the answers do not change)."""
    try:
        eq = dispatch.solve_prepared(solver, loads, spec.method)
    except (ConvergenceError, ValueError, TypeError) as error:
        if len(rows) == 1:
            data["status"][rows] = FAILED if isinstance(error, ConvergenceError) else INVALID
            data["message"][rows] = _reason(error)
            return
        half = len(rows) // 2
        for part in (rows[:half], rows[half:]):
            part_loads = plan.rebatch(group, values[part])
            _solve_rows(plan, solver, spec, group, part, part_loads, values, data)
        return
    _record(eq, rows, data)


def _solve_path(plan, solver, spec, group, values, data) -> None:
    """Quasi-static: case after case from the previous equilibrium (``Solver.solve``)."""
    for row in group.rows:
        loads = plan.rebatch(group, values[row:row + 1])
        try:
            eq = solver.solve(loads)
        except (ConvergenceError, ValueError, TypeError) as error:
            solver.reset()
            data["status"][row] = FAILED if isinstance(error, ConvergenceError) else INVALID
            data["message"][row] = _reason(error)
            continue
        _record(eq, np.array([row]), data)


def _record(eq, rows: np.ndarray, data: dict) -> None:
    n = len(rows)
    poses = eq.poses.reshape(n, -1, 4, 4)
    if "positions" in data:
        data["positions"][rows] = poses[..., :3, 3]
    if "orientations" in data:
        data["orientations"][rows] = so3.to_quaternion(poses[..., :3, :3])
    if "tip_position" in data:
        data["tip_position"][rows] = poses[:, -1, :3, 3]
    if "tip_orientation" in data:
        data["tip_orientation"][rows] = so3.to_quaternion(poses[:, -1, :3, :3])
    if "strains" in data:
        data["strains"][rows] = eq.strains.reshape(n, -1, 6)
    if "stresses" in data:
        data["stresses"][rows] = eq.stresses.reshape(n, -1, 6)
    data["residual"][rows] = np.broadcast_to(np.asarray(eq.residual, dtype=float), (n,))
    data["error_estimate"][rows] = np.broadcast_to(
        np.asarray(eq.error_estimate, dtype=float), (n,))
    data["status"][rows] = SOLVED


# --------------------------------------------------------------------------------------------
# run
# --------------------------------------------------------------------------------------------


def design_of(case) -> Design:
    """The sweep design of a case: its ``[sweep]`` design, or its one-parameter sweep as a
    list design over ``load[i].field.component``."""
    if case.design is not None:
        return case.design
    sweep = case.sweep
    if sweep is None:
        raise ValueError(f"{case.source or case.name}: the case has no [sweep] table")
    return Design((Parameter(f"load[{sweep.load + 1}].{sweep.field}.{sweep.component}",
                             values=sweep.values),), "list")


def run(case, design: Design | None = None, *, out=None, map: Callable | None = None,
        chunk: int | None = None, fields: Iterable[str] | None = None,
        stations: int | None = None, dtype: str | None = None, method: str | None = None,
        tol: float | None = None, resume: bool = False, path: bool | None = None,
        progress: Callable | None = None, single_thread: bool | None = None):
    """Solve every case of a sweep design, in chunks, with any map-like executor.

    Parameters
    ----------
    case : softarm.Case
    design : Design, optional
        Default: the case's ``[sweep]`` (a one-parameter sweep becomes a list design).
    out : path, optional
        Zarr store to write (``zarr_format=2``). None: the result is built in memory.
    map : callable, optional
        ``map(function, iterable)`` returning the results in order: the builtin ``map``
        (default, in-process), ``ProcessPoolExecutor.map``, a Dask client's
        ``client.get_executor().map``.
    chunk : int, optional
        Cases per chunk (default up to 1000, at least 16 chunks for small designs).
    fields : iterable of str, optional
        Which outputs to keep: "tip", "positions", "orientations", "poses", "strains",
        "stresses" (default "tip" and "positions").
    stations : int, optional
        Output stations (uniform on [0, L]); default the case's ``[solve] stations``.
    dtype : {"float64", "float32"}, optional
        Of the stored outputs (default float64; status, residuals and parameters stay exact).
    method, tol : optional
        Override the case's ``[solve]`` options.
    resume : bool
        Finish a store written by an interrupted run of the same sweep (the chunks whose done
        flag is set are kept). The options ``chunk``, ``fields``, ``stations``, ``dtype``,
        ``method``, ``tol`` and ``path`` not given are those the store was started with;
        one given that differs from the store's is a ValueError naming it.
    path : bool, optional
        Follow a one-parameter load sweep quasi-statically, serially (a prepared Solver, as
        :meth:`softarm.statics.Solver.solve`), instead of solving each case from the unloaded
        arm (default False).
    progress : callable, optional
        ``progress(cases_done, cases_total, cases_failed)`` after each chunk.

    Returns
    -------
    xarray.Dataset
        The store opened lazily (:func:`open_sweep`), or the in-memory result.

    Raises
    ------
    ValueError
        A bad design (unknown key path, empty range, a value that makes the arm or a load
        invalid: before any solve), a store that exists without ``resume``, one that holds
        another sweep (another case or design), or an option given with ``resume`` that
        differs from the store's.
    """
    xarray, _ = need_store_packages()
    design = design_of(case) if design is None else design
    if not isinstance(design, Design):
        raise TypeError(f"design must be a softarm.sweep.Design, got {design!r}")
    options = case.solve
    given = {"chunk": chunk, "fields": fields, "stations": stations, "dtype": dtype,
             "method": method, "tol": tol, "path": path}
    recorded = recorded_options(out) if resume and out is not None else None
    if recorded is not None:  # resuming: what is not given is what the store was started with
        chunk, fields, stations, dtype, method, tol, path = (
            recorded[name] if value is None else value for name, value in given.items())
    fields = DEFAULT_FIELDS if fields is None else tuple(fields)
    dtype = "float64" if dtype is None else dtype
    for f in fields:
        if f not in FIELDS:
            raise ValueError(f"fields must be among {', '.join(FIELDS)}, got {f!r}")
    if dtype not in ("float64", "float32"):
        raise ValueError(f"dtype must be 'float64' or 'float32', got {dtype!r}")
    size = design.size
    chunk = max(1, min(1000, math.ceil(size / 16))) if chunk is None else \
        count(chunk, "chunk", 1)
    stations = count(options.stations if stations is None else stations, "stations", 2)
    tol = check_tol(options.tol if tol is None else tol)
    method = options.method if method is None else method
    if method not in dispatch.METHODS:
        raise ValueError(f"method must be one of {dispatch.METHODS}, got {method!r}")
    if out is None:  # everything in memory: refuse what cannot fit, before solving
        check_allocation(size, stations, "the sweep (give out= to write a store)")
    else:
        check_allocation(chunk, stations, "one chunk (give a smaller chunk)")
    plan = Plan(case, design)  # resolves every key path
    if path:
        if len(design.parameters) != 1 or not plan.targets[0].batched:
            raise ValueError("path=True follows one load parameter; this design has "
                             f"{', '.join(design.paths)}")
        if map is not None:
            raise ValueError("path=True is serial (each case starts from the previous one); "
                             "give no map")
        chunk = size
    if recorded is not None:
        _check_given(out, given, recorded, {
            "chunk": chunk, "fields": fields, "stations": stations, "dtype": dtype,
            "method": method, "tol": tol, "path": bool(path)})
    plan.check()  # every parameter value buildable, before any solve
    spec = Spec(case.to_dict(), str(case.source) if case.source else None, design,
                method, stations, tol, fields, dtype, chunk,
                None if out is None else os.path.abspath(out), bool(path),  # any worker's cwd
                bool(map is not None if single_thread is None else single_thread))
    chunks = math.ceil(size / chunk)
    todo = list(range(chunks))
    if out is not None:
        todo = prepare_store(spec, plan, case, resume, chunks, out)
    total = size
    done = size - sum(min(size, (k + 1) * chunk) - k * chunk for k in todo)  # by a past run
    failed = 0
    if map is not None and todo:  # compile (or load) the solver once before forking
        _warm_up(case)
    results = []
    for window in range(0, len(todo), _WINDOW):
        # lists (Dask maps no iterators), a window at a time: the parameter values of 10^8
        # cases are never all held as tasks
        tasks = [Task(spec, k, k * chunk, min(size, (k + 1) * chunk),
                      design.values(k * chunk, min(size, (k + 1) * chunk)))
                 for k in todo[window:window + _WINDOW]]
        for result in (map or builtins_map)(solve_chunk, tasks):
            done += result.stop - result.start
            failed += result.failed
            if out is None:
                results.append(result)
            if progress is not None:
                progress(done, total, failed)
    if out is not None:
        return open_sweep(out)
    results.sort(key=lambda r: r.index)
    data = {name: np.concatenate([r.data[name] for r in results])
            for name in results[0].data} if results else allocate(spec, 0)
    values = design.values()
    variables = {name: (dims(name), array, variable_attrs(name))
                 for name, array in data.items()}
    return xarray.Dataset(variables, coords=dataset_coords(spec, plan, values),
                          attrs=dataset_attrs(spec, case_text(case)))


def _check_given(out, given: dict, recorded: dict, final: dict) -> None:
    """ValueError naming the options given with ``resume`` that differ from the store's."""
    differ = [name for name, value in given.items()
              if value is not None and final[name] != recorded[name]]
    if differ:
        def shown(options):
            return ", ".join(f"{name} {_text(options[name])}" for name in differ)

        raise ValueError(f"{Path(out)}: was started with {shown(recorded)}; given "
                         f"{shown(final)}: resume without {'it' if len(differ) == 1 else 'them'}"
                         " (the store's options are taken), or choose another output")


def _text(value) -> str:
    """An option's value in a message (a float with every digit that tells it apart)."""
    return ",".join(value) if isinstance(value, tuple) else format_value(value) \
        if isinstance(value, float) else str(value)


builtins_map = map
_WINDOW = 512  # tasks handed to the map at a time


def _warm_up(case) -> None:
    """Compile (or load from the cache) the solver in this process: one tiny solve of the
    case's own arm and loads. Forked workers then inherit the compiled kernels."""
    try:
        dispatch.solve(case.arm, case.loads, method="numeric", s=2, tol=1e-3)
    except (ConvergenceError, ValueError, TypeError):  # the sweep reports every case itself
        pass


def _started(_) -> int:
    return os.getpid()


def process_pool(workers: int, case=None):
    """A :class:`concurrent.futures.ProcessPoolExecutor` of ``workers`` processes for
    :func:`run` (``map=pool.map``): forked where the platform allows it and this process runs
    no other thread (a fork copies the compiled solver; forking threads may deadlock),
    else spawned (each worker then loads the solver from numba's on-disk cache, shared by all).

    With ``case``, the solver is compiled (or loaded) here first, and the workers are started
    at once, before any store thread exists.
    """
    import concurrent.futures
    import multiprocessing
    import threading

    if case is not None:
        _warm_up(case)
    fork = "fork" in multiprocessing.get_all_start_methods() and \
        threading.active_count() == 1
    context = multiprocessing.get_context("fork" if fork else "spawn")
    pool = concurrent.futures.ProcessPoolExecutor(workers, mp_context=context)
    list(pool.map(_started, range(workers)))
    return pool



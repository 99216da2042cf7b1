"""Running a sweep design: chunks of cases solved in-process, on a process pool or a Dask
cluster, written to a resumable Zarr store (private; the public names are in
:mod:`softarm.sweep`).

The unit of work is a *chunk*: consecutive cases of the design. :func:`solve_chunk`, a
module-level function (a Dask scheduler and a process pool pickle it by name), builds the
chunk's arms and loads (:class:`softarm._sweep_design.Plan`), solves them in batched calls of
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

from ._sweep_design import Design, Parameter, Plan

__all__ = ["FIELDS", "ChunkResult", "Spec", "Task", "open_sweep", "process_pool", "run",
           "solve_chunk"]

#: ``--fields`` choices: the variables each adds to the store.
FIELDS = {
    "tip": ("tip_position", "tip_orientation"),
    "positions": ("positions",),
    "orientations": ("orientations",),
    "poses": ("positions", "orientations"),
    "strains": ("strains",),
    "stresses": ("stresses",),
}
DEFAULT_FIELDS = ("tip", "positions")

#: Per-case status codes (the ``status`` variable).
NOT_COMPUTED, SOLVED, FAILED, INVALID = -1, 0, 1, 2
STATUS_MEANINGS = "not_computed solved solver_failed invalid_input"
MESSAGE_WIDTH = 160

_FROM_UNLOADED = ("every case solved from the unloaded arm, as softarm.solve defines it "
                  "(independent of chunking, workers and order)")
_PATH = ("quasi-static path: one prepared softarm.statics.Solver follows the cases in order, "
         "each from the previous equilibrium (hysteresis possible); after a failed case the "
         "path restarts from the unloaded arm")

_VARIABLES = {  # name: (dims after case, units, long name)
    "tip_position": (("axis",), "m", "tip position, spatial frame"),
    "tip_orientation": (("quaternion",), "1",
                        "tip material frame as a unit quaternion (w, x, y, z), w >= 0"),
    "positions": (("station", "axis"), "m", "centreline position, spatial frame"),
    "orientations": (("station", "quaternion"), "1",
                     "material frame as a unit quaternion (w, x, y, z), w >= 0"),
    "strains": (("station", "component"), "1 (gamma), 1/m (kappa)",
                "strains (gamma1, gamma2, gamma3, kappa1, kappa2, kappa3), material frame"),
    "stresses": (("station", "component"), "N (n), N m (m)",
                 "internal force and moment (n1, n2, n3, m1, m2, m3), material frame"),
}


def _need_store_packages():
    try:
        import xarray
        import zarr
    except ImportError as error:
        raise ImportError(f"sweeps to a Zarr store need xarray and zarr ({error.name} is "
                          "missing): pip install 'softarm[sweep]'") from None
    return xarray, zarr


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
        from .case import parse_case

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
    _write_chunk(spec, task, data)
    return result


# --------------------------------------------------------------------------------------------
# Solving a chunk
# --------------------------------------------------------------------------------------------


def _allocate(spec: Spec, count: int) -> dict:
    S = spec.stations
    shapes = {"tip_position": (3,), "tip_orientation": (4,), "positions": (S, 3),
              "orientations": (S, 4), "strains": (S, 6), "stresses": (S, 6)}
    data = {name: np.full((count, *shapes[name]), np.nan, dtype=spec.dtype)
            for name in _variables(spec.fields)}
    data["status"] = np.full(count, NOT_COMPUTED, dtype=np.int8)
    data["message"] = np.full(count, "", dtype=f"<U{MESSAGE_WIDTH}")
    for name in ("residual", "error_estimate", "length"):
        data[name] = np.full(count, np.nan)
    return data


def _variables(fields) -> list[str]:
    names: list[str] = []
    for f in fields:
        names += [n for n in FIELDS[f] if n not in names]
    return names


_CASE_WHERE = re.compile(r" for load case \([^)]*\)")


def _reason(error: Exception) -> str:
    return _CASE_WHERE.sub("", str(error))[:MESSAGE_WIDTH]


def _compute(plan: Plan, solvers: dict, spec: Spec, values: np.ndarray) -> dict:
    data = _allocate(spec, len(values))
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
    from .statics import Solver

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
    from .dispatch import solve_prepared
    from .errors import ConvergenceError

    try:
        eq = solve_prepared(solver, loads, spec.method)
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
    _store(eq, rows, data)


def _solve_path(plan, solver, spec, group, values, data) -> None:
    """Quasi-static: case after case from the previous equilibrium (``Solver.solve``)."""
    from .errors import ConvergenceError

    for row in group.rows:
        loads = plan.rebatch(group, values[row:row + 1])
        try:
            eq = solver.solve(loads)
        except (ConvergenceError, ValueError, TypeError) as error:
            solver.reset()
            data["status"][row] = FAILED if isinstance(error, ConvergenceError) else INVALID
            data["message"][row] = _reason(error)
            continue
        _store(eq, np.array([row]), data)


def _store(eq, rows: np.ndarray, data: dict) -> None:
    from .lie import so3

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
# The store
# --------------------------------------------------------------------------------------------


def _coords(spec: Spec, plan: Plan, values: np.ndarray) -> dict:
    coords: dict = {"case": ("case", np.arange(len(values)))}
    for j, (p, unit) in enumerate(zip(spec.design.parameters, plan.units, strict=True)):
        coords[p.path] = ("case", values[:, j], {"units": unit, "long_name": p.path})
    coords["station"] = ("station", np.linspace(0.0, 1.0, spec.stations),
                         {"units": "1", "long_name": "arc length s / L of the case's arm"})
    coords["axis"] = ("axis", np.array(["x", "y", "z"]))
    coords["quaternion"] = ("quaternion", np.array(["w", "x", "y", "z"]))
    coords["component"] = ("component", np.arange(6), {
        "long_name": "6-vector component, linear part first: (gamma; kappa) for strains, "
                     "(n; m) for stresses"})
    return coords


def _attrs(spec: Spec, case_text: str) -> dict:
    from . import __version__

    return {"softarm_version": __version__, "case": case_text,
            "case_json": json.dumps(spec.case_data, default=str),
            "case_source": spec.source or "",
            "design": json.dumps(spec.design.to_dict()), "method": spec.method,
            "tol": spec.tol, "stations": spec.stations, "fields": ",".join(spec.fields),
            "dtype": spec.dtype, "chunk_size": spec.chunk,
            "semantics": _PATH if spec.chained else _FROM_UNLOADED,
            "sweep_fingerprint": spec.key}


def _variable_attrs(name: str) -> dict:
    if name in _VARIABLES:
        _, units, long_name = _VARIABLES[name]
        return {"units": units, "long_name": long_name}
    return {
        "status": {"long_name": "per-case status", "flag_values": [-1, 0, 1, 2],
                   "flag_meanings": STATUS_MEANINGS},
        "message": {"long_name": "why a case was not solved (empty when solved)"},
        "residual": {"units": "N, N m", "long_name": "boundary-condition residual"},
        "error_estimate": {"units": "m", "long_name": "estimated tip position error"},
        "length": {"units": "m", "long_name": "arm length of the case"},
        "chunk_done": {"long_name": "1 once the chunk's cases are all written"},
    }[name]


def _dims(name: str) -> tuple[str, ...]:
    if name in _VARIABLES:
        return ("case", *_VARIABLES[name][0])
    return ("chunk",) if name == "chunk_done" else ("case",)


def _create_store(spec: Spec, plan: Plan, case_text: str) -> None:
    """The store's layout: coordinates and attributes through xarray, then each data
    variable as an empty Zarr array (nothing is allocated; chunks are written by workers)."""
    xarray, zarr = _need_store_packages()
    values = spec.design.values()
    size = len(values)
    header = xarray.Dataset(coords=_coords(spec, plan, values), attrs=_attrs(spec, case_text))
    big = min(size, 1 << 20)
    encoding = {p.path: {"chunks": (big,)} for p in spec.design.parameters}
    encoding["case"] = {"chunks": (big,)}
    header.to_zarr(spec.out, mode="w-", zarr_format=2, consolidated=False, encoding=encoding)
    group = zarr.open_group(spec.out, mode="r+")
    template = _allocate(spec, 1)
    chunks = math.ceil(size / spec.chunk)
    for name, array in [*template.items(), ("chunk_done", np.zeros(1, np.uint8))]:
        if name == "chunk_done":
            shape, chunk_shape, fill = (chunks,), (1,), 0
        else:
            shape, chunk_shape = (size, *array.shape[1:]), (spec.chunk, *array.shape[1:])
            fill = {"status": NOT_COMPUTED, "message": ""}.get(name, np.nan)
        attrs = {"_ARRAY_DIMENSIONS": list(_dims(name)), **_variable_attrs(name)}
        _zarr_array(zarr, group, name, shape, chunk_shape, array.dtype, fill, attrs)
    zarr.consolidate_metadata(spec.out)


def _zarr_array(zarr, group, name, shape, chunks, dtype, fill, attrs) -> None:
    if hasattr(group, "create_array"):  # zarr >= 3
        group.create_array(name, shape=shape, chunks=chunks, dtype=dtype, fill_value=fill,
                           attributes=attrs)
    else:  # pragma: no cover - zarr 2
        array = group.create_dataset(name, shape=shape, chunks=chunks, dtype=dtype,
                                     fill_value=fill)
        array.attrs.update(attrs)


def _write_chunk(spec: Spec, task: Task, data: dict) -> None:
    """The chunk's region of every variable, then its done flag (last: a chunk killed while
    being written has no flag and is solved again on resume).

    The layout and metadata are xarray's (:func:`_create_store`); the chunks are written
    with zarr directly, through arrays opened once per process: an xarray region write
    re-reads the group's metadata each time (about 50 ms a chunk, benchmarks/sweep_scaling.py),
    a zarr write of an aligned chunk is one file per variable."""
    arrays = _open_arrays(spec)
    region = slice(task.start, task.stop)
    for name, array in data.items():
        if name != "status":
            arrays[name][region] = array
    arrays["status"][region] = data["status"]
    arrays["chunk_done"][task.index:task.index + 1] = np.ones(1, np.uint8)


_ARRAYS: dict = {}  # (store, fingerprint) -> {name: zarr array}; one per process


def _open_arrays(spec: Spec) -> dict:
    key = (spec.out, spec.key)
    if key not in _ARRAYS:
        _, zarr = _need_store_packages()
        _ARRAYS.clear()
        group = zarr.open_group(spec.out, mode="r+")
        names = [*_allocate(spec, 0), "chunk_done"]
        _ARRAYS[key] = {name: group[name] for name in names}
    return _ARRAYS[key]


def open_sweep(path):
    """The sweep store at ``path`` as an :class:`xarray.Dataset`, read lazily.

    Variables (as chosen by ``fields``): ``positions`` (case, station, axis) in m,
    ``orientations`` (case, station, quaternion), ``strains`` and ``stresses`` (case, station,
    component), ``tip_position`` (case, axis), ``tip_orientation`` (case, quaternion); always
    ``status`` (case; 0 solved, 1 the solver failed, 2 invalid input, -1 not computed yet),
    ``message`` (case; the reason of a failure), ``residual``, ``error_estimate`` and
    ``length`` (case), ``chunk_done`` (chunk). The parameters are coordinates on ``case``,
    named by their key paths; ``station`` is s/L. Attributes: the case, the design, the
    solve options, the softarm version and the semantics.

    Needs ``pip install 'softarm[sweep]'``.
    """
    xarray, _ = _need_store_packages()
    path = Path(path)
    if not (path / ".zattrs").is_file() and not (path / "zarr.json").is_file():
        raise FileNotFoundError(f"{path}: no sweep store here")
    try:
        import dask  # noqa: F401
        chunks = {}
    except ImportError:
        chunks = None
    return xarray.open_dataset(path, engine="zarr", chunks=chunks, consolidated=True,
                               mask_and_scale={"status": False, "chunk_done": False})


# --------------------------------------------------------------------------------------------
# run
# --------------------------------------------------------------------------------------------


def design_of(case) -> Design:
    """The sweep design of a case: its ``[sweep]`` design, or its one-parameter sweep as a
    list design over ``load[i].field.component``."""
    if getattr(case, "design", None) is not None:
        return case.design
    sweep = case.sweep
    if sweep is None:
        raise ValueError(f"{case.source or case.name}: the case has no [sweep] table")
    return Design((Parameter(f"load[{sweep.load + 1}].{sweep.field}.{sweep.component}",
                             values=sweep.values),), "list")


def run(case, design: Design | None = None, *, out=None, map: Callable | None = None,
        chunk: int | None = None, fields: Iterable[str] = DEFAULT_FIELDS,
        stations: int | None = None, dtype: str = "float64", method: str | None = None,
        tol: float | None = None, resume: bool = False, path: bool = False,
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
    fields : iterable of str
        Which outputs to keep: "tip", "positions", "orientations", "poses", "strains",
        "stresses".
    stations : int, optional
        Output stations (uniform on [0, L]); default the case's ``[solve] stations``.
    dtype : {"float64", "float32"}
        Of the stored outputs (status, residuals and parameters stay exact).
    method, tol : optional
        Override the case's ``[solve]`` options.
    resume : bool
        Finish a store written by an interrupted run of the same sweep (the chunks whose done
        flag is set are kept).
    path : bool
        Follow a one-parameter load sweep quasi-statically, serially (a prepared Solver, as
        :meth:`softarm.statics.Solver.solve`), instead of solving each case from the unloaded
        arm.
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
        invalid: before any solve), a store that exists without ``resume``, or one that holds
        another sweep.
    """
    xarray, _ = _need_store_packages()
    design = design_of(case) if design is None else design
    if not isinstance(design, Design):
        raise TypeError(f"design must be a softarm.sweep.Design, got {design!r}")
    options = case.solve
    fields = tuple(fields)
    for f in fields:
        if f not in FIELDS:
            raise ValueError(f"fields must be among {', '.join(FIELDS)}, got {f!r}")
    if dtype not in ("float64", "float32"):
        raise ValueError(f"dtype must be 'float64' or 'float32', got {dtype!r}")
    from ._validate import check_allocation, count
    from .dispatch import METHODS
    from .statics.solver import check_tol

    size = design.size
    chunk = max(1, min(1000, math.ceil(size / 16))) if chunk is None else \
        count(chunk, "chunk", 1)
    stations = count(options.stations if stations is None else stations, "stations", 2)
    tol = check_tol(options.tol if tol is None else tol)
    method = options.method if method is None else method
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
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
    plan.check()  # every parameter value buildable, before any solve
    spec = Spec(case.to_dict(), str(case.source) if case.source else None, design,
                method, stations, tol, fields, dtype, chunk,
                None if out is None else os.path.abspath(out), bool(path),  # any worker's cwd
                bool(map is not None if single_thread is None else single_thread))
    chunks = math.ceil(size / chunk)
    todo = list(range(chunks))
    if out is not None:
        todo = _prepare_store(spec, plan, case, resume, chunks)
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
            for name in results[0].data} if results else _allocate(spec, 0)
    values = design.values()
    variables = {name: (_dims(name), array, _variable_attrs(name))
                 for name, array in data.items()}
    return xarray.Dataset(variables, coords=_coords(spec, plan, values),
                          attrs=_attrs(spec, _case_text(case)))


builtins_map = map
_WINDOW = 512  # tasks handed to the map at a time


def _warm_up(case) -> None:
    """Compile (or load from the cache) the solver in this process: one tiny solve of the
    case's own arm and loads. Forked workers then inherit the compiled kernels."""
    from .dispatch import solve
    from .errors import ConvergenceError

    try:
        solve(case.arm, case.loads, method="numeric", s=2, tol=1e-3)
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


def _case_text(case) -> str:
    if case.source is not None:
        try:
            return Path(case.source).read_text(encoding="utf-8")
        except OSError:
            pass
    return json.dumps(case.to_dict(), default=str)


def _prepare_store(spec: Spec, plan: Plan, case, resume: bool, chunks: int) -> list[int]:
    out = Path(spec.out)
    if out.exists():
        if not resume:
            raise ValueError(f"{out}: exists; give --resume (resume=True) to finish an "
                             "interrupted sweep, or remove it or choose another output")
        try:
            store = open_sweep(out)
        except Exception as error:
            raise ValueError(f"{out}: not a sweep store softarm can resume ({error})") from None
        if store.attrs.get("sweep_fingerprint") != spec.key:
            mine = _attrs(spec, "")
            differ = [k for k in ("case_json", "design", "method", "tol", "stations", "fields",
                                  "dtype", "chunk_size", "semantics")
                      if str(store.attrs.get(k)) != str(mine[k])]
            raise ValueError(f"{out}: holds another sweep (its {', '.join(differ) or 'version'}"
                             " differ); resume with the case and options it was started with, "
                             "or choose another output")
        done = np.asarray(store["chunk_done"].values)
        return [k for k in range(chunks) if not done[k]]
    if not out.parent.is_dir():
        raise ValueError(f"{out}: folder {out.parent} does not exist")
    _create_store(spec, plan, _case_text(case))
    return list(range(chunks))

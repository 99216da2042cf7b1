"""Case files (TOML): the case model, and the reader that turns a file into a :class:`Case`.

A *case file* describes an arm, its loads and how to solve it; :func:`load_case` reads it into a
:class:`Case` that notebooks and the ``softarm`` command share, and :func:`solve_case` solves
it (every step of a one-parameter ``[sweep]``; a design is :func:`softarm.sweep.run`'s, above
this module: the case knows its ``[sweep]`` table as plain data, :mod:`softarm._sweep_table`).
Every key is documented in ``docs/case-files.md``; the keys of each table are declared once, in
:mod:`softarm._schema`, which also writes models back (:func:`arm_to_dict`,
:func:`loads_to_dict`). Unknown keys, wrong types and invalid values raise :class:`CaseError`
naming the file, the key path and what is wrong: the reader checks what a TOML value is, the
model (:mod:`softarm.model`, :mod:`softarm.loads`) whether it is allowed, and the reader
reports the model's message at the key path. Result files are :mod:`softarm.io`.

Examples
--------
>>> case = parse_case({"arm": {"length": 1.0, "stiffness": {"EA": 1e6, "GAy": 1e6, "GAz": 1e6,
...     "GJ": 1.0, "EIy": 1.0, "EIz": 1.0}}, "load": [{"kind": "tip", "moment": [0, 3, 0]}]})
>>> case.arm.length, case.loads[0].moment
(1.0, array([0., 3., 0.]))
"""

from __future__ import annotations

import copy
import math
import os
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from numbers import Real
from pathlib import Path

import numpy as np

from . import _schema, dispatch
from ._keypath import resolve
from ._schema import Schema, Table, arm_to_dict, loads_to_dict
from ._simulate_table import BaseMotion, Schedule, Simulation
from ._sweep_table import DESIGNS, Design, Parameter, Sweep
from ._validate import check_allocation, count, format_value
from .contact import Contact
from .dynamics import Damping, Simulator, Trajectory
from .equilibrium import Equilibrium, Stability
from .errors import CaseError, CaseTypeError
from .loads import LOAD_KINDS, InputRules
from .model import Arm, SegmentedArm, StiffnessMatrix
from .statics import Solver
from .statics.solver import check_tol

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "Case",
    "CaseError",
    "CaseTypeError",
    "Schedule",
    "Simulation",
    "SolveOptions",
    "Sweep",
    "arm_to_dict",
    "join_trajectories",
    "load_case",
    "loads_to_dict",
    "parse_case",
    "simulate_case",
    "simulation_parts",
    "solve_case",
]

# Sweep (softarm._sweep_table, public in softarm.sweep), arm_to_dict and loads_to_dict
# (softarm._schema) are re-exported here: softarm.case named them first.


# --------------------------------------------------------------------------------------------
# Case model
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SolveOptions:
    """How to solve a case (the ``[solve]`` table).

    Parameters
    ----------
    method : str
        ``"auto"`` (a closed form where one is exact, else the numerical solver) or
        ``"numeric"``.
    stations : int
        Number of uniformly spaced output stations on [0, L], >= 2.
    tol : float
        Tolerance of the numerical solver: tip-position error relative to the arm length, in
        [1e-13, 0.1] (see ``softarm.solve``).
    branch : str
        ``"connected"`` (the equilibrium connected to the unloaded arm, with a stability
        warning if it is unstable) or ``"stable"`` (``softarm.solve(..., branch="stable")``).
    """

    method: str = "auto"
    stations: int = 101
    tol: float = 1e-8
    branch: str = "connected"

    def __post_init__(self):
        object.__setattr__(self, "stations", count(self.stations, "SolveOptions.stations", 2))
        try:
            tol = check_tol(self.tol)  # the solver's own rule
        except (TypeError, ValueError) as error:
            raise type(error)(f"SolveOptions.{error}") from None
        object.__setattr__(self, "tol", tol)
        if self.branch not in ("connected", "stable"):
            raise ValueError(f"SolveOptions.branch must be 'connected' or 'stable', got "
                             f"{format_value(self.branch)}")


@dataclass(frozen=True)
class InverseTask:
    """The ``[inverse]`` table: where the tip should go (``softarm inverse``).

    Attributes
    ----------
    target : tuple of 3 floats
        The tip position in m, spatial frame.
    tol : float
        Position tolerance relative to L.
    lower, upper : tuple of floats or None
        Bounds per actuation input (in the order of the loads' inputs; tensions are >= 0
        anyway).
    max_iterations : int
    starts : int
        Starts tried before a target is called unreachable (``softarm.InverseSolver``).
    """

    target: tuple
    tol: float = 1e-6
    lower: tuple | None = None
    upper: tuple | None = None
    max_iterations: int = 10
    starts: int = 6

    def __post_init__(self):
        target = np.asarray(self.target, dtype=float)
        if target.shape != (3,) or not np.all(np.isfinite(target)):
            raise ValueError(f"InverseTask.target must be 3 finite numbers in m, got "
                             f"{format_value(self.target)}")
        object.__setattr__(self, "target", tuple(float(v) for v in target))
        if not (isinstance(self.tol, float) and self.tol > 0):
            raise ValueError(f"InverseTask.tol must be > 0, got {format_value(self.tol)}")
        if self.max_iterations < 1:
            raise ValueError(f"InverseTask.max_iterations must be >= 1, got "
                             f"{format_value(self.max_iterations)}")
        if self.starts < 1:
            raise ValueError(f"InverseTask.starts must be >= 1, got "
                             f"{format_value(self.starts)}")


@dataclass(frozen=True, eq=False)
class Case:
    """An arm, its loads and how to solve them, as read from a case file.

    Attributes
    ----------
    name : str
        The case's name (the file's ``name`` key, else the file name without suffix).
    arm : Arm or SegmentedArm
    loads : tuple
        The loads as written (a sweep is not applied; see :attr:`batched_loads`): the
        ``[[load]]`` tables in file order, then one :class:`softarm.Contact` holding the
        ``[[obstacle]]`` tables if there are any.
    solve : SolveOptions
    sweep : Sweep or None
        A one-parameter ``[sweep]`` (``load``, ``field``, ``component``).
    design : softarm.sweep.Design or None
        A ``[sweep]`` with ``design`` and ``[[sweep.parameter]]`` tables, run by
        ``softarm sweep`` / :func:`softarm.sweep.run`.
    source : pathlib.Path or None
        The file read, None for a case built from a dict.
    data : dict
        The validated contents of the file (what result files embed as the case).
    description : str
    inverse : InverseTask or None
        The ``[inverse]`` table, if any.
    simulation : Simulation or None
        The ``[simulate]`` table, if any (:func:`simulate_case`).
    """

    name: str
    arm: Arm | SegmentedArm
    loads: tuple
    solve: SolveOptions = field(default_factory=SolveOptions)
    sweep: Sweep | None = None
    source: Path | None = None
    data: dict = field(default_factory=dict, repr=False)
    description: str = ""
    design: Design | None = None
    inverse: InverseTask | None = None
    simulation: Simulation | None = None

    @property
    def batched_loads(self) -> tuple:
        """The loads to solve: with the sweep applied (batch shape (steps,)) if there is one."""
        return self.sweep.apply(self.loads) if self.sweep is not None else self.loads

    def to_dict(self) -> dict:
        """A copy of the case as a dict in the case-file schema (TOML/JSON ready)."""
        return copy.deepcopy(self.data)


# --------------------------------------------------------------------------------------------
# Reader
# --------------------------------------------------------------------------------------------


def _arm(table: Table) -> Arm:
    """One ``[arm]`` or ``[[segment]]`` table: its keys, then ``stiffness`` or ``section`` and
    ``material``."""
    values = _schema.ARM.read(table)
    if table.has("stiffness_matrix"):
        for other in ("stiffness", "section", "material"):
            if table.has(other):
                raise table.error("stiffness_matrix", f"give either 'stiffness_matrix' or "
                                  f"'{other}', not both")
        matrix = table.raw("stiffness_matrix")
        try:
            values["section"] = StiffnessMatrix(matrix)
        except (TypeError, ValueError) as error:
            raise table.error("stiffness_matrix", str(error).removeprefix(
                "the stiffness matrix K ")) from None
        values["material"] = None
    elif table.has("stiffness"):
        if table.has("section") or table.has("material"):
            raise table.error("stiffness", "give either 'stiffness' or 'section' and "
                              "'material', not both")
        values["section"] = _build(table.table("stiffness"), _schema.STIFFNESS)
        values["material"] = None
    else:  # a missing table is reported by build() after the keys before it
        values["section"] = values["material"] = None
        if not table.has("section"):
            table.lacks("section", "a [section] table with 'kind', or a [stiffness] table "
                        "instead of section and material")
        else:
            section = table.table("section")
            kind = section.string("kind", tuple(_schema.SECTIONS))
            values["section"] = _build(section, _schema.SECTIONS[kind])
        if not table.has("material"):
            table.lacks("material", "a table with E, nu or G, and density")
        else:
            values["material"] = _build(table.table("material"), _schema.MATERIAL)
    return table.build(_schema.ARM.keys, lambda: Arm(**values))


def _build(table: Table, schema: _schema.Schema):
    """The model object of a table read by its schema (the model checks the values)."""
    values = schema.read(table)
    return table.build(schema.keys, lambda: schema.cls(**values))


#: The kinds of a ``[[load]]`` table: every load but the contact, which the ``[[obstacle]]``
#: and ``[contact]`` tables give (:func:`_contact`).
_LOAD_TABLE_KINDS = tuple(kind for kind in LOAD_KINDS if kind != Contact.kind)


def _load(table: Table):
    """A ``[[load]]`` table, read by the load class's own schema (:class:`softarm.loads.Key`)."""
    if table.data.get("kind") == Contact.kind:
        raise table.error("kind", "contact is given by [[obstacle]] tables (kind = \"plane\", "
                          "\"sphere\" or \"capsule\") and an optional [contact] table, not "
                          "by a [[load]] (docs/case-files.md)")
    cls = LOAD_KINDS[table.string("kind", _LOAD_TABLE_KINDS)]
    return _build(table, _schema.Schema(cls.kind, cls, cls.schema))


def _contact(top: Table, arm) -> Contact | None:
    """The ``[[obstacle]]`` tables and the ``[contact]`` table as one :class:`Contact`, or
    None without obstacles. A fault names the obstacle's table (``obstacle[2].radius``) or
    the contact table's key."""
    rows = top.tables("obstacle")
    if not rows:
        if top.has("contact"):
            raise top.error("contact", "a [contact] table needs one or more [[obstacle]] "
                            "tables (kind = \"plane\", \"sphere\" or \"capsule\")")
        return None
    obstacles = []
    for row in rows:
        schema = _schema.OBSTACLES[row.string("kind", tuple(_schema.OBSTACLES))]
        obstacles.append(_build(row, schema))
    table = top.table("contact") if top.has("contact") else Table({}, "contact", top.where)
    values = _schema.CONTACT.read(table)
    contact = table.build(_schema.CONTACT.keys, lambda: Contact(tuple(obstacles), **values))
    table.build(_schema.CONTACT.keys, lambda: contact.check(arm))  # a radius for the arm
    return contact


def _solve_options(table: Table) -> SolveOptions:
    _check_size(table, "stations", 1, table.data.get("stations"))  # before the type
    return _build(table, _schema.Schema("", SolveOptions, _schema.SOLVE))


def _design(table: Table, data: dict) -> Design:
    """A ``[sweep]`` with ``design`` and ``[[sweep.parameter]]`` tables: the design, its key
    paths resolved against the file (errors name the key path)."""
    keys = _schema.DESIGN
    kind = table.string("design", DESIGNS, default="grid")
    samples = table.read(keys["samples"]) if table.has("samples") else None
    seed = table.read(keys["seed"]) if table.has("seed") else 0
    rows = table.tables("parameter")
    if not rows:
        raise table.missing("parameter", "one or more [[sweep.parameter]] tables")
    parameters = []
    for row in rows:
        values = {k: row.read(keys[k]) for k in ("path", "values", "start", "stop", "steps")
                  if row.has(k)}
        row.done()
        if "path" not in values:
            raise row.missing("path", "a key path such as 'load[1].force.magnitude'")
        try:
            resolve(data, values["path"])
        except ValueError as error:
            raise row.error("path", str(error)) from None
        parameter = row.build(tuple(keys[k] for k in ("values", "start", "stop", "steps")),
                              lambda values=values: Parameter(**values))
        parameters.append(parameter)
    table.done()
    try:
        return Design(tuple(parameters), kind, samples, seed)
    except (ValueError, TypeError) as error:
        text = str(error)
        for row, parameter in zip(rows, parameters, strict=True):  # a fault of one row
            if text.startswith(f"{parameter.path}: "):
                raise row.error(None, text) from None
        raise table.error(None, text) from None


def _input_count(load) -> int:
    """The number of actuation inputs of a load (a magnetic field's are 3)."""
    return sum(int(np.size(getattr(load, name))) for name in load.inputs)


def _simulation(table: Table, loads: tuple, arm) -> Simulation:
    """The ``[simulate]`` table with its ``damping``, ``[[simulate.input]]`` and ``base``;
    a schedule's values obey its load's rules on ``arm`` (a tension >= 0, the size limit)."""
    keys = _schema.SIMULATE
    values = {name: table.read(key) for name, key in keys.items() if table.wants(key)}
    if table.has("damping"):
        values["damping"] = _build(table.table("damping"),
                                   Schema("", Damping, _schema.DAMPING))
    schedules = []
    for row in table.tables("input"):
        read = {key.name: row.read(key) for key in _schema.SCHEDULE if row.wants(key)}
        index = read.get("load")
        if index is not None:
            if index > len(loads):
                raise row.error("load", f"there are {len(loads)} [[load]] tables, got load = "
                                f"{index} (counted from 1)")
            load = loads[index - 1]
            if not load.inputs:
                raise row.error("load", f"load {index} ({load.kind}) has no actuation input; "
                                "give a tendon, chamber or magnetic load")
        schedule = row.build(_schema.SCHEDULE, lambda read=read: Schedule(
            read["load"] - 1, read["times"], read["values"]))
        width = _input_count(loads[schedule.load])
        if schedule.width != width:
            raise row.error("values", f"load {schedule.load + 1} ({loads[schedule.load].kind}) "
                            f"has {width} input{'s' if width > 1 else ''} "
                            f"({', '.join(loads[schedule.load].inputs)}); give "
                            f"{'one number' if width == 1 else f'a list of {width} numbers'} "
                            f"per time, got {schedule.width}")
        rules = InputRules(arm, [loads[schedule.load]])
        for at, value in zip(schedule.times, schedule.values, strict=True):
            fault = rules.first_fault(value)
            if fault is not None:
                raise row.error("values", f"at t = {format_value(at)} s: {fault[1]}")
        for j, other in enumerate(schedules):
            if other.load == schedule.load:
                raise row.error("load", f"load {schedule.load + 1} has a schedule already "
                                f"({table.key('input')}[{j + 1}])")
        schedules.append(schedule)
    values["inputs"] = tuple(schedules)
    if table.has("base"):
        values["base"] = _build(table.table("base"), Schema("", BaseMotion, _schema.BASE))
    return table.build(tuple(keys.values()), lambda: Simulation(**values))


def _sweep(table: Table, loads: tuple, stations: int) -> Sweep:
    keys = _schema.SWEEP
    index = table.read(keys["load"]) if table.has("load") else 1
    if index > len(loads):
        raise table.error("load", f"there are {len(loads)} [[load]] tables, got load = "
                          f"{index} (counted from 1)")
    kind = loads[index - 1].kind
    fields = dict(loads[index - 1].vectors)
    if not fields:
        raise table.error("load", f"load {index} ({kind}) has no vector to sweep this way; "
                          f"use a design: [[sweep.parameter]] path = \"load[{index}]."
                          f"{loads[index - 1].arrays[0][0] if loads[index - 1].arrays else 'key'}"
                          "\" (docs/case-files.md)")
    field_name = table.string("field", tuple(fields), default=next(iter(fields)))
    component = table.read(keys["component"]) if table.has("component") else "magnitude"
    label = table.read(keys["name"]) if table.has("name") else ""
    if table.has("values"):
        for key in ("start", "stop", "steps"):
            if table.has(key):
                raise table.error(key, "give either 'values' or 'start', 'stop' and 'steps', "
                                  "not both")
        values = table.read(keys["values"])
        _check_size(table, "values", len(values), stations)
    else:
        start, stop = (table.number(k, fields[field_name], finite=True)
                       for k in ("start", "stop"))
        _check_size(table, "steps", table.data.get("steps"), stations)  # before the type
        steps = table.integer("steps", minimum=keys["steps"].minimum)
        values = tuple(np.linspace(start, stop, steps).tolist())
    table.done()
    vector = getattr(loads[index - 1], field_name)
    if component == "magnitude" and not np.any(vector != 0):
        raise table.error("component", f"'magnitude' needs a nonzero {field_name} in load "
                          f"{index} to give the direction, got (0, 0, 0)")
    return Sweep(index - 1, kind, field_name, component, values, label)


def _check_size(table: Table, key: str, steps, stations) -> None:
    """A sweep of ``steps`` × ``stations`` whose result cannot fit in memory, rejected with the
    memory it would need (before anything is allocated; an integral float counts too)."""
    if isinstance(steps, bool) or not isinstance(steps, Real) or not math.isfinite(steps):
        return
    if isinstance(stations, bool) or not isinstance(stations, Real) or \
            not math.isfinite(stations):
        return
    try:
        check_allocation(int(steps), int(stations), "the sweep")
    except ValueError as error:
        raise table.error(key, str(error).removeprefix("the sweep: ")) from None


def parse_case(data: dict, source: str | os.PathLike | None = None, *,
               name: str | None = None) -> Case:
    """A :class:`Case` from the contents of a case file (a dict as ``tomllib`` returns it).

    Parameters
    ----------
    data : dict
        Top-level keys ``name``, ``description``, ``arm`` or ``segment``, ``load``,
        ``obstacle``, ``contact``, ``solve``, ``sweep``, ``inverse``, ``simulate`` (see
        ``docs/case-files.md``).
    source : path, optional
        The file the dict came from, for messages and :attr:`Case.source`.
    name : str, optional
        Fallback name when ``data`` has none.

    Raises
    ------
    CaseError
        Naming the file, the key path and what is wrong.
    """
    return _parse(data, source, name=name, batched=False)


#: Deepest nesting of tables and arrays a case accepts: a case file needs about six levels, a
#: result file's case a few more (a batch array has one per batch axis, at most 64).
MAX_DEPTH = 100


def _check_depth(data, where: str) -> None:
    """CaseError if ``data`` nests tables and arrays more than :data:`MAX_DEPTH` deep: a
    hostile file must not end in a RecursionError further on (every reader of a case walks it
    recursively). Walked with an explicit stack, not by recursion."""
    stack = [(data, 1)]
    while stack:
        value, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise _too_deep(where)
        children = value.values() if isinstance(value, dict) else \
            value if isinstance(value, (list, tuple)) else ()
        stack.extend((child, depth + 1) for child in children
                     if isinstance(child, (dict, list, tuple)))


def _too_deep(where) -> CaseError:
    return CaseError(f"{where}: tables and arrays nested more than {MAX_DEPTH} levels deep (a "
                     "case file needs about six)")


def _parse(data, source, *, name=None, batched=False) -> Case:
    where = str(source) if source is not None else "<case>"
    _check_depth(data, where)
    top = Table(data, "", where, batched=batched)
    case_name = top.string("name", default=name or (Path(source).stem if source else "case"))
    description = top.string("description", default="")
    if top.has("arm") == top.has("segment"):
        raise CaseError(f"{where}: arm: give exactly one [arm] table or one or more "
                        "[[segment]] tables")
    if top.has("arm"):
        if isinstance(top.data["arm"], list):
            raise top.error("arm", "must be a single [arm] table (use [[segment]] for a "
                            "segmented arm)")
        arm = _arm(top.table("arm"))
    else:
        segments = [_arm(t) for t in top.tables("segment")]
        if not segments:
            raise top.error("segment", "must hold at least one [[segment]] table")
        arm = SegmentedArm(tuple(segments))
    tables = top.tables("load")
    loads = tuple(_load(t) for t in tables)
    for table, load in zip(tables, loads, strict=True):
        table.build(load.schema, lambda load=load: load.check(arm))  # the model's own rule
    contact = _contact(top, arm)
    options = _solve_options(top.table("solve")) if top.has("solve") else SolveOptions()
    sweep = design = None
    if top.has("sweep"):
        table = top.table("sweep")
        if table.has("parameter") or table.has("design"):
            design = _design(table, data)
        else:
            sweep = _sweep(table, loads, options.stations)
    inverse = _build(top.table("inverse"), _schema.Schema("", InverseTask, _schema.INVERSE)) \
        if top.has("inverse") else None
    simulation = _simulation(top.table("simulate"), loads, arm) if top.has("simulate") \
        else None
    top.done()
    if contact is not None:  # after the [[load]] tables, which [sweep] and [simulate] count
        loads = (*loads, contact)
    clean = dict(data)
    clean.setdefault("name", case_name)
    return Case(case_name, arm, loads, options, sweep,
                Path(source) if source is not None else None, copy.deepcopy(clean), description,
                design, inverse, simulation)


def load_case(path: str | os.PathLike) -> Case:
    """Read a TOML case file.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Case

    Raises
    ------
    CaseError
        If the file is missing or not TOML, or a key is missing, unknown, of the wrong type or
        out of range; the message names the file and the key path.
    """
    path = Path(path)
    try:
        text = path.read_bytes()
    except FileNotFoundError:
        raise CaseError(f"{path}: no such file") from None
    except OSError as error:
        raise CaseError(f"{path}: cannot read: {error.strerror or error}") from None
    try:
        data = tomllib.loads(text.decode("utf-8"))
    except UnicodeDecodeError:
        raise CaseError(f"{path}: not a UTF-8 text file") from None
    except tomllib.TOMLDecodeError as error:
        raise CaseError(f"{path}: not valid TOML: {error}") from None
    except RecursionError:  # the TOML reader recurses per level: some hundred levels deep
        raise _too_deep(path) from None
    return parse_case(data, path)


# --------------------------------------------------------------------------------------------
# Solving a case
# --------------------------------------------------------------------------------------------


def _solver():
    """``softarm.solve`` with the arm's preparation kept from one call to the next (sweep
    chunks).

    One prepared :class:`softarm.statics.Solver` per (arm, stations, tol) serves every call
    through :func:`softarm.dispatch.solve_prepared`: the same routes, checks and answers as
    ``softarm.solve`` (every case from the unloaded arm, so a sweep's answers do not depend on
    how it is cut into chunks); only the arm's preparation is not paid again.
    """
    prepared = {}

    def solve(arm, loads, *, method="auto", s=None, tol=1e-8, branch=None):
        if branch == "stable":
            return dispatch.solve(arm, loads, method=method, s=s, tol=tol, branch=branch)
        key = (arm, s, tol)
        if key not in prepared:
            prepared[key] = Solver(arm, s=s, tol=tol)
        return dispatch.solve_prepared(prepared[key], loads, method)

    return solve


def solve_case(case: Case, *, method: str | None = None, stations: int | None = None,
               tol: float | None = None, progress: Callable[[int, int], None] | None = None,
               solve: Callable | None = None) -> Equilibrium:
    """Solve a case (every step of its sweep, if it has one).

    A sweep is solved as batched calls of ``softarm.solve`` (each case from the unloaded arm,
    the arm prepared once for all calls). When the first step shows that the whole sweep
    will take more than about a second, the rest is solved in a few consecutive chunks so that
    ``progress(done, total)`` can report; otherwise in one call.

    Parameters
    ----------
    case : Case
    method, stations, tol : optional
        Override the case's ``[solve]`` options.
    progress : callable, optional
        Called as ``progress(steps_done, steps_total)`` after each chunk of a long sweep.
    solve : callable, optional
        The solver, with the signature of ``softarm.solve``; by default ``softarm.solve`` on
        an arm prepared once for all calls (:func:`_solver`).

    Returns
    -------
    Equilibrium
        Batch shape (steps,) for a sweep, () otherwise.
    """
    if case.design is not None:
        raise ValueError(f"{case.source or case.name}: [sweep] is a design over "
                         f"{', '.join(case.design.paths)}; run it with softarm sweep CASE.toml "
                         "-o OUT.zarr (softarm.sweep.run)")
    solve = _solver() if solve is None else solve
    options = case.solve
    kwargs = {"method": method or options.method,
              "s": int(stations if stations is not None else options.stations),
              "tol": float(tol if tol is not None else options.tol)}
    steps = len(case.sweep.values) if case.sweep is not None else 1
    check_allocation(steps, kwargs["s"], "")
    if options.branch == "stable":
        kwargs["branch"] = "stable"  # one case at a time: each its own stable branch
    if case.sweep is None:
        return solve(case.arm, case.loads, **kwargs)
    loads = case.batched_loads
    total = len(case.sweep.values)
    if options.branch == "stable":
        parts = []
        for k in range(total):
            parts.append(_batched(solve(case.arm, _step(loads, k), **kwargs)))
            if progress is not None:
                progress(k + 1, total)
        return _concatenate(parts, loads)
    start = time.perf_counter()
    parts = [solve(case.arm, _take(loads, 0, 1), **kwargs)]
    first = time.perf_counter() - start
    done = 1
    if progress is not None:
        progress(done, total)
    budget = 0.25  # seconds per chunk when progress is shown
    chunk = total - 1 if first * (total - 1) < 1.0 else max(1, int(budget / max(first, 1e-9)))
    while done < total:
        stop = min(total, done + chunk)
        parts.append(solve(case.arm, _take(loads, done, stop), **kwargs))
        done = stop
        if progress is not None:
            progress(done, total)
    return _concatenate(parts, loads)


def _contact_of(loads) -> Contact | None:
    return next((load for load in loads if isinstance(load, Contact)), None)


def _with_contact(loads: tuple, parts: list[Equilibrium]) -> tuple:
    """``loads`` with their Contact replaced by the law the parts were solved with: each
    case's penalty stiffness (the solver's choice per case, softarm.Contact), one array
    over the sweep's steps, or one number where they are all the same."""
    laws = [_contact_of(part.loads) for part in parts]
    if laws[0] is None or all(law.stiffness is None for law in laws):
        return loads  # (no penalty: every case a tip held exactly, statics/tip_contact.py)
    # (a part whose cases are all held at the tip has no stiffness: none of them, as a
    # part partly held says with zeros, Solver._held_at_tip)
    stiffness = np.concatenate([np.broadcast_to(
        0.0 if law.stiffness is None else law.stiffness, part.batch_shape).ravel()
        for law, part in zip(laws, parts, strict=True)])
    law = laws[0].replace(stiffness=float(stiffness[0]) if np.all(stiffness == stiffness[0])
                          else stiffness)
    return tuple(law if isinstance(load, Contact) else load for load in loads)


def _batched(eq: Equilibrium) -> Equilibrium:
    """A single case as a batch of one (branch='stable' solves one case at a time)."""
    if eq.batch_shape:
        return eq
    verdict = eq.stability
    if verdict is not None:
        verdict = Stability.of(np.array([verdict.index]), np.array([verdict.conservative]),
                                 (1,))
    resultant = None if eq.contact_resultant is None else eq.contact_resultant[None]
    return replace(eq, poses=eq.poses[None], strains=eq.strains[None],
                   stresses=eq.stresses[None], residual=np.array([eq.residual]),
                   contact_resultant=resultant,
                   error_estimate=np.array([eq.error_estimate]), stability=verdict,
                   tip_compliance=None, compliance=None, base_wrench=None,
                   tendon_tensions=None, tendon_lengths=None, tendon_length_changes=None,
                   tendon_slack=None)


def _step(loads: tuple, k: int) -> tuple:
    """Case k of the batched loads, unbatched (branch='stable' takes one case)."""
    return tuple(load.take(k) if load.batch_shape else load for load in loads)


def _take(loads: tuple, start: int, stop: int) -> tuple:
    """Cases start..stop-1 of the batched loads (unbatched loads as they are)."""
    return tuple(load.take(slice(start, stop)) if load.batch_shape else load for load in loads)


def _concatenate(parts: list[Equilibrium], loads: tuple) -> Equilibrium:
    """The parts of a sweep as one equilibrium with the sweep's ``loads`` (and the contact
    law the parts were solved with, :func:`_with_contact`)."""
    loads = _with_contact(loads, parts)
    if len(parts) == 1:
        return replace(parts[0], loads=loads)
    first = parts[0]

    def cat(name):
        return np.concatenate([np.broadcast_to(np.asarray(getattr(p, name), dtype=float),
                                               p.batch_shape) for p in parts])

    def fields(name):  # fresh and read-only: Equilibrium takes it without a copy
        array = np.concatenate([getattr(p, name) for p in parts])
        array.setflags(write=False)
        return array

    methods = sorted({p.method for p in parts})
    stability = None
    if all(p.stability is not None for p in parts):
        stability = Stability.of(
            np.concatenate([np.atleast_1d(p.stability.index) for p in parts]),
            np.concatenate([np.broadcast_to(p.stability.conservative, p.batch_shape)
                            for p in parts]), (sum(p.batch_shape[0] for p in parts),))
    # the contact wrench each part took from its own balance (a tip held exactly has no
    # contact force per length to integrate), and the base wrench, where every part has them
    kept = {name: fields(name) for name in ("contact_resultant", "base_wrench")
            if all(getattr(p, name) is not None for p in parts)}
    return Equilibrium(
        s=first.s,
        poses=fields("poses"),
        strains=fields("strains"),
        stresses=fields("stresses"),
        arm=first.arm, loads=loads, method="+".join(methods),
        exact=all(bool(p.exact) for p in parts),
        residual=cat("residual"), error_estimate=cat("error_estimate"), stability=stability,
        **kept)


# --------------------------------------------------------------------------------------------
# Simulating a case
# --------------------------------------------------------------------------------------------


def _simulator(case: Case) -> tuple[Simulator, Callable | None]:
    """The case's :class:`~softarm.Simulator` and its inputs over time (None: constant).

    The loads with actuation inputs (tendons, chambers, magnetic fields) are the actuators,
    in file order; a scheduled one starts from its schedule's first value. With
    ``initial = "equilibrium"`` the arm starts at rest in the equilibrium of all the loads
    at t = 0 (``softarm.solve`` with the ``[solve]`` options; the Simulator balances it again
    on its own stations)."""
    options = case.simulation
    if options is None:
        raise ValueError(f"{case.source or case.name}: simulate: missing (the case has no "
                         "[simulate] table; docs/case-files.md)")
    scheduled = {schedule.load: schedule for schedule in options.inputs}
    loads = list(case.batched_loads)
    for index, schedule in scheduled.items():
        first, load, start = schedule(0.0), loads[index], 0
        changes = {}
        for name in load.inputs:
            shape = np.shape(getattr(load, name))
            size = int(np.prod(shape))
            changes[name] = first[start:start + size].reshape(shape) if shape else \
                float(first[start])
            start += size
        loads[index] = load.replace(**changes)
    actuators = [load for load in loads if load.inputs]
    passive = [load for load in loads if not load.inputs]
    inputs = None
    if scheduled:
        parts = [(scheduled.get(index), np.concatenate(
            [np.ravel(np.asarray(getattr(load, name), dtype=float)) for name in load.inputs]))
            for index, load in enumerate(loads) if load.inputs]

        def inputs(t: float) -> np.ndarray:
            return np.concatenate([values if schedule is None else schedule(t)
                                   for schedule, values in parts])

    initial = None
    if options.initial == "equilibrium":
        initial = dispatch.solve(case.arm, loads, method=case.solve.method,
                                 s=options.stations, tol=case.solve.tol,
                                 base=None if options.base is None else options.base(0.0))
    simulator = Simulator(case.arm, actuators, passive, dt=options.dt, damping=options.damping,
                          initial=initial, base=options.base, stations=options.stations,
                          tol=options.tol, alpha=options.alpha)
    return simulator, inputs


def simulation_parts(case: Case, *, seconds: float = 0.25,
                     joined: bool = True) -> Iterator[Trajectory]:
    """The case's ``[simulate]`` run in consecutive chunks of steps, each yielded as it is
    done (:func:`join_trajectories` makes them one trajectory; a caller that stops early, on
    Ctrl-C or a ConvergenceError, keeps the chunks it has).

    The first chunk is one step (it shows the cost of a step, the compile excluded: a first
    use of the dynamics kernel compiles it); the next ones take about ``seconds`` each. The
    first chunk includes the initial state (T = steps + 1); the others start after it. A
    sweep's cases go on past a case that fails (its values NaN from its failed step,
    ``Trajectory.failed``); a single case raises ConvergenceError. ``joined``: the caller
    keeps every part (the whole run must fit in memory: checked first); False, a caller
    that writes each part and drops it (softarm.io.TrajectoryStore): each part is checked.
    """
    simulator, inputs = _simulator(case)
    total = case.simulation.steps
    if joined:  # (the chunks are joined: the whole trajectory)
        simulator._check_run(total, "simulate")
    if inputs is not None:  # one contact law for every chunk, sized for the schedules'
        # largest inputs (at their knots: piecewise linear) as simulate's for its whole run
        knots = sorted({0.0, *(t for schedule in case.simulation.inputs for t in schedule.times)})
        simulator._follow_contact(np.array([inputs(t) for t in knots])[None])
    done, chunk = 0, 1
    while done < total:
        steps = min(chunk, total - done)
        start = time.perf_counter()
        part = simulator.run(steps, inputs, failures="keep" if case.sweep else "raise")
        elapsed = time.perf_counter() - start
        yield part if done == 0 else _from(part, 1)
        done += steps
        chunk = max(1, min(total, int(seconds * steps / max(elapsed, 1e-9))))


def _from(trajectory: Trajectory, start: int) -> Trajectory:
    """``trajectory`` from its time index ``start`` on."""
    return join_trajectories([trajectory], start)


def join_trajectories(parts, start: int = 0, every: int = 1) -> Trajectory:
    """Consecutive trajectories (each starting where the last ended, without repeating its
    time) as one, from time index ``start`` of the first on, every ``every``-th time; the
    final state is the last's."""
    parts = list(parts)
    if not parts:
        raise ValueError("join_trajectories: no trajectory given")
    axis = len(parts[0].batch_shape)

    def cat(arrays, axis=axis):
        array = np.concatenate([np.asarray(a) for a in arrays], axis=axis)
        array = array[(slice(None),) * axis + (slice(start, None, every),)]
        array.setflags(write=False)
        return array

    energy = type(parts[0].energy)(*(cat([getattr(p.energy, name) for p in parts])
                                     for name in ("kinetic", "elastic", "gravity",
                                                  "dissipated")))
    lengths = None if parts[0].tendon_lengths is None else \
        cat([p.tendon_lengths for p in parts])
    return Trajectory(
        times=cat([p.times for p in parts], 0), s=parts[0].s,
        positions=cat([p.positions for p in parts]),
        rotations=cat([p.rotations for p in parts]),
        velocities=cat([p.velocities for p in parts]),
        angular_velocities=cat([p.angular_velocities for p in parts]),
        strains=cat([p.strains for p in parts]), stresses=cat([p.stresses for p in parts]),
        energy=energy, errors=cat([p.errors for p in parts]),
        iterations=cat([p.iterations for p in parts]), tendon_lengths=lengths,
        final=parts[-1].final, failed=parts[-1].failed, contact=parts[0].contact,
        contact_radii=parts[0].contact_radii)


def simulate_case(case: Case, *, progress: Callable[[int, int], None] | None = None
                  ) -> Trajectory:
    """Run a case's ``[simulate]`` table: its arm under its loads (a ``[sweep]`` of a load
    gives one trajectory per step: batch shape (steps,)), the actuators following their
    ``[[simulate.input]]`` schedules, the base its ``[simulate.base]`` motion.

    Parameters
    ----------
    case : Case
        With a ``[simulate]`` table.
    progress : callable, optional
        ``progress(steps_done, steps_total)`` after each chunk of steps
        (:func:`simulation_parts`).

    Returns
    -------
    Trajectory
        ``duration / dt + 1`` times, the initial state first.

    Raises
    ------
    ValueError
        The case has no ``[simulate]`` table, or the simulation rejects its data.
    ConvergenceError
        A time step could not be solved.
    """
    parts, done = [], 0
    for part in simulation_parts(case):
        parts.append(part)
        done += part.times.size - (1 if done == 0 else 0)
        if progress is not None:
            progress(done, case.simulation.steps)
    return join_trajectories(parts)

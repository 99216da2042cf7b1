"""Case files (TOML): read them into a :class:`Case`, and solve a case with its sweep.

A *case file* describes an arm, its loads and how to solve it; :func:`load_case` reads it into a
:class:`Case` that notebooks and the ``softarm`` command share, and :func:`solve_case` solves it
(every step of its ``[sweep]``, reporting progress on long sweeps). Every key is documented in
``docs/case-files.md``. Unknown keys, wrong types and invalid values raise :class:`CaseError`
naming the file, the key path and what is wrong. Result files are :mod:`softarm.io`.

Examples
--------
>>> case = parse_case({"arm": {"length": 1.0, "stiffness": {"EA": 1e6, "GAy": 1e6, "GAz": 1e6,
...     "GJ": 1.0, "EIy": 1.0, "EIz": 1.0}}, "load": [{"kind": "tip", "moment": [0, 3, 0]}]})
>>> case.arm.length, case.loads[0].moment
(1.0, array([0., 3., 0.]))
"""

from __future__ import annotations

import copy
import difflib
import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from numbers import Integral, Real
from pathlib import Path

import numpy as np

from ._validate import as_array, check_allocation
from .equilibrium import Equilibrium
from .loads import LOAD_KINDS, as_loads
from .model import Arm, Circle, Material, Rectangle, Rigidities, Section, SegmentedArm, Tube
from .statics.solver import check_tol

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "Case",
    "CaseError",
    "CaseTypeError",
    "SolveOptions",
    "Sweep",
    "arm_to_dict",
    "load_case",
    "loads_to_dict",
    "parse_case",
    "solve_case",
]


class CaseError(ValueError):
    """A case or result file that cannot be used: the message names the file, key and fault."""


class CaseTypeError(CaseError, TypeError):
    """A value of the wrong type in a case file (a string, bool or array where a number is
    expected, ...): a :class:`CaseError` that is also a TypeError, as the library raises."""


# --------------------------------------------------------------------------------------------
# Case model
# --------------------------------------------------------------------------------------------

_METHODS = ("auto", "numeric")


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
    """

    method: str = "auto"
    stations: int = 101
    tol: float = 1e-8


_COMPONENTS = ("magnitude", "x", "y", "z")


@dataclass(frozen=True)
class Sweep:
    """One load parameter varied over a range (the ``[sweep]`` table).

    Parameters
    ----------
    load : int
        Index of the swept load in the case's loads (0-based; the file counts from 1).
    kind : str
        Kind of that load (``"tip"``, ``"point"``, ``"distributed"``, ``"gravity"``).
    field : str
        The swept vector: ``"force"``, ``"moment"`` or ``"acceleration"``.
    component : str
        ``"x"``, ``"y"`` or ``"z"`` (that component takes the swept value, the others keep
        the file's values) or ``"magnitude"`` (the vector has the swept length along the
        file's direction).
    values : tuple of float
        The parameter values, in the field's unit.
    name : str
        Label for plots and the table column.
    """

    load: int
    kind: str
    field: str
    component: str
    values: tuple[float, ...]
    name: str = ""

    @property
    def unit(self) -> str:
        """Unit of the swept parameter, e.g. ``"N"``."""
        return dict(LOAD_KINDS[self.kind].vectors)[self.field]

    @property
    def label(self) -> str:
        """Human-readable label with unit, e.g. ``"tip force magnitude (N)"``."""
        name = self.name or f"{self.kind} {self.field} {self.component}"
        return f"{name} ({self.unit})"

    @property
    def column(self) -> str:
        """Table column name with unit, e.g. ``"tip_force_magnitude_N"``."""
        unit = {"N": "N", "N m": "Nm", "N/m": "N_per_m", "N m/m": "Nm_per_m",
                "m/s²": "m_per_s2"}[self.unit]
        name = self.name or f"{self.kind}_{self.field}_{self.component}"
        name = "".join(c if c.isalnum() else "_" for c in name).strip("_")
        return f"{name}_{unit}"

    def apply(self, loads) -> tuple:
        """``loads`` with the swept field replaced by a stack of shape (steps, 3)."""
        loads = as_loads(loads)
        target = loads[self.load]
        base = np.asarray(getattr(target, self.field), dtype=np.float64)
        values = np.asarray(self.values, dtype=np.float64)
        if self.component == "magnitude":
            direction = base / np.max(np.abs(base))  # scaled first: its norm cannot overflow
            stack = values[:, None] * (direction / np.linalg.norm(direction))
        else:
            stack = np.repeat(base[None, :], values.size, axis=0)
            stack[:, "xyz".index(self.component)] = values
        swept = replace(target, **{self.field: stack})
        return (*loads[: self.load], swept, *loads[self.load + 1:])


@dataclass(frozen=True, eq=False)
class Case:
    """An arm, its loads and how to solve them, as read from a case file.

    Attributes
    ----------
    name : str
        The case's name (the file's ``name`` key, else the file name without suffix).
    arm : Arm or SegmentedArm
    loads : tuple
        The loads as written (a sweep is not applied; see :attr:`batched_loads`).
    solve : SolveOptions
    sweep : Sweep or None
    source : pathlib.Path or None
        The file read, None for a case built from a dict.
    data : dict
        The validated contents of the file (what result files embed as the case).
    description : str
    """

    name: str
    arm: Arm | SegmentedArm
    loads: tuple
    solve: SolveOptions = field(default_factory=SolveOptions)
    sweep: Sweep | None = None
    source: Path | None = None
    data: dict = field(default_factory=dict, repr=False)
    description: str = ""

    @property
    def batched_loads(self) -> tuple:
        """The loads to solve: with the sweep applied (batch shape (steps,)) if there is one."""
        return self.sweep.apply(self.loads) if self.sweep is not None else self.loads

    def to_dict(self) -> dict:
        """A copy of the case as a dict in the case-file schema (TOML/JSON ready)."""
        return copy.deepcopy(self.data)


# --------------------------------------------------------------------------------------------
# Parsing
# --------------------------------------------------------------------------------------------


class _Table:
    """A TOML table being read: typed getters that record the key path, then ``done()``
    rejects the keys nobody asked for."""

    def __init__(self, data, path: str, where: str, *, batched: bool = False):
        if not isinstance(data, dict):
            raise CaseError(f"{where}: {path or 'file'}: must be a table, got {data!r}")
        self.data = data
        self.path = path
        self.where = where
        self.batched = batched
        self.used: set[str] = set()

    def key(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def error(self, key: str | None, what: str, kind: type = CaseError) -> CaseError:
        return kind(f"{self.where}: {self.key(key) if key else self.path}: {what}")

    def type_error(self, key: str | None, what: str) -> CaseError:
        return self.error(key, what, CaseTypeError)

    def missing(self, key: str, what: str) -> CaseError:
        """'missing', or 'unknown key' when a present key looks like a misspelling of it."""
        close = difflib.get_close_matches(key, [k for k in self.data if k not in self.used],
                                          n=1, cutoff=0.6)
        if close:
            return self.error(close[0], f"unknown key; did you mean {key!r}?")
        return self.error(key, f"missing ({what})")

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=None):
        self.used.add(key)
        return self.data.get(key, default)

    def number(self, key: str, unit: str, *, required: bool = True, default=None,
               positive: bool = True):
        if key not in self.data:
            if required:
                raise self.missing(key, f"a number in {unit}")
            self.used.add(key)
            return default
        value = self.raw(key)
        if isinstance(value, bool) or not isinstance(value, Real):
            raise self.type_error(key, f"must be a number in {unit}, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise self.error(key, f"must be finite, got {value!r}")
        if positive and value <= 0:
            raise self.error(key, f"must be positive (in {unit}), got {value!r}")
        return value

    def integer(self, key: str, *, default=None, minimum: int = 0) -> int:
        if key not in self.data:
            if default is None:
                raise self.missing(key, "an integer")
            self.used.add(key)
            return default
        value = self.raw(key)
        if isinstance(value, bool) or not isinstance(value, Integral):
            raise self.type_error(key, f"must be an integer, got {value!r}")
        if value < minimum:
            raise self.error(key, f"must be >= {minimum}, got {value!r}")
        return int(value)

    def string(self, key: str, choices=None, *, default=None) -> str:
        if key not in self.data:
            if default is None:
                raise self.missing(key, f"one of {_quoted(choices)}" if choices else "a string")
            self.used.add(key)
            return default
        value = self.raw(key)
        if not isinstance(value, str):
            raise self.type_error(key, f"must be a string, got {value!r}")
        if choices is not None and value not in choices:
            raise self.error(key, f"unknown value {value!r}; expected one of "
                             f"{_quoted(choices)}{_suggest(value, choices)}")
        return value

    def boolean(self, key: str, *, default: bool) -> bool:
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise self.type_error(key, f"must be true or false, got {value!r}")
        return value

    def vector(self, key: str, unit: str, *, default=(0.0, 0.0, 0.0)) -> np.ndarray:
        value = self.raw(key, default)
        what = f"must be a list of 3 finite numbers in {unit}, got {value!r}"
        try:
            array = as_array(value, key)  # strict: no strings, bools or complex numbers
        except TypeError as error:
            raise self.type_error(key, f"{what} ({str(error).split(', got ')[-1]})") from None
        except ValueError:
            raise self.error(key, what) from None
        if not (array.ndim >= 1 and array.shape[-1] == 3 and (self.batched or array.ndim == 1)):
            raise self.error(key, what)
        return array

    def table(self, key: str) -> _Table:
        return _Table(self.raw(key), self.key(key), self.where, batched=self.batched)

    def tables(self, key: str) -> list[_Table]:
        value = self.raw(key, [])
        if isinstance(value, dict):
            value = [value]
        if not isinstance(value, list):
            raise self.error(key, f"must be an array of tables ([[{key}]]), got {value!r}")
        return [_Table(item, f"{self.key(key)}[{i + 1}]", self.where, batched=self.batched)
                for i, item in enumerate(value)]

    def done(self) -> None:
        unknown = [k for k in self.data if k not in self.used]
        if unknown:
            key = unknown[0]
            known = sorted(self.used)
            raise self.error(key, "unknown key" + _suggest(key, known)
                             + (f" (known keys here: {', '.join(known)})" if known else ""))


def _has_bool(value) -> bool:
    if isinstance(value, bool):
        return True
    if isinstance(value, (list, tuple)):
        return any(_has_bool(v) for v in value)
    return False


def _quoted(choices) -> str:
    return ", ".join(repr(c) for c in choices)


def _suggest(value: str, choices) -> str:
    close = difflib.get_close_matches(str(value), list(choices), n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


_SECTION_KEYS = {
    "circle": ("radius",),
    "tube": ("outer_radius", "inner_radius"),
    "rectangle": ("width", "height"),
    "general": ("area", "Iy", "Iz", "J"),
}
_SECTION_UNITS = {"radius": "m", "outer_radius": "m", "inner_radius": "m", "width": "m",
                  "height": "m", "area": "m²", "Iy": "m⁴", "Iz": "m⁴", "J": "m⁴"}
_STIFFNESS_UNITS = {"EA": "N", "GAy": "N", "GAz": "N", "GJ": "N m²", "EIy": "N m²",
                    "EIz": "N m²"}


def _model(table: _Table, build: Callable):
    """Call a model constructor, turning its ValueError/TypeError into a CaseError."""
    try:
        return build()
    except TypeError as error:
        raise table.type_error(None, str(error)) from None
    except ValueError as error:
        raise table.error(None, str(error)) from None


def _section(table: _Table):
    kind = table.string("kind", tuple(_SECTION_KEYS))
    values = [table.number(k, _SECTION_UNITS[k]) for k in _SECTION_KEYS[kind]]
    if kind == "general":
        factor_keys = ("shear_factor_y", "shear_factor_z")
        factors = [table.number(k, "(dimensionless)", required=False, default=1.0)
                   for k in factor_keys]
        for k, f in zip(factor_keys, factors, strict=True):
            if f > 1.0:
                raise table.error(k, f"must lie in (0, 1], got {f!r}")
        table.done()
        return _model(table, lambda: Section(*values, *factors))
    table.done()
    if kind == "tube" and values[1] >= values[0]:
        raise table.error("inner_radius", f"must be smaller than outer_radius = {values[0]!r} "
                          f"m, got {values[1]!r}")
    cls = {"circle": Circle, "tube": Tube, "rectangle": Rectangle}[kind]
    return _model(table, lambda: cls(*values))


def _material(table: _Table) -> Material:
    E = table.number("E", "Pa")
    if table.has("nu") == table.has("G"):
        raise table.error(None, "needs exactly one of 'nu' (Poisson's ratio) and 'G' (shear "
                          "modulus in Pa)")
    nu = table.number("nu", "(dimensionless)", required=False, positive=False)
    G = table.number("G", "Pa", required=False)
    if nu is not None and not -1.0 < nu <= 0.5:
        raise table.error("nu", f"must lie in (-1, 0.5], got {nu!r}")
    density = table.number("density", "kg/m³", required=False)
    table.done()
    return _model(table, lambda: Material(E, poisson_ratio=nu, shear_modulus=G,
                                                density=density))


def _arm(table: _Table) -> Arm:
    length = table.number("length", "m")
    curvature = tuple(table.vector("curvature", "1/m").tolist())
    mass = table.number("mass_per_length", "kg/m", required=False)
    if table.has("stiffness"):
        if table.has("section") or table.has("material"):
            raise table.error("stiffness", "give either 'stiffness' or 'section' and "
                              "'material', not both")
        stiff = table.table("stiffness")
        values = {k: stiff.number(k, u) for k, u in _STIFFNESS_UNITS.items()}
        stiff.done()
        table.done()
        return _model(table, lambda: Arm.from_stiffness(
            length, **values, curvature=curvature, mass_per_length=mass))
    if not table.has("section"):
        raise table.missing("section", "a [section] table with 'kind', or a [stiffness] "
                            "table instead of section and material")
    section = _section(table.table("section"))
    if not table.has("material"):
        raise table.missing("material", "a table with E, nu or G, and density")
    material = _material(table.table("material"))
    table.done()
    return _model(table, lambda: Arm(length, section, material, curvature, mass))


def _load(table: _Table):
    """A ``[[load]]`` table, read by the load class's own schema (:class:`softarm.loads.Key`)."""
    kind = table.string("kind", tuple(LOAD_KINDS))
    cls = LOAD_KINDS[kind]
    values = {}
    for key in cls.schema:
        if not table.has(key.name):
            if key.required:
                raise table.missing(key.name, f"a {key.kind} in {key.unit}" if key.unit
                                    else f"a {key.kind}")
            continue
        if key.kind == "vector":
            values[key.name] = table.vector(key.name, key.unit)
        elif key.kind == "number":
            values[key.name] = table.number(key.name, key.unit, positive=False)
        elif key.kind == "flag":
            values[key.name] = table.boolean(key.name, default=False)
        elif key.kind == "index":
            values[key.name] = table.integer(key.name, minimum=0)
        else:  # a span: two numbers in m
            raw = table.raw(key.name)
            if not (isinstance(raw, list) and len(raw) == 2 and not _has_bool(raw)
                    and all(isinstance(v, Real) for v in raw)):
                raise table.error(key.name, f"must be [s0, s1], two numbers in m, got {raw!r}")
            values[key.name] = tuple(float(v) for v in raw)
    table.done()
    return _model(table, partial(cls, **values))


def _stations(table: _Table) -> int:
    _check_size(table, "stations", 1, table.data.get("stations"))  # before the type
    return table.integer("stations", default=101, minimum=2)


def _solve_options(table: _Table) -> SolveOptions:
    options = SolveOptions(
        method=table.string("method", _METHODS, default="auto"),
        stations=_stations(table),
        tol=table.number("tol", "units of the arm length", required=False, default=1e-8),
    )
    try:
        check_tol(options.tol)  # the solver's own rule, reported with the key path
    except ValueError as error:
        raise table.error("tol", str(error).removeprefix("tol ")) from None
    table.done()
    return options


def _sweep(table: _Table, loads: tuple, stations: int) -> Sweep:
    index = table.integer("load", default=1, minimum=1)
    if index > len(loads):
        raise table.error("load", f"there are {len(loads)} [[load]] tables, got load = "
                          f"{index} (counted from 1)")
    kind = loads[index - 1].kind
    fields = dict(loads[index - 1].vectors)
    field_name = table.string("field", tuple(fields), default=next(iter(fields)))
    component = table.string("component", _COMPONENTS, default="magnitude")
    label = table.string("name", default="")
    if table.has("values"):
        for key in ("start", "stop", "steps"):
            if table.has(key):
                raise table.error(key, "give either 'values' or 'start', 'stop' and 'steps', "
                                  "not both")
        raw = table.raw("values")
        if (not isinstance(raw, list) or not raw or _has_bool(raw)
                or not all(isinstance(v, Real) and math.isfinite(v) for v in raw)):
            raise table.error("values", f"must be a non-empty list of finite numbers, got "
                              f"{raw!r}", CaseTypeError if isinstance(raw, list) and raw
                              and not all(isinstance(v, Real) and not isinstance(v, bool)
                                          for v in raw) else CaseError)
        _check_size(table, "values", len(raw), stations)
        values = tuple(float(v) for v in raw)
    else:
        start = table.number("start", fields[field_name], positive=False)
        stop = table.number("stop", fields[field_name], positive=False)
        _check_size(table, "steps", table.data.get("steps"), stations)  # before the type
        steps = table.integer("steps", minimum=2)
        values = tuple(np.linspace(start, stop, steps).tolist())
    table.done()
    vector = getattr(loads[index - 1], field_name)
    if component == "magnitude" and not np.max(np.abs(vector)) > 0:
        raise table.error("component", f"'magnitude' needs a nonzero {field_name} in load "
                          f"{index} to give the direction, got (0, 0, 0)")
    return Sweep(index - 1, kind, field_name, component, values, label)


def _check_size(table: _Table, key: str, steps, stations) -> None:
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
        ``solve``, ``sweep`` (see ``docs/case-files.md``).
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


def _parse(data, source, *, name=None, batched=False) -> Case:
    where = str(source) if source is not None else "<case>"
    top = _Table(data, "", where, batched=batched)
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
    loads = tuple(_load(t) for t in top.tables("load"))
    for i, load in enumerate(loads):
        try:
            load.check(arm)  # the model's own rule, reported with the key path
        except ValueError as error:
            text, key = str(error), ""
            prefix = f"{type(load).__name__}."
            if text.startswith(prefix):  # "PointLoad.s must ..." -> load[i].s: must ...
                key, _, text = text[len(prefix):].partition(" ")
                key = "." + key
            raise CaseError(f"{where}: load[{i + 1}]{key}: {text}") from None
    options = _solve_options(top.table("solve")) if top.has("solve") else SolveOptions()
    sweep = _sweep(top.table("sweep"), loads, options.stations) if top.has("sweep") else None
    top.done()
    clean = dict(data)
    clean.setdefault("name", case_name)
    return Case(case_name, arm, loads, options, sweep,
                Path(source) if source is not None else None, copy.deepcopy(clean), description)


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
    return parse_case(data, path)


# --------------------------------------------------------------------------------------------
# Model -> dict (for results saved without their case file)
# --------------------------------------------------------------------------------------------


def _section_dict(section) -> dict:
    if isinstance(section, Circle):
        return {"kind": "circle", "radius": section.radius}
    if isinstance(section, Tube):
        return {"kind": "tube", "outer_radius": section.outer_radius,
                "inner_radius": section.inner_radius}
    if isinstance(section, Rectangle):
        return {"kind": "rectangle", "width": section.width, "height": section.height}
    return {"kind": "general", "area": section.area, "Iy": section.Iy, "Iz": section.Iz,
            "J": section.J, "shear_factor_y": section.shear_factor_y,
            "shear_factor_z": section.shear_factor_z}


def _one_arm_dict(arm: Arm) -> dict:
    out: dict = {"length": float(arm.length)}
    if isinstance(arm.section, Rigidities):
        r = arm.section
        out["stiffness"] = {k: float(getattr(r, k)) for k in _STIFFNESS_UNITS}
    else:
        out["section"] = _section_dict(arm.section)
        m = arm.material
        material = {"E": m.E}
        if m.poisson_ratio is not None:
            material["nu"] = float(m.poisson_ratio)
        else:
            material["G"] = float(m.shear_modulus)
        if m.density is not None:
            material["density"] = float(m.density)
        out["material"] = material
    out["curvature"] = [float(c) for c in arm.curvature]
    if arm.mass_per_length is not None:
        out["mass_per_length"] = float(arm.mass_per_length)
    return out


def arm_to_dict(arm: Arm | SegmentedArm) -> dict:
    """The case-file tables describing ``arm``: ``{"arm": {...}}`` or ``{"segment": [...]}``."""
    if isinstance(arm, SegmentedArm):
        return {"segment": [_one_arm_dict(a) for a in arm.segments]}
    return {"arm": _one_arm_dict(arm)}


def loads_to_dict(loads) -> list[dict]:
    """The ``[[load]]`` tables describing ``loads`` (batched vectors become nested lists)."""
    return [load.to_case() for load in as_loads(loads)]


# --------------------------------------------------------------------------------------------
# Solving a case
# --------------------------------------------------------------------------------------------


def _solver():
    """``softarm.solve`` that warm-starts each call from the previous one (sweep chunks).

    One prepared :class:`softarm.statics.Solver` per (arm, stations, tol) serves every call
    through :func:`softarm.dispatch.solve_prepared`: the same routes and checks as
    ``softarm.solve``, but each chunk of a sweep starts from the last solution of the previous
    chunk instead of from the unloaded arm.
    """
    from . import dispatch  # the solver is imported when first needed
    from .statics import Solver

    prepared = {}

    def solve(arm, loads, *, method="auto", s=None, tol=1e-8):
        key = (arm, s, tol)
        if key not in prepared:
            prepared[key] = Solver(arm, s=s, tol=tol)
        return dispatch.solve_prepared(prepared[key], loads, method)

    return solve


def solve_case(case: Case, *, method: str | None = None, stations: int | None = None,
               tol: float | None = None, progress: Callable[[int, int], None] | None = None,
               solve: Callable | None = None) -> Equilibrium:
    """Solve a case (every step of its sweep, if it has one).

    A sweep is solved as batched calls of ``softarm.solve`` (warm-started along the batch inside
    the solver, and from one call to the next). When the first step shows that the whole sweep
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
        The solver, with the signature of ``softarm.solve``; by default ``softarm.solve``
        warm-started from one call to the next (:func:`_solver`).

    Returns
    -------
    Equilibrium
        Batch shape (steps,) for a sweep, () otherwise.
    """
    solve = _solver() if solve is None else solve
    options = case.solve
    kwargs = {"method": method or options.method,
              "s": int(stations if stations is not None else options.stations),
              "tol": float(tol if tol is not None else options.tol)}
    steps = len(case.sweep.values) if case.sweep is not None else 1
    check_allocation(steps, kwargs["s"], "")
    if case.sweep is None:
        return solve(case.arm, case.loads, **kwargs)
    loads = case.batched_loads
    total = len(case.sweep.values)
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


def _take(loads: tuple, start: int, stop: int) -> tuple:
    out = []
    for load in loads:
        if load.batch_shape:
            load = replace(load, **{name: np.asarray(getattr(load, name))[start:stop]
                                    for name, _ in load.vectors
                                    if np.ndim(getattr(load, name)) > 1})
        out.append(load)
    return tuple(out)


def _concatenate(parts: list[Equilibrium], loads: tuple) -> Equilibrium:
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
    return Equilibrium(
        s=first.s,
        poses=fields("poses"),
        strains=fields("strains"),
        stresses=fields("stresses"),
        arm=first.arm, loads=loads, method="+".join(methods),
        exact=all(bool(p.exact) for p in parts),
        residual=cat("residual"), error_estimate=cat("error_estimate"))


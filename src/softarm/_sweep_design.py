"""Sweep designs: parameters named by key path, the design that samples them, and the plan
that turns a chunk of design points into batched solves (private; public names are in
:mod:`softarm.sweep`).

A *key path* names one number of a case file, counted as the file counts its tables
(from 1): ``load[2].force.magnitude``, ``load[1].moment.y``, ``load[3].tension``,
``arm.length``, ``arm.section.radius``, ``segment[2].material.E``, ``arm.curvature.z``.
Load paths are resolved against the load class's own ``schema`` (:data:`softarm.loads.
LOAD_KINDS`), arm paths against the case-file schema of the arm's tables
(:mod:`softarm._schema`): a new load kind or section kind is sweepable without code here.

Values are applied in two ways, both generic:

- a load field that the load class accepts with a leading batch axis (every vector field,
  and number fields of kinds that batch them) is set for a whole group of cases at once;
- anything else (arm parameters, a number a load cannot batch, e.g. a point load's ``s``) is
  written into a copy of the case file's tables, which the case reader then checks and builds:
  cases are grouped by these values, one arm (one prepared solver) per group.
"""

from __future__ import annotations

import copy
import math
import re
import warnings
from dataclasses import dataclass, field
from numbers import Integral, Real

import numpy as np

__all__ = ["DESIGNS", "Design", "Parameter", "Plan", "Target", "resolve"]

#: The values of ``design`` in a ``[sweep]`` table.
DESIGNS = ("grid", "list", "latin-hypercube", "sobol")

#: Components of a vector named in a key path.
VECTOR_COMPONENTS = ("x", "y", "z", "magnitude")

_PATH = re.compile(r"(?:(load|segment)\[(\d+)\]|(arm))\.(\w+(?:\.\w+)*)")


def _finite(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class Parameter:
    """One swept parameter: a key path and its values or range.

    Parameters
    ----------
    path : str
        Key path of the number in the case file, e.g. ``"load[2].force.magnitude"`` or
        ``"segment[1].section.radius"`` (tables counted from 1).
    values : sequence of float, optional
        The values explicitly (``"grid"`` and ``"list"`` designs), in the key's unit.
    start, stop : float, optional
        The range: ``linspace(start, stop, steps)`` for a grid, the sampled interval for
        ``"latin-hypercube"`` and ``"sobol"``.
    steps : int, optional
        Number of grid values (>= 2) with ``start`` and ``stop``.

    Examples
    --------
    >>> Parameter("arm.length", start=0.2, stop=0.4, steps=3).grid_values()
    array([0.2, 0.3, 0.4])
    """

    path: str
    values: tuple[float, ...] | None = None
    start: float | None = None
    stop: float | None = None
    steps: int | None = None

    def __post_init__(self):
        where = str(self.path)
        if not isinstance(self.path, str) or _PATH.fullmatch(self.path) is None:
            raise ValueError(f"Parameter.path must be a key path such as "
                             f"'load[1].force.magnitude', 'arm.length' or "
                             f"'segment[2].section.radius', got {self.path!r}")
        if self.values is not None:
            if any(v is not None for v in (self.start, self.stop, self.steps)):
                raise ValueError(f"{where}: give either values or start and stop, not both")
            try:
                values = tuple(self.values)
            except TypeError:
                raise ValueError(f"{where}: values must be a list of numbers, got "
                                 f"{self.values!r}") from None
            if not values:
                raise ValueError(f"{where}: values is empty (an empty range)")
            object.__setattr__(self, "values", tuple(_finite(v, f"{where}: values")
                                                    for v in values))
            return
        if self.start is None or self.stop is None:
            raise ValueError(f"{where}: give values, or start and stop")
        object.__setattr__(self, "start", _finite(self.start, f"{where}: start"))
        object.__setattr__(self, "stop", _finite(self.stop, f"{where}: stop"))
        if self.start == self.stop:
            raise ValueError(f"{where}: start == stop == {self.start!r} is an empty range")
        if self.steps is not None:
            if isinstance(self.steps, bool) or not isinstance(self.steps, Integral) \
                    or self.steps < 2:
                raise ValueError(f"{where}: steps must be an integer >= 2, got {self.steps!r}")
            object.__setattr__(self, "steps", int(self.steps))

    def grid_values(self) -> np.ndarray:
        """The values of a grid or list design, shape (n,)."""
        if self.values is not None:
            return np.asarray(self.values, dtype=np.float64)
        if self.steps is None:
            raise ValueError(f"{self.path}: a grid needs values, or start, stop and steps")
        return np.linspace(self.start, self.stop, self.steps)


@dataclass(frozen=True)
class Design:
    """How the parameters are combined into cases.

    Parameters
    ----------
    parameters : sequence of Parameter
    kind : {"grid", "list", "latin-hypercube", "sobol"}
        ``"grid"``: the Cartesian product (the first parameter varies slowest);
        ``"list"``: the i-th case takes the i-th value of every parameter (equal lengths);
        ``"latin-hypercube"``, ``"sobol"``: ``samples`` points of
        :mod:`scipy.stats.qmc` (scrambled Sobol) with ``seed``, scaled to each parameter's
        [start, stop].
    samples : int, optional
        Number of cases of a sampled design.
    seed : int
        Seed of a sampled design (default 0: the same design every time).

    Examples
    --------
    >>> d = Design((Parameter("arm.length", values=(1.0, 2.0)),
    ...             Parameter("load[1].force.z", start=0.0, stop=1.0, steps=3)))
    >>> d.size, d.values(0, 4).tolist()
    (6, [[1.0, 0.0], [1.0, 0.5], [1.0, 1.0], [2.0, 0.0]])
    """

    parameters: tuple[Parameter, ...]
    kind: str = "grid"
    samples: int | None = None
    seed: int = 0
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        params = tuple(self.parameters)
        object.__setattr__(self, "parameters", params)
        if not params or not all(isinstance(p, Parameter) for p in params):
            raise TypeError(f"Design.parameters must be a non-empty sequence of Parameter, "
                            f"got {self.parameters!r}")
        paths = [p.path for p in params]
        twice = sorted({p for p in paths if paths.count(p) > 1})
        if twice:
            raise ValueError(f"{twice[0]}: given twice")
        if self.kind not in DESIGNS:
            raise ValueError(f"Design.kind must be one of {DESIGNS}, got {self.kind!r}")
        sampled = self.kind in ("latin-hypercube", "sobol")
        if sampled:
            if isinstance(self.samples, bool) or not isinstance(self.samples, Integral) \
                    or self.samples < 1:
                raise ValueError(f"a {self.kind} design needs samples, an integer >= 1, got "
                                 f"{self.samples!r}")
            for p in params:
                if p.values is not None or p.steps is not None:
                    raise ValueError(f"{p.path}: a {self.kind} design samples "
                                     "[start, stop]; give start and stop only")
        elif self.samples is not None:
            raise ValueError(f"samples is for 'latin-hypercube' and 'sobol' designs, not "
                             f"{self.kind!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, Integral) or self.seed < 0:
            raise ValueError(f"Design.seed must be an integer >= 0, got {self.seed!r}")
        if self.kind == "list":
            sizes = {p.path: p.grid_values().size for p in params}
            if len(set(sizes.values())) > 1:
                raise ValueError(f"a list design needs the same number of values for every "
                                 f"parameter, got {sizes}")
        elif self.kind == "grid":
            for p in params:
                p.grid_values()  # a range without steps is an error here

    def __getstate__(self):  # tasks carry the design: never its cached samples
        return {k: v for k, v in self.__dict__.items() if k != "_cache"}

    def __setstate__(self, state):
        for k, v in {**state, "_cache": {}}.items():
            object.__setattr__(self, k, v)

    @property
    def paths(self) -> tuple[str, ...]:
        return tuple(p.path for p in self.parameters)

    @property
    def shape(self) -> tuple[int, ...]:
        """The grid's shape (one axis per parameter), else (size,)."""
        if self.kind == "grid":
            return tuple(p.grid_values().size for p in self.parameters)
        if self.kind == "list":
            return (self.parameters[0].grid_values().size,)
        return (int(self.samples),)

    @property
    def size(self) -> int:
        """Number of cases."""
        return math.prod(self.shape)

    def values(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Parameter values of cases ``start`` .. ``stop - 1``, shape (cases, parameters)."""
        stop = self.size if stop is None else min(stop, self.size)
        index = np.arange(start, stop)
        if self.kind == "grid":
            axes = [p.grid_values() for p in self.parameters]
            digits = np.unravel_index(index, self.shape)
            return np.stack([a[d] for a, d in zip(axes, digits, strict=True)], axis=-1)
        if self.kind == "list":
            return np.stack([p.grid_values()[index] for p in self.parameters], axis=-1)
        if "unit" not in self._cache:
            self._cache["unit"] = self._sample()
        unit = self._cache["unit"][index]
        low = np.array([p.start for p in self.parameters])
        high = np.array([p.stop for p in self.parameters])
        return low + unit * (high - low)

    def _sample(self) -> np.ndarray:
        from scipy.stats import qmc

        d, n = len(self.parameters), int(self.samples)
        rng = np.random.default_rng(self.seed)
        if self.kind == "latin-hypercube":
            return qmc.LatinHypercube(d, rng=rng).random(n)
        with warnings.catch_warnings():
            # scipy warns when n is not a power of 2 (the balance of the full sequence is
            # lost; the first n points remain a low-discrepancy set): docs/case-files.md
            warnings.filterwarnings("ignore", "The balance properties of Sobol",
                                    UserWarning)
            return qmc.Sobol(d, scramble=True, rng=rng).random(n)

    def to_dict(self) -> dict:
        """The ``[sweep]`` table of this design (case-file form)."""
        out: dict = {"design": self.kind}
        if self.samples is not None:
            out["samples"] = int(self.samples)
            out["seed"] = int(self.seed)
        rows = []
        for p in self.parameters:
            row: dict = {"path": p.path}
            if p.values is not None:
                row["values"] = list(p.values)
            else:
                row["start"], row["stop"] = p.start, p.stop
                if p.steps is not None:
                    row["steps"] = p.steps
            rows.append(row)
        out["parameter"] = rows
        return out


# --------------------------------------------------------------------------------------------
# Key paths
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Target:
    """A resolved key path: where its number lives in the case file's tables.

    ``table``: the keys from the file's top level to the table holding the number (e.g.
    ``("segment", 1, "section")``, list indices from 0); ``key`` the number's key;
    ``component`` one of x, y, z, magnitude for a vector, else None; ``unit``; ``load`` the
    load index (from 0) for a load field, else None; ``batched``: the load class takes this
    field with a leading batch axis (set by :class:`Plan`).
    """

    path: str
    table: tuple
    key: str
    component: str | None
    unit: str
    load: int | None = None
    batched: bool = False


def _choose(path: str, what: str, name: str, choices) -> None:
    from ._schema import suggest

    if name not in choices:
        raise ValueError(f"{path}: unknown {what} {name!r}{suggest(name, choices)}; expected "
                         f"one of {', '.join(choices) if choices else '(none)'}")


def _number_or_vector(path: str, keys, rest: list[str], table: tuple, load=None) -> Target:
    """The target of ``rest`` = [key] or [key, component] among ``keys`` (schema rows)."""
    sweepable = {k.name: k for k in keys if k.kind in ("number", "magnitude", "vector")}
    _choose(path, "key", rest[0], tuple(sweepable))
    key = sweepable[rest[0]]
    if key.kind == "vector":
        if len(rest) != 2:
            raise ValueError(f"{path}: {key.name} is a vector; name a component: "
                             f"{', '.join(f'{key.name}.{c}' for c in VECTOR_COMPONENTS)}")
        _choose(path, "component", rest[1], VECTOR_COMPONENTS)
        return Target(path, table, key.name, rest[1], key.unit, load)
    if len(rest) != 1:
        raise ValueError(f"{path}: {key.name} is a number; nothing follows it")
    return Target(path, table, key.name, None, key.unit, load)


def resolve(data: dict, path: str) -> Target:
    """The :class:`Target` of key path ``path`` in the validated case-file dict ``data``.

    Raises
    ------
    ValueError
        Naming the path and what is wrong (unknown table, index out of range, unknown key,
        a vector without a component, a key that is not a number).
    """
    from . import _schema
    from .loads import LOAD_KINDS

    match = _PATH.fullmatch(path)
    if match is None:
        raise ValueError(f"{path}: not a key path (expected e.g. 'load[1].force.magnitude', "
                         "'arm.length' or 'segment[2].section.radius')")
    head, number, arm_head, rest = match.groups()
    rest = rest.split(".")
    if head == "load":
        loads = data.get("load", [])
        loads = [loads] if isinstance(loads, dict) else loads
        index = int(number)
        if not 1 <= index <= len(loads):
            raise ValueError(f"{path}: there are {len(loads)} [[load]] tables, got load[{index}]"
                             " (counted from 1)")
        cls = LOAD_KINDS[loads[index - 1]["kind"]]
        return _number_or_vector(path, cls.schema, rest, ("load", index - 1), index - 1)
    if arm_head:
        if "arm" not in data:
            raise ValueError(f"{path}: this case has [[segment]] tables, not [arm]; use "
                             "segment[1]., segment[2]., ...")
        table, where = data["arm"], ("arm",)
    else:
        segments = data.get("segment")
        if segments is None:
            raise ValueError(f"{path}: this case has an [arm] table, not [[segment]]; use "
                             "arm.")
        segments = [segments] if isinstance(segments, dict) else segments
        index = int(number)
        if not 1 <= index <= len(segments):
            raise ValueError(f"{path}: there are {len(segments)} [[segment]] tables, got "
                             f"segment[{index}] (counted from 1)")
        table, where = segments[index - 1], ("segment", index - 1)
    subtables = ("section", "material") if "section" in table else ("stiffness",)
    if rest[0] in ("section", "material", "stiffness"):
        if rest[0] not in subtables:
            raise ValueError(f"{path}: this arm is given by its {' and '.join(subtables)}, "
                             f"not {rest[0]}")
        if len(rest) < 2:
            raise ValueError(f"{path}: name a key of the {rest[0]} table")
        if rest[0] == "section":
            schema = _schema.SECTIONS[table["section"]["kind"]]
        else:
            schema = _schema.MATERIAL if rest[0] == "material" else _schema.STIFFNESS
        return _number_or_vector(path, schema.keys, rest[1:], (*where, rest[0]))
    choices = (*(k.name for k in _schema.ARM.keys), *subtables)
    if rest[0] not in [k.name for k in _schema.ARM.keys]:
        _choose(path, "key", rest[0], choices)
    return _number_or_vector(path, _schema.ARM.keys, rest, where)


def _set_vector(vector: np.ndarray, component: str, values: np.ndarray, path: str
                ) -> np.ndarray:
    """``vector`` (..., 3) with ``component`` set to ``values`` (...,): a coordinate, or the
    length along the vector's direction (ValueError naming ``path`` if it is zero)."""
    out = np.array(np.broadcast_to(vector, (*np.shape(values), 3)), dtype=np.float64)
    if component == "magnitude":
        scale = np.max(np.abs(out), axis=-1, keepdims=True)  # scaled first: |v|² may overflow
        if np.any(scale == 0):
            raise ValueError(f"{path}: a magnitude needs a nonzero vector to give the "
                             "direction, got (0, 0, 0)")
        direction = out / scale
        direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
        return np.asarray(values)[..., None] * direction
    out[..., "xyz".index(component)] = values
    return out


def _table_of(data: dict, table: tuple) -> dict:
    node = data
    for key in table:
        if not (isinstance(key, int) and isinstance(node, dict)):  # a lone [segment] table
            node = node[key]
    return node


def set_value(data: dict, target: Target, value: float) -> None:
    """Write ``value`` at ``target`` into the case-file dict ``data`` (in place)."""
    table = _table_of(data, target.table)
    if target.component is None:
        table[target.key] = float(value)
    else:
        current = np.asarray(table.get(target.key, (0.0, 0.0, 0.0)), dtype=np.float64)
        table[target.key] = _set_vector(current, target.component, np.float64(value),
                                        target.path).tolist()


# --------------------------------------------------------------------------------------------
# Plan: design points -> groups of batched solves
# --------------------------------------------------------------------------------------------


@dataclass
class Group:
    """Cases of one chunk that share an arm: their rows in the chunk, the arm and the loads
    (batch shape (rows,)), or the reason they cannot be built."""

    rows: np.ndarray
    arm: object = None
    loads: tuple = ()
    error: str = ""
    base_loads: tuple = ()


class Plan:
    """A case and a design, resolved: builds the arm and loads of any set of design points.

    Parameters
    ----------
    case : softarm.case.Case
    design : Design
    """

    def __init__(self, case, design: Design):
        self.case = case
        self.design = design
        data = copy.deepcopy(case.data)
        data.pop("sweep", None)
        self.data = data
        targets = []
        for p in design.parameters:
            target = resolve(data, p.path)
            if target.load is not None:
                target = Target(**{**target.__dict__, "batched": self._batches(target)})
            targets.append(target)
        self.targets = tuple(targets)
        self.grouped = [j for j, t in enumerate(self.targets) if not t.batched]
        self._cases: dict = {}

    def _batches(self, target: Target) -> bool:
        """Whether the load class takes ``target``'s field with a leading batch axis."""
        load = self.case.loads[target.load]
        value = np.asarray(getattr(load, target.key), dtype=np.float64)
        try:
            batched = load.replace(**{target.key: np.stack([value, value])})
        except (TypeError, ValueError):
            return False
        return batched.batch_shape[:1] == (2,)

    @property
    def units(self) -> tuple[str, ...]:
        return tuple(t.unit for t in self.targets)

    def base(self, key: tuple):
        """(arm, loads) of the case with the grouped parameters at ``key`` (cached), or the
        reader's message naming the key path."""
        from .case import parse_case
        from .errors import CaseError

        if key in self._cases:
            return self._cases[key]
        data = copy.deepcopy(self.data)
        try:
            for j, value in zip(self.grouped, key, strict=True):
                set_value(data, self.targets[j], value)
            case = parse_case(data, self.case.source or "<case>")
            result = (case.arm, case.loads)
        except (CaseError, ValueError, TypeError) as error:
            message = str(error)
            where = f"{self.case.source or '<case>'}: "
            result = message[len(where):] if message.startswith(where) else message
        if len(self._cases) > 64:
            self._cases.clear()
        self._cases[key] = result
        return result

    def groups(self, values: np.ndarray) -> list[Group]:
        """The cases with parameter values ``values`` (cases, parameters), grouped by arm."""
        values = np.asarray(values, dtype=np.float64)
        if self.grouped:
            keys, inverse = np.unique(values[:, self.grouped], axis=0, return_inverse=True)
            inverse = inverse.reshape(-1)
        else:
            keys, inverse = np.zeros((1, 0)), np.zeros(len(values), dtype=np.int64)
        out = []
        for g, key in enumerate(keys):
            rows = np.flatnonzero(inverse == g)
            base = self.base(tuple(float(v) for v in key))
            if isinstance(base, str):
                out.append(Group(rows, error=base))
                continue
            arm, loads = base
            try:
                out.append(Group(rows, arm, self._batched_loads(loads, values[rows]),
                                 base_loads=loads))
            except (ValueError, TypeError):  # find the cases at fault, one by one
                for row in rows:
                    try:
                        batched = self._batched_loads(loads, values[row:row + 1])
                    except (ValueError, TypeError) as error:
                        out.append(Group(np.array([row]), error=str(error)))
                    else:
                        out.append(Group(np.array([row]), arm, batched, base_loads=loads))
        return out

    def rebatch(self, group: Group, values: np.ndarray) -> tuple:
        """The loads of ``group``'s arm for a subset of its cases (parameter ``values``)."""
        return self._batched_loads(group.base_loads, np.asarray(values, dtype=np.float64))

    def _batched_loads(self, loads: tuple, values: np.ndarray) -> tuple:
        """The loads with the batched parameters set, every load of batch shape (cases,)."""
        loads = list(loads)
        changes: dict[int, dict] = {}
        for j, target in enumerate(self.targets):
            if not target.batched:
                continue
            fields = changes.setdefault(target.load, {})
            current = fields.get(target.key, getattr(loads[target.load], target.key))
            if target.component is None:
                fields[target.key] = values[:, j].copy()
            else:
                fields[target.key] = _set_vector(current, target.component, values[:, j],
                                                 target.path)
        for index, fields in changes.items():
            try:
                loads[index] = loads[index].replace(**fields)
            except (TypeError, ValueError) as error:
                raise ValueError(f"load[{index + 1}]: {error}") from None
        return tuple(loads)

    def check(self) -> None:
        """ValueError naming the key path if a parameter value cannot be applied, before any
        solve: each parameter's values (for a sampled design its extremes and up to 256
        quantiles) are built with the other parameters at the first case's values, and the
        loads checked against the arm. A combination that is invalid only together with
        other values is recorded per case (status 2) instead."""
        first = self.design.values(0, 1)[0]
        sampled = self.design.kind in ("latin-hypercube", "sobol")
        every = self.design.values() if sampled else None
        for j, (p, target) in enumerate(zip(self.design.parameters, self.targets,
                                            strict=True)):
            distinct = np.unique(every[:, j]) if sampled else np.unique(p.grid_values())
            if distinct.size > 256 + 2:
                distinct = np.unique(np.quantile(distinct, np.linspace(0.0, 1.0, 258)))
            trial = np.repeat(first[None, :], distinct.size, axis=0)
            trial[:, j] = distinct
            for group in self.groups(trial):
                error = group.error
                if not error:
                    try:
                        for load in group.loads:
                            load.check(group.arm)
                    except (ValueError, TypeError) as e:
                        error = str(e)
                if error:
                    bad = float(trial[group.rows[0], j])
                    raise ValueError(f"sweep: {target.path} = {bad!r}: "
                                     f"{error.removeprefix(target.path + ': ')}")

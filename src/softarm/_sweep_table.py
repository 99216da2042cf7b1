"""The plain data of a case file's ``[sweep]`` table (public names in :mod:`softarm.sweep`).

- :class:`Sweep`: a one-parameter sweep of one load's vector (``load``, ``field``,
  ``component`` and the values), which :attr:`softarm.case.Case.batched_loads` applies;
- :class:`Design`: any number of :class:`Parameter` s, each named by a key path of the case
  file, combined on a grid, as a list, a Latin hypercube or a Sobol sequence.

Each is checked on construction and knows its own values; what the values mean for a case
(key paths resolved in the file's tables: :mod:`softarm._keypath`) and how the cases are
solved, chunked and stored (:mod:`softarm.sweep`) is decided above this module, which
imports nothing of softarm but the loads.

Examples
--------
>>> from softarm import TipLoad
>>> sweep = Sweep(load=0, kind="tip", field="moment", component="y", values=(0.0, 1.0, 2.0))
>>> sweep.apply([TipLoad(moment=[0.0, 5.0, 0.0])])[0].moment
array([[0., 0., 0.],
       [0., 1., 0.],
       [0., 2., 0.]])
>>> sweep.column
'tip_moment_y_Nm'
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field, replace
from numbers import Integral, Real

import numpy as np

from .loads import LOAD_KINDS, as_loads

__all__ = ["COMPONENTS", "DESIGNS", "KEY_PATH", "Design", "Parameter", "Sweep", "set_vector"]

#: The values of ``design`` in a ``[sweep]`` table.
DESIGNS = ("grid", "list", "latin-hypercube", "sobol")

#: A key path: ``load[i].key[.component]``, ``segment[i].key...`` or ``arm.key...`` (tables
#: counted from 1; groups: the table kind, its number, "arm", the rest).
KEY_PATH = re.compile(r"(?:(load|segment)\[(\d+)\]|(arm))\.(\w+(?:\.\w+)*)")

#: The values of ``component`` in a ``[sweep]`` table.
COMPONENTS = ("magnitude", "x", "y", "z")


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
        stack = set_vector(getattr(target, self.field), self.component,
                           np.asarray(self.values, dtype=np.float64),
                           f"sweep: load {self.load + 1}'s {self.field}")
        swept = replace(target, **{self.field: stack})
        return (*loads[: self.load], swept, *loads[self.load + 1:])


def set_vector(vector: np.ndarray, component: str, values: np.ndarray, path: str
               ) -> np.ndarray:
    """``vector`` (..., 3) with ``component`` (one of :data:`COMPONENTS`) set to ``values``
    (...,): a coordinate, or the length along the vector's direction (ValueError naming
    ``path`` if it is zero). A case file's key path and a ``[sweep]`` both use it."""
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
        if not isinstance(self.path, str) or KEY_PATH.fullmatch(self.path) is None:
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

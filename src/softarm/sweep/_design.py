"""A design's cases, built: the plan that turns a chunk of design points into batched solves
(private; the public names are in :mod:`softarm.sweep`).

A design's values are applied to the case in two ways, both generic:

- a load field that the load class accepts with a leading batch axis (every vector field,
  and number fields of kinds that batch them) is set for a whole group of cases at once;
- anything else (arm parameters, a number a load cannot batch, e.g. a point load's ``s``) is
  written into a copy of the case file's tables (:func:`softarm._keypath.set_value`), which
  the case reader then checks and builds: cases are grouped by these values, one arm (one
  prepared solver) per group.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from .._keypath import Target, resolve, set_value
from .._sweep_table import Design, set_vector
from ..case import Case, parse_case
from ..errors import CaseError

__all__ = ["Group", "Plan"]


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
    design : softarm.sweep.Design
    """

    def __init__(self, case: Case, design: Design):
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
                fields[target.key] = set_vector(current, target.component, values[:, j],
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

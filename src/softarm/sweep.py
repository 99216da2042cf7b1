"""Sweeps (public): one load parameter in memory, or designs over any parameters at scale.

- A :class:`Sweep` describes a one-parameter ``[sweep]`` table of a case file;
  :func:`solve_case` solves a :class:`softarm.case.Case`, every step of its sweep if it has
  one, in batched calls of ``softarm.solve``, in chunks that report progress on long sweeps.
- A :class:`Design` varies any number of :class:`Parameter` s, each named by a key path of
  the case file (``load[2].force.magnitude``, ``segment[1].section.radius``, ...), on a grid,
  a list, a Latin hypercube or a Sobol sequence; :func:`run` solves it in chunks with any
  map-like executor (in-process, a process pool, a Dask client), into a resumable Zarr store
  that :func:`open_sweep` reads as an xarray Dataset (``pip install 'softarm[sweep]'``).

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

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ._sweep_design import DESIGNS, Design, Parameter
from ._sweep_run import FIELDS, design_of, open_sweep, process_pool, run, solve_chunk
from ._validate import check_allocation
from .equilibrium import Equilibrium, Stability
from .loads import LOAD_KINDS, as_loads

if TYPE_CHECKING:
    from .case import Case

__all__ = ["DESIGNS", "FIELDS", "Design", "Parameter", "Sweep", "design_of", "open_sweep",
           "process_pool", "run", "solve_case", "solve_chunk"]


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
        base = np.asarray(getattr(target, self.field), dtype=np.float64)
        values = np.asarray(self.values, dtype=np.float64)
        if self.component == "magnitude":
            direction = base / np.max(np.abs(base))  # scaled first: |v|² may overflow
            stack = values[:, None] * (direction / np.linalg.norm(direction))
        else:
            stack = np.repeat(base[None, :], values.size, axis=0)
            stack[:, "xyz".index(self.component)] = values
        swept = replace(target, **{self.field: stack})
        return (*loads[: self.load], swept, *loads[self.load + 1:])



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
    if getattr(case, "design", None) is not None:
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
    if options.branch == "stable":
        parts = []
        for k in range(len(case.sweep.values)):
            parts.append(_batched(solve(case.arm, _take(loads, k, k + 1), **kwargs)))
            if progress is not None:
                progress(k + 1, len(case.sweep.values))
        return _concatenate(parts, loads)
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


def _batched(eq: Equilibrium) -> Equilibrium:
    """A single case as a batch of one (branch='stable' solves one case at a time)."""
    if eq.batch_shape:
        return eq
    verdict = eq.stability
    if verdict is not None:
        verdict = Stability.of(np.array([verdict.index]), np.array([verdict.conservative]),
                                 (1,))
    return replace(eq, poses=eq.poses[None], strains=eq.strains[None],
                   stresses=eq.stresses[None], residual=np.array([eq.residual]),
                   error_estimate=np.array([eq.error_estimate]), stability=verdict,
                   tip_compliance=None, compliance=None, base_wrench=None,
                   tendon_tensions=None, tendon_lengths=None, tendon_length_changes=None,
                   tendon_slack=None)


def _take(loads: tuple, start: int, stop: int) -> tuple:
    """Cases start..stop-1 of the batched loads (unbatched loads as they are)."""
    return tuple(load.take(slice(start, stop)) if load.batch_shape else load for load in loads)


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
    stability = None
    if all(p.stability is not None for p in parts):
        stability = Stability.of(
            np.concatenate([np.atleast_1d(p.stability.index) for p in parts]),
            np.concatenate([np.broadcast_to(p.stability.conservative, p.batch_shape)
                            for p in parts]), (sum(p.batch_shape[0] for p in parts),))
    return Equilibrium(
        s=first.s,
        poses=fields("poses"),
        strains=fields("strains"),
        stresses=fields("stresses"),
        arm=first.arm, loads=loads, method="+".join(methods),
        exact=all(bool(p.exact) for p in parts),
        residual=cat("residual"), error_estimate=cat("error_estimate"), stability=stability)


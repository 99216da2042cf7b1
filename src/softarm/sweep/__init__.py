"""Sweeps (public): one load parameter in memory, or designs over any parameters at scale.

- A :class:`Sweep` describes a one-parameter ``[sweep]`` table of a case file;
  :func:`solve_case` solves a :class:`softarm.case.Case`, every step of its sweep if it has
  one, in batched calls of ``softarm.solve``, in chunks that report progress on long sweeps.
- A :class:`Design` varies any number of :class:`Parameter` s, each named by a key path of
  the case file (``load[2].force.magnitude``, ``segment[1].section.radius``, ...), on a grid,
  a list, a Latin hypercube or a Sobol sequence; :func:`run` solves it in chunks with any
  map-like executor (in-process, a process pool, a Dask client), into a resumable Zarr store
  that :func:`open_sweep` reads as an xarray Dataset (``pip install 'softarm[sweep]'``).

This package sits above :mod:`softarm.case`: the case reader knows a ``[sweep]`` table only as
plain data (:class:`Sweep`, :class:`Design`, defined in :mod:`softarm._sweep_table`); building
a design's cases (``_design``), solving them in chunks (``_run``) and the store (``_store``)
are here. :func:`solve_case` is :mod:`softarm.case`'s, re-exported. (An example of a
:class:`Sweep`: :mod:`softarm._sweep_table`.)
"""

from .._sweep_table import COMPONENTS, DESIGNS, Design, Parameter, Sweep
from ..case import solve_case
from ._run import design_of, process_pool, run, solve_chunk
from ._store import FIELDS, open_sweep

__all__ = ["COMPONENTS", "DESIGNS", "FIELDS", "Design", "Parameter", "Sweep", "design_of",
           "open_sweep", "process_pool", "run", "solve_case", "solve_chunk"]

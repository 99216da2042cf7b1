"""A sweep's Zarr store: its layout, the chunks workers write, and resuming it (private; the
public names are in :mod:`softarm.sweep`).

The layout and metadata are xarray's (:func:`create_store`, ``zarr_format=2``); each data
variable is chunked along ``case`` exactly as the sweep's chunks of cases, so that a worker
writes its own files and no two writers touch the same one; a chunk's done flag is written
last (:func:`write_chunk`), so a chunk killed while being written is solved again on resume
(:func:`prepare_store`).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .. import __version__

if TYPE_CHECKING:
    from ._design import Plan
    from ._run import Spec, Task

__all__ = ["FIELDS", "create_store", "open_sweep", "prepare_store", "recorded_options",
           "write_chunk"]

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


def need_store_packages():
    try:
        import xarray
        import zarr
    except ImportError as error:
        raise ImportError(f"sweeps to a Zarr store need xarray and zarr ({error.name} is "
                          "missing): pip install 'softarm[sweep]'") from None
    return xarray, zarr


def allocate(spec: Spec, count: int) -> dict:
    S = spec.stations
    shapes = {"tip_position": (3,), "tip_orientation": (4,), "positions": (S, 3),
              "orientations": (S, 4), "strains": (S, 6), "stresses": (S, 6)}
    data = {name: np.full((count, *shapes[name]), np.nan, dtype=spec.dtype)
            for name in variables(spec.fields)}
    data["status"] = np.full(count, NOT_COMPUTED, dtype=np.int8)
    data["message"] = np.full(count, "", dtype=f"<U{MESSAGE_WIDTH}")
    for name in ("residual", "error_estimate", "length"):
        data[name] = np.full(count, np.nan)
    return data


def variables(fields) -> list[str]:
    names: list[str] = []
    for f in fields:
        names += [n for n in FIELDS[f] if n not in names]
    return names


def dataset_coords(spec: Spec, plan: Plan, values: np.ndarray) -> dict:
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


def dataset_attrs(spec: Spec, text: str) -> dict:
    """The store's attributes: ``text`` the case file's text, then the design and options."""
    return {"softarm_version": __version__, "case": text,
            "case_json": json.dumps(spec.case_data, default=str),
            "case_source": spec.source or "",
            "design": json.dumps(spec.design.to_dict()), "method": spec.method,
            "tol": spec.tol, "stations": spec.stations, "fields": ",".join(spec.fields),
            "dtype": spec.dtype, "chunk_size": spec.chunk,
            "semantics": _PATH if spec.chained else _FROM_UNLOADED,
            "sweep_fingerprint": spec.key}


def variable_attrs(name: str) -> dict:
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


def dims(name: str) -> tuple[str, ...]:
    if name in _VARIABLES:
        return ("case", *_VARIABLES[name][0])
    return ("chunk",) if name == "chunk_done" else ("case",)


def create_store(spec: Spec, plan: Plan, text: str) -> None:
    """The store's layout: coordinates and attributes through xarray, then each data
    variable as an empty Zarr array (nothing is allocated; chunks are written by workers)."""
    xarray, zarr = need_store_packages()
    values = spec.design.values()
    size = len(values)
    header = xarray.Dataset(coords=dataset_coords(spec, plan, values),
                            attrs=dataset_attrs(spec, text))
    big = min(size, 1 << 20)
    encoding = {p.path: {"chunks": (big,)} for p in spec.design.parameters}
    encoding["case"] = {"chunks": (big,)}
    header.to_zarr(spec.out, mode="w-", zarr_format=2, consolidated=False, encoding=encoding)
    group = zarr.open_group(spec.out, mode="r+")
    template = allocate(spec, 1)
    chunks = math.ceil(size / spec.chunk)
    for name, array in [*template.items(), ("chunk_done", np.zeros(1, np.uint8))]:
        if name == "chunk_done":
            shape, chunk_shape, fill = (chunks,), (1,), 0
        else:
            shape, chunk_shape = (size, *array.shape[1:]), (spec.chunk, *array.shape[1:])
            fill = {"status": NOT_COMPUTED, "message": ""}.get(name, np.nan)
        attrs = {"_ARRAY_DIMENSIONS": list(dims(name)), **variable_attrs(name)}
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


def write_chunk(spec: Spec, task: Task, data: dict) -> None:
    """The chunk's region of every variable, then its done flag (last: a chunk killed while
    being written has no flag and is solved again on resume).

    The layout and metadata are xarray's (:func:`create_store`); the chunks are written
    with zarr directly, through arrays opened once per process: an xarray region write
    re-reads the group's metadata each time (about 50 ms a chunk, benchmarks/sweep_scaling.py),
    a zarr write of an aligned chunk is one file per variable."""
    arrays = open_arrays(spec)
    region = slice(task.start, task.stop)
    for name, array in data.items():
        if name != "status":
            arrays[name][region] = array
    arrays["status"][region] = data["status"]
    arrays["chunk_done"][task.index:task.index + 1] = np.ones(1, np.uint8)


_ARRAYS: dict = {}  # (store, fingerprint) -> {name: zarr array}; one per process


def open_arrays(spec: Spec) -> dict:
    key = (spec.out, spec.key)
    if key not in _ARRAYS:
        _, zarr = need_store_packages()
        _ARRAYS.clear()
        group = zarr.open_group(spec.out, mode="r+")
        names = [*allocate(spec, 0), "chunk_done"]
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
    xarray, _ = need_store_packages()
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


def case_text(case) -> str:
    if case.source is not None:
        try:
            return Path(case.source).read_text(encoding="utf-8")
        except OSError:
            pass
    return json.dumps(case.to_dict(), default=str)


#: The options a store records (its attributes) and the names :func:`softarm.sweep.run` gives
#: them; the case and the design make the rest of its fingerprint.
_OPTIONS = {"chunk": "chunk_size", "fields": "fields", "stations": "stations",
            "dtype": "dtype", "method": "method", "tol": "tol", "path": "semantics"}
_FINGERPRINT = {"case": "case_json", "design": "design", **_OPTIONS}


def _existing(out: Path):
    try:
        return open_sweep(out)
    except Exception as error:  # whatever xarray or zarr find wrong: one line
        raise ValueError(f"{out}: not a sweep store softarm can resume ({error})") from None


def recorded_options(out) -> dict | None:
    """The options the store at ``out`` was started with, by :func:`softarm.sweep.run`'s
    names (``path`` a bool), or None if there is nothing at ``out``."""
    out = Path(out)
    if not out.exists():
        return None
    attrs = _existing(out).attrs
    try:
        return {"chunk": int(attrs["chunk_size"]), "fields": tuple(attrs["fields"].split(",")),
                "stations": int(attrs["stations"]), "dtype": str(attrs["dtype"]),
                "method": str(attrs["method"]), "tol": float(attrs["tol"]),
                "path": attrs["semantics"] == _PATH}
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise ValueError(f"{out}: not a sweep store softarm can resume (its attribute "
                         f"{error} is missing or wrong)") from None


def _listing(names: list[str]) -> str:
    """The names in words: a; a and b; a, b and c."""
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"


def prepare_store(spec: Spec, plan: Plan, case, resume: bool, chunks: int, where) -> list[int]:
    """The chunks left to solve: every one for a new store (created here), those without
    their done flag for a store resumed. ``where``: the store's path as the caller gave it
    (for messages; ``spec.out`` is absolute)."""
    out, where = Path(spec.out), Path(where)
    if out.exists():
        if not resume:
            raise ValueError(f"{where}: exists; give --resume (resume=True) to finish an "
                             "interrupted sweep, or remove it or choose another output")
        store = _existing(where)
        if store.attrs.get("sweep_fingerprint") != spec.key:
            mine = dataset_attrs(spec, "")
            differ = [name for name, key in _FINGERPRINT.items()
                      if str(store.attrs.get(key)) != str(mine[key])] or ["softarm version"]
            raise ValueError(f"{where}: holds another sweep (its {_listing(differ)} "
                             f"{'differs' if len(differ) == 1 else 'differ'}); resume with the "
                             "case it was started with, or choose another output")
        done = np.asarray(store["chunk_done"].values)
        return [k for k in range(chunks) if not done[k]]
    if not out.parent.is_dir():
        raise ValueError(f"{where}: folder {out.parent} does not exist")
    create_store(spec, plan, case_text(case))
    return list(range(chunks))

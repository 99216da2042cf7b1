"""Result files: an :class:`~softarm.Equilibrium` out to CSV, JSON or NPZ, and back.

:func:`save_result` writes an equilibrium as one row per station (and per sweep step), with the
case it came from embedded; :func:`load_result` and :func:`load_saved` read any of the three
formats back. Outputs are written through :func:`write_atomic`: to a temporary file beside the
target, then renamed, so a failure never leaves a half-written file. Case files are
:mod:`softarm.case`.
"""

from __future__ import annotations

import csv
import io as _stdio
import json
import math
import os
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import __version__
from ._files import write_atomic
from ._schema import arm_to_dict, contact_to_dict, loads_to_dict
from .case import Case, CaseError, _parse
from .contact import Contact
from .dynamics import Energy
from .dynamics._results import Trajectories
from .equilibrium import Equilibrium, Stability
from .lie import se3, so3

__all__ = [
    "COLUMNS",
    "FORMATS",
    "TRAJECTORY_ARRAYS",
    "TRAJECTORY_COLUMNS",
    "TRAJECTORY_FORMATS",
    "SavedResult",
    "SavedTrajectory",
    "TrajectoryStore",
    "load_result",
    "load_saved",
    "read_trajectory",
    "save_result",
    "save_trajectory",
    "write_atomic",
]

#: Result columns, one row per station: name (unit in the name), in file order. Rotations are
#: given twice: the rotation vector (axis × angle, rad) and the unit quaternion in the order
#: (w, x, y, z), scalar first, w >= 0. Strain and stress components are in the material frame
#: (1 = axis e1, 2 = e2, 3 = e3); positions and rotations in the spatial (base) frame.
COLUMNS = (
    "s_m",
    "x_m", "y_m", "z_m",
    "rotvec_x_rad", "rotvec_y_rad", "rotvec_z_rad",
    "quat_w", "quat_x", "quat_y", "quat_z",
    "gamma_1", "gamma_2", "gamma_3",
    "kappa_1_per_m", "kappa_2_per_m", "kappa_3_per_m",
    "n_1_N", "n_2_N", "n_3_N",
    "m_1_Nm", "m_2_Nm", "m_3_Nm",
)

_ROTATION_NOTE = (
    "rotation of the material frame R(s) (columns e1 e2 e3 in the base frame): rotation "
    "vector rotvec_* in rad and unit quaternion in the order (w, x, y, z), scalar first; "
    "strains gamma/kappa and stresses n/m in material components (1 = arm axis e1)"
)


def _stack(columns: dict, names) -> np.ndarray:
    """The named columns as the components of a vector (last axis)."""
    return np.stack([columns[n] for n in names], axis=-1)


def _table(result: Equilibrium) -> np.ndarray:
    """The per-station columns of :data:`COLUMNS`, shape (B..., N, 23)."""
    rotvec, quat = so3.log(result.rotations), so3.to_quaternion(result.rotations)
    s = np.broadcast_to(result.s, result.poses.shape[:-2])[..., None]
    return np.concatenate([s, result.positions, rotvec, quat, result.strains,
                           result.stresses], axis=-1)


def _case_dict(result: Equilibrium, case: Case | None) -> dict:
    if case is not None:
        return case.to_dict()
    return {"name": "result", **arm_to_dict(result.arm), "load": loads_to_dict(result.loads),
            **contact_to_dict(result.loads)}


def _sweep_values(result: Equilibrium, case: Case | None):
    if case is None or case.sweep is None:
        return None
    values = np.asarray(case.sweep.values, dtype=float)
    if result.batch_shape != values.shape:
        raise ValueError(f"result has batch shape {result.batch_shape} but the case's sweep "
                         f"has {values.size} steps")
    return values


def _meta(result: Equilibrium, case: Case | None) -> dict:
    sweep = case.sweep if case is not None else None
    return {
        "softarm_version": __version__,
        "name": case.name if case is not None else "result",
        "method": result.method,
        "exact": bool(result.exact),
        "batch_shape": list(result.batch_shape),
        "stations": int(result.s.size),
        "sweep_column": sweep.column if sweep is not None else None,
        "sweep_label": sweep.label if sweep is not None else None,
        "stability": _verdict(result.stability),
        "rotation": _ROTATION_NOTE,
        "case": _case_dict(result, case),
        "contact": _contact_law(result.loads),
        # the solver's exact total (Equilibrium.contact_wrench): the stations saved may not
        # resolve a contact zone, so it is not recomputed from them when read back
        "contact_wrench": None if result.contact_resultant is None else
        np.asarray(result.contact_resultant).tolist(),
    }


def _contact_law(loads) -> dict | None:
    """The contact law the solver used (``stiffness`` N/m², ``distance`` m) of the
    :class:`softarm.Contact` among ``loads``, or None: a result read back draws the contact
    forces of that law (its case may leave them to the solver)."""
    for load in loads:
        if isinstance(load, Contact) and load.stiffness is not None:
            return {"stiffness": np.asarray(load.stiffness).tolist(),
                    "distance": load.distance}
    return None


def _with_contact_law(loads: tuple, law, path, kind: str = "softarm result file") -> tuple:
    """``loads`` with the Contact's law set to ``law`` (:func:`_contact_law`'s, read from the
    file ``path``, a ``kind``: CaseError if it is not one)."""
    if law is None:
        return loads
    try:
        if not (isinstance(law, dict) and set(law) == {"stiffness", "distance"}):
            raise ValueError(f"must be an object with stiffness and distance, got {law!r}")
        return tuple(load.replace(**law) if isinstance(load, Contact) else load
                     for load in loads)
    except (TypeError, ValueError) as error:
        raise CaseError(f"{path}: not a {kind} ('contact' {_brief(error)})") from None


def _saved_contact_wrench(value, batch, path) -> np.ndarray | None:
    """The saved Equilibrium.contact_wrench (``batch`` + (6,)), or None if none was saved
    (CaseError if it is not one)."""
    if value is None:
        return None
    try:
        wrench = _numbers(value, "contact_wrench")
        if wrench.size != 6 * math.prod(batch):
            raise ValueError(f"{wrench.size} numbers for the batch shape {tuple(batch)}")
    except (TypeError, ValueError) as error:
        raise CaseError(f"{path}: not a softarm result file ('contact_wrench': "
                        f"{_brief(error)})") from None
    return wrench.reshape(*batch, 6)


def _verdict(stability: Stability | None) -> dict | None:
    """The stability verdict as plain JSON: the Morse index and the conservative flag, each a
    number or a nested list of the batch shape (the verdict is derived from them)."""
    if stability is None:
        return None
    return {"index": np.asarray(stability.index).tolist(),
            "conservative": np.asarray(stability.conservative).tolist()}


#: File suffixes that save_result writes and load_result reads.
FORMATS = (".csv", ".json", ".npz")


def save_result(result: Equilibrium, path: str | os.PathLike, case: Case | None = None) -> Path:
    """Write an equilibrium to ``path``; the suffix chooses the format.

    ``.csv``: five ``#`` comment lines (softarm version and case name; method, residual and
    stability verdict; the rotation convention; the metadata and the case as one line of JSON
    each), then a header line of :data:`COLUMNS` (a first column for the swept parameter, or
    ``batch_index`` for another batch) and one row per station (per step, step-major).
    ``.json`` and ``.npz``: the same columns as arrays of shape (B..., N), the poses,
    residuals, the case as a dict and the softarm version. Every format carries the stability
    verdict (``stability``: the Morse index and the conservative flag per case, or null), so
    a result read back is drawn with it.

    Parameters
    ----------
    result : Equilibrium
    path : str or path-like
        Ending in ``.csv``, ``.json`` or ``.npz``.
    case : Case, optional
        Embedded in the file (and names the sweep column); without it the arm and loads of
        ``result`` are embedded.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    if not isinstance(result, Equilibrium):
        raise TypeError(f"result must be a softarm.Equilibrium, got {type(result).__name__}")
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"{path}: unknown output format {path.suffix!r}; use one of "
                         f"{', '.join(FORMATS)}")
    meta = _meta(result, case)
    table = _table(result)
    sweep = _sweep_values(result, case)
    residual = np.broadcast_to(np.asarray(result.residual, float), result.batch_shape)
    estimate = np.broadcast_to(np.asarray(result.error_estimate, float), result.batch_shape)
    if suffix == ".csv":
        text = _csv_text(result, table, meta, sweep, residual, estimate)
        with write_atomic(path, "w") as stream:
            stream.write(text)
    elif suffix == ".json":
        document = {**meta, "residual": residual.tolist(), "error_estimate": estimate.tolist(),
                    "sweep_values": sweep.tolist() if sweep is not None else None,
                    "columns": {name: table[..., i].tolist() for i, name in enumerate(COLUMNS)},
                    "poses": result.poses.tolist()}
        with write_atomic(path, "w") as stream:
            json.dump(document, stream, indent=1, allow_nan=True)
            stream.write("\n")
    else:
        arrays = {name: table[..., i] for i, name in enumerate(COLUMNS)}
        arrays.update(poses=result.poses, strains=result.strains, stresses=result.stresses,
                      residual=residual, error_estimate=estimate,
                      meta=np.array(json.dumps(meta)))
        if sweep is not None:
            arrays["sweep_values"] = sweep
        with write_atomic(path, "wb") as stream:
            np.savez(stream, **arrays)
    return path


def _csv_text(result, table, meta, sweep, residual, estimate) -> str:
    buffer = _stdio.StringIO()
    buffer.write(f"# softarm {meta['softarm_version']} equilibrium: {meta['name']}\n")
    verdict = "" if result.stability is None or result.batch_shape else \
        f"; stability: {result.stability.describe()}"  # a batch's: in the '# meta:' line
    buffer.write(f"# method: {meta['method']}; exact: {str(meta['exact']).lower()}; residual "
                 f"(N, N m): max {float(np.max(residual)):.3e}{verdict}\n")
    buffer.write(f"# {meta['rotation']}\n")
    line = {k: v for k, v in meta.items() if k not in ("rotation", "case")}
    line.update(residual=residual.tolist(), error_estimate=estimate.tolist())
    buffer.write("# meta: " + json.dumps(line) + "\n")
    buffer.write("# case: " + json.dumps(meta["case"]) + "\n")
    n = result.s.size
    rows = table.reshape(-1, len(COLUMNS))
    header = list(COLUMNS)
    if result.batch_shape:
        steps = int(np.prod(result.batch_shape))
        if sweep is not None:
            header.insert(0, meta["sweep_column"])
            lead = np.repeat(sweep, n)
        else:
            header.insert(0, "batch_index")
            lead = np.repeat(np.arange(steps, dtype=float), n)
        rows = np.concatenate([lead[:, None], rows], axis=1)
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow([repr(float(v)) for v in row])
    return buffer.getvalue()


@dataclass(frozen=True, eq=False)
class SavedResult:
    """A result file read back: the equilibrium, the case it embeds and file facts.

    Attributes
    ----------
    result : Equilibrium
    case : Case or None
        The embedded case (every file written by :func:`save_result` carries one).
    version : str
        softarm version that wrote the file.
    sweep_values : ndarray or None
        The swept parameter per step.
    sweep_label : str or None
        Its label with unit.
    path : pathlib.Path
    """

    result: Equilibrium
    case: Case | None
    version: str
    sweep_values: np.ndarray | None
    sweep_label: str | None
    path: Path


def load_result(path: str | os.PathLike) -> Equilibrium:
    """Read a result written by :func:`save_result` (CSV, JSON or NPZ) as an Equilibrium."""
    return load_saved(path).result


def _existing(path, formats, what: str) -> tuple[Path, str]:
    """(the path, its lower-case suffix) of an existing file of one of ``formats``, else a
    CaseError naming the file."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in formats:
        raise CaseError(f"{path}: unknown {what} format {path.suffix!r}; expected one of "
                        f"{', '.join(formats)}")
    if not path.exists():
        raise CaseError(f"{path}: no such file")
    return path, suffix


def load_saved(path: str | os.PathLike) -> SavedResult:
    """Read a result file with its embedded case and metadata (see :class:`SavedResult`).

    Raises
    ------
    CaseError
        If the file is missing, of an unknown format or not a softarm result.
    """
    path, suffix = _existing(path, FORMATS, "result")
    if path.is_dir():
        raise CaseError(f"{path}: is a folder, not a result file")
    try:
        if suffix == ".json":
            document = json.loads(path.read_text(encoding="utf-8"))
            if not isinstance(document, dict):
                raise CaseError(f"{path}: not a softarm result file (not a JSON object)")
            meta = document
            columns = {k: _numbers(v, k) for k, v in document["columns"].items()}
            poses = _numbers(document["poses"], "poses")
            residual = _numbers(document["residual"], "residual")
            estimate = _numbers(document["error_estimate"], "error_estimate")
            sweep = document.get("sweep_values")
            sweep = None if sweep is None else _numbers(sweep, "sweep_values")
        elif suffix == ".npz":
            if not zipfile.is_zipfile(path):
                raise CaseError(f"{path}: not a softarm result file (not an NPZ archive, or "
                                "truncated)")
            with np.load(path, allow_pickle=False) as data:
                meta = json.loads(str(data["meta"]))
                columns = {k: data[k] for k in COLUMNS}
                poses = data["poses"]
                residual, estimate = data["residual"], data["error_estimate"]
                sweep = data["sweep_values"] if "sweep_values" in data.files else None
        else:
            meta, columns, poses, residual, estimate, sweep = _read_csv(path)
    except (CaseError, MemoryError):
        raise
    except KeyError as error:
        raise CaseError(f"{path}: not a softarm result file (no {error} entry)") from None
    except Exception as error:  # any failure to parse: truncated or garbage files included
        raise CaseError(f"{path}: not a softarm result file ({type(error).__name__}: "
                        f"{_brief(error)})") from None
    batch = _check_saved(path, meta, columns, poses, residual, estimate, sweep)
    case = None
    if meta.get("case"):
        try:
            case = _parse(meta["case"], path, batched=True)
        except CaseError as error:
            raise CaseError(f"{path}: embedded case: {error}") from None
    s = columns["s_m"].reshape(-1, columns["s_m"].shape[-1])[0]
    strains = _stack(columns, COLUMNS[11:17])
    stresses = _stack(columns, COLUMNS[17:23])
    if case is None:  # pragma: no cover - every file written by save_result embeds its case
        raise CaseError(f"{path}: the file carries no case (arm and loads)")
    verdict = meta.get("stability")
    result = Equilibrium(
        s=s, poses=poses.reshape(*batch, s.size, 4, 4),
        strains=strains.reshape(*batch, s.size, 6), stresses=stresses.reshape(*batch, s.size, 6),
        arm=case.arm, loads=_with_contact_law(case.batched_loads, meta.get("contact"), path),
        method=meta["method"], exact=meta["exact"],
        residual=residual.reshape(batch) if batch else float(residual),
        error_estimate=estimate.reshape(batch) if batch else float(estimate),
        stability=None if verdict is None else Stability.of(verdict["index"],
                                                            verdict["conservative"], batch),
        contact_resultant=_saved_contact_wrench(meta.get("contact_wrench"), batch, path))
    sweep = None if sweep is None else np.asarray(sweep, dtype=float)
    return SavedResult(result, case, str(meta.get("softarm_version", "")), sweep,
                       meta.get("sweep_label"), path)


def _brief(error: BaseException, limit: int = 120) -> str:
    """An exception's message on one line, cut to ``limit`` characters."""
    text = " ".join(str(error).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _numbers(value, name: str) -> np.ndarray:
    """A JSON value as a float array: numbers (and null for NaN) only, never strings or bools."""
    def ok(v):
        if isinstance(v, list):
            return all(ok(x) for x in v)
        return v is None or (isinstance(v, (int, float)) and not isinstance(v, bool))

    if not ok(value):
        raise ValueError(f"{name!r} must hold numbers only")
    return np.asarray(value, dtype=float)


def _check_saved(path: Path, meta, columns, poses, residual, estimate, sweep) -> tuple:
    """Every field of a result file checked: types, shapes, finiteness, rigid poses.

    Returns the batch shape; CaseError naming the file and the field otherwise.
    """
    def fail(what: str) -> CaseError:
        return CaseError(f"{path}: not a valid softarm result: {what}")

    if not isinstance(meta, dict):
        raise fail("the metadata is not an object")
    if not isinstance(meta.get("method"), str):
        raise fail(f"'method' must be a string, got {meta.get('method')!r}")
    if not isinstance(meta.get("exact"), bool):
        raise fail(f"'exact' must be true or false, got {meta.get('exact')!r}")
    shape = meta.get("batch_shape", [])
    if not (isinstance(shape, list) and all(isinstance(b, int) and not isinstance(b, bool)
                                            and b >= 0 for b in shape)):
        raise fail(f"'batch_shape' must be a list of integers >= 0, got {shape!r}")
    n = meta.get("stations")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise fail(f"'stations' must be an integer >= 1, got {n!r}")
    batch = tuple(shape)
    expected = (*batch, n)
    for name in COLUMNS:
        column = np.asarray(columns[name])
        if column.dtype.kind not in "fiu":
            raise fail(f"column {name!r} holds {column.dtype} values, not numbers")
        if column.shape != expected:
            raise fail(f"column {name!r} has shape {column.shape}, expected {expected} "
                       f"(batch {batch}, {n} stations)")
        bad = np.flatnonzero(~np.isfinite(column).reshape(-1))
        if bad.size:
            index = np.unravel_index(int(bad[0]), expected)
            raise fail(f"column {name!r} is not finite at index {tuple(map(int, index))}")
    s = np.asarray(columns["s_m"]).reshape(-1, n)
    if np.any(np.diff(s, axis=-1) <= 0) or np.any(s != s[:1]):
        raise fail("column 's_m' must be the same strictly increasing stations for every case")
    poses = np.asarray(poses)
    if poses.shape != (*expected, 4, 4):
        raise fail(f"'poses' has shape {poses.shape}, expected {(*expected, 4, 4)}")
    if not np.all(np.isfinite(poses)):
        raise fail("'poses' is not finite")
    R = poses[..., :3, :3]
    deviation = np.max(np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)), initial=0.0)
    if deviation > 1e-6 or not np.allclose(poses[..., 3, :], [0.0, 0.0, 0.0, 1.0], atol=1e-12,
                                           rtol=0.0):
        raise fail(f"'poses' are not rigid transforms (RᵀR − I up to {deviation:.1e})")
    positions = _stack(columns, ("x_m", "y_m", "z_m"))
    scale = max(1.0, float(np.max(np.abs(positions), initial=0.0)))
    if np.max(np.abs(positions - poses[..., :3, 3]), initial=0.0) > 1e-9 * scale:
        raise fail("columns x_m, y_m, z_m disagree with the positions in 'poses'")
    quat = _stack(columns, ("quat_w", "quat_x", "quat_y", "quat_z"))
    if np.max(np.abs(np.linalg.norm(quat, axis=-1) - 1.0), initial=0.0) > 1e-6:
        raise fail("columns quat_* are not unit quaternions")
    for name, values, finite in (("residual", residual, True),
                                 ("error_estimate", estimate, False)):
        values = np.asarray(values)
        if values.dtype.kind not in "fiu" or values.shape not in (batch, ()):
            raise fail(f"'{name}' must be numbers of shape {batch}, got shape {values.shape}")
        if finite and not np.all(np.isfinite(values)):
            raise fail(f"'{name}' is not finite")
        if not finite and np.any(np.isinf(values)):
            raise fail(f"'{name}' is infinite")
    if sweep is not None:
        sweep = np.asarray(sweep)
        if sweep.dtype.kind not in "fiu" or sweep.shape != batch[:1] or len(batch) != 1 \
                or not np.all(np.isfinite(sweep)):
            raise fail(f"'sweep_values' must be {batch[:1]} finite numbers, got shape "
                       f"{sweep.shape}")
    _check_verdict(meta.get("stability"), batch, fail)
    for key in ("softarm_version", "sweep_label", "sweep_column"):
        if meta.get(key) is not None and not isinstance(meta[key], str):
            raise fail(f"{key!r} must be a string, got {meta[key]!r}")
    return batch


def _check_verdict(verdict, batch: tuple, fail) -> None:
    """The ``stability`` entry: null (none computed, or a file of softarm 0.2) or the Morse
    indices (integers >= -1) and conservative flags (booleans), each of the batch shape."""
    if verdict is None:
        return
    if not (isinstance(verdict, dict) and set(verdict) == {"index", "conservative"}):
        raise fail("'stability' must be null or an object with 'index' and 'conservative'")
    for key, kind, valid in (("index", "integers >= -1",
                              lambda v: isinstance(v, int) and not isinstance(v, bool)
                              and v >= -1),
                             ("conservative", "booleans", lambda v: isinstance(v, bool))):
        values = np.asarray(verdict[key], dtype=object)
        if values.shape != batch or not all(valid(v) for v in values.flat):
            raise fail(f"'stability' {key!r} must be {kind} of shape {batch}")


def _csv_rows(path: Path, finite: bool = True) -> tuple[dict, list[str] | None,
                                                       list[list[float]]]:
    """(meta, header, rows) of a softarm CSV file: the ``# meta:`` and ``# case:`` lines,
    the first other line as the header, then rows of numbers, one per column, finite unless
    ``finite`` is False (a trajectory's failed cases are NaN) (CaseError naming the line
    otherwise)."""
    meta: dict = {}
    header = None
    rows = []
    with path.open(newline="", encoding="utf-8") as stream:
        for number, line in enumerate(stream, start=1):
            if line.startswith("# meta: "):
                meta.update(json.loads(line[len("# meta: "):]))
            elif line.startswith("# case: "):
                meta["case"] = json.loads(line[len("# case: "):])
            elif line.startswith("#") or not line.strip():
                continue
            elif header is None:
                header = next(csv.reader([line]))
            else:
                fields = next(csv.reader([line]))
                if len(fields) != len(header):
                    raise CaseError(f"{path}: line {number}: {len(fields)} values, expected "
                                    f"{len(header)} (one per column of the header)")
                try:
                    row = [float(v) for v in fields]
                except ValueError:
                    raise CaseError(f"{path}: line {number}: not a row of numbers") from None
                if finite and not all(math.isfinite(v) for v in row):
                    column = header[next(i for i, v in enumerate(row) if not math.isfinite(v))]
                    raise CaseError(f"{path}: line {number}: column {column!r} is not finite")
                rows.append(row)
    return meta, header, rows


def _read_csv(path: Path):
    meta, header, rows = _csv_rows(path)
    if header is None or "method" not in meta:
        raise CaseError(f"{path}: not a softarm result file (no '# meta:' line or header)")
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise CaseError(f"{path}: column {missing[0]!r} missing from the header")
    batch = tuple(meta.get("batch_shape", ()))
    n = meta.get("stations")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1 or not all(
            isinstance(b, int) and not isinstance(b, bool) and b >= 0 for b in batch):
        raise CaseError(f"{path}: not a valid softarm result: 'stations' {n!r} and "
                        f"'batch_shape' {list(batch)!r} must be integers")
    shape = (*batch, n)
    if len(rows) != math.prod(shape):
        raise CaseError(f"{path}: {len(rows)} rows, expected {math.prod(shape)} (batch "
                        f"{batch}, {n} stations)")
    table = np.asarray(rows, dtype=float).reshape(-1, len(header))
    columns = {c: table[:, header.index(c)].reshape(shape) for c in COLUMNS}
    positions = _stack(columns, ("x_m", "y_m", "z_m"))
    quat = _stack(columns, ("quat_w", "quat_x", "quat_y", "quat_z"))
    poses = se3.from_rotation_translation(so3.from_quaternion(quat), positions)
    sweep = None
    if batch and meta.get("sweep_column") in header:
        sweep = table[:, header.index(meta["sweep_column"])].reshape(shape)[..., 0]
    residual = np.asarray(meta.get("residual", np.nan), dtype=float)
    estimate = np.asarray(meta.get("error_estimate", np.nan), dtype=float)
    return meta, columns, poses, residual, estimate, sweep


# --------------------------------------------------------------------------------------------
# Trajectories (softarm simulate)
# --------------------------------------------------------------------------------------------

#: File suffixes that :func:`save_trajectory` writes and :func:`read_trajectory` reads.
TRAJECTORY_FORMATS = (".npz", ".zarr", ".csv")

#: A trajectory file's arrays: name -> (dimensions after the batch axes, unit, meaning).
#: ``.npz`` and ``.zarr`` hold them as they are (``.zarr``: the batch axis of a sweep is the
#: dimension ``case``); ``.csv`` holds them in long form (:data:`TRAJECTORY_COLUMNS`).
TRAJECTORY_ARRAYS = {
    "times": (("time",), "s", "time t"),
    "s": (("station",), "m", "arc length of the stations"),
    "positions": (("time", "station", "axis"), "m", "centreline position, spatial frame"),
    "rotations": (("time", "station", "row", "column"), "1",
                  "material frame R (columns e1 e2 e3 in the spatial frame)"),
    "velocities": (("time", "station", "axis"), "m/s", "centreline velocity, spatial frame"),
    "angular_velocities": (("time", "station", "axis"), "rad/s",
                           "angular velocity of the sections, spatial frame"),
    "strains": (("time", "station", "component"), "1 (gamma), 1/m (kappa)",
                "strains eps - eps0 (gamma1..3, kappa1..3), material frame"),
    "stresses": (("time", "station", "component"), "N (n), N m (m)",
                 "internal force and moment (n1..3, m1..3), material frame, viscous included"),
    "energy_kinetic": (("time",), "J", "kinetic energy"),
    "energy_elastic": (("time",), "J", "strain energy"),
    "energy_gravity": (("time",), "J", "potential energy of gravity"),
    "energy_dissipated": (("time",), "J", "work of the damping since t = 0 (cumulative)"),
    "errors": (("time",), "1", "each step's predictor-corrector distance relative to L"),
    "iterations": (("time",), "1", "Newton iterations of each step"),
    "tendon_lengths": (("time", "tendon"), "m", "each tendon's length along its path"),
}
_UNBATCHED = ("times", "s")
_ENERGIES = ("kinetic", "elastic", "gravity", "dissipated")

#: The ``.csv`` columns of a trajectory, one row per (case, time, station), case-major: a first
#: column for the swept parameter (or ``batch_index``) in a sweep, then these; the columns of
#: one time (energies, error, iterations, tendon lengths ``tendon_K_length_m``) repeat on each
#: of its stations' rows.
TRAJECTORY_COLUMNS = (
    "t_s", "s_m", "x_m", "y_m", "z_m", "quat_w", "quat_x", "quat_y", "quat_z",
    "v_x_m_per_s", "v_y_m_per_s", "v_z_m_per_s",
    "omega_x_rad_per_s", "omega_y_rad_per_s", "omega_z_rad_per_s",
    "gamma_1", "gamma_2", "gamma_3", "kappa_1_per_m", "kappa_2_per_m", "kappa_3_per_m",
    "n_1_N", "n_2_N", "n_3_N", "m_1_Nm", "m_2_Nm", "m_3_Nm",
    "kinetic_J", "elastic_J", "gravity_J", "dissipated_J", "step_error", "iterations",
)


@dataclass(frozen=True, eq=False)
class SavedTrajectory(Trajectories):
    """A trajectory file read back (:func:`read_trajectory`): the arrays of a
    :class:`softarm.Trajectory` under the same names and shapes (without ``final``: a file
    keeps no solver state to continue from), the case and what the file says of the run.

    Attributes
    ----------
    times, s, positions, rotations, velocities, angular_velocities, strains, stresses,
    energy, errors, iterations, tendon_lengths
        As :class:`softarm.Trajectory`'s (batch axes first).
    case : Case
        The case embedded in the file.
    complete : bool
        False if the run stopped early (Ctrl-C, a step that could not be solved): the file
        holds the steps done before.
    steps_requested : int
        ``duration / dt`` of the case's ``[simulate]`` table.
    reason : str
        Why the run stopped early ("" when complete).
    sweep_values : ndarray or None
        The swept parameter per case (batch shape (cases,)), with its ``sweep_label``.
    version : str
        softarm version that wrote the file.
    path : pathlib.Path
    contact : Contact or None
        The case's Contact with the law the steps used (its stiffness and distance, kept in
        the file), for ``gaps``, ``contact_forces``, ``contact_wrench`` and
        ``contact_energy`` as a Trajectory's; None without contact, or for a file written
        before the law was kept.
    contact_radii : ndarray, shape (S,), or None
        The arm's surface radius at each station (m).
    """

    times: np.ndarray
    s: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray
    velocities: np.ndarray
    angular_velocities: np.ndarray
    strains: np.ndarray
    stresses: np.ndarray
    energy: object
    errors: np.ndarray
    iterations: np.ndarray
    tendon_lengths: np.ndarray | None
    case: Case
    complete: bool
    steps_requested: int
    reason: str
    sweep_values: np.ndarray | None
    sweep_label: str | None
    version: str
    path: Path
    contact: object = None
    contact_radii: np.ndarray | None = None


def _trajectory_arrays(trajectory) -> dict:
    arrays = {name: np.asarray(getattr(trajectory, name)) for name in TRAJECTORY_ARRAYS
              if not name.startswith("energy_") and name != "tendon_lengths"}
    for name in _ENERGIES:
        arrays[f"energy_{name}"] = np.asarray(getattr(trajectory.energy, name))
    if trajectory.tendon_lengths is not None:
        arrays["tendon_lengths"] = np.asarray(trajectory.tendon_lengths)
    return arrays


def _trajectory_meta(case: Case, batch_shape: tuple, steps: int, failed, complete: bool,
                     reason: str, every: int = 1, contact=None) -> dict:
    """A trajectory file's metadata: ``failed`` the failed cases' mask (or None); ``steps``
    the steps stored, every ``every``-th of the run's; ``contact`` the law the steps used
    (``Trajectory.contact``: its stiffness and distance are kept, for the contact's gaps,
    forces and stored energy read back)."""
    sweep = case.sweep
    return {"softarm_version": __version__, "kind": "trajectory", "name": case.name,
            "contact": None if contact is None else _contact_law([contact]),
            "batch_shape": list(batch_shape), "steps": int(steps), "every": int(every),
            "steps_requested": int(case.simulation.steps) if case.simulation else None,
            "complete": bool(complete), "reason": reason,
            "failed_cases": [] if failed is None else np.flatnonzero(np.ravel(failed)).tolist(),
            "sweep_column": sweep.column if sweep is not None else None,
            "sweep_label": sweep.label if sweep is not None else None,
            "sweep_values": list(sweep.values) if sweep is not None else None,
            "rotation": _ROTATION_NOTE.replace("rotation vector rotvec_* in rad and ", ""),
            "case": case.to_dict()}


def save_trajectory(trajectory, path: str | os.PathLike, case: Case, *, complete: bool = True,
                    reason: str = "", every: int = 1) -> Path:
    """Write a :class:`softarm.Trajectory` of ``case`` to ``path``; the suffix chooses the
    format (``.npz``, ``.zarr`` (a folder; needs ``softarm[sweep]``) or ``.csv``).

    ``.npz``: the arrays of :data:`TRAJECTORY_ARRAYS` and ``meta`` (one JSON string: the
    softarm version, ``complete``, ``steps`` and ``steps_requested``, ``reason``, the sweep,
    the case). ``.zarr``: the same arrays as an xarray Dataset (``zarr_format=2``), dims as
    in :data:`TRAJECTORY_ARRAYS` after ``case`` for a sweep, the metadata in the attribute
    ``meta``. ``.csv``: ``#`` comment lines (the title, the conventions, ``# meta:`` and
    ``# case:`` JSON lines), a header and one row per (case, time, station)
    (:data:`TRAJECTORY_COLUMNS`). Every format is written to a temporary name beside
    ``path`` and renamed: no half-written output. ``complete=False`` (with a ``reason``)
    marks a run that stopped early; ``every``: the trajectory holds every ``every``-th
    time step of the run (its metadata say so).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in TRAJECTORY_FORMATS:
        raise ValueError(f"{path}: unknown trajectory format {path.suffix!r}; use one of "
                         f"{', '.join(TRAJECTORY_FORMATS)}")
    arrays = _trajectory_arrays(trajectory)
    meta = _trajectory_meta(case, trajectory.batch_shape, trajectory.times.size - 1,
                            getattr(trajectory, "failed", None), complete, reason, every,
                            getattr(trajectory, "contact", None))
    if suffix == ".npz":
        with write_atomic(path, "wb") as stream:
            np.savez(stream, **arrays, meta=np.array(json.dumps(meta)))
    elif suffix == ".zarr":
        _save_zarr(arrays, meta, path)
    else:
        with write_atomic(path, "w") as stream:
            _write_trajectory_csv(stream, arrays, meta)
    return path


def _dataset(arrays: dict, meta: dict):
    import xarray

    batch = tuple(meta["batch_shape"])
    names = ("case",) if len(batch) == 1 else tuple(f"batch_{i}" for i in range(len(batch)))
    variables = {}
    for name, array in arrays.items():
        dims, unit, meaning = TRAJECTORY_ARRAYS[name]
        if name in _UNBATCHED:
            continue
        variables[name] = ((*names, *dims), array, {"units": unit, "long_name": meaning})
    coords = {"time": ("time", arrays["times"], {"units": "s"}),
              "station": ("station", arrays["s"], {"units": "m", "long_name": "arc length s"})}
    if meta["sweep_values"] is not None:
        coords[meta["sweep_column"]] = ("case", np.asarray(meta["sweep_values"]),
                                        {"long_name": meta["sweep_label"]})
    return xarray.Dataset(variables, coords=coords,
                          attrs={"softarm_version": meta["softarm_version"],
                                 "complete": int(meta["complete"]),
                                 "meta": json.dumps(meta)})


def _check_zarr_target(path: Path) -> None:
    """CaseError unless a Zarr store can be written at ``path``: xarray and zarr installed,
    and ``path`` a folder or nothing yet."""
    try:
        import xarray  # noqa: F401
        import zarr  # noqa: F401
    except ImportError as error:
        raise CaseError(f"{path}: a .zarr output needs xarray and zarr ({error.name} is "
                        "missing): pip install 'softarm[sweep]'") from None
    if path.exists() and not path.is_dir():
        raise CaseError(f"{path}: exists and is not a folder (a Zarr store is a folder)")


def _save_zarr(arrays: dict, meta: dict, path: Path) -> None:
    """The Dataset written to a temporary folder beside ``path``, then renamed onto it (an
    old store at ``path`` is removed only after the new one is whole)."""
    import shutil
    import tempfile

    _check_zarr_target(path)
    parent = path.parent if str(path.parent) else Path(".")
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".part", dir=parent))
    old = None
    try:
        _dataset(arrays, meta).to_zarr(tmp / "store", mode="w", zarr_format=2,
                                       consolidated=True)
        if path.exists():
            old = tmp / "old"
            os.replace(path, old)
        os.replace(tmp / "store", path)
    except BaseException:
        if old is not None and not path.exists():
            os.replace(old, path)
        raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


class TrajectoryStore:
    """A trajectory written to a Zarr store while it is computed: runs too long to hold in
    memory (an hour of a control loop at 1 kHz is 3.6 million steps), in a memory that does
    not grow with the run, what one chunk of each array holds (about ``chunk_bytes``).

    Parameters
    ----------
    path : str or path-like
        A ``.zarr`` folder (needs ``softarm[sweep]``), read back by :func:`read_trajectory`
        with the layout :func:`save_trajectory` writes. A store already there is replaced
        at the first write.
    case : Case, optional
        The run's case, kept in the metadata as :func:`save_trajectory` keeps it; or
    arm, loads :
        the arm and every load of the run (the actuators' included), kept as a case.
    every : int
        Keep every ``every``-th time step of the run (its first time included); default 1.
    chunk_bytes : int
        The size of a chunk of the largest array (the rotations), default 4 MiB: the parts
        appended are held until a chunk is full, then written.

    :meth:`append` takes the run's parts in order, each a :class:`softarm.Trajectory` that
    continues the last (its first time, when it is the last time stored, is left out: the
    parts of ``Simulator.run`` called again and again, and those of
    :func:`softarm.case.simulation_parts`, both fit). :meth:`close` writes what is held and
    marks the file complete (or not, with a reason). Until then the store holds every chunk
    written so far, marked incomplete ("the run did not close the store"): a crash keeps
    them. As a context manager, an exception closes it incomplete, with the exception.

    Examples
    --------
    >>> import softarm
    >>> from softarm.case import simulation_parts
    >>> with TrajectoryStore("swing.zarr", case, every=10) as store:  # doctest: +SKIP
    ...     for part in simulation_parts(case):
    ...         store.append(part)
    """

    def __init__(self, path: str | os.PathLike, case: Case | None = None, *, arm=None,
                 loads=(), every: int = 1, chunk_bytes: int = 1 << 22):
        from ._validate import count

        self.path = Path(path)
        if self.path.suffix.lower() != ".zarr":
            raise ValueError(f"path must name a .zarr folder, got {str(path)!r}")
        _check_zarr_target(self.path)
        if (case is None) == (arm is None):
            raise TypeError("give case (a softarm Case) or arm (and loads), one of them: the "
                            "file keeps what was simulated")
        if case is None:  # (the case of an arm and loads, as save_result keeps a result's)
            case = _parse({"name": "trajectory", **arm_to_dict(arm),
                           "load": loads_to_dict(loads), **contact_to_dict(loads)}, None)
        elif not isinstance(case, Case):
            raise TypeError(f"case must be a softarm Case (its metadata are kept), got "
                            f"{type(case).__name__}")
        self.case = case
        self.every = count(every, "every", 1)
        self.chunk_bytes = count(chunk_bytes, "chunk_bytes", 1)
        self.steps = -1  # the times stored (written or held), less one
        self._next = 0  # the run's index of the next time appended
        self._last_time = None
        self._held: list[dict] = []  # parts' kept arrays, not yet written
        self._held_times = 0
        self._chunk = None  # the time chunk (set by the first part)
        self._started = False  # the store exists (its first chunk written)
        self._shape = None  # the run's (batch shape, stations), from its first part
        self._contact = None  # the contact law of its steps (the first part's)
        self._failed = None
        self.closed = False

    def append(self, trajectory) -> None:
        """Add the next part of the run (a :class:`softarm.Trajectory`)."""
        if self.closed:
            raise ValueError(f"{self.path}: the store is closed")
        times = np.asarray(trajectory.times)
        start = 1 if self._last_time is not None and times.size and \
            times[0] == self._last_time else 0
        shape = (tuple(trajectory.batch_shape), np.asarray(trajectory.s).size)
        if self._shape is None:
            self._shape = shape
            self._contact = getattr(trajectory, "contact", None)
            per_time = 8 * 9 * shape[1] * int(np.prod(shape[0], dtype=np.int64))
            self._chunk = max(1, self.chunk_bytes // per_time)
        elif shape != self._shape:
            raise ValueError(f"{self.path}: a part of batch shape {shape[0]} and {shape[1]} "
                             f"stations does not continue the run's ({self._shape[0]}, "
                             f"{self._shape[1]})")
        if times.size > start:
            self._last_time = float(times[-1])
        index = self._next + np.arange(times.size - start)
        keep = start + np.flatnonzero(index % self.every == 0)
        self._next += times.size - start
        if getattr(trajectory, "failed", None) is not None:
            failed = np.asarray(trajectory.failed, dtype=bool)
            self._failed = failed if self._failed is None else self._failed | failed
        if keep.size:
            axis = len(trajectory.batch_shape)
            arrays = _trajectory_arrays(trajectory)
            self._held.append({name: np.take(array, keep, axis=0 if name == "times" else axis)
                               if name != "s" else array for name, array in arrays.items()})
            self._held_times += keep.size
            self.steps += keep.size
        if self._held_times >= self._chunk:
            self._write(complete=False, reason=_UNCLOSED)

    def close(self, complete: bool = True, reason: str = "") -> Path | None:
        """Write what is held and the final metadata; the store's path, or None if no part
        was appended (nothing is written)."""
        if self.closed:
            return self.path if self._started else None
        self.closed = True
        if self._shape is None:
            return None
        self._write(complete=complete, reason=reason)
        return self.path

    def __enter__(self) -> TrajectoryStore:
        return self

    def __exit__(self, kind, error, traceback) -> None:
        if error is None:
            self.close()
        else:
            self.close(complete=False, reason=f"{kind.__name__}: {_brief(error)}"
                       if str(error) else kind.__name__)

    def _meta(self, complete: bool, reason: str) -> dict:
        return _trajectory_meta(self.case, self._shape[0], self.steps, self._failed,
                                complete, reason, self.every, self._contact)

    def _write(self, complete: bool, reason: str) -> None:
        """Append the parts held (if any) and set the metadata."""
        import zarr

        meta = self._meta(complete, reason)
        if not self._held:
            group = zarr.open_group(str(self.path), mode="r+", zarr_format=2)
            group.attrs.update({"complete": int(complete), "meta": json.dumps(meta)})
            zarr.consolidate_metadata(str(self.path), zarr_format=2)
            return
        axis = len(self._shape[0])
        arrays = {name: np.concatenate([part[name] for part in self._held],
                                       axis=0 if name == "times" else axis)
                  for name in self._held[0] if name != "s"}
        arrays["s"] = self._held[0]["s"]
        self._held, self._held_times = [], 0
        data = _dataset(arrays, meta)
        if not self._started:
            encoding = {name: {"chunks": tuple(self._chunk if dim == "time" else size
                                               for dim, size in zip(variable.dims,
                                                                    variable.shape,
                                                                    strict=True))}
                        for name, variable in data.variables.items() if "time" in variable.dims}
            data.to_zarr(self.path, mode="w", zarr_format=2, consolidated=True,
                         encoding=encoding)
            self._started = True
        else:
            fixed = [name for name, variable in data.variables.items()
                     if "time" not in variable.dims]
            data.drop_vars(fixed).to_zarr(self.path, append_dim="time", zarr_format=2,
                                          consolidated=True)


#: A store's reason until it is closed (a crash leaves it so).
_UNCLOSED = "the run did not close the store (it stopped, or is still running)"


def _write_trajectory_csv(stream, arrays: dict, meta: dict) -> None:
    stream.write(f"# softarm {meta['softarm_version']} trajectory: {meta['name']}"
                 + ("" if meta["complete"] else f" (INCOMPLETE: {meta['reason']})") + "\n")
    stream.write(f"# {meta['rotation']}; velocities in the spatial frame\n")
    stream.write("# meta: " + json.dumps({k: v for k, v in meta.items()
                                          if k not in ("rotation", "case")}) + "\n")
    stream.write("# case: " + json.dumps(meta["case"]) + "\n")
    batch = tuple(meta["batch_shape"])
    cases = int(np.prod(batch))
    times, s = arrays["times"], arrays["s"]
    T, S = times.size, s.size

    def per_station(name, width):
        return np.asarray(arrays[name]).reshape(cases, T, S, width)

    def per_time(name):  # repeated on each station
        value = np.asarray(arrays[name], dtype=float).reshape(cases, T, -1)
        return np.broadcast_to(value[:, :, None, :], (cases, T, S, value.shape[-1]))

    quat = so3.to_quaternion(np.asarray(arrays["rotations"])).reshape(cases, T, S, 4)
    blocks = [np.broadcast_to(times[None, :, None, None], (cases, T, S, 1)),
              np.broadcast_to(s[None, None, :, None], (cases, T, S, 1)),
              per_station("positions", 3), quat, per_station("velocities", 3),
              per_station("angular_velocities", 3), per_station("strains", 6),
              per_station("stresses", 6)]
    blocks += [per_time(f"energy_{name}") for name in _ENERGIES]
    blocks += [per_time("errors"), per_time("iterations")]
    header = list(TRAJECTORY_COLUMNS)
    if "tendon_lengths" in arrays:
        lengths = per_time("tendon_lengths")
        blocks.append(lengths)
        header += [f"tendon_{k + 1}_length_m" for k in range(lengths.shape[-1])]
    if batch:
        lead = np.asarray(meta["sweep_values"], dtype=float) if meta["sweep_values"] \
            is not None else np.arange(cases, dtype=float)
        blocks.insert(0, np.broadcast_to(lead[:, None, None, None], (cases, T, S, 1)))
        header.insert(0, meta["sweep_column"] or "batch_index")
    table = np.concatenate(blocks, axis=-1).reshape(-1, len(header))
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(header)
    for row in table:
        writer.writerow([repr(float(v)) for v in row])


def read_trajectory(path: str | os.PathLike) -> SavedTrajectory:
    """Read a trajectory written by :func:`save_trajectory` (``softarm simulate -o``).

    Returns
    -------
    SavedTrajectory
        The arrays as :class:`softarm.Trajectory` names them, the case, and whether the run
        was complete.

    Raises
    ------
    CaseError
        If the file is missing, of an unknown format or not a softarm trajectory.
    """
    path, suffix = _existing(path, TRAJECTORY_FORMATS, "trajectory")
    try:
        if suffix == ".npz":
            with np.load(path, allow_pickle=False) as data:
                meta = json.loads(str(data["meta"]))
                arrays = {name: data[name] for name in data.files if name != "meta"}
        elif suffix == ".zarr":
            import xarray

            with xarray.open_dataset(path, engine="zarr", consolidated=True) as data:
                meta = json.loads(data.attrs["meta"])
                arrays = {name: np.asarray(data[name].values) for name in data.data_vars}
                arrays["times"] = np.asarray(data["time"].values)
                arrays["s"] = np.asarray(data["station"].values)
        else:
            meta, arrays = _read_trajectory_csv(path)
        if meta.get("kind") != "trajectory":
            raise CaseError(f"{path}: not a softarm trajectory (kind {meta.get('kind')!r})")
        batch = tuple(meta["batch_shape"])
        T, S = arrays["times"].size, arrays["s"].size
        for name, array in arrays.items():
            dims = TRAJECTORY_ARRAYS[name][0]
            sizes = {"time": T, "station": S, "axis": 3, "row": 3, "column": 3,
                     "component": 6}
            shape = (*(() if name in _UNBATCHED else batch),
                     *(sizes.get(d, array.shape[-1]) for d in dims))
            if array.shape != shape:
                raise CaseError(f"{path}: not a valid softarm trajectory: {name!r} has shape "
                                f"{array.shape}, expected {shape}")
        case = _parse(meta["case"], path)
        contact = radii = None
        if meta.get("contact") is not None:
            laws = [load for load in _with_contact_law(case.loads, meta["contact"], path,
                                                       "softarm trajectory")
                    if isinstance(load, Contact)]
            if laws:
                contact = laws[0]
                radii = contact.station_radii(case.arm, arrays["s"])
    except CaseError:
        raise
    except KeyError as error:
        raise CaseError(f"{path}: not a softarm trajectory (no {error} entry)") from None
    except Exception as error:  # truncated or garbage files included
        raise CaseError(f"{path}: not a softarm trajectory ({type(error).__name__}: "
                        f"{_brief(error)})") from None
    sweep = meta.get("sweep_values")
    return SavedTrajectory(
        times=arrays["times"], s=arrays["s"], positions=arrays["positions"],
        rotations=arrays["rotations"], velocities=arrays["velocities"],
        angular_velocities=arrays["angular_velocities"], strains=arrays["strains"],
        stresses=arrays["stresses"],
        energy=Energy(*(arrays[f"energy_{name}"] for name in _ENERGIES)),
        errors=arrays["errors"], iterations=arrays["iterations"].astype(np.int64),
        tendon_lengths=arrays.get("tendon_lengths"), case=case,
        complete=bool(meta["complete"]), steps_requested=meta.get("steps_requested"),
        reason=str(meta.get("reason", "")),
        sweep_values=None if sweep is None else np.asarray(sweep, dtype=float),
        sweep_label=meta.get("sweep_label"), version=str(meta.get("softarm_version", "")),
        path=path, contact=contact, contact_radii=radii)


def _read_trajectory_csv(path: Path) -> tuple[dict, dict]:
    meta, header, rows = _csv_rows(path, finite=False)
    if header is None or meta.get("kind") != "trajectory":
        raise CaseError(f"{path}: not a softarm trajectory (no '# meta:' line or header)")
    batch = tuple(meta["batch_shape"])
    table = np.asarray(rows, dtype=float)
    column = {name: table[:, k] for k, name in enumerate(header)}
    cases = int(np.prod(batch))
    times = np.unique(column["t_s"])
    s = np.unique(column["s_m"])
    T, S = times.size, s.size
    if table.shape[0] != cases * T * S:
        raise CaseError(f"{path}: {table.shape[0]} rows, expected {cases * T * S} (batch "
                        f"{batch}, {T} times, {S} stations)")

    def get(names):
        return np.stack([column[n] for n in names], -1).reshape(*batch, T, S, len(names))

    n = TRAJECTORY_COLUMNS
    arrays = {"times": times, "s": s, "positions": get(n[2:5]),
              "rotations": so3.from_quaternion(get(n[5:9])),
              "velocities": get(n[9:12]), "angular_velocities": get(n[12:15]),
              "strains": get(n[15:21]), "stresses": get(n[21:27])}
    for name, key in zip(_ENERGIES, n[27:31], strict=True):
        arrays[f"energy_{name}"] = get((key,))[..., 0, 0]
    arrays["errors"] = get(("step_error",))[..., 0, 0]
    arrays["iterations"] = get(("iterations",))[..., 0, 0]
    tendons = [h for h in header if h.startswith("tendon_") and h.endswith("_length_m")]
    if tendons:
        arrays["tendon_lengths"] = get(tendons)[..., 0, :]
    return meta, arrays

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
from ._schema import arm_to_dict, loads_to_dict
from .case import Case, CaseError, _parse
from .equilibrium import Equilibrium, Stability
from .lie import se3, so3

__all__ = [
    "COLUMNS",
    "FORMATS",
    "TRAJECTORY_ARRAYS",
    "SavedResult",
    "SavedTrajectory",
    "is_trajectory_file",
    "load_result",
    "load_saved",
    "load_trajectory",
    "save_result",
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
    return {"name": "result", **arm_to_dict(result.arm), "load": loads_to_dict(result.loads)}


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
    }


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


def load_saved(path: str | os.PathLike) -> SavedResult:
    """Read a result file with its embedded case and metadata (see :class:`SavedResult`).

    Raises
    ------
    CaseError
        If the file is missing, of an unknown format or not a softarm result.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise CaseError(f"{path}: unknown result format {path.suffix!r}; expected one of "
                        f"{', '.join(FORMATS)}")
    if not path.exists():
        raise CaseError(f"{path}: no such file")
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
        arm=case.arm, loads=case.batched_loads, method=meta["method"], exact=meta["exact"],
        residual=residual.reshape(batch) if batch else float(residual),
        error_estimate=estimate.reshape(batch) if batch else float(estimate),
        stability=None if verdict is None else Stability.of(verdict["index"],
                                                            verdict["conservative"], batch))
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


def _read_csv(path: Path):
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
                if not all(math.isfinite(v) for v in row):
                    column = header[next(i for i, v in enumerate(row) if not math.isfinite(v))]
                    raise CaseError(f"{path}: line {number}: column {column!r} is not finite")
                rows.append(row)
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


# ------------------------------------------------------------------------- trajectories

#: The arrays a trajectory's NPZ file holds (named after :class:`softarm.Trajectory`'s
#: attributes; T times, S stations): times (T,) s; s (S,) m; positions (T, S, 3) m, spatial;
#: rotations (T, S, 3, 3) (columns e1 e2 e3, spatial); energy_kinetic, energy_elastic,
#: energy_gravity, energy_dissipated (T,) J. Optional: radii (S,) m, the tube's radius at
#: each station (for drawing); name, the case's name (a string); meta, JSON text whose
#: "case" entry is a case as :func:`save_result` embeds it (its arm is drawn). Further arrays
#: (velocities, strains, ...) may be present and are not read.
TRAJECTORY_ARRAYS = ("times", "s", "positions", "rotations", "energy_kinetic",
                     "energy_elastic", "energy_gravity", "energy_dissipated")


@dataclass(frozen=True)
class TrajectoryEnergy:
    """A saved trajectory's energies (J), each (T,): as :class:`softarm.Energy`'s."""

    kinetic: np.ndarray
    elastic: np.ndarray
    gravity: np.ndarray
    dissipated: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.elastic + self.gravity + self.dissipated


@dataclass(frozen=True)
class SavedTrajectory:
    """A motion read by :func:`load_trajectory`: the arrays of :data:`TRAJECTORY_ARRAYS`
    under :class:`softarm.Trajectory`'s names (``energy`` with its ``kinetic``, ...), what
    the viewer draws (``radii`` or the case's ``arm``, ``name``) and the file's ``path``."""

    times: np.ndarray
    s: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray
    energy: TrajectoryEnergy
    radii: np.ndarray | None
    name: str | None
    arm: object | None
    path: Path


def is_trajectory_file(path: str | os.PathLike) -> bool:
    """True if ``path`` is an NPZ archive holding a ``times`` array (a trajectory, not an
    equilibrium written by :func:`save_result`)."""
    path = Path(path)
    if path.suffix.lower() != ".npz" or not zipfile.is_zipfile(path):
        return False
    with zipfile.ZipFile(path) as archive:
        return "times.npy" in archive.namelist()


def load_trajectory(path: str | os.PathLike) -> SavedTrajectory:
    """Read a trajectory's NPZ file (the arrays of :data:`TRAJECTORY_ARRAYS`).

    Raises
    ------
    CaseError
        If the file is missing, not an NPZ archive, or lacks an array or has one of the
        wrong shape or with values that are not finite, naming it.
    """
    path = Path(path)
    if not path.exists():
        raise CaseError(f"{path}: no such file")
    if path.is_dir() or not zipfile.is_zipfile(path):
        raise CaseError(f"{path}: not a softarm trajectory file (not an NPZ archive, or "
                        "truncated)")
    try:
        with np.load(path, allow_pickle=False) as data:
            missing = [name for name in TRAJECTORY_ARRAYS if name not in data.files]
            if missing:
                raise CaseError(f"{path}: not a softarm trajectory file (no "
                                f"{', '.join(missing)} array{'s' if len(missing) > 1 else ''})")
            arrays = {name: np.asarray(data[name], dtype=float) for name in TRAJECTORY_ARRAYS}
            radii = np.asarray(data["radii"], dtype=float) if "radii" in data.files else None
            name = str(data["name"]) if "name" in data.files else None
            meta = json.loads(str(data["meta"])) if "meta" in data.files else {}
    except CaseError:
        raise
    except Exception as error:  # truncated or garbage archives
        raise CaseError(f"{path}: not a softarm trajectory file ({type(error).__name__}: "
                        f"{_brief(error)})") from None
    T, S = arrays["times"].size, arrays["s"].size
    shapes = {"times": (T,), "s": (S,), "positions": (T, S, 3), "rotations": (T, S, 3, 3),
              **{name: (T,) for name in TRAJECTORY_ARRAYS[4:]}}
    for key, shape in shapes.items():
        if arrays[key].shape != shape:
            raise CaseError(f"{path}: {key} must have shape {shape} (T = {T} times, S = {S} "
                            f"stations), got {arrays[key].shape}")
        if not np.all(np.isfinite(arrays[key])):
            raise CaseError(f"{path}: {key} holds values that are not finite")
    if T < 1 or S < 2 or np.any(np.diff(arrays["times"]) <= 0):
        raise CaseError(f"{path}: times must increase and there must be two stations or more")
    if radii is not None and (radii.shape != (S,) or not np.all(radii > 0)):
        raise CaseError(f"{path}: radii must be {S} positive radii in m, got shape "
                        f"{radii.shape}")
    arm = None
    if meta.get("case"):
        try:
            case = _parse(meta["case"], path, batched=True)
        except CaseError as error:
            raise CaseError(f"{path}: embedded case: {error}") from None
        arm, name = case.arm, name or case.name
    energy = TrajectoryEnergy(*(arrays[f"energy_{k}"] for k in
                                ("kinetic", "elastic", "gravity", "dissipated")))
    return SavedTrajectory(arrays["times"], arrays["s"], arrays["positions"],
                           arrays["rotations"], energy, radii, name, arm, path)

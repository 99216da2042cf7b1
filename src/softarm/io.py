"""Result files: an :class:`~softarm.Equilibrium` out to CSV, JSON or NPZ, and back.

:func:`save_result` writes an equilibrium as one row per station (and per sweep step), with the
case it came from embedded; :func:`load_result` and :func:`load_saved` read any of the three
formats back. Outputs are written through :func:`write_atomic`: to a temporary file beside the
target, then renamed, so a failure never leaves a half-written file. Case files are
:mod:`softarm.case`.
"""

from __future__ import annotations

import contextlib
import csv
import io as _stdio
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import __version__
from .case import Case, CaseError, _parse, arm_to_dict, loads_to_dict
from .equilibrium import Equilibrium
from .lie import se3, so3

__all__ = [
    "COLUMNS",
    "FORMATS",
    "SavedResult",
    "load_result",
    "load_saved",
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
        "rotation": _ROTATION_NOTE,
        "case": _case_dict(result, case),
    }


@contextlib.contextmanager
def write_atomic(path: str | os.PathLike, mode: str = "w"):
    """Open a temporary file beside ``path``; rename it to ``path`` only if the block succeeds.

    A failure (or an interrupt) removes the temporary file and leaves any old ``path`` as it
    was.
    """
    path = Path(path)
    handle, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                                   dir=path.parent if str(path.parent) else ".")
    try:
        # mkstemp makes the file private (0600); give it the permissions of a normal new file
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        with os.fdopen(handle, mode, **({"newline": ""} if "b" not in mode else {})) as stream:
            yield stream
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


#: File suffixes that save_result writes and load_result reads.
FORMATS = (".csv", ".json", ".npz")


def save_result(result: Equilibrium, path: str | os.PathLike, case: Case | None = None) -> Path:
    """Write an equilibrium to ``path``; the suffix chooses the format.

    ``.csv``: ``#`` comment lines (softarm version, case name, method, residual, the rotation
    convention and the case as one line of JSON), then a header line of :data:`COLUMNS` (a
    first column for the swept parameter, or ``batch_index`` for another batch) and one row per
    station (per step, step-major). ``.json`` and ``.npz``: the same columns as arrays of shape
    (B..., N), the poses, residuals, the case as a dict and the softarm version.

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
    buffer.write(f"# method: {meta['method']}; exact: {str(meta['exact']).lower()}; residual "
                 f"(N, N m): max {float(np.max(residual)):.3e}\n")
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
    try:
        if suffix == ".json":
            document = json.loads(path.read_text(encoding="utf-8"))
            meta = document
            columns = {k: np.asarray(v, dtype=float) for k, v in document["columns"].items()}
            poses = np.asarray(document["poses"], dtype=float)
            residual = np.asarray(document["residual"], dtype=float)
            estimate = np.asarray(document["error_estimate"], dtype=float)
            sweep = document.get("sweep_values")
        elif suffix == ".npz":
            with np.load(path, allow_pickle=False) as data:
                meta = json.loads(str(data["meta"]))
                columns = {k: data[k] for k in COLUMNS}
                poses = data["poses"]
                residual, estimate = data["residual"], data["error_estimate"]
                sweep = data["sweep_values"] if "sweep_values" in data.files else None
        else:
            meta, columns, poses, residual, estimate, sweep = _read_csv(path)
    except CaseError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as error:
        raise CaseError(f"{path}: not a softarm result file ({type(error).__name__}: "
                        f"{error})") from None
    case = None
    if meta.get("case"):
        try:
            case = _parse(meta["case"], path, batched=True)
        except CaseError as error:
            raise CaseError(f"{path}: embedded case: {error}") from None
    batch = tuple(meta.get("batch_shape", ()))
    s = columns["s_m"].reshape(-1, columns["s_m"].shape[-1])[0]
    strains = _stack(columns, COLUMNS[11:17])
    stresses = _stack(columns, COLUMNS[17:23])
    if case is None:  # pragma: no cover - every file written by save_result embeds its case
        raise CaseError(f"{path}: the file carries no case (arm and loads)")
    result = Equilibrium(
        s=s, poses=poses.reshape(*batch, s.size, 4, 4),
        strains=strains.reshape(*batch, s.size, 6), stresses=stresses.reshape(*batch, s.size, 6),
        arm=case.arm, loads=case.batched_loads, method=meta["method"], exact=bool(meta["exact"]),
        residual=residual.reshape(batch) if batch else float(residual),
        error_estimate=estimate.reshape(batch) if batch else float(estimate))
    sweep = None if sweep is None else np.asarray(sweep, dtype=float)
    return SavedResult(result, case, str(meta.get("softarm_version", "")), sweep,
                       meta.get("sweep_label"), path)


def _read_csv(path: Path):
    meta: dict = {}
    header = None
    rows = []
    with path.open(newline="", encoding="utf-8") as stream:
        for line in stream:
            if line.startswith("# meta: "):
                meta.update(json.loads(line[len("# meta: "):]))
            elif line.startswith("# case: "):
                meta["case"] = json.loads(line[len("# case: "):])
            elif line.startswith("#") or not line.strip():
                continue
            elif header is None:
                header = next(csv.reader([line]))
            else:
                rows.append([float(v) for v in next(csv.reader([line]))])
    if header is None or "method" not in meta:
        raise CaseError(f"{path}: not a softarm result file (no '# meta:' line or header)")
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise CaseError(f"{path}: column {missing[0]!r} missing from the header")
    table = np.asarray(rows, dtype=float).reshape(-1, len(header))
    batch = tuple(meta.get("batch_shape", ()))
    n = int(meta["stations"])
    shape = (*batch, n)
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

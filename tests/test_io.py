"""Case files in, result files out: parsing, error messages and round trips."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import io
from softarm.lie import se3

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

STIFF = "stiffness = { EA = 1e6, GAy = 1e6, GAz = 1e6, GJ = 1.0, EIy = 1.0, EIz = 1.0 }"


def write(tmp_path, text: str, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def arc(kappa: float = 3.0, n: int = 11, length: float = 1.0, batch=None):
    """An exact circular arc of curvature κ about material y (pure bending, paper eq. 38)."""
    arm = softarm.Arm.from_stiffness(length, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    s = np.linspace(0.0, length, n)
    kappa = np.asarray(kappa, dtype=float)
    twist = np.array([1.0, 0, 0, 0, 0, 0]) + kappa[..., None] * np.array([0, 0, 0, 0, 1, 0])
    poses = se3.exp(s[:, None] * twist[..., None, :])
    strains = np.broadcast_to((twist - [1, 0, 0, 0, 0, 0])[..., None, :], (*kappa.shape, n, 6))
    moment = np.stack([0 * kappa, kappa, 0 * kappa], axis=-1)
    return softarm.Equilibrium(s, poses, strains, strains, arm,
                               (softarm.TipLoad(moment=moment),), "test.arc", True,
                               np.zeros(kappa.shape) if kappa.shape else 0.0,
                               np.zeros(kappa.shape) if kappa.shape else 0.0)


# ------------------------------------------------------------------------------------ parsing


def test_every_example_parses():
    for path in sorted(EXAMPLES.glob("*.toml")):
        case = io.load_case(path)
        assert case.source == path
        assert case.loads
        assert case.name == path.stem


def test_full_case(tmp_path):
    path = write(tmp_path, """
name = "full"
description = "all the keys"
[[segment]]
length = 0.2
curvature = [0.0, 1.0, 0.0]
section = { kind = "tube", outer_radius = 0.01, inner_radius = 0.004 }
material = { E = 1e6, G = 4e5, density = 1000.0 }
[[segment]]
length = 0.1
mass_per_length = 0.05
section = { kind = "rectangle", width = 0.01, height = 0.02 }
material = { E = 1e6, nu = 0.45 }
[[segment]]
length = 0.1
section = { kind = "general", area = 1e-4, Iy = 1e-9, Iz = 2e-9, J = 2e-9, shear_factor_y = 0.9 }
material = { E = 1e6, nu = 0.3, density = 900.0 }
[[load]]
kind = "tip"
force = [1, 2, 3]
moment = [0, 0, 1]
follower = true
[[load]]
kind = "gravity"
acceleration = [0, -9.81, 0]
[[load]]
kind = "distributed"
force = [0, 0, -1]
[[load]]
kind = "point"
s = 0.15
force = [0, 1, 0]
[solve]
method = "numeric"
stations = 11
tol = 1e-6
[sweep]
load = 4
component = "y"
values = [0.0, 1.0, 2.0]
""")
    case = softarm.load_case(path)
    assert case.name == "full" and case.description == "all the keys"
    assert isinstance(case.arm, softarm.SegmentedArm)
    first, second, third = case.arm.segments
    assert isinstance(first.section, softarm.Tube) and first.curvature == (0.0, 1.0, 0.0)
    assert first.material.G == 4e5 and second.mass_per_length == 0.05
    assert isinstance(third.section, softarm.Section) and third.section.shear_factor_y == 0.9
    tip, gravity, distributed, point = case.loads
    assert tip.follower and np.array_equal(tip.force, [1, 2, 3])
    assert np.array_equal(gravity.acceleration, [0, -9.81, 0])
    assert np.array_equal(distributed.force, [0, 0, -1]) and point.s == 0.15
    assert case.solve == io.SolveOptions("numeric", 11, 1e-6)
    assert case.sweep.load == 3 and case.sweep.field == "force"
    swept = case.batched_loads[3]
    assert swept.force.shape == (3, 3)
    assert np.array_equal(swept.force[:, 1], [0.0, 1.0, 2.0])
    assert case.sweep.column == "point_force_y_N"
    assert case.to_dict()["solve"]["stations"] == 11


def test_defaults(tmp_path):
    case = io.load_case(write(tmp_path, f"[arm]\nlength = 2\n{STIFF}\n[[load]]\nkind = 'tip'\n"))
    assert case.name == "case" and case.solve == io.SolveOptions()
    assert case.sweep is None and case.arm.curvature == (0.0, 0.0, 0.0)
    assert np.array_equal(case.loads[0].force, [0, 0, 0])


def test_sweep_range_and_magnitude(tmp_path):
    case = io.load_case(write(tmp_path, f"""
[arm]
length = 1.0
{STIFF}
[[load]]
kind = "tip"
force = [0.0, 3.0, 4.0]
[sweep]
start = 0.0
stop = 20.0
steps = 21
name = "payload"
"""))
    assert case.sweep.values == tuple(np.linspace(0, 20, 21))
    force = case.batched_loads[0].force
    np.testing.assert_allclose(np.linalg.norm(force, axis=-1), np.linspace(0, 20, 21))
    np.testing.assert_allclose(force[-1], [0.0, 12.0, 16.0])
    assert case.sweep.label == "payload (N)" and case.sweep.column == "payload_N"


BAD_CASES = {
    "misspelled key": (f"[arm]\nlenght = 1.0\n{STIFF}\n", "arm.lenght", "did you mean 'length'"),
    "unknown top-level table": (f"[arm]\nlength = 1.0\n{STIFF}\n[solver]\nmethod = 'auto'\n",
                                "solver", "unknown key"),
    "missing length": (f"[arm]\n{STIFF}\n", "arm.length", "missing"),
    "wrong type": (f"[arm]\nlength = 'long'\n{STIFF}\n", "arm.length", "must be a number"),
    "negative length": (f"[arm]\nlength = -1.0\n{STIFF}\n", "arm.length", "must be positive"),
    "unknown section kind": (
        "[arm]\nlength = 1.0\nsection = { kind = 'hexagon', radius = 0.01 }\n"
        "material = { E = 1e6, nu = 0.3 }\n", "arm.section.kind", "unknown value 'hexagon'"),
    "missing stiffness": ("[arm]\nlength = 1.0\nstiffness = { EA = 1.0 }\n", "arm.stiffness.GAy",
                          "missing"),
    "both nu and G": ("[arm]\nlength = 1.0\nsection = { kind = 'circle', radius = 0.01 }\n"
                      "material = { E = 1e6, nu = 0.3, G = 1e5 }\n", "arm.material",
                      "exactly one of 'nu'"),
    "bad nu": ("[arm]\nlength = 1.0\nsection = { kind = 'circle', radius = 0.01 }\n"
               "material = { E = 1e6, nu = 0.7 }\n", "arm.material.nu", "(-1, 0.5]"),
    "tube radii": ("[arm]\nlength = 1.0\nsection = { kind = 'tube', outer_radius = 0.01, "
                   "inner_radius = 0.02 }\nmaterial = { E = 1e6, nu = 0.3 }\n",
                   "arm.section.inner_radius", "smaller than outer_radius"),
    "load kind": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'tipp'\n", "load[1].kind",
                  "did you mean 'tip'"),
    "load vector": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'tip'\nforce = [1, 2]\n",
                    "load[1].force", "list of 3 finite numbers"),
    "follower type": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'tip'\nfollower = 1\n",
                      "load[1].follower", "true or false"),
    "gravity without mass": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'gravity'\n",
                             "load[1]", "needs the arm's mass"),
    "point load off the arm": (
        f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'point'\ns = 2.0\nforce = [0, 0, 1]\n",
        "load[1].s", "must lie on the arm"),
    "no arm": ("[[load]]\nkind = 'tip'\n", "arm", "exactly one [arm]"),
    "arm and segment": (f"[arm]\nlength = 1.0\n{STIFF}\n[[segment]]\nlength = 1.0\n{STIFF}\n",
                        "arm", "exactly one [arm]"),
    "stations": (f"[arm]\nlength = 1.0\n{STIFF}\n[solve]\nstations = 1\n", "solve.stations",
                 ">= 2"),
    "method": (f"[arm]\nlength = 1.0\n{STIFF}\n[solve]\nmethod = 'magic'\n", "solve.method",
               "unknown value 'magic'"),
    "sweep load index": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'tip'\n[sweep]\n"
                         "load = 2\nvalues = [1.0]\n", "sweep.load", "there are 1 [[load]]"),
    "sweep zero direction": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'tip'\n[sweep]\n"
                             "values = [1.0]\n", "sweep.component", "nonzero force"),
    "sweep field": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'tip'\n[sweep]\n"
                    "field = 'acceleration'\nvalues = [1.0]\n", "sweep.field", "unknown value"),
    "sweep steps": (f"[arm]\nlength = 1.0\n{STIFF}\n[[load]]\nkind = 'tip'\nforce = [0, 0, 1]\n"
                    "[sweep]\nstart = 0.0\nstop = 1.0\nsteps = 1.5\n", "sweep.steps",
                    "must be an integer"),
    "not TOML": ("[arm\nlength = 1", "", "not valid TOML"),
}


@pytest.mark.parametrize("name", sorted(BAD_CASES))
def test_bad_case_names_file_key_and_fault(tmp_path, name):
    text, key, what = BAD_CASES[name]
    path = write(tmp_path, text)
    with pytest.raises(io.CaseError) as info:
        io.load_case(path)
    message = str(info.value)
    assert isinstance(info.value, ValueError)
    assert message.startswith(f"{path}: {key}"), message
    assert what in message, message
    assert "\n" not in message


def test_missing_file(tmp_path):
    with pytest.raises(io.CaseError, match="no such file"):
        io.load_case(tmp_path / "nope.toml")


# ------------------------------------------------------------------------------- result files


def test_columns_of_an_arc(tmp_path):
    """CSV columns against the closed-form arc: x = sin(κs)/κ, z = -(1 - cos κs)/κ, R = Ry(κs)
    (paper eq. 38), rotation vector (0, κs, 0), quaternion (cos κs/2, 0, sin κs/2, 0)."""
    result = arc(2.0)
    path = io.save_result(result, tmp_path / "arc.csv")
    lines = path.read_text().splitlines()
    comments = [line for line in lines if line.startswith("#")]
    assert any("(w, x, y, z)" in line for line in comments)
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    assert list(rows[0]) == list(io.COLUMNS)
    table = {k: np.array([float(r[k]) for r in rows]) for k in io.COLUMNS}
    s, k = table["s_m"], 2.0
    np.testing.assert_allclose(table["x_m"], np.sin(k * s) / k, atol=1e-15)
    np.testing.assert_allclose(table["z_m"], -(1 - np.cos(k * s)) / k, atol=1e-15)
    np.testing.assert_allclose(table["rotvec_y_rad"], k * s, atol=1e-15)
    np.testing.assert_allclose(table["quat_w"], np.cos(k * s / 2), atol=1e-15)
    np.testing.assert_allclose(table["quat_y"], np.sin(k * s / 2), atol=1e-15)
    np.testing.assert_allclose(table["kappa_2_per_m"], k)
    np.testing.assert_allclose(table["m_2_Nm"], k)
    # as docs/case-files.md says: five comment lines, then the header
    array = np.genfromtxt(path, delimiter=",", names=True, skip_header=5)
    assert array.dtype.names == io.COLUMNS
    np.testing.assert_array_equal(array["x_m"], table["x_m"])


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
@pytest.mark.parametrize("batch", [None, (3, 1, 2)])
def test_round_trip_without_case(tmp_path, suffix, batch):
    kappa = 2.0 if batch is None else np.linspace(0.5, 3.0, 6).reshape(batch)
    result = arc(kappa)
    back = io.load_result(io.save_result(result, tmp_path / f"r{suffix}"))
    atol = 1e-15 if suffix != ".csv" else 1e-14  # CSV rebuilds R from the quaternion
    assert back.batch_shape == result.batch_shape
    np.testing.assert_allclose(back.poses, result.poses, atol=atol, rtol=0)
    np.testing.assert_array_equal(back.strains, result.strains)
    np.testing.assert_array_equal(back.stresses, result.stresses)
    np.testing.assert_array_equal(back.s, result.s)
    assert back.method == result.method and back.exact == result.exact
    np.testing.assert_array_equal(back.residual, result.residual)
    assert back.arm == result.arm
    np.testing.assert_array_equal(back.loads[0].moment, result.loads[0].moment)


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
def test_round_trip_with_sweep_case(tmp_path, suffix):
    case = io.load_case(EXAMPLES / "fig2_sweep.toml")
    values = np.asarray(case.sweep.values)
    result = arc(values)
    path = io.save_result(result, tmp_path / f"sweep{suffix}", case)
    saved = io.load_saved(path)
    assert saved.version == softarm.__version__
    assert saved.case.name == "fig2_sweep" and saved.case.sweep == case.sweep
    np.testing.assert_array_equal(saved.sweep_values, values)
    assert saved.sweep_label == case.sweep.label
    np.testing.assert_allclose(saved.result.poses, result.poses, atol=1e-14, rtol=0)
    np.testing.assert_array_equal(saved.result.loads[0].moment[:, 1], values)
    if suffix == ".csv":
        header = next(line for line in path.read_text().splitlines() if not line[0] == "#")
        assert header.startswith("tip_moment_tau_Nm,s_m,x_m")
    if suffix == ".json":
        document = json.loads(path.read_text())
        assert document["case"]["sweep"]["stop"] == 5.0
        assert document["softarm_version"] == softarm.__version__


def test_save_rejects_unknown_format(tmp_path):
    with pytest.raises(ValueError, match=r"unknown output format '\.txt'"):
        io.save_result(arc(), tmp_path / "r.txt")
    assert list(tmp_path.iterdir()) == []


def test_load_rejects_other_files(tmp_path):
    path = write(tmp_path, "a,b\n1,2\n", "other.csv")
    with pytest.raises(io.CaseError, match="not a softarm result"):
        io.load_result(path)
    with pytest.raises(io.CaseError, match="no such file"):
        io.load_result(tmp_path / "missing.json")


def test_atomic_write_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError), io.write_atomic(target) as stream:
        stream.write("half")
        raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]

"""Case files in: parsing, defaults, sweeps and error messages."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm.case import CaseError, SolveOptions, load_case

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

STIFF = "stiffness = { EA = 1e6, GAy = 1e6, GAz = 1e6, GJ = 1.0, EIy = 1.0, EIz = 1.0 }"


def write(tmp_path, text: str, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# ------------------------------------------------------------------------------------ parsing


def test_every_example_parses():
    for path in sorted(EXAMPLES.glob("*.toml")):
        case = load_case(path)
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
    assert case.solve == SolveOptions("numeric", 11, 1e-6)
    assert case.sweep.load == 3 and case.sweep.field == "force"
    swept = case.batched_loads[3]
    assert swept.force.shape == (3, 3)
    assert np.array_equal(swept.force[:, 1], [0.0, 1.0, 2.0])
    assert case.sweep.column == "point_force_y_N"
    assert case.to_dict()["solve"]["stations"] == 11


def test_defaults(tmp_path):
    case = load_case(write(tmp_path, f"[arm]\nlength = 2\n{STIFF}\n[[load]]\nkind = 'tip'\n"))
    assert case.name == "case" and case.solve == SolveOptions()
    assert case.sweep is None and case.arm.curvature == (0.0, 0.0, 0.0)
    assert np.array_equal(case.loads[0].force, [0, 0, 0])


def test_sweep_range_and_magnitude(tmp_path):
    case = load_case(write(tmp_path, f"""
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


def test_a_sweep_on_the_stable_branch_solves_each_step(tmp_path):
    """branch = "stable" solves a sweep one step at a time (each step unbatched: it once
    failed with 'takes a single load case, got batch shape (1,)'): the paper's Fig. 2
    circles, tip (sin τ/τ, 0, -(1 - cos τ)/τ) for τ = 1 ... 5 N m on EI = 1 N m² (eq. 38)."""
    case = load_case(write(tmp_path, (EXAMPLES / "fig2_sweep.toml").read_text()
                           + '\n[solve]\nbranch = "stable"\n'))
    result = softarm.case.solve_case(case)
    tau = np.asarray(case.sweep.values)
    np.testing.assert_allclose(result.tip_position[:, 0], np.sin(tau) / tau, atol=1e-6)
    np.testing.assert_allclose(result.tip_position[:, 2], -(1 - np.cos(tau)) / tau, atol=1e-6)


BAD_CASES = {
    "misspelled key": (f"[arm]\nlenght = 1.0\n{STIFF}\n", "arm.lenght", "did you mean 'length'"),
    "unknown top-level table": (f"[arm]\nlength = 1.0\n{STIFF}\n[solver]\nmethod = 'auto'\n",
                                "solver", "unknown key"),
    "missing length": (f"[arm]\n{STIFF}\n", "arm.length", "missing"),
    "wrong type": (f"[arm]\nlength = 'long'\n{STIFF}\n", "arm.length", "must be a number"),
    "negative length": (f"[arm]\nlength = -1.0\n{STIFF}\n", "arm.length",
                        "must be a positive finite value in m, got -1.0"),
    "unknown section kind": (
        "[arm]\nlength = 1.0\nsection = { kind = 'hexagon', radius = 0.01 }\n"
        "material = { E = 1e6, nu = 0.3 }\n", "arm.section.kind", "unknown value 'hexagon'"),
    "missing stiffness": ("[arm]\nlength = 1.0\nstiffness = { EA = 1.0 }\n", "arm.stiffness.GAy",
                          "missing"),
    "both nu and G": ("[arm]\nlength = 1.0\nsection = { kind = 'circle', radius = 0.01 }\n"
                      "material = { E = 1e6, nu = 0.3, G = 1e5 }\n", "arm.material",
                      "exactly one of nu and G, got nu=0.3, G=100000.0"),
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
    with pytest.raises(CaseError) as info:
        load_case(path)
    message = str(info.value)
    assert isinstance(info.value, ValueError)
    assert message.startswith(f"{path}: {key}"), message
    assert what in message, message
    assert "\n" not in message


def test_missing_file(tmp_path):
    with pytest.raises(CaseError, match="no such file"):
        load_case(tmp_path / "nope.toml")


def test_solver_tolerance_is_checked_with_its_key_path(tmp_path):
    """tol is the tip-position tolerance / L of softarm.solve, in [1e-13, 0.1]."""
    path = tmp_path / "case.toml"
    path.write_text(f"[arm]\nlength = 1\n{STIFF}\n[[load]]\nkind = 'tip'\n[solve]\ntol = 0.5\n")
    with pytest.raises(CaseError, match=r"case\.toml: solve\.tol: must be .*\[1e-13, 0\.1\], "
                                        r"got 0\.5"):
        load_case(path)

"""Every example solves, and its numbers agree with an independent reference where one exists."""

from __future__ import annotations

import runpy
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from softarm.case import load_case, solve_case

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CASES = sorted(p.stem for p in EXAMPLES.glob("*.toml") if p.stem != "design_sweep")


def solve(name: str):
    case = load_case(EXAMPLES / f"{name}.toml")
    return case, solve_case(case)


def test_the_examples_are_there():
    assert {"demo", "fig2_pure_bending", "fig2_sweep", "fig3_shear_load",
            "mattiasson_cantilever", "precurved", "tendon_robot", "pneumatic_actuator",
            "magnetic_catheter", "greenhill_upright"} <= set(CASES)
    assert (EXAMPLES / "design_sweep.toml").is_file()  # run by test_design_sweep_example


@pytest.mark.parametrize("name", ["tendon_robot", "pneumatic_actuator"])
def test_actuated_examples_balance(name):
    """The arm with its tendons or chambers: the rod's stress plus the actuators' shares
    balances gravity and the payload on every [s, L] (tests/test_actuation.py)."""
    sys.path.insert(0, str(Path(__file__).parent))
    from test_actuation import assert_actuated_balance

    import softarm

    case = load_case(EXAMPLES / f"{name}.toml")
    actuators = [load for load in case.loads if isinstance(load, (softarm.Tendon,
                                                                  softarm.Chamber))]
    external = [load for load in case.loads if load not in actuators]
    assert actuators and external
    assert_actuated_balance(case.arm, external, actuators)


def test_magnetic_catheter_tip_is_turned_by_the_dipole_couple():
    """A tip dipole m in a uniform field B is the tip couple (R(L) m) × B: the same arm under
    that dead couple, evaluated at the returned tip frame, has the same shape."""
    import softarm

    case, result = solve("magnetic_catheter")
    couple = np.cross(result.tip[:3, :3] @ case.arm.tip_magnet, case.loads[0].field)
    again = softarm.solve(case.arm, softarm.TipLoad(moment=couple), method="numeric",
                          s=case.solve.stations)
    np.testing.assert_allclose(result.poses, again.poses, rtol=0, atol=1e-7 * case.arm.length)
    # the field turns the magnet towards it: the tip axis gains a +y component
    assert result.tip[1, 0] > 0.5


def test_design_sweep_example():
    """The design example (run by softarm sweep) solves every case, and each equals
    softarm.solve of that case built by hand."""
    pytest.importorskip("xarray", reason="softarm.sweep.run needs pip install "
                        "'softarm[sweep]'")
    import softarm

    case = load_case(EXAMPLES / "design_sweep.toml")
    ds = softarm.sweep.run(case, fields=("tip", "positions"))
    assert ds.sizes["case"] == 60 and np.all(ds["status"].values == 0)
    for k in (0, 27, 59):
        radius = float(ds["segment[1].section.radius"][k])
        silicone = softarm.Material(2.0e6, poisson_ratio=0.49, density=1070.0)
        arm = softarm.SegmentedArm([softarm.Arm(0.25, softarm.Circle(radius), silicone),
                                    softarm.Arm(0.15, softarm.Tube(0.011, 0.005), silicone)])
        force = [0.0, float(ds["load[2].force.y"][k]), float(ds["load[2].force.z"][k])]
        eq = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=force)],
                           method="numeric", s=21)
        np.testing.assert_allclose(ds["positions"][k].values, eq.positions, rtol=0,
                                   atol=1e-12)


@pytest.mark.parametrize("name", CASES)
def test_example_solves(name):
    case, result = solve(name)
    steps = (len(case.sweep.values),) if case.sweep else ()
    assert result.batch_shape == steps
    assert np.all(np.isfinite(result.poses))
    assert result.s.size == case.solve.stations


def test_fig2_circle():
    """Paper Fig. 2 / eq. 38: τ = 3 N m on EI_y = 1 N m², L = 1 m bends the arm into a circle of
    radius 1/3 m: x = sin(κs)/κ, z = -(1 - cos κs)/κ with κ = 3 1/m."""
    _, result = solve("fig2_pure_bending")
    k, s = 3.0, result.s
    np.testing.assert_allclose(result.positions[:, 0], np.sin(k * s) / k, atol=1e-6)
    np.testing.assert_allclose(result.positions[:, 1], 0.0, atol=1e-9)
    np.testing.assert_allclose(result.positions[:, 2], -(1 - np.cos(k * s)) / k, atol=1e-6)
    np.testing.assert_allclose(result.strains[:, 4], k, rtol=1e-6)


def test_fig2_sweep_circles():
    case, result = solve("fig2_sweep")
    tau = np.asarray(case.sweep.values)  # τ = 1 ... 5 N m, curvature τ/EI (eq. 38)
    np.testing.assert_allclose(result.tip_position[:, 0], np.sin(tau) / tau, atol=1e-6)
    np.testing.assert_allclose(result.tip_position[:, 2], -(1 - np.cos(tau)) / tau, atol=1e-6)


def test_fig3_timoshenko():
    """Paper Fig. 3 (eqs. 56-59): the small-deflection tip deflection of the shear-loaded
    cantilever, w = PL³/(3 EI_y) + PL/GA_z, within 0.2 % (the exact answer is slightly smaller:
    the load parameter PL²/EI = 0.095, and Mattiasson's k = 1 value is 9.5 % below 1/3)."""
    _, result = solve("fig3_shear_load")
    P, L, EI, GA = 13.345, 0.508, 36.28, 0.9039e6
    w = P * L**3 / (3 * EI) + P * L / GA
    assert result.tip_position[2] == pytest.approx(w, rel=2e-3)
    assert result.tip_position[2] < w
    assert result.tip_position[1] == pytest.approx(0.0, abs=1e-12)


def test_mattiasson():
    """Mattiasson (1981), Table 1, k = 5: w/L = 0.71379, u/L = 0.38763
    (softarm/validation/data/mattiasson_cantilever.json)."""
    _, result = solve("mattiasson_cantilever")
    x, _, z = result.tip_position
    assert -z == pytest.approx(0.71379, abs=2e-5)
    assert 1.0 - x == pytest.approx(0.38763, abs=2e-5)


def test_precurved_arc():
    """A follower end moment about a principal axis keeps the curvature uniform:
    κ = κ⁰ + m/EI_z (paper eqs. 30-31 with initial curvature), an arc in the x-y plane."""
    case, result = solve("precurved")
    EIz = case.arm.rigidities.EIz
    k = case.arm.curvature[2] + case.loads[0].moment[2] / EIz
    assert k == pytest.approx(4.0, rel=1e-4)
    s = result.s
    np.testing.assert_allclose(result.positions[:, 0], np.sin(k * s) / k, atol=1e-6)
    np.testing.assert_allclose(result.positions[:, 1], (1 - np.cos(k * s)) / k, atol=1e-6)


def test_greenhill_upright_buckles_at_greenhills_load(capsys):
    """`softarm critical` on the upright heavy arm: the weight scaled by λ buckles it at
    q L³/EI = 7.837347438943 (Greenhill 1881; buckling.json, greenhill_heavy_column), in both
    bending planes of the round section at once (nullity 2); the case has q L³/EI = 1."""
    from conftest import reference_table

    from softarm import cli

    case = load_case(EXAMPLES / "greenhill_upright.toml")
    arm = case.arm
    q = arm.linear_density * float(np.linalg.norm(case.loads[0].acceleration))
    assert q * arm.length**3 / arm.rigidities.EIy == pytest.approx(1.0, rel=1e-12)
    assert cli.main(["critical", str(EXAMPLES / "greenhill_upright.toml")]) == 0
    out = capsys.readouterr().out
    line = next(line for line in out.splitlines() if line.startswith("critical"))
    factor = float(line.split("λc = ")[1].split()[0])
    greenhill = reference_table("buckling.json")["facts"]["greenhill_heavy_column"]["C"]
    assert factor == pytest.approx(greenhill, rel=1e-9)
    assert "(bifurcation, nullity 2; Morse index 0 -> 2)" in line
    _, result = solve("greenhill_upright")  # at λ = 1 it stands straight, and is stable
    assert result.stability.stable
    np.testing.assert_allclose(result.tip_position, [1.0, 0.0, 0.0], atol=1e-8)


def test_demo_global_equilibrium():
    """The base reaction balances all applied loads: n(0) in the spatial frame equals the tip
    force plus the weight Σ μ_i L_i g."""
    case, result = solve("demo")
    gravity, tip = case.loads
    weight = sum(a.linear_density * a.length for a in case.arm.segments) * gravity.acceleration
    np.testing.assert_allclose(result.forces_spatial[0], tip.force + weight, atol=1e-8)


def test_demo_case_ships_with_the_package():
    shipped = (resources.files("softarm") / "data" / "demo.toml").read_text()
    assert shipped == (EXAMPLES / "demo.toml").read_text()


def test_quickstart(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sys, "argv", ["quickstart.py", str(tmp_path)])
    runpy.run_path(str(EXAMPLES / "quickstart.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "tip at" in out and "written" in out
    assert (tmp_path / "fig2.csv").exists()


@pytest.mark.parametrize("name", ["table", "catheter_bend", "probe_on_surface"])
def test_contact_examples_balance(name):
    """The whole arm is in balance: the internal force at the clamp (spatial: R(0) = I)
    carries the tip force, the weight and the obstacles' forces (contact_wrench, the
    trapezoidal rule over the stations: 4801 of them resolve the narrow contact zones; at
    the example's 301 the catheter's sum is off by 2 %, at 1201 by 0.04 %; the table's by
    1e-4 at 4801)."""
    import softarm

    case = load_case(EXAMPLES / f"{name}.toml")
    result = solve_case(case, stations=4801)
    assert isinstance(case.loads[-1], softarm.Contact)
    tip = sum((np.asarray(load.force) for load in case.loads if load.kind == "tip"),
              np.zeros(3))
    weight = sum(((case.arm.linear_density or 0.0) * np.asarray(load.acceleration)
                  * case.arm.length for load in case.loads if load.kind == "gravity"),
                 np.zeros(3))
    applied = tip + weight + result.contact_wrench[:3]
    scale = np.abs(tip).max() + np.abs(weight).max() + np.abs(result.contact_wrench[:3]).max()
    np.testing.assert_allclose(result.stresses[0, :3], applied, rtol=0, atol=2e-4 * scale)
    # the obstacles carry load: far more than the balance's tolerance
    assert np.abs(result.contact_wrench[:3]).max() > 100 * 2e-4 * scale


def test_table_example_lies_on_the_table():
    """The tip rests on the table: z = -0.05 + r (within the contact distance 1e-5 L)."""
    _, result = solve("table")
    assert result.tip_position[2] == pytest.approx(-0.04, abs=1e-5 * 0.5)
    assert np.all(result.gaps > -1e-8 * 0.5)


def test_gripper_finger_example_touches_the_cylinder():
    """The finger presses on the cylinder (a contact force towards +z, up and away from its
    axis) and goes round it: its tip is below the cylinder's top (z = -0.015 m)."""
    _, result = solve("gripper_finger")
    assert result.contact_wrench[2] > 1.0
    assert result.tip_position[2] < -0.015
    assert np.min(result.gaps) > -1e-8 * 0.12


@pytest.mark.slow
def test_the_gripper_finger_example_says_what_it_shows():
    """Its comment once said the finger wraps onto the cylinder; it presses on a short patch.
    The numbers its comment gives: the free curl (κ = τ d / EI, the hand formula for a
    straight tendon, against the solver's free finger), wider than the cylinder; the loaded
    patch; the contact's total, which balances the reaction at the clamp (global balance: the
    tendon's pull is internal to the arm)."""
    import re

    import softarm

    header = (EXAMPLES / "gripper_finger.toml").read_text(encoding="utf-8").split("name =")[0]
    assert "wraps onto" not in header and "does\n# not wrap" in header
    case, result = solve("gripper_finger")
    kappa = 15.0 * 0.007 / (1.0e6 * np.pi * 0.01**4 / 4)  # τ d / EI, 1/m
    free = softarm.solve(case.arm, case.loads[:1], s=5)  # the tendon alone
    np.testing.assert_allclose(np.linalg.norm(free.strains[:, 3:], axis=-1), kappa, rtol=1e-6)
    said_kappa = float(re.search(r"κ = τ d / EI =\s*#?\s*([\d.]+) 1/m", header).group(1))
    said_radius = float(re.search(r"a circle of ([\d.]+) mm radius", header).group(1))
    assert said_kappa == pytest.approx(kappa, abs=0.05)
    assert said_radius == pytest.approx(1e3 / kappa, abs=0.5)
    assert said_radius > (0.03 + 0.01) * 1e3  # wider than the cylinder: no wrap
    first, last = (float(v) for v in re.search(r"s = (\d+)-(\d+) mm", header).groups())
    loaded = result.s[np.linalg.norm(result.contact_forces, axis=-1) > 0] * 1e3  # mm
    assert first - 0.5 <= loaded.min() and loaded.max() <= last + 0.5
    free_length = float(re.search(r"its last (\d+) mm free", header).group(1))
    assert free_length == pytest.approx(120.0 - loaded.max(), abs=1.0)
    total = float(re.search(r"([\d.]+) N in all", header).group(1))
    assert np.linalg.norm(result.contact_wrench[:3]) == pytest.approx(total, abs=0.05)
    # (the contact's resultant is integrated over the stations: 1e-4 N of the 1.6)
    np.testing.assert_allclose(result.contact_wrench[:3], result.base_wrench[:3], atol=1e-4)

"""Stability verdicts (issue 15): the Morse index of equilibria against classical buckling
results (softarm/validation/data/buckling.json) and a finite-difference determinant."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from conftest import reference_table

import softarm
from softarm import Arm, Gravity, StabilityWarning, TipLoad
from softarm.routing import Straight
from softarm.statics import Solver

BUCKLING = reference_table("buckling.json")["facts"]
# buckling.json, euler_cantilever: (2n-1)² π²/4, n = 1, 2, 3 (Euler 1744)
EULER = np.array(BUCKLING["euler_cantilever"]["P_cr_L2_over_EI"])
# buckling.json, greenhill_heavy_column: qL³/EI of modes 1 and 2 (Greenhill 1881)
GREENHILL = (BUCKLING["greenhill_heavy_column"]["C"],
             BUCKLING["greenhill_heavy_column"]["second_mode"]["C2"])


def model_critical(Q, EA, GA):
    """The extensible, shearable rod's critical force for the inextensible value Q:
    P (1 + P (1/GA - 1/EA)) = Q (buckling.json, cosserat_cantilever_extensible_shearable)."""
    c = 1.0 / GA - 1.0 / EA
    return Q if c == 0.0 else (-1.0 + np.sqrt(1.0 + 4.0 * c * Q)) / (2.0 * c)


def quiet_solve(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StabilityWarning)
        return softarm.solve(*args, **kwargs)


def _det_sign_by_differences(solver, load, eq):
    """sign det ∂r/∂x at the solution, ∂r/∂x by central differences of the shooting residual
    (400 steps): an independent route to the parity of the Morse index."""
    x = np.asarray(eq.base_wrench)
    J = np.empty((6, 6))
    for d in range(6):
        e = np.zeros(6)
        e[d] = 1e-6
        J[:, d] = (solver.shoot(load, x + e, steps=400).residual
                   - solver.shoot(load, x - e, steps=400).residual) / 2e-6
    return np.sign(np.linalg.det(J))


@pytest.mark.parametrize("EIz", [1.0, 1.7])
def test_compressed_cantilever_index_counts_the_critical_loads_below(EIz):
    # A soft arm (shear and extension lower the critical loads by ~1 %): the index of the
    # straight column is the number of critical loads below P, each plane on its own (a
    # round section counts every one twice: a double root of det Θ).
    L, EA, GA, EIy = 1.0, 400.0, 150.0, 1.0
    arm = Arm.from_stiffness(L, EA=EA, GAy=GA, GAz=GA, GJ=0.8, EIy=EIy, EIz=EIz)
    # critical loads of each bending plane (EIy: bending about y, the z deflection)
    crit = np.sort(np.concatenate([model_critical(EULER * EIy, EA, GA),
                                   model_critical(EULER * EIz, EA, GA)]))
    distinct = np.unique(crit)
    points = np.concatenate([[0.5 * distinct[0]], 0.5 * (distinct[:-1] + distinct[1:])])
    for P in points:
        k = int(np.sum(crit < P))
        eq = quiet_solve(arm, TipLoad(force=[-P, 0.0, 0.0]), method="numeric")
        assert eq.stability.index == k, (P, eq.stability)
        assert eq.stability.conservative
        assert eq.stability.stable == (k == 0)
        np.testing.assert_allclose(eq.tip_position, [L * (1 - P / EA), 0, 0], atol=1e-12)


def test_closed_form_route_also_carries_the_verdict():
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    with pytest.warns(StabilityWarning, match="Morse index 2"):
        eq = softarm.solve(arm, TipLoad(force=[-1.5 * EULER[0], 0.0, 0.0]))
    assert eq.method == "analytic.axial_force"
    assert (eq.stability.index, eq.stability.stable) == (2, False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        eq = softarm.solve(arm, TipLoad(force=[-0.9 * EULER[0], 0.0, 0.0]))
    assert eq.stability.stable


def test_batch_verdict_and_warning_name_the_case():
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    P = np.array([0.5, 1.5, 0.9, 3.0])[:, None] * EULER[0]
    with pytest.warns(StabilityWarning, match=r"load case \(1,\), and 1 more"):
        eq = softarm.solve(arm, TipLoad(force=np.concatenate([-P, 0 * P, 0 * P], 1)),
                           method="numeric")
    np.testing.assert_array_equal(eq.stability.index, [0, 2, 0, 2])
    np.testing.assert_array_equal(eq.stability.stable, [True, False, True, False])
    assert softarm.solve(arm, TipLoad(force=[-0.5, 0, 0]), stability=False).stability is None


@pytest.mark.parametrize("ratio", [0.9, 1.1, 3.0, 0.99 * GREENHILL[1] / GREENHILL[0],
                                   1.01 * GREENHILL[1] / GREENHILL[0]])
def test_upright_heavy_column(ratio):
    # Greenhill (1881): the upright round column is stable below qL³/EI = 7.8373 and has
    # index 2 (both planes) above it, 4 above the second mode 55.977 (buckling.json). The
    # sign of det ∂r/∂x is + for index 2 and 4: it alone could not tell.
    mu = 1.0
    g = ratio * GREENHILL[0]  # q = μ g with L = EI = 1
    arm = Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0,
                             mass_per_length=mu)
    eq = quiet_solve(arm, Gravity(acceleration=[-g, 0.0, 0.0]), method="numeric")
    expected = 2 * int(np.sum(g > np.array(GREENHILL) * (1 + 1e-9)))
    assert eq.stability.index == expected
    assert eq.stability.stable == (expected == 0)


def test_index_parity_is_the_sign_of_a_finite_difference_determinant():
    # (-1)^index = sign det ∂r/∂x: the shooting map differentiated by central differences
    arm = Arm.from_stiffness(1.0, EA=300.0, GAy=100.0, GAz=100.0, GJ=0.8, EIy=1.0, EIz=1.6)
    solver = Solver(arm)
    for P in (1.0, 3.0, 4.5, 12.0):
        load = TipLoad(force=[-P, 0.1 * P, 0.05 * P])
        eq = quiet_solve(arm, load, method="numeric")
        assert (-1) ** eq.stability.index == _det_sign_by_differences(solver, load, eq), P


def test_buckled_branch_is_stable_and_straight_one_is_not():
    # The elastica past P_cr: a tiny lateral force selects the buckled branch, which is
    # stable; the straight equilibrium under the same axial force is not.
    arm = Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0)
    P = 2.0 * EULER[0]
    bent = softarm.solve(arm, TipLoad(force=[-P, 0.05, 0.0]), method="numeric")
    assert bent.stability.stable and abs(bent.tip_position[1]) > 0.5
    straight = quiet_solve(arm, TipLoad(force=[-P, 0.0, 0.0]), method="numeric")
    assert straight.stability.index == 2


def test_mattiasson_cantilever_k10_is_stable():
    # Mattiasson (1981), k = PL²/EI = 10, transverse dead tip force: a stable equilibrium
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    eq = softarm.solve(arm, TipLoad(force=[0.0, 0.0, 10.0]), method="numeric")
    assert eq.stability.stable


def test_follower_load_is_nonconservative_never_buckled():
    # Beck's column (buckling.json): a tangential tip force has no static critical load, it
    # flutters at 20.05 EI/L². Beyond it the static test finds no conjugate point, and the
    # verdict says it cannot decide (conservative False), never "buckled".
    arm = Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        eq = softarm.solve(arm, TipLoad(force=[-30.0, 0.0, 0.0], follower=True),
                           method="numeric")
    assert (eq.stability.index, eq.stability.conservative, eq.stability.stable) == \
        (0, False, False)


def test_dead_tip_couple_is_reported_nonconservative():
    arm = Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0)
    eq = softarm.solve(arm, TipLoad(moment=[0.0, 1.0, 0.0]), method="numeric")
    assert not eq.stability.conservative and not eq.stability.stable


def test_a_centred_tendon_never_buckles_the_arm():
    # A frictionless tendon threaded along the centreline compresses the arm but cannot
    # buckle it, whatever its tension (the classical result for a beam prestressed by a
    # tendon bonded or ducted along it: the tendon follows the axis); the same force as a
    # dead tip load buckles it.
    arm = Arm.from_stiffness(1.0, EA=1e4, GAy=1e4, GAz=1e4, GJ=1.0, EIy=1.0, EIz=1.0)
    tension = 10.0 * EULER[0]
    eq = softarm.solve(arm, softarm.Tendon(tension, Straight(0.0, 0.0)), method="numeric")
    assert eq.stability.conservative and eq.stability.index == 0
    dead = quiet_solve(arm, TipLoad(force=[-tension, 0.0, 0.0]), method="numeric")
    assert dead.stability.index == 4


# ------------------------------------------------------------------ critical loads, branches

def test_euler_critical_load_of_a_soft_arm_and_its_mode():
    # buckling.json: P (1 + P (1/GA - 1/EA)) = π²EI/(4L²) for the extensible, shearable rod
    L, EA, GA = 1.0, 300.0, 100.0
    arm = Arm.from_stiffness(L, EA=EA, GAy=GA, GAz=GA, GJ=0.8, EIy=1.0, EIz=1.0)
    point = softarm.critical_load(arm, TipLoad(force=[-1.0, 0.0, 0.0]))
    assert point.factor == pytest.approx(model_critical(EULER[0], EA, GA), rel=1e-8)
    assert (point.kind, point.nullity) == ("bifurcation", 2)
    # the null vector: the base force does not change (a dead load), the base moment does
    assert np.allclose(point.mode.base_reaction[:, :3], 0.0, atol=1e-9)
    assert np.all(np.linalg.norm(point.mode.base_reaction[:, 3:], axis=1) > 0.1)


def test_euler_mode_shape_is_one_minus_cosine():
    # buckling.json: w(x) = 1 - cos(π x / 2L) (inextensible: a very stiff EA, GA)
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=2.0)
    point = softarm.critical_load(arm, TipLoad(force=[-1.0, 0.0, 0.0]))
    assert point.factor == pytest.approx(EULER[0], rel=1e-8)
    assert point.nullity == 1
    w = point.mode.displacement[0]
    lateral = w[:, 2]  # bending about y (the soft axis EIy): deflection along z
    np.testing.assert_allclose(lateral, 1 - np.cos(np.pi * point.mode.s / 2), atol=1e-6)
    np.testing.assert_allclose(w[:, :2], 0.0, atol=1e-6)


def test_greenhill_critical_weight():
    # buckling.json: qL³/EI = 7.837347438943 (inextensible limit; EA = GA = 1e9 EI/L² shift
    # it by ~1e-9)
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0,
                             mass_per_length=1.0)
    point = softarm.critical_load(arm, Gravity(acceleration=[-1.0, 0.0, 0.0]))
    assert point.factor == pytest.approx(GREENHILL[0], rel=1e-6)
    assert point.nullity == 2


def test_heavy_column_with_a_tip_load_only_the_tip_load_varies():
    # buckling.json, heavy_column_with_tip_load: qL³/EI = 3 held, P_cr L²/EI = 1.55601544419
    # (the Airy-function solution)
    fact = BUCKLING["heavy_column_with_tip_load"]["example"]
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0,
                             mass_per_length=1.0)
    weight = Gravity(acceleration=[-fact["q_L3_over_EI"], 0.0, 0.0])
    tip = TipLoad(force=[-1.0, 0.0, 0.0])
    point = softarm.critical_load(arm, [weight, tip], vary=tip)
    assert point.factor == pytest.approx(fact["P_cr_L2_over_EI"], rel=1e-6)


def test_prandtl_lateral_torsional_buckling():
    # buckling.json: P_cr = 4.0126 √(EI_weak GJ)/L² for EI_strong → ∞; EI_strong = 1e6 EI_weak
    # raises it by about (EI_weak + GJ)/(2 EI_strong) ~ 1e-6 (the note there)
    C = BUCKLING["prandtl_lateral_torsional_cantilever"]["C"]
    EIw, GJ = 1.0, 0.5
    arm = Arm.from_stiffness(1.0, EA=1e10, GAy=1e10, GAz=1e10, GJ=GJ, EIy=EIw, EIz=1e6)
    point = softarm.critical_load(arm, TipLoad(force=[0.0, 1.0, 0.0]))
    assert point.factor == pytest.approx(C * np.sqrt(EIw * GJ), rel=1e-4)
    assert (point.kind, point.nullity) == ("bifurcation", 1)


def test_no_static_critical_load_for_a_follower_force():
    arm = Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0)
    with pytest.raises(ValueError, match="flutter"):
        softarm.critical_load(arm, TipLoad(force=[-1.0, 0.0, 0.0], follower=True))


def test_no_critical_load_under_tension():
    arm = Arm.from_stiffness(1.0, EA=1e4, GAy=1e4, GAz=1e4, GJ=1.0, EIy=1.0, EIz=1.0)
    assert softarm.critical_load(arm, TipLoad(force=[1.0, 0.0, 0.0]), max_factor=50) is None


def test_continuation_finds_euler_modes_1_to_3_and_the_buckled_branch():
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    branch = softarm.continuation(arm, TipLoad(force=[-EULER[0], 0.0, 0.0]), lam=(0, 26))
    factors = [c.factor for c in branch.critical]
    np.testing.assert_allclose(factors, EULER / EULER[0], rtol=1e-7)
    assert [c.nullity for c in branch.critical] == [2, 2, 2]
    np.testing.assert_array_equal(np.unique(branch.index), [0, 2, 4, 6])
    assert branch.lam[-1] == 26.0
    # the first mode's branch, followed to λ = 3.105361984277 (buckling.json, α = 150°)
    row = BUCKLING["elastica_postbuckling_cantilever"]["table"][14]
    bent = branch.switch(0, lam=row["P_over_Pcr"], imperfection=[0.0, 1.0, 0.0])
    assert bent.lam[-1] == row["P_over_Pcr"]
    assert np.all(bent.index[1:] == 0)
    np.testing.assert_allclose(bent.equilibria.tip_position[-1],
                               [row["x_over_L"], row["delta_over_L"], 0.0], atol=1e-7)


@pytest.mark.parametrize("row", [0, 5, 8, 14, 17])
def test_stable_branch_matches_the_elastica_table(row):
    # buckling.json, elastica_postbuckling_cantilever (Timoshenko & Gere §2.7; elliptic
    # integrals to 13 digits): tip deflection δ/L and x/L at P/P_cr, to 1e-8 L
    row = BUCKLING["elastica_postbuckling_cantilever"]["table"][row]
    arm = Arm.from_stiffness(1.0, EA=1e11, GAy=1e11, GAz=1e11, GJ=1.0, EIy=1.0, EIz=1.0)
    load = TipLoad(force=[-row["P_over_Pcr"] * EULER[0], 0.0, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        eq = softarm.solve(arm, load, branch="stable", imperfection=[0.0, 0.0, -1.0])
    assert eq.stability.stable
    np.testing.assert_allclose(eq.tip_position, [row["x_over_L"], 0.0, -row["delta_over_L"]],
                               atol=1e-8)


def test_stable_branch_is_the_connected_one_when_that_is_stable():
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    load = TipLoad(force=[0.0, 0.0, 10.0])
    a = softarm.solve(arm, load, branch="stable")
    b = softarm.solve(arm, load)
    assert a.stability.stable
    np.testing.assert_allclose(a.poses, b.poses, atol=1e-8)


def test_upright_soft_arm_example(tmp_path, monkeypatch):
    # examples/upright_arm.py (docs/stability.md): runs, draws, and its numbers hold: the
    # critical length agrees with Greenhill's (7.8373 EI/q)^(1/3) to the shift of extension
    # and shear (silicone: q L / EA ~ 1e-3)
    import runpy
    import sys
    from pathlib import Path

    pytest.importorskip("matplotlib")
    monkeypatch.setattr(sys, "argv", ["upright_arm.py", str(tmp_path)])
    script = Path(__file__).resolve().parents[1] / "examples" / "upright_arm.py"
    names = runpy.run_path(str(script), run_name="__main__")
    assert (tmp_path / "stability_upright.png").stat().st_size > 10_000
    greenhill = (GREENHILL[0] * names["EI"] / names["q"]) ** (1 / 3)
    critical = 0.15 * names["point"].factor ** (1 / 3)
    assert critical == pytest.approx(greenhill, rel=2e-3)
    assert names["short"].stability.stable
    assert names["straight"].stability.index == 2
    assert names["fallen"].stability.stable
    assert names["fallen"].tip_position[2] < 0.0  # it has fallen over


def test_magnetic_gradient_sweep_parity_and_conservative():
    # a hard-magnet arm in a field with a gradient: the sweep seeds translations too (6
    # columns); its index parity is the sign of a finite-difference det ∂r/∂x, and magnets,
    # tendons and chambers are conservative
    G = np.array([[0.0, 0.3, 0.0], [0.3, 0.0, 0.0], [0.0, 0.0, 0.0]])
    arm = Arm.from_stiffness(1.0, EA=300.0, GAy=100.0, GAz=100.0, GJ=0.8, EIy=1.0, EIz=1.3,
                             magnetization=(2.0, 0.0, 0.0))
    solver = Solver(arm)
    for B in ((-3.0, 0.2, 0.0), (-6.0, 0.1, 0.3)):
        load = softarm.MagneticField(field=B, gradient=G)
        eq = quiet_solve(arm, load, method="numeric")
        assert eq.stability.conservative
        assert (-1) ** eq.stability.index == _det_sign_by_differences(solver, load, eq), B
    # a magnetisation along the axis in a uniform field against it: like a compressive load,
    # m B L²/EI = 2 × 3 = 6 > π²/4 (the magnetic torque density m × B), so index > 0
    eq = quiet_solve(arm, softarm.MagneticField(field=(-3.0, 0.0, 0.0)), method="numeric")
    assert eq.stability.index > 0
    soft = Arm.from_stiffness(1.0, EA=1e4, GAy=1e4, GAz=1e4, GJ=1.0, EIy=1.0, EIz=1.0)
    chamber = softarm.Chamber(pressure=1e4, area=1e-4, routing=Straight(0.0, 0.01))
    eq = softarm.solve(soft, chamber, method="numeric")
    assert eq.stability.conservative and eq.stability.stable


def test_branch_stable_refuses_a_batch():
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    with pytest.raises(ValueError, match="single load case"):
        softarm.solve(arm, TipLoad(force=[[-3.0, 0, 0], [-4.0, 0, 0]]), branch="stable")
    with pytest.raises(ValueError, match="branch must be"):
        softarm.solve(arm, TipLoad(force=[-3.0, 0, 0]), branch="unstable")


CASE = """
name = "column"
[arm]
length = 1.0
stiffness = {{ EA = 1.0e9, GAy = 1.0e9, GAz = 1.0e9, GJ = 1.0, EIy = 1.0, EIz = 1.0 }}
[[load]]
kind = "tip"
force = [{force}, 0.0, 0.0]
[solve]
method = "numeric"
{branch}
"""


def test_cli_critical_and_the_stable_branch_in_a_case_file(tmp_path, capsys):
    from softarm.cli import main

    path = tmp_path / "column.toml"
    path.write_text(CASE.format(force=-1.0, branch=""))
    assert main(["critical", str(path)]) == 0
    out = capsys.readouterr().out
    # Euler: λc = π²/4 (buckling.json), nullity 2 on a round section
    assert "λc = 2.4674011003" in out and "bifurcation, nullity 2" in out
    path.write_text(CASE.format(force=-1.5 * EULER[0], branch=""))
    assert main(["solve", str(path)]) == 0
    captured = capsys.readouterr()
    assert "UNSTABLE (Morse index 2" in captured.out
    assert captured.err.startswith("softarm: warning:") and captured.err.count("\n") == 1
    path.write_text(CASE.format(force=-1.5 * EULER[0], branch='branch = "stable"'))
    assert main(["solve", str(path)]) == 0
    captured = capsys.readouterr()
    assert "stability stable (Morse index 0)" in captured.out and captured.err == ""
    path.write_text(CASE.format(force=-1.0, branch="").replace('kind = "tip"',
                                                                'kind = "tip"\nfollower = true'))
    assert main(["critical", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "flutter" in err


@pytest.mark.slow
def test_closed_form_axial_index_agrees_with_the_count_and_the_sweep():
    # the closed form's index (a formula) and the numerical route's (the sweep) against the
    # count of the model's critical loads below P, over a range reaching index 5
    arm = Arm.from_stiffness(1.0, EA=400.0, GAy=150.0, GAz=120.0, GJ=0.8, EIy=1.0, EIz=1.7)
    P = np.linspace(0.1, 70.0, 60)
    crit = np.concatenate([model_critical(EULER * 1.0, 400.0, 120.0),
                           model_critical(EULER * 1.7, 400.0, 150.0)])
    expected = (P[:, None] > crit[None, :]).sum(1)
    force = np.column_stack([-P, 0 * P, 0 * P])
    closed = quiet_solve(arm, TipLoad(force=force), s=11)
    numeric = quiet_solve(arm, TipLoad(force=force), s=11, method="numeric")
    assert closed.method == "analytic.axial_force"
    np.testing.assert_array_equal(closed.stability.index, expected)
    np.testing.assert_array_equal(numeric.stability.index, expected)


def test_the_live_app_shows_the_verdict():
    # an upright heavy column (gravity along -e1), qL³/EI = 10 above Greenhill's 7.8373
    # (buckling.json): the live app's reply says it is unstable (index 2: a round section
    # buckles in two planes at once); at qL³/EI = 5 it says stable
    import tomllib

    from softarm.app import LiveCase
    from softarm.case import parse_case

    text = """
[arm]
length = 1.0
stiffness = { EA = 1e9, GAy = 1e9, GAz = 1e9, GJ = 1.0, EIy = 1.0, EIz = 1.0 }
mass_per_length = {mu}
[[load]]
kind = "gravity"
acceleration = [-1.0, 0.0, 0.0]
"""
    unstable = LiveCase(parse_case(tomllib.loads(text.replace("{mu}", "10.0")))).solve()
    assert unstable["stability"].startswith("UNSTABLE (Morse index 2")
    stable = LiveCase(parse_case(tomllib.loads(text.replace("{mu}", "5.0")))).solve()
    assert stable["stability"] == "stable (Morse index 0)"

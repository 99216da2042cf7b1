"""Multiple shooting (issue 31): the stiff route's verdicts, its agreement with single
shooting where both work, equilibrium at every station, its errors. The references of the
stiff regime itself (linear tension theory, the separatrix of a hard pull, hanging arms
against solve_bvp) are in test_stiff_tension.py and test_stiff_hanging.py."""

import time

import numpy as np
import pytest

import softarm
from softarm import Arm, Circle, DistributedForce, Gravity, Material, TipLoad
from softarm.statics.solver import Solver

ROD = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
NUDGE = DistributedForce([0.0, 0.0, 0.0])  # (keeps a tip-load case on the numerical route)


def pull(F, lateral=1e-3):
    return [TipLoad(force=[F, 0.0, lateral * F]), NUDGE]


@pytest.mark.parametrize(("P", "index"), [(5.0, 2), (30.0, 4)])
def test_the_verdict_of_a_compressed_column_is_the_same_on_both_routes(P, index):
    # the straight column under P L²/EI = 5 and 30 has lost stability at (2n - 1)² π²/4 in
    # each of its two bending planes: once (2.47) and twice (2.47, 22.2)
    assert sum(2 for n in (1, 2, 3) if (2 * n - 1) ** 2 * np.pi ** 2 / 4 < P) == index
    for shooting in ("single", "multiple"):
        eq = Solver(ROD, s=5, shooting=shooting).solve([TipLoad(force=[-P, 0.0, 0.0]), NUDGE])
        assert int(eq.stability.index) == index


@pytest.mark.parametrize("F", [1e3, 1e6])
def test_a_rod_in_strong_tension_is_stable(F):
    eq = softarm.solve(ROD, pull(F))
    assert eq.stability.stable
    assert int(eq.stability.index) == 0


@pytest.mark.parametrize("F", [100.0, 150.0])
def test_both_routes_agree_where_single_shooting_still_works(F):
    # kL = 10 and 12: single shooting's growth e^{kL} still leaves it 1e-8 L; the intervals
    # of the multiple-shooting route cut the arm in 2 and 3
    loads = [TipLoad(force=[0.5 * F, 0.0, F]), NUDGE]
    single = Solver(ROD, s=11, shooting="single").solve(loads)
    multiple = Solver(ROD, s=11, shooting="multiple").solve(loads)
    assert np.abs(single.positions - multiple.positions).max() < 1e-9
    assert np.abs(single.stresses - multiple.stresses).max() < 1e-6 * F


def test_a_hanging_hose_carries_the_weight_below_every_station():
    # a 3 m silicone hose (qL³/EI = 7.6e3, kL = 87): n(s) = ∫_s^L f = -q (L - s) e_z at
    # every station (n' = -f, n(L) = 0), spatial, from the material stresses rotated by R(s)
    L, q = 3.0, 1070.0 * np.pi * 1e-4 * 9.81
    arm = Arm(L, Circle(0.01), Material(1.5e6, poisson_ratio=0.49, density=1070.0))
    eq = softarm.solve(arm, [Gravity([0.0, 0.0, -9.81])], s=31)
    n = np.einsum("sij,sj->si", eq.poses[:, :3, :3], eq.stresses[:, :3])
    expected = np.zeros_like(n)
    expected[:, 2] = -q * (L - eq.s)
    assert np.abs(n - expected).max() < 1e-9 * q * L
    assert eq.error_estimate <= 1e-8 * L


def test_a_chained_solver_gives_the_unchained_answer_of_a_stiff_case():
    solver = Solver(ROD, s=5)
    solver.solve(pull(1.0))
    chained = solver.solve(pull(1e5))
    alone = softarm.solve(ROD, pull(1e5), s=5)
    assert np.abs(chained.positions - alone.positions).max() < 1e-12
    again = solver.solve(pull(2.0))  # from the unloaded arm again, as after a reset
    assert np.abs(again.positions - softarm.solve(ROD, pull(2.0), s=5).positions).max() < 1e-9


def test_a_stiff_failure_is_fast_and_says_what_was_reached():
    solver = Solver(ROD, s=5, max_shootings=3)
    start = time.process_time()
    with pytest.raises(softarm.ConvergenceError, match="max_shootings=3") as caught:
        solver.solve(pull(1e6))
    assert time.process_time() - start < 2.0
    assert caught.value.load_factor < 1.0


def test_the_shooting_route_is_checked():
    with pytest.raises(ValueError, match="shooting must be 'auto', 'single' or 'multiple', "
                                         "got 'double'"):
        Solver(ROD, shooting="double")




@pytest.mark.slow  # the stiff route with Jacobians: a compile no other default test needs
def test_the_compliance_under_strong_tension_is_the_finite_difference():
    # kL = 100 (F L²/EI = 1e4): the block system's implicit function against central
    # differences of tight solves
    force = np.array([1e4, 0.0, 100.0])
    eq = softarm.solve(ROD, [TipLoad(force=force), NUDGE], jacobians=True, s=3)
    h = 10.0  # (1e-3 of F: the truncation ~1e-6 relative, the solves' 1e-12 L ~1e-7)
    tight = Solver(ROD, s=3, tol=1e-12, stability=False)
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        plus = tight.solve([TipLoad(force=force + step), NUDGE]).tip_position
        minus = tight.solve([TipLoad(force=force - step), NUDGE]).tip_position
        column = (plus - minus) / (2 * h)
        assert np.abs(eq.tip_compliance[:3, k] - column).max() < 1e-5 * np.abs(column).max()
        assert np.array_equal(eq.compliance[-1], eq.tip_compliance)


@pytest.mark.slow  # the stiff actuated route with Jacobians: a compile no other default test needs
def test_a_tendon_robot_under_large_tensions_solves_alike_on_both_routes():
    # tendons at τ L²/EI = 2500 (kL = 50 by the tension): the backbone is compressed, so
    # single shooting still works; both routes agree, and their actuation Jacobians are
    # the central differences
    arm = Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0)
    routes = (softarm.routing.Straight(0.0, 1e-3), softarm.routing.Straight(1e-3, 0.0))

    def loads(t1, t2):
        return [softarm.Tendon(t1, routes[0]), softarm.Tendon(t2, routes[1]),
                TipLoad(force=[0.0, 0.5, 0.0])]

    tau = np.array([2500.0, 750.0])
    results = [Solver(arm, s=3, shooting=shooting).solve(loads(*tau), jacobians=True)
               for shooting in ("single", "multiple")]
    # (each within tol = 1e-8 L of the exact answer: within 2e-8 L of each other)
    assert np.abs(results[0].positions - results[1].positions).max() < 2e-8
    tight = Solver(arm, s=3, tol=1e-12, stability=False, shooting="multiple")
    h = 1e-3
    for k in range(2):
        step = np.zeros(2)
        step[k] = h
        # (each from the unloaded arm: a chained pair would start its second solve from
        # the first's grid, and the difference would hold the grids' 1e-12 L, not cancel it)
        column = (tight.solve_from_unloaded(loads(*(tau + step))).tip_position
                  - tight.solve_from_unloaded(loads(*(tau - step))).tip_position) / (2 * h)
        for eq in results:
            assert np.abs(eq.actuation_jacobian[:3, k] - column).max() < 1e-8 * np.abs(column).max()


def _tensioned_rod_tip(T, q, P, EI, EA, GA, L):
    """The lateral tip deflection of a clamped, extensible and shearable rod under an axial
    tension T, a lateral load q per length and a lateral tip force P (planar, linear in the
    rotation θ of the sections). The lateral internal force is n_z = q (L - s) + P; the
    strains v1 = 1 + T/EA, v3 = (n_z - T θ)/GA give w' = v1 θ + v3, and the moment balance
    m' = -p' × n with m = -EI θ' gives θ'' = K² (θ - n_z/T), K² = c T/EI, c = v1 - T/GA,
    θ(0) = 0, θ'(L) = 0. So θ = n_z/T + c1 cosh Ks + c2 sinh Ks, c1 = -(qL + P)/T,
    c2 = q/(T K cosh KL) - c1 tanh KL, and w(L) = c ∫θ + ∫n_z/GA, written without
    cosh KL (which overflows)."""
    c = 1.0 + T / EA - T / GA
    K = np.sqrt(c * T / EI)
    c1 = -(q * L + P) / T
    moment = q * L * L / 2 + P * L  # ∫ n_z ds
    integral = moment / T + c1 * np.tanh(K * L) / K + q * (1.0 - 1.0 / np.cosh(K * L)) / (T * K * K)
    return c * integral + moment / GA


@pytest.mark.parametrize(("radius", "length", "T"), [(2e-4, 1.0, 5.0), (2.5e-4, 1.5, 5.0),
                                                     (5e-4, 2.0, 40.0)])
def test_a_nitinol_guide_wire_in_tension_under_its_weight(radius, length, T):
    # a horizontal nitinol wire (E 60 GPa, ρ 6450 kg/m³) under gravity, a tip tension T and
    # a lateral tip force of 10 mN: kL = 233-258; against the linear theory of a rod in
    # tension (slopes qL/T + P/T below 3e-3: the nonlinear terms below 1e-8 L)
    wire = Arm(length, Circle(radius), Material(60e9, poisson_ratio=0.33, density=6450.0))
    rigidities = wire.rigidities
    EI = rigidities.EIy
    q = -6450.0 * np.pi * radius ** 2 * 9.81
    P = 0.01
    assert length * np.sqrt(T / EI) > 200
    eq = softarm.solve(wire, [Gravity([0.0, 0.0, -9.81]), TipLoad(force=[T, 0.0, P])], s=3)
    w = _tensioned_rod_tip(T, q, P, EI, rigidities.EA, rigidities.GAz, length)
    assert abs(eq.tip_position[2] - w) < 1e-7 * length
    assert eq.stability.stable


@pytest.mark.slow  # the verdict of a given state: a compile no other default test needs
@pytest.mark.parametrize("F", [1e3, 1e4])
def test_the_closed_form_of_a_rod_in_tension_is_stable(F):
    # the elastica's closed form (a tip force alone) under kL = 32 and 100: its verdict's
    # sweep takes the closed form's states (integrated backwards they grow like e^{kL}, and
    # it reported Morse index 15 at kL = 100, with a StabilityWarning, an error here)
    eq = softarm.solve(ROD, [TipLoad(force=[F, 0.0, 1e-3 * F])])
    assert eq.method.startswith("analytic")
    w = _tensioned_rod_tip(F, 0.0, 1e-3 * F, 1.0, 1e6, 1e6, 1.0)
    assert abs(eq.tip_position[2] - w) < 1e-8
    assert eq.stability.stable


@pytest.mark.slow  # the stiff actuated route with Jacobians: a compile no other default test needs
def test_the_control_loop_solves_a_tendon_arm_under_a_strong_pull():
    # a tendon arm pulled at its tip by 3 kN (kL = 55): ForwardSolver's call takes the
    # multiple-shooting route from the unloaded arm; the same equilibrium as softarm.solve,
    # and its actuation Jacobian the central differences of tight solves
    arm = Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0)
    routes = (softarm.routing.Straight(0.0, 1e-2), softarm.routing.Straight(1e-2, 0.0))
    pull_ = TipLoad(force=[3000.0, 0.0, 1.0])

    def loads(t1, t2):
        return [softarm.Tendon(t1, routes[0]), softarm.Tendon(t2, routes[1]), pull_]

    model = softarm.ForwardSolver(arm, [softarm.Tendon(0.0, r) for r in routes], [pull_])
    for q in ([10.0, 5.0], [12.0, 6.0]):
        result = model.solve(q)
        alone = softarm.solve(arm, loads(*q))
        assert np.abs(result.tip_position - alone.tip_position).max() < 1e-12
        assert result.stability.stable
    tight = Solver(arm, s=2, tol=1e-12, stability=False)
    h = 1e-2
    for k in range(2):
        step = np.zeros(2)
        step[k] = h
        column = (tight.solve(loads(*(np.array(q) + step))).tip_position
                  - tight.solve(loads(*(np.array(q) - step))).tip_position) / (2 * h)
        assert np.abs(result.actuation_jacobian[:3, k] - column).max() < 1e-6 * np.abs(column).max()

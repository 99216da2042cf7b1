"""Actuation: tendons (Rucker & Webster 2011 in total-wrench form), pneumatic chambers (the
rigid-section fluid wrench) and hard magnets in a magnetic field, in the numerical solver.

References, none of them the library's solver:

- the constant-strain closed forms (the arm under its tendons or chambers alone carries no
  total wrench, so the strain solves an algebraic equation, solved here with
  ``scipy.optimize.root``; poses by ``scipy.linalg.expm`` of the SE(3) twist), including
  tendons that end mid-arm (a product of exponentials) and the helical tendon's exact helix;
- peer codes' outputs, run at stated commits (softarm/validation/data/actuation_benchmarks.json):
  Till & Rucker's ContinuumRobotExamples (straight and helical 4-tendon robots under gravity)
  and tdcr-modeling's two-segment Cosserat example;
- the Mattiasson (1981) elastica table: a uniformly, axially magnetised rod in a uniform field
  is exactly the inextensible elastica under the dead tip force m_l B;
- global balance of the arm with its actuators (the total base wrench against the external
  loads), and central finite differences of the shooting residual for every new tangent
  term.
"""

from __future__ import annotations

import json
import warnings
from importlib import resources

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.linalg import expm
from scipy.optimize import root

import softarm
from softarm import Arm, Chamber, Gravity, MagneticField, SegmentedArm, Tendon, TipLoad
from softarm.routing import Helix, Polynomial, Straight


def _data(name):
    return json.loads(resources.files("softarm.validation.data").joinpath(name).read_text())


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def twist(eps):
    """The 4 × 4 matrix of the body strain (v; u)."""
    X = np.zeros((4, 4))
    X[:3, :3] = hat(eps[3:])
    X[:3, 3] = eps[:3]
    return X


def constant_strain(K, f0, tendons, chambers=()):
    """The root ε of K (ε - f0) + Σ τ (t; r × t) = Σ_c q (e1; r × e1), t = w/|w|, w = v + u × r
    + r' (tendons: (τ, r, r'); chambers: (pA, r)), by scipy's root finder from f0."""
    wrench = np.zeros(6)
    for q, r in chambers:
        wrench += q * np.concatenate([[1.0, 0.0, 0.0], np.cross(r, [1.0, 0.0, 0.0])])

    def residual(eps):
        out = K @ (eps - f0) - wrench
        for tau, r, dr in tendons:
            w = eps[:3] + np.cross(eps[3:], r) + dr
            t = w / np.linalg.norm(w)
            out += tau * np.concatenate([t, np.cross(r, t)])
        return out

    eps = root(residual, f0, method="lm", options={"xtol": 1e-15, "ftol": 1e-15}).x
    assert np.max(np.abs(residual(eps))) < 1e-9 * np.max(np.abs(K))
    return eps


def numeric(arm, loads, **options):
    return softarm.solve(arm, loads, method="numeric", **options)


STEEL = dict(EA=67858.40131753951, GAy=26099.4, GAz=26099.4, GJ=0.0047, EIy=0.006107256118578555,
             EIz=0.006107256118578555)


# ============================================================================================
# Closed forms: constant strain
# ============================================================================================

def test_straight_tendon_arc_from_the_reference_example():
    # actuation_benchmarks.json, closed_forms[0].example_evaluated_here: EA, EI, L = 0.25 m,
    # τ = 3 N at r = (0, 0, 0.008): u = (0, -3.92975..., 0), axial strain -4.42e-5
    example = _data("actuation_benchmarks.json")["closed_forms"][0]["example_evaluated_here"]
    EA, EI, L = example["EA"], example["EI"], example["L"]
    arm = Arm.from_stiffness(L, EA=EA, GAy=EA, GAz=EA, GJ=EI, EIy=EI, EIz=EI)
    eq = numeric(arm, Tendon(example["tension"], Straight(*example["offset_material"][1:])),
                 tol=1e-10)
    np.testing.assert_allclose(eq.tip_position, example["tip_position"], rtol=0, atol=1e-8 * L)
    np.testing.assert_allclose(eq.poses[-1, :3, :3], example["tip_rotation"], atol=1e-8)
    np.testing.assert_allclose(eq.strains[:, 4], example["curvature_u"][1], rtol=1e-9)
    np.testing.assert_allclose(eq.strains[:, 0], example["axial_strain"], rtol=1e-7)


def test_tendons_on_a_coupled_stiffness_have_constant_strain_at_every_station():
    # a full symmetric positive-definite K (fibre-reinforced: extension-twist and
    # shear-bending couplings): t is no longer e1, the root is found by scipy's root finder
    K = np.diag([2.0e3, 8.0e2, 9.0e2, 2.0e-3, 3.0e-3, 3.5e-3])
    K[0, 3] = K[3, 0] = 0.6
    K[1, 5] = K[5, 1] = 0.2
    K[2, 4] = K[4, 2] = -0.25
    L = 0.2
    arm = Arm.from_stiffness_matrix(L, K, curvature=(0.0, 1.0, 0.0))
    tendons = [Tendon(1.5, Straight(0.004, 0.003)), Tendon(0.7, Straight(-0.005, 0.0))]
    eq = numeric(arm, tendons, s=21, tol=1e-11)
    f0 = arm.reference_strain
    eps = constant_strain(K, f0, [(1.5, np.array([0.0, 0.004, 0.003]), np.zeros(3)),
                                  (0.7, np.array([0.0, -0.005, 0.0]), np.zeros(3))])
    expected = np.array([expm(s * twist(eps)) for s in eq.s])
    np.testing.assert_allclose(eq.poses, expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(eq.strains, np.broadcast_to(eps - f0, (21, 6)), rtol=0,
                               atol=1e-10 * np.max(np.abs(eps - f0)))
    # no external load: the total wrench vanishes, the rod's own stress is K (ε - f0)
    np.testing.assert_allclose(eq.base_wrench, 0.0, atol=1e-10)
    np.testing.assert_allclose(eq.stresses, np.broadcast_to(K @ (eps - f0), (21, 6)),
                               rtol=0, atol=1e-9 * 1.5)


def test_tendons_ending_mid_arm_are_a_product_of_exponentials():
    arm = SegmentedArm([Arm.from_stiffness(0.15, **STEEL), Arm.from_stiffness(0.1, **STEEL)])
    loads = [Tendon(2.0, Straight(0.0, 0.008), end=0.15), Tendon(1.0, Straight(0.008, 0.0)),
             Tendon(0.5, Straight(-0.004, -0.004), end=0.2)]
    s = np.linspace(0.0, 0.25, 26)
    eq = numeric(arm, loads, s=s, tol=1e-11)
    K = np.diag(list(STEEL.values()))
    f0 = np.array([1.0, 0, 0, 0, 0, 0])
    all_ = [(2.0, np.array([0, 0, 0.008]), np.zeros(3)), (1.0, np.array([0, 0.008, 0]),
                                                            np.zeros(3)),
            (0.5, np.array([0, -0.004, -0.004]), np.zeros(3))]
    pieces = [(0.0, 0.15, all_), (0.15, 0.2, all_[1:]), (0.2, 0.25, all_[1:2])]
    start = np.eye(4)
    expected = []
    for s0, s1, active in pieces:
        X = twist(constant_strain(K, f0, active))
        for si in s:
            if s0 <= si < s1 or (si == s1 == 0.25):
                expected.append(start @ expm((si - s0) * X))
        start = start @ expm((s1 - s0) * X)
    np.testing.assert_allclose(eq.poses, np.array(expected), rtol=0, atol=1e-10)
    # each tendon's length change: the integral of |w| - 1 (here t = e1, |w| = v1 + u × r)
    change = eq.tendon_length_changes
    assert change.shape == (3,)
    eps0 = constant_strain(K, f0, all_)
    w0 = eps0[0] + eps0[4] * 0.008  # tendon 0 on the first 0.15 m: v1 + u_y z
    np.testing.assert_allclose(change[0], 0.15 * (w0 - 1.0), rtol=1e-9)


def test_chambers_bend_the_arm_away_exactly_for_any_stiffness():
    # ε = f0 + K⁻¹ Σ p A (e1; r × e1) on the chambers' spans, for a coupled K
    K = np.diag([4.0e2, 1.5e2, 1.5e2, 4.0e-4, 6.0e-4, 6.0e-4])
    K[0, 4] = K[4, 0] = 0.05
    L = 0.3
    arm = Arm.from_stiffness_matrix(L, K)
    p, area = 2.0e4, 2.0e-5
    loads = [Chamber(p, area, Straight(0.0, 0.006)),
             Chamber(0.5 * p, area, Straight(0.006, 0.0), start=0.1, end=0.2)]
    s = np.linspace(0.0, L, 31)
    eq = numeric(arm, loads, s=s, tol=1e-11)
    f0 = arm.reference_strain
    W = [p * area * np.array([1, 0, 0, 0, 0.006, 0.0]),
         0.5 * p * area * np.array([1, 0, 0, 0, 0.0, -0.006])]
    eps = [f0 + np.linalg.solve(K, W[0]), f0 + np.linalg.solve(K, W[0] + W[1])]
    expected, start = [], np.eye(4)
    for s0, s1, e in ((0.0, 0.1, eps[0]), (0.1, 0.2, eps[1]), (0.2, L, eps[0])):
        for si in s:
            if s0 <= si < s1 or si == s1 == L:
                expected.append(start @ expm((si - s0) * twist(e)))
        start = start @ expm((s1 - s0) * twist(e))
    np.testing.assert_allclose(eq.poses, np.array(expected), rtol=0, atol=1e-10)
    assert eq.tip_position[2] < 0  # away from the chamber at +z
    assert eq.tendon_lengths is None


def test_helical_tendon_on_an_axisymmetric_rod_is_an_exact_helix():
    # actuation_benchmarks.json closed_forms[4]: ε(s) = blockdiag(Q, Q) ε0, Q = exp(k s e1~);
    # in the frame R Q the strain is constant (v0; u0 + k e1)
    EA, GA, GJ, EI = 3.0e3, 1.2e3, 4.0e-3, 5.0e-3
    L, rho, turns, tau = 0.25, 0.01, 2.0, 1.2
    arm = Arm.from_stiffness(L, EA=EA, GAy=GA, GAz=GA, GJ=GJ, EIy=EI, EIz=EI)
    routing = Helix(rho, turns)
    eq = numeric(arm, Tendon(tau, routing), s=26, tol=1e-11)
    k = 2 * np.pi * turns
    K = np.diag([EA, GA, GA, GJ, EI, EI])
    eps0 = constant_strain(K, arm.reference_strain,
                           [(tau, routing.position(0.0), routing.derivative(0.0))])
    xi = eps0 + np.array([0, 0, 0, k, 0, 0])
    for si, pose in zip(eq.s, eq.poses, strict=True):
        g = expm(si * twist(xi))
        Q = expm(si * k * hat([1.0, 0, 0]))
        np.testing.assert_allclose(pose[:3, 3], g[:3, 3], rtol=0, atol=1e-10)
        np.testing.assert_allclose(pose[:3, :3], g[:3, :3] @ Q.T, rtol=0, atol=1e-9)


# ============================================================================================
# Peer codes
# ============================================================================================

def _till_arm(peer):
    par = peer["parameters"]
    E, G, r = par["E"], par["G"], par["radius"]
    A, second = np.pi * r**2, np.pi * r**4 / 4
    return Arm.from_stiffness(par["L"], EA=E * A, GAy=G * A, GAz=G * A, GJ=G * 2 * second,
                              EIy=E * second, EIz=E * second, mass_per_length=par["rho"] * A)


@pytest.mark.parametrize("name", ["till_tendon_robot_straight", "till_tendon_robot_helical"])
def test_till_rucker_tendon_robots_under_gravity(name):
    # JohnDTill/ContinuumRobotExamples at 064f593 (converged settings: 4001 grid points),
    # mapped to softarm's axes (peer e3 = softarm e1): reproduced to 1e-11 m independently
    peer = _data("actuation_benchmarks.json")["peer_code_outputs"][name]
    arm = _till_arm(peer)
    d = 0.01506
    tensions = peer["parameters"]["tensions"]
    if name.endswith("straight"):
        routes = [Straight(d * np.cos(a), d * np.sin(a)) for a in np.arange(4) * np.pi / 2]
    else:
        routes = [Helix(d, 1.0 / peer["parameters"]["L"], phase=i * np.pi / 2)
                  for i in range(4)]
    loads = [Gravity([0.0, 9.81, 0.0])] + [Tendon(t, r) for t, r in zip(tensions, routes,
                                                                         strict=True)]
    eq = numeric(arm, loads, tol=1e-11)
    ref = peer["converged_settings"]
    np.testing.assert_allclose(eq.tip_position, ref["tip_position_softarm"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(eq.poses[-1, :3, :3], ref["tip_rotation_softarm"], rtol=0,
                               atol=1e-8)
    # the printed base force n(0) = (0.12327, 0, -15) N in the peer's frame is the rod's own
    # (the tendon's 15 N pull is not in it): softarm's rod stress at s = 0
    nb0 = np.array(ref["base_guess_printed"]["nb0_peer_frame"])
    np.testing.assert_allclose(eq.forces_spatial[0], nb0[[2, 0, 1]], rtol=0, atol=1e-7)


def test_tdcr_modeling_two_segment_cosserat_example():
    # SvenLilge/tdcr-modeling at 379d34a, its default example, 'Cosserat Rod' model (peer
    # ODE tolerance rkf45 abs 1e-6 / rel 1e-3: equal to the closed form to 4.4e-8 m)
    peer = _data("actuation_benchmarks.json")["peer_code_outputs"]["tdcr_modeling_default"]
    E = 54e9
    G = E / 2.6
    r = 0.0007
    A, second = np.pi * r**2, np.pi * r**4 / 4
    seg = Arm.from_stiffness(0.2, EA=E * A, GAy=G * A, GAz=G * A, GJ=2 * G * second,
                             EIy=E * second, EIz=E * second)
    arm = SegmentedArm([seg, seg])
    d = 0.01
    angles = np.deg2rad([90.0, -30.0, 210.0])
    routes = [Straight(d * np.cos(a), d * np.sin(a)) for a in angles]  # peer (x, y) -> (y, z)
    tensions = peer["parameters"]["tensions_N"]
    loads = [Tendon(t, routes[i % 3], end=0.2 if i < 3 else None)
             for i, t in enumerate(tensions)]
    eq = numeric(arm, loads, tol=1e-11)
    np.testing.assert_allclose(eq.tip_position, peer["tip_position_softarm"]["Cosserat Rod"],
                               rtol=0, atol=1e-7)


# ============================================================================================
# Magnetic actuation
# ============================================================================================

@pytest.mark.parametrize("k", [1.0, 2.0, 5.0])
def test_axially_magnetised_rod_is_the_inextensible_elastica(k):
    # a uniform field B ⟂ the rod, magnetisation m_l e1: the inextensible elastica under the
    # dead tip force m_l B (shear and extension do not enter: n = 0); Mattiasson (1981) via
    # the elliptic-integral table in mattiasson_cantilever.json (computed_here, 7 digits)
    table = {row["k"]: row for row in _data("mattiasson_cantilever.json")["computed_here"][
        "table"]}
    row = table[k]
    EI, L, m_l = 0.02, 0.5, 2.0
    arm = Arm.from_stiffness(L, EA=50.0, GAy=30.0, GAz=30.0, GJ=0.015, EIy=EI, EIz=EI,
                             magnetization=(m_l, 0.0, 0.0))
    B = k * EI / (L**2 * m_l)
    eq = numeric(arm, MagneticField([0.0, 0.0, B]), tol=1e-11)
    np.testing.assert_allclose(eq.tip_position[2] / L, row["w_over_L"], rtol=0, atol=2e-8)
    np.testing.assert_allclose(1 - eq.tip_position[0] / L, row["u_over_L"], rtol=0, atol=2e-7)
    np.testing.assert_allclose(eq.strains[:, :3], 0.0, atol=1e-12)  # no stretch, no shear
    # base wrench: n(0) = 0, m(0) = m_l p(L) × B
    np.testing.assert_allclose(eq.base_wrench[:3], 0.0, atol=1e-12)
    np.testing.assert_allclose(eq.base_wrench[3:], m_l * np.cross(eq.tip_position, [0, 0, B]),
                               rtol=1e-9, atol=1e-15)


def test_a_tip_dipole_in_a_uniform_field_is_a_tip_couple():
    # the tip dipole m in a uniform B: the couple (R(L) m) × B, a "follower" couple whose
    # moment depends on the tip's rotation; its equilibrium: the same arm under the dead tip
    # moment (R(L) m) × B evaluated at the solution (a fixed-point check)
    EI = 0.01
    arm = Arm.from_stiffness(0.3, EA=1e3, GAy=1e3, GAz=1e3, GJ=0.008, EIy=EI, EIz=EI,
                             tip_magnet=(0.05, 0.0, 0.0))
    B = np.array([0.0, 0.1, 0.05])
    eq = numeric(arm, MagneticField(B), tol=1e-11)
    couple = np.cross(eq.poses[-1, :3, :3] @ [0.05, 0.0, 0.0], B)
    again = numeric(arm, TipLoad(moment=couple), tol=1e-11)
    np.testing.assert_allclose(eq.poses, again.poses, rtol=0, atol=1e-10)


def test_magnetic_gradient_and_global_balance():
    # a gradient field pulls the magnetised arm: the total base wrench balances the force
    # ∫ Gᵀ R m ds and moment ∫ (p × Gᵀ R m + (R m) × B(p)) ds rebuilt from the stations
    G = np.array([[0.2, 0.1, 0.0], [0.1, -0.5, 0.05], [0.0, 0.05, 0.3]])
    mag = np.array([1.5, 0.3, -0.2])
    arm = Arm.from_stiffness(0.4, EA=2e2, GAy=1e2, GAz=1e2, GJ=0.01, EIy=0.02, EIz=0.015,
                             magnetization=tuple(mag))
    field = MagneticField([0.01, -0.02, 0.03], gradient=G)
    s = np.linspace(0.0, 0.4, 801)
    eq = numeric(arm, field, s=s, tol=1e-11)
    Rm = eq.rotations @ mag
    p = eq.positions
    B = field.field + p @ G.T
    f = Rm @ G  # Gᵀ (R m)
    torque = np.cross(Rm, B)
    force = simpson(f, x=s, axis=0)
    moment = simpson(np.cross(p, f) + torque, x=s, axis=0)
    np.testing.assert_allclose(eq.base_wrench[:3], force, rtol=0, atol=1e-9 * np.abs(f).max())
    np.testing.assert_allclose(eq.base_wrench[3:], moment, rtol=0,
                               atol=1e-9 * np.abs(torque).max())


def test_a_gradient_that_no_current_free_field_has_warns():
    with pytest.warns(UserWarning, match="symmetric and traceless"):
        MagneticField([0, 0, 0.01], gradient=np.eye(3))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        MagneticField([0, 0, 0.01], gradient=np.diag([1.0, -0.5, -0.5]))


# ============================================================================================
# Tangents: finite differences of the shooting residual
# ============================================================================================

def test_every_new_tangent_term_matches_central_differences():
    # tendons (straight, helical, polynomial, ending mid-arm), a chamber, a magnetised arm
    # with a tip dipole in a gradient field, and gravity: ∂r/∂x and ∂r/∂λ of the shooting
    # residual against central differences (fixed steps: enough that the R projection's
    # effect, which the tangents do not differentiate, is below the differences' error)
    G = np.array([[0.1, 0.2, 0.0], [0.2, -0.3, 0.1], [0.0, 0.1, 0.2]])
    arm = SegmentedArm([
        Arm.from_stiffness(0.2, EA=40.0, GAy=20.0, GAz=25.0, GJ=0.004, EIy=0.006, EIz=0.005,
                           mass_per_length=0.05, magnetization=(0.3, 0.1, 0.0),
                           tip_magnet=(0.0, 0.02, 0.0)),
        Arm.from_stiffness(0.15, EA=30.0, GAy=15.0, GAz=15.0, GJ=0.003, EIy=0.004,
                           EIz=0.004, mass_per_length=0.04, curvature=(0.0, 1.0, 0.5),
                           tip_magnet=(0.01, 0.0, 0.01))])
    loads = [Gravity(), Tendon(0.4, Straight(0.0, 0.01)),
             Tendon(0.3, Helix(0.008, 3.0, phase=0.4), end=0.25),
             Tendon(0.2, Polynomial(y=[0.01, -0.02, 0.05], z=[-0.005, 0.01])),
             Chamber(3e3, 1e-5, Straight(0.006, -0.004), start=0.05, end=0.3),
             MagneticField([0.01, 0.02, -0.01], gradient=G), TipLoad(force=[0.0, 0.05, 0.0])]
    solver = softarm.statics.Solver(arm)
    x = np.array([0.02, -0.1, 0.05, 0.01, -0.02, 0.015])
    lam = 0.7
    base = solver.shoot(loads, x, lam, steps=256)
    h = 1e-6
    for d in range(6):
        dx = np.zeros(6)
        dx[d] = h
        fd = (solver.shoot(loads, x + dx, lam, steps=256).residual
              - solver.shoot(loads, x - dx, lam, steps=256).residual) / (2 * h)
        np.testing.assert_allclose(base.jacobian_x[:, d], fd, rtol=0,
                                   atol=1e-8 * np.abs(base.jacobian_x).max())
    fd = (solver.shoot(loads, x, lam + h, steps=256).residual
          - solver.shoot(loads, x, lam - h, steps=256).residual) / (2 * h)
    np.testing.assert_allclose(base.jacobian_load, fd, rtol=0,
                               atol=1e-8 * np.abs(base.jacobian_load).max())


def test_the_tendon_law_with_and_without_tangents_solves_the_law_equation():
    # the compiled law alone, on a coupled (non-diagonal) stiffness with three tendons far
    # from the tendons-along-d1 guess (large shear and torsion): the state-only route (chord
    # steps after small Newton steps) and the tangent route (Newton throughout, H's LDLᵀ
    # factors left for the tangents) against the law equation and its Jacobian in numpy
    from softarm import kernels as k

    rng = np.random.default_rng(7)
    A = rng.normal(size=(6, 6))
    K = np.diag([40.0, 20.0, 25.0, 0.004, 0.006, 0.005])
    K = K + 0.05 * np.sqrt(np.outer(np.diag(K), np.diag(K))) * (A + A.T) / 2
    f0 = np.array([[1.0, 0.0, 0.0, 0.5, 1.0, 0.0]])
    # (y, z) offsets with a helix on the second: bound, radius, 2π n, phase, y0, z0
    routes = np.array([[0.01, 0.0, 0.0, 0.0, 0.0, 0.01],
                       [0.012, 0.004, 2 * np.pi * 3.0, 0.4, 0.006, -0.004],
                       [0.01, 0.0, 0.0, 0.0, -0.007, -0.004]])
    arm = (np.zeros(1), np.array([0.3]), np.linalg.inv(K)[None], f0, np.zeros((1, 6)), False,
           0.3, np.ones(6), K[None])
    act = (routes, np.zeros(3, dtype=np.int64), np.ones((1, 3)), np.zeros((1, 3)),
           np.zeros((2, 3)))
    tension = np.array([4.0, 2.5, 1.0])
    now = np.zeros((1, k.PIECE_LOADS + 3))
    now[0, k.PIECE_LOADS:] = tension
    s = 0.11
    sigma = np.array([-3.0, 6.0, -5.0, 0.01, 0.02, -0.015])  # shear strain ~0.3, twist ~2.5

    def route(a):  # r, r' in the section (material), as Straight + Helix define them
        angle = routes[a, 3] + routes[a, 2] * s
        c, sn = np.cos(angle), np.sin(angle)
        r = np.array([0.0, routes[a, 4] + routes[a, 1] * c, routes[a, 5] + routes[a, 1] * sn])
        dr = np.array([0.0, -routes[a, 1] * routes[a, 2] * sn, routes[a, 1] * routes[a, 2] * c])
        return r, dr

    def law_equation(eps):  # K (ε - f⁰) + Σ τ (t; r × t) - σ, and its Jacobian H
        value, H = K @ (eps - f0[0]) - sigma, K.copy()
        for a, tau in enumerate(tension):
            r, dr = route(a)
            w = eps[:3] + np.cross(eps[3:], r) + dr
            t = w / np.linalg.norm(w)
            J = np.hstack([np.eye(3), -hat(r)])
            value = value + tau * J.T @ t
            H += tau / np.linalg.norm(w) * J.T @ (np.eye(3) - np.outer(t, t)) @ J
        return value, H

    strains = {}
    for tangents in (0, 6):
        law = k._scratch(1, 3, 7)[8]
        *eps, factored = k._law(arm, act, 0, s, now, law, np.int64(tangents), *sigma)
        eps = np.array(eps)
        value, H = law_equation(eps)
        np.testing.assert_allclose(value, 0.0, atol=1e-12 * np.abs(sigma).max())
        strains[tangents] = eps
        if tangents:
            assert factored == 1.0
            # L (unit diagonal) below the diagonal, 1/D on it: H = L D Lᵀ at the point
            # before the last correction, within _LAW_TOL of H at the root
            L = np.tril(law[0][:, :6], -1) + np.eye(6)
            D = np.diag(1.0 / np.diag(law[0][:, :6]))
            np.testing.assert_allclose(L @ D @ L.T, H, rtol=0, atol=1e-8 * np.abs(H).max())
    assert np.abs(strains[6] - strains[0]).max() < 1e-13 * np.abs(strains[6]).max()
    # (the guess is far: the first Newton step is larger than a chord step may follow)
    guess = f0[0] + np.linalg.solve(K, sigma + np.concatenate(
        [-tension.sum() * np.eye(3)[0], -sum(tau * np.cross(route(a)[0], np.eye(3)[0])
                                             for a, tau in enumerate(tension))]))
    assert np.abs(guess - strains[6]).max() > 1e-2


def test_tip_compliance_with_tendons_matches_finite_differences():
    arm = Arm.from_stiffness(0.3, EA=50.0, GAy=25.0, GAz=25.0, GJ=0.005, EIy=0.008,
                             EIz=0.008, mass_per_length=0.05)
    loads = [Gravity(), Tendon(0.6, Straight(0.0, 0.01)), Tendon(0.3, Helix(0.01, 1.5))]
    eq = numeric(arm, loads, jacobians=True, steps=96)
    h = 1e-5
    for d in range(6):
        w = np.zeros(6)
        w[d] = h
        plus = numeric(arm, [*loads, TipLoad(w[:3], w[3:])], steps=96)
        minus = numeric(arm, [*loads, TipLoad(-w[:3], -w[3:])], steps=96)
        dp = (plus.tip_position - minus.tip_position) / (2 * h)
        dR = (plus.poses[-1, :3, :3] - minus.poses[-1, :3, :3]) / (2 * h)
        W = dR @ eq.poses[-1, :3, :3].T
        dtheta = np.array([W[2, 1], W[0, 2], W[1, 0]])
        np.testing.assert_allclose(eq.tip_compliance[:3, d], dp, rtol=1e-6,
                                   atol=1e-6 * np.abs(eq.tip_compliance).max())
        np.testing.assert_allclose(eq.tip_compliance[3:, d], dtheta, rtol=1e-6,
                                   atol=1e-6 * np.abs(eq.tip_compliance).max())


# ============================================================================================
# Batches, inputs
# ============================================================================================

def test_batched_tensions_and_pressures_equal_looped():
    arm = Arm.from_stiffness(0.25, EA=40.0, GAy=20.0, GAz=20.0, GJ=0.004, EIy=0.006,
                             EIz=0.006, mass_per_length=0.05)
    tension = np.array([[0.0, 0.5], [1.0, 0.2], [0.3, 0.0]])
    pressure = np.array([1e3, 0.0])
    loads = [Gravity(), Tendon(tension, Straight(0.0, 0.008)),
             Chamber(pressure, 2e-5, Straight(0.008, 0.0), end=0.2)]
    batch = numeric(arm, loads, s=11, tol=1e-9)
    assert batch.poses.shape == (3, 2, 11, 4, 4)
    for i, j in np.ndindex(3, 2):
        one = numeric(arm, [Gravity(), Tendon(tension[i, j], Straight(0.0, 0.008)),
                            Chamber(pressure[j], 2e-5, Straight(0.008, 0.0), end=0.2)],
                      s=11, tol=1e-9)
        np.testing.assert_allclose(batch.poses[i, j], one.poses, rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.tendon_lengths[i, j], one.tendon_lengths, rtol=0,
                                   atol=1e-14)
    np.testing.assert_array_equal(batch.tendon_tensions[..., 0], tension)


def test_bad_actuation_input_is_named():
    with pytest.raises(ValueError, match=r"Tendon.tension must be >= 0 N"):
        Tendon(-1.0, Straight(0.0, 0.01))
    with pytest.raises(TypeError, match=r"Tendon\.routing"):
        Tendon(1.0, (0.0, 0.01))
    with pytest.raises(ValueError, match=r"Helix\.radius"):
        Helix(0.0, 1.0)
    with pytest.raises(ValueError, match=r"Chamber\.area"):
        Chamber(1e3, 0.0, Straight(0, 0.01))
    with pytest.raises(ValueError, match="positive definite"):
        Arm.from_stiffness_matrix(1.0, -np.eye(6))
    with pytest.raises(ValueError, match="symmetric"):
        K = np.eye(6)
        K[0, 1] = 1.0
        Arm.from_stiffness_matrix(1.0, K)
    arm = Arm.from_stiffness(0.2, EA=1, GAy=1, GAz=1, GJ=1, EIy=1, EIz=1)
    with pytest.raises(ValueError, match=r"Tendon\.end must lie on the arm"):
        softarm.solve(arm, Tendon(1.0, Straight(0, 0.01), end=0.5))


# ============================================================================================
# The closed form in softarm.analytic, and method="auto"
# ============================================================================================

def test_the_actuated_closed_form_agrees_with_the_numerical_route_station_by_station():
    K = np.diag([2.0e3, 8.0e2, 9.0e2, 2.0e-3, 3.0e-3, 3.5e-3])
    K[0, 3] = K[3, 0] = 0.6
    K[2, 4] = K[4, 2] = -0.25
    arm = SegmentedArm([Arm.from_stiffness_matrix(0.15, K, curvature=(0.0, 0.5, 0.0)),
                        Arm.from_stiffness(0.1, **STEEL)])
    tension = np.array([0.0, 0.8, 1.6])
    loads = [Tendon(tension, Straight(0.0, 0.006), end=0.2),
             Tendon(0.5, Straight(-0.005, 0.002)),
             Chamber(np.array([[1e4], [3e4]]), 1e-5, Straight(0.004, -0.004), start=0.05,
                     end=0.12)]
    s = np.linspace(0.0, 0.25, 51)
    exact = softarm.analytic.actuated(arm, loads, s=s)
    auto = softarm.solve(arm, loads, s=s)
    assert exact.method == auto.method == "analytic.actuated"
    num = numeric(arm, loads, s=s, tol=1e-11)
    assert exact.poses.shape == num.poses.shape == (2, 3, 51, 4, 4)
    np.testing.assert_allclose(exact.poses, num.poses, rtol=0, atol=1e-8 * 0.25)
    np.testing.assert_allclose(exact.strains, num.strains, rtol=0,
                               atol=1e-8 * np.abs(num.strains).max())
    np.testing.assert_allclose(exact.stresses, num.stresses, rtol=0,
                               atol=1e-8 * np.abs(num.stresses).max())
    np.testing.assert_allclose(exact.tendon_lengths, num.tendon_lengths, rtol=0, atol=1e-10)
    np.testing.assert_allclose(exact.tendon_length_changes, num.tendon_length_changes,
                               rtol=0, atol=1e-10)
    np.testing.assert_allclose(num.base_wrench, 0.0, atol=1e-10)


def test_solves_of_different_actuator_structures_on_one_arm_do_not_mix():
    # the arm's solver data remembers each actuator structure (routing rows, unloaded tendon
    # lengths) for the next solve of that structure: interleaved solves of several structures
    # on one arm must each match their own closed form
    arm = Arm.from_stiffness(0.25, **STEEL)
    structures = {
        "a": [Tendon(1.2, Straight(0.0, 0.006))],
        "b": [Tendon(0.9, Straight(-0.005, 0.002), end=0.1)],
        "c": [Tendon(1.2, Straight(0.0, 0.006)), Tendon(0.4, Straight(0.004, -0.003))],
        "d": [Chamber(2e4, 1e-5, Straight(0.004, -0.004))],
    }
    for name in "abcadbca":
        loads = structures[name]
        exact = softarm.analytic.actuated(arm, loads, s=11)
        num = numeric(arm, loads, s=11, tol=1e-10)
        np.testing.assert_allclose(num.poses, exact.poses, rtol=0, atol=1e-8 * 0.25,
                                   err_msg=name)
        if name != "d":
            np.testing.assert_allclose(num.tendon_length_changes, exact.tendon_length_changes,
                                       rtol=0, atol=1e-11, err_msg=name)


def test_a_users_unhashable_routing_solves_like_the_builtin_one():
    # the arm's solver data remembers actuator structures keyed on their routings; a user's
    # routing class that cannot be hashed is solved without that memory, to the same numbers
    # (poses, compliance, actuation Jacobian) as the built-in routing of the same path
    from softarm.routing import Routing

    class Offset(Routing):
        __hash__ = None  # (as for any class that defines __eq__ without __hash__)

        def __init__(self, y, z):
            self.y_coefficients, self.z_coefficients = (y,), (z,)

    arm = Arm.from_stiffness(0.25, **STEEL, mass_per_length=0.02)

    def solved(routing):
        return softarm.solve(arm, [Gravity(), Tendon(1.2, routing)], s=5, tol=1e-8,
                             jacobians=True)

    builtin = solved(Straight(0.0, 0.006))
    for _ in range(2):  # (the second time, the built-in structure is remembered)
        users = solved(Offset(0.0, 0.006))
        for name in ("poses", "tip_compliance", "actuation_jacobian", "tendon_length_jacobian"):
            np.testing.assert_allclose(getattr(users, name), getattr(builtin, name), rtol=1e-12,
                                       atol=1e-15, err_msg=name)
    assert np.hypot(*builtin.tip_position[1:]) > 1e-2 * arm.length  # (bent: a real test)


def test_no_closed_form_for_curved_paths_or_other_loads():
    arm = Arm.from_stiffness(0.2, **STEEL, mass_per_length=0.02)
    assert softarm.analytic.actuated(arm, [Tendon(1.0, Helix(0.01, 1.0))]) is None
    assert softarm.analytic.actuated(arm, [Tendon(1.0, Straight(0, 0.01)), Gravity()]) is None
    assert softarm.solve(arm, [Tendon(1.0, Straight(0, 0.01)), Gravity()]).method == \
        "numeric.shooting"


# ============================================================================================
# Case files
# ============================================================================================

CASE = """
name = "three actuators"

[[segment]]
length = 0.2
magnetization = [0.5, 0.0, 0.0]
stiffness_matrix = [[40.0, 0, 0, 0.01, 0, 0], [0, 20.0, 0, 0, 0, 0], [0, 0, 20.0, 0, 0, 0],
                    [0.01, 0, 0, 0.004, 0, 0], [0, 0, 0, 0, 0.006, 0], [0, 0, 0, 0, 0, 0.006]]

[[segment]]
length = 0.1
tip_magnet = [0.0, 0.01, 0.0]
[segment.stiffness]
EA = 30.0
GAy = 15.0
GAz = 15.0
GJ = 0.003
EIy = 0.004
EIz = 0.004

[[load]]
kind = "tendon"
tension = 0.4
end = 0.25
[load.routing]
kind = "helix"
radius = 0.008
turns_per_metre = 2.0

[[load]]
kind = "chamber"
pressure = 2000.0
area = 1e-5
start = 0.05
[load.routing]
kind = "polynomial"
y = [0.005, -0.01]
z = [0.0]

[[load]]
kind = "magnetic"
field = [0.0, 0.02, 0.01]
gradient = [[0.1, 0.0, 0.0], [0.0, -0.05, 0.0], [0.0, 0.0, -0.05]]
"""


def test_actuators_in_a_case_file_round_trip_and_solve_as_in_python():
    import tomllib

    from softarm.case import arm_to_dict, loads_to_dict, parse_case

    case = parse_case(tomllib.loads(CASE))
    K = np.diag([40.0, 20.0, 20.0, 0.004, 0.006, 0.006])
    K[0, 3] = K[3, 0] = 0.01
    arm = SegmentedArm([
        Arm.from_stiffness_matrix(0.2, K, magnetization=(0.5, 0.0, 0.0)),
        Arm.from_stiffness(0.1, EA=30.0, GAy=15.0, GAz=15.0, GJ=0.003, EIy=0.004, EIz=0.004,
                           tip_magnet=(0.0, 0.01, 0.0))])
    loads = [Tendon(0.4, Helix(0.008, 2.0), end=0.25),
             Chamber(2000.0, 1e-5, Polynomial(y=[0.005, -0.01], z=[0.0]), start=0.05),
             MagneticField([0.0, 0.02, 0.01], gradient=np.diag([0.1, -0.05, -0.05]))]
    assert case.arm == arm
    again = parse_case({"name": "again", **arm_to_dict(case.arm),
                        "load": loads_to_dict(case.loads)})
    assert loads_to_dict(again.loads) == loads_to_dict(case.loads)
    a = numeric(case.arm, case.loads, s=11, tol=1e-9)
    b = numeric(arm, loads, s=11, tol=1e-9)
    np.testing.assert_array_equal(a.poses, b.poses)
    np.testing.assert_array_equal(numeric(again.arm, again.loads, s=11, tol=1e-9).poses,
                                  b.poses)


@pytest.mark.parametrize(("change", "message"), [
    (("tension = 0.4", "tension = -0.4"), r"load\[1\]\.tension: must be >= 0 N"),
    (('kind = "helix"', 'kind = "helics"'), r"load\[1\]\.routing\.kind: unknown value "
                                             r"'helics'.*did you mean 'helix'"),
    (("radius = 0.008", "radius = -0.008"), r"load\[1\]\.routing\.radius: must be > 0"),
    (("area = 1e-5", 'area = "big"'), r"load\[2\]\.area: must be a number"),
    (("y = [0.005, -0.01]", "y = []"), r"load\[2\]\.routing\.y: must be a non-empty list"),
    (("[0.0, 0.0, -0.05]]", "[0.0, 0.0]]"), r"load\[3\]\.gradient: must be a 3 × 3 list"),
    (("[0, 0, 0, 0, 0, 0.006]]", "[0, 0, 0, 0, 0, -0.006]]"),
     r"segment\[1\]\.stiffness_matrix: must be positive definite"),
])
def test_bad_actuator_keys_are_named_by_key_path(change, message):
    import tomllib

    from softarm import CaseError
    from softarm.case import parse_case

    with pytest.raises(CaseError, match=message):
        parse_case(tomllib.loads(CASE.replace(*change)), "case.toml")


# ============================================================================================
# Global balance with the actuators' shares rebuilt from the solution
# ============================================================================================

def total_wrench_stresses(eq, actuators):
    """The total wrench (material, per station) of an unbatched actuated equilibrium: the
    returned rod stresses plus each tendon's pull τ (t; r × t), t = w/|w| from the returned
    strains, minus each chamber's fluid wrench p A (e1; r × e1). A station where an actuator
    ends belongs to the tip side (the kernel's convention)."""
    s = np.asarray(eq.s)
    total = np.array(eq.stresses)
    f0 = np.array([seg.reference_strain for seg in eq.arm.segments])
    bounds = np.array(eq.arm.boundaries)
    segment = np.clip(np.searchsorted(bounds, s, side="right") - 1, 0, len(f0) - 1)
    strains = eq.strains + f0[segment]
    length = float(eq.arm.length)
    e1 = np.array([1.0, 0.0, 0.0])
    for load in actuators:
        start, end = load.path_span(length)
        on = (s >= start) & ((s < end) | (end >= length))
        r = load.routing.position(s)
        if isinstance(load, Tendon):
            w = strains[:, :3] + np.cross(strains[:, 3:], r) + load.routing.derivative(s)
            t = w / np.linalg.norm(w, axis=-1, keepdims=True)
            share = load.tension * np.concatenate([t, np.cross(r, t)], axis=-1)
        else:
            share = -load.pressure * load.area * np.concatenate(
                [np.broadcast_to(e1, r.shape), np.cross(r, e1)], axis=-1)
        total[on] += share[on]
    return total


def assert_actuated_balance(arm, external, actuators, rel=1e-9):
    """Global balance of the arm with its actuators at the balance check's own stations."""
    import dataclasses
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from _equilibrium_checks import balance_errors, fine_stations

    eq = numeric(arm, [*external, *actuators], s=fine_stations(arm, external), tol=1e-11)
    total = dataclasses.replace(eq, stresses=total_wrench_stresses(eq, actuators),
                                loads=tuple(external))
    force, moment, force_scale, moment_scale = balance_errors(total)
    assert force <= rel * force_scale and moment <= rel * moment_scale, (force, moment)


def test_rod_stress_plus_actuator_shares_balances_the_external_loads():
    # The returned stresses are the rod's own, K (ε - f0). Adding each tendon's pull and
    # removing each chamber's fluid wrench must give the total wrench, which balances the
    # external loads on [s, L] (rebuilt from the returned poses by
    # tests/_equilibrium_checks.py). Actuators start and end at segment joints, where the
    # balance check cuts its quadrature.
    seg = dict(EA=40.0, GAy=20.0, GAz=20.0, GJ=0.004, EIy=0.006, EIz=0.005,
               mass_per_length=0.05)
    arm = SegmentedArm([Arm.from_stiffness(0.15, **seg),
                        Arm.from_stiffness(0.15, **seg, curvature=(0.0, 1.0, 0.0))])
    actuators = [Tendon(0.5, Helix(0.008, 2.0, phase=0.3), end=0.15),
                 Tendon(0.3, Polynomial(y=[0.006, 0.01], z=[0.0, -0.02])),
                 Chamber(4e3, 1e-5, Straight(0.0, -0.006), start=0.15)]
    assert_actuated_balance(arm, [Gravity(), TipLoad(force=[0.0, 0.05, -0.02])], actuators)


# ============================================================================================
# Actuation Jacobians (issue 16): exact, by the implicit function theorem
# ============================================================================================

def _tip_motion(plus, minus, eq, h):
    """Central differences of the tip's (δp; δθ), spatial, δR = δθ~ R."""
    dp = (plus.tip_position - minus.tip_position) / (2 * h)
    W = (plus.poses[-1, :3, :3] - minus.poses[-1, :3, :3]) / (2 * h) @ eq.poses[-1, :3, :3].T
    return np.r_[dp, W[2, 1], W[0, 2], W[1, 0]]


def test_actuation_jacobian_matches_central_differences_for_every_kind_of_input():
    arm = Arm.from_stiffness(0.3, EA=50.0, GAy=25.0, GAz=25.0, GJ=0.005, EIy=0.008, EIz=0.008,
                             mass_per_length=0.05, magnetization=(0.5, 0.0, 0.0),
                             tip_magnet=(0.0, 0.01, 0.0))

    def loads(q):
        return [Gravity(), Tendon(q[0], Straight(0.0, 0.01)),
                Tendon(q[1], Helix(0.01, 1.5), end=0.2), Chamber(q[2], 1e-5, Straight(0.006, 0)),
                MagneticField(q[3:6])]

    q = np.array([0.6, 0.3, 2e3, 0.01, 0.02, -0.01])  # N, N, Pa, T, T, T
    eq = numeric(arm, loads(q), jacobians=True, steps=96)
    A = eq.actuation_jacobian
    assert A.shape == (6, 6) and eq.station_actuation_jacobian.shape == (101, 6, 6)
    np.testing.assert_array_equal(eq.station_actuation_jacobian[-1], A)
    errors = []
    for i in range(6):
        h = 1e-6 * max(abs(q[i]), 1e-2)
        dq = np.zeros(6)
        dq[i] = h
        fd = _tip_motion(numeric(arm, loads(q + dq), steps=96),
                         numeric(arm, loads(q - dq), steps=96), eq, h)
        errors.append(np.abs(A[:, i] - fd).max() / np.abs(fd).max())
    assert max(errors) <= 1e-6 and np.median(errors) <= 1e-7, errors


def test_actuation_jacobian_of_a_tendon_arc_equals_the_closed_form_derivative():
    # one straight tendon at z on a straight arm: u_y = -τ z/EI, v1 = 1 - τ/EA, the tip
    # p = v1 (sin θ, 0, 1 - cos θ)/|u| with θ = -u_y L, rotation θ about -y... differentiated
    # in τ by the complex step (exact to round-off)
    EA, EI, L, z, tau = 2e3, 4e-3, 0.25, 0.006, 0.8
    arm = Arm.from_stiffness(L, EA=EA, GAy=EA, GAz=EA, GJ=EI, EIy=EI, EIz=EI)

    def tip(t):
        u = -t * z / EI  # curvature about y
        v1 = 1.0 - t / EA
        return np.array([v1 * np.sin(u * L) / u, 0.0 * t, -v1 * (1 - np.cos(u * L)) / u,
                         0.0 * t, u * L, 0.0 * t])

    h = 1e-30
    exact = np.imag(tip(tau + 1j * h)) / h  # (dp/dτ; dθ/dτ): θ = u_y L about +y
    eq = numeric(arm, Tendon(tau, Straight(0.0, z)), jacobians=True, tol=1e-11)
    np.testing.assert_allclose(eq.actuation_jacobian[:, 0], exact, rtol=0,
                               atol=1e-9 * np.abs(exact).max())


def test_reciprocity_of_tip_motion_per_tension_and_tendon_length_per_tip_force():
    # Maxwell–Betti for the potential U + Σ τ ℓ - F·p(L): ∂p(L)/∂τ = -∂ℓ/∂F, two independent
    # columns (the exact actuation Jacobian; central differences of the tendon's length)
    arm = Arm.from_stiffness(0.3, EA=60.0, GAy=30.0, GAz=30.0, GJ=0.005, EIy=0.008,
                             EIz=0.006, mass_per_length=0.05)
    base = [Gravity(), Tendon(0.5, Helix(0.008, 2.0, phase=0.3))]
    eq = numeric(arm, [*base, TipLoad(force=[0.0, 0.02, 0.0])], jacobians=True, steps=128)
    dp_dtau = eq.actuation_jacobian[:3, 0]
    h = 1e-5
    dl_dF = []
    for k in range(3):
        f = np.array([0.0, 0.02, 0.0])
        f_plus, f_minus = f.copy(), f.copy()
        f_plus[k] += h
        f_minus[k] -= h
        plus = numeric(arm, [*base, TipLoad(force=f_plus)], steps=128).tendon_lengths[0]
        minus = numeric(arm, [*base, TipLoad(force=f_minus)], steps=128).tendon_lengths[0]
        dl_dF.append((plus - minus) / (2 * h))
    np.testing.assert_allclose(dp_dtau, -np.array(dl_dF), rtol=0,
                               atol=1e-6 * np.abs(dp_dtau).max())


def test_a_coupled_stiffness_never_takes_a_diagonal_closed_form():
    # the elastica closed form reads only the diagonal of K: on a coupled arm, auto must take
    # the numerical route (and agree with it)
    K = np.diag([1e3, 5e2, 5e2, 0.01, 0.02, 0.02])
    K[0, 4] = K[4, 0] = 1.0
    arm = Arm.from_stiffness_matrix(0.5, K)
    auto = softarm.solve(arm, TipLoad(force=[0.0, 0.0, 0.1]))
    assert auto.method == "numeric.shooting"


def test_a_tendon_path_that_doubles_back_is_refused():
    # y(s) = -s·1 m/m: r' = (0, -1, 0) and w = e1 + r' has |w| = √2 (fine); with κ⁰ about z
    # = 1/m and r = (0, 1, 0) m: κ⁰ × r = (-1, 0, 0) cancels e1, so w = 0 all along
    arm = Arm.from_stiffness(0.5, EA=1e3, GAy=1e3, GAz=1e3, GJ=1.0, EIy=1.0, EIz=1.0,
                             curvature=(0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match=r"Tendon\.routing: the path's tangent .* vanishes"):
        softarm.solve(arm, Tendon(1.0, Straight(1.0, 0.0)))
    numeric(arm, Tendon(1.0, Straight(0.5, 0.0)), s=5)  # |w| = 0.5: fine


def test_a_design_sweep_over_tension_and_pressure_equals_direct_solves():
    pytest.importorskip("xarray", reason="softarm.sweep.run needs pip install 'softarm[sweep]'")
    import tomllib

    from softarm import CaseError
    from softarm.case import parse_case

    text = CASE.split("[[load]]")[0] + """
[[load]]
kind = "tendon"
tension = 1.0
routing = { kind = "straight", y = 0.0, z = 0.008 }

[[load]]
kind = "chamber"
pressure = 0.0
area = 1e-5
routing = { kind = "straight", y = 0.008, z = 0.0 }

[sweep]
design = "grid"
[[sweep.parameter]]
path = "load[1].tension"
values = [0.0, 0.5]
[[sweep.parameter]]
path = "load[2].pressure"
start = 0.0
stop = 2e4
steps = 3
"""
    case = parse_case(tomllib.loads(text))
    ds = softarm.sweep.run(case, fields=("tip", "positions"), stations=11, tol=1e-9)
    assert ds.sizes["case"] == 6 and np.all(ds["status"].values == 0)
    for k in range(6):
        tension = float(ds["load[1].tension"][k])
        pressure = float(ds["load[2].pressure"][k])
        eq = numeric(case.arm, [case.loads[0].replace(tension=tension),
                                case.loads[1].replace(pressure=pressure)], s=11, tol=1e-9)
        # the sweep takes method "auto" (the closed form where it applies): both within tol
        np.testing.assert_allclose(ds["positions"][k].values, eq.positions, rtol=0,
                                   atol=1e-9 * case.arm.length)
    # the one-parameter [sweep] form sweeps vectors only; it says what to write instead
    old = text.split("[sweep]")[0] + "[sweep]\nload = 1\nvalues = [0.0, 1.0]\n"
    with pytest.raises(CaseError, match=r"sweep\.load: load 1 \(tendon\) has no vector.*"
                                        r"load\[1\]\.tension"):
        parse_case(tomllib.loads(old))


def test_the_actuated_arm_rows_are_built_once_per_structure(monkeypatch):
    # what depends on the actuators' kinds, paths and spans alone is remembered per arm: a
    # second solve of the same structure with other tensions builds nothing (the remembered
    # (arm, act) pair was once compared by its first element with the cut, and rebuilt)
    from softarm.statics import solver as solver_module

    built = []
    original = solver_module._Channels._build_actuated_arm

    def counting(self):
        built.append(1)
        return original(self)

    monkeypatch.setattr(solver_module._Channels, "_build_actuated_arm", counting)
    silicone = softarm.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)
    arm = softarm.Arm(0.3, softarm.Circle(0.01), silicone)
    for tension in (0.2, 0.4, 0.6):
        softarm.solve(arm, [softarm.Gravity(), softarm.Tendon(tension, Straight(0.0, 0.008))],
                      method="numeric")
    assert len(built) == 1

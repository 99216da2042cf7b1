"""Checks of the hard-contact table reference (tests/_table_reference.py, issue 33).

A heavy soft arm (contact_refs.md's defaults: L = 0.5 m, r = 0.01 m, E = 1 MPa, ν = 0.5,
ρ = 1000 kg/m³: w L³/EI = 49, the free tip sags 0.455 m) clamped horizontally d = 0.02 m above
the height at which its surface touches a frictionless table: the far 53 % lies on it.

Measured (tol 1e-8 against 1e-10, 2001 stations): positions agree to 1e-11 L, s_c to 1e-14 m.
A penalty law c_z = k·max(0, −gap) (smoothed over 0.1 w/k), solved on the whole arm without
zones from a straight start, converges to the hard shape: max |Δp| = 1.0e-3, 1.6e-4, 2.4e-5,
3.5e-6, 4.5e-7 L for k = 1e4 … 1e8 N/m², 0.81–0.89 decades per decade of k (→ 1: the
difference is the penetration c/k, whose peak c rises towards the hard pressure peak as the
penalty's smoothing length shrinks); the clamp moment converges at exactly rate 1.
The point-reaction model differs by 9.2e-5 L and penetrates by 1.8e-5 m.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _table_reference import point_reaction_reference, table_reference
from scipy.integrate import quad, solve_bvp

L, R = 0.5, 0.01  # m
E = 1e6  # Pa
AREA, SECOND_MOMENT = math.pi * R**2, math.pi * R**4 / 4  # m², m⁴
EA, GA, EI = E * AREA, E / 3 * AREA, E * SECOND_MOMENT  # N, N (no shear correction), N m²
W = 1000.0 * AREA * 9.81  # N/m
D = 0.02  # m: drop of the centreline from the clamp to the table
ELL = math.sqrt(EI / GA)  # m
STATIONS = np.linspace(0.0, L, 2001)


@pytest.fixture(scope="module")
def hard():
    return table_reference(L, EA, GA, EI, R, W, D, tol=1e-8)


def test_geometry_of_the_default_case(hard):
    # the brief: a visible far part (30-60 %) on the table; the tip lies on it, x(L) < L
    assert 0.4 < hard.s_c / L < 0.7
    tip = hard.positions(L)[0]
    assert tip[2] == -D and 0.99 * L < tip[0] < L
    assert hard.table_height == pytest.approx(D + R)


def test_refinement(hard):
    fine = table_reference(L, EA, GA, EI, R, W, D, tol=1e-10)
    # measured 9.9e-12 L (560 against 2738 nodes)
    assert np.max(np.abs(hard.positions(STATIONS) - fine.positions(STATIONS))) < 1e-10 * L
    assert abs(hard.s_c - fine.s_c) < 1e-10 * L
    assert np.max(np.abs(hard.forces(STATIONS) - fine.forces(STATIONS))) < 1e-8


def _penalty_shapes(ks, d=D):
    """Penalty contact on the whole arm (x, z, θ, n_x, n_z, m; no zones, no n_x = 0 assumed):
    c_z = k (√(g² + δ²) − g)/2 with g = z + d the gap, δ = 0.1 w/k; k raised step by step,
    each solve started from the previous one, the first from a straight arm bent down to the
    table. Yields (k, positions at STATIONS, (n_z(0), m(0)))."""
    eps_a, eps_g = EI / (EA * L**2), EI / (GA * L**2)
    qt, dt = W * L**3 / EI, d / L

    def rhs(kt, delta):
        def fun(t, y):
            _, z, th, nx, nz, m = y
            c, s = np.cos(th), np.sin(th)
            n1, n3 = nx * c + nz * s, -nx * s + nz * c
            dx = c * (1 + eps_a * n1) - s * eps_g * n3
            dz = s * (1 + eps_a * n1) + c * eps_g * n3
            g = z + dt
            cz = 0.5 * kt * (np.sqrt(g * g + delta * delta) - g)
            return np.vstack([dx, dz, m, np.zeros_like(t), qt - cz, -(dx * nz - dz * nx)])
        return fun

    def bc(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[3], yb[4], yb[5]])

    t = np.linspace(0.0, 1.0, 201)
    y = np.zeros((6, t.size))
    y[0], y[1] = t, -dt * np.minimum(1.0, 2.0 * t)
    for k in ks:
        sol = solve_bvp(rhs(k * L**4 / EI, 0.1 * W / k / L), bc, t, y, tol=1e-6,
                        max_nodes=100_000)
        assert sol.success, sol.message
        t, y = sol.x, sol.y
        p = sol.sol(STATIONS / L) * L
        yield (k, np.stack([p[0], np.zeros_like(p[0]), p[1]], axis=-1),
               (sol.y[4, 0] * EI / L**2, sol.y[5, 0] * EI / L))


def test_penalty_converges_to_hard_contact(hard):
    exact = hard.positions(STATIONS)
    n0, m0 = hard.forces(0.0)[0, 1:]
    errors, force_errors, moment_errors = [], [], []
    for _, shape, (pn0, pm0) in _penalty_shapes([1e4, 1e5, 1e6, 1e7, 1e8]):
        errors.append(np.max(np.abs(shape - exact)) / L)
        force_errors.append(abs(pn0 - n0))
        moment_errors.append(abs(pm0 - m0))
    errors = np.array(errors)
    # the clamp's reaction: force 3.0e-4 … 3.4e-7 N (of −0.504 N), moment 1.14e-4 … 1.13e-8 N m
    assert np.all(np.diff(force_errors) < 0) and force_errors[-1] < 5e-7
    assert np.allclose(-np.diff(np.log10(moment_errors)), 1.0, atol=0.01)
    rates = -np.diff(np.log10(errors))
    # measured 1.03e-3, 1.56e-4, 2.41e-5, 3.49e-6, 4.50e-7; rates 0.82, 0.81, 0.84, 0.89
    assert errors[-1] < 6e-7
    assert np.all(rates > 0.75) and np.all(rates < 1.0)
    assert np.all(np.diff(rates[1:]) > 0)  # rising towards 1


@pytest.mark.parametrize(("d", "ga"), [(0.01, GA), (D, GA), (0.08, GA), (D, EA), (D, GA / 10)])
def test_balance_pressure_and_gap(d, ga):
    sol = table_reference(L, EA, ga, EI, R, W, d)
    ell = math.sqrt(EI / ga)
    # global balance: clamp reaction (−n(0), −m(0)) + weight + contact = 0
    _, nz0, m0 = sol.forces(0.0)[0]
    weight_moment = -W * quad(lambda s: sol.state(s)[0, 0], 0.0, L, epsabs=0.0, epsrel=1e-12,
                              limit=200, points=[sol.s_c])[0]
    assert sol.contact_force[0] == 0.0
    assert abs(-nz0 - W * L + sol.contact_force[1]) < 1e-9 * W * L  # measured ≤ 7e-12
    assert abs(-m0 + weight_moment + sol.contact_moment) < 1e-9 * W * L**2
    # the multiplier is ≥ 0: the weight plus a positive excess, which decays from s_c
    near = min(10 * ell, (L - sol.s_c) / 2)
    s_zone = sol.s_c + np.concatenate([np.linspace(0.0, near, 2001),
                                       np.linspace(near, L - sol.s_c, 501)])
    p = sol.pressure(s_zone)
    assert np.all(p[:2001] > W) and np.all(np.diff(p[:2001]) < 0)
    assert np.all(p >= W * (1 - 1e-12))  # measured: (p − w)/w ≥ −3e-16 on the far part
    assert p[-1] == pytest.approx(W, rel=1e-7)
    # the free end's reaction (m(L) = 0 needs the growing mode): ≈ 2 GA |θ_c| e^{−(L−s_c)/ℓ}
    end = 2 * ga * abs(sol.theta(sol.s_c)[0]) * math.exp(-(L - sol.s_c) / ell)
    assert sol.tip_reaction >= 0.0
    assert sol.tip_reaction == pytest.approx(end, rel=0.05, abs=1e-13)
    # no penetration: the gap z + d is > 0 on the free arc, 0 on the table
    air = np.linspace(0.0, sol.s_c, 2001)
    gap = sol.positions(air)[:, 2] + d
    assert np.all(gap[:-1] > 0.0) and abs(gap[-1]) < 1e-12 * L
    assert np.all(sol.positions(s_zone[1:])[:, 2] == -d)  # s_zone[0] = s_c: the gap above
    assert np.all(sol.pressure(air[:-1]) == 0.0)


def test_zone_against_its_first_integral_and_quadrature(hard):
    """On the table the moment is m = √(EI D(θ)) n_z (the stable manifold of the zone's saddle,
    module docstring) and ds = −√(EI D(θ)) dθ / sin θ."""
    s = hard.s_c + ELL * np.array([0.0, 0.5, 1.0, 2.0, 5.0, 10.0])
    th = hard.theta(s)
    _, nz, m = hard.forces(s).T

    def compliance(t):
        return np.sin(t) ** 2 / EA + np.cos(t) ** 2 / GA

    assert np.all(th < 0) and np.all(nz > 0)
    np.testing.assert_allclose(m, np.sqrt(EI * compliance(th)) * nz, rtol=1e-6)
    for s_i, th_i in zip(s[1:], th[1:], strict=True):
        arc = quad(lambda t: np.sqrt(EI * compliance(t)) / np.sin(t), abs(th_i), abs(th[0]),
                   epsabs=0.0, epsrel=1e-12)[0]
        # measured 1e-8 ℓ at ≤ 5ℓ, 2e-6 ℓ at 10ℓ (θ ≈ 1e-7 rad there: δs = ℓ δθ/θ)
        assert abs(hard.s_c + arc - s_i) < 1e-5 * ELL
    # decay length of the section angle: ℓ at small θ (θ_c ≈ −2e-3)
    assert -1.0 / np.gradient(np.log(-th), s)[3] == pytest.approx(ELL, rel=1e-5)


def test_lift_off_is_smooth_for_the_sections_but_not_for_the_centreline(hard):
    """θ, m, n_z continuous at s_c; the pressure jumps from 0 to c_z(s_c⁺), so the centreline's
    curvature jumps from z''(s_c⁻) = D(θ_c) c_z(s_c⁺) to 0."""
    s_c, h = hard.s_c, 1e-4 * ELL
    left = hard.state(s_c - np.array([0.0, h, 2 * h]))
    right = hard.state(s_c + np.array([0.0, h, 2 * h]))
    np.testing.assert_allclose(left[[2, 4, 5], 0], right[[2, 4, 5], 0], rtol=1e-12)
    # θ' = m/EI matches on both sides to O(h)
    dth = (left[2, 0] - left[2, 1]) / h, (right[2, 1] - right[2, 0]) / h
    assert dth[0] == pytest.approx(dth[1], rel=1e-3)
    z_curv = (left[1, 0] - 2 * left[1, 1] + left[1, 2]) / h**2
    th_c = left[2, 0]
    jump = (math.sin(th_c) ** 2 / EA + math.cos(th_c) ** 2 / GA) * hard.pressure(s_c)[0]
    assert z_curv == pytest.approx(jump, rel=2e-3)
    assert hard.pressure(s_c)[0] == pytest.approx(W + hard.forces(s_c)[0, 1] / ELL, rel=3e-3)


def test_point_reaction_model_is_off_by_about_1e4_L_and_penetrates(hard):
    s_c, reaction, positions = point_reaction_reference(L, EA, GA, EI, R, W, D, tol=1e-10)
    shape = positions(STATIONS)
    # measured 9.2e-5 L, penetration 1.79e-5 m = 0.86 R ℓ/GA, lift-off moved by 1.015 ℓ
    assert 3e-5 * L < np.max(np.abs(shape - hard.positions(STATIONS))) < 3e-4 * L
    depth = -(np.min(shape[:, 2]) + D)
    assert 0.5 < depth / (reaction * ELL / GA) < 1.5
    # the zone's excess pressure, n_z(s_c) e^{−(s−s_c)/ℓ}/ℓ, has its resultant ≈ ℓ past s_c
    assert (s_c - hard.s_c) / ELL == pytest.approx(1.0, abs=0.1)
    assert reaction == pytest.approx(hard.forces(hard.s_c)[0, 1], rel=0.2)


def test_an_arm_that_does_not_lie_on_the_table_is_refused():
    with pytest.raises(ValueError, match=r"d must let the arm's far part lie flat .* d = 0\.3 m"):
        table_reference(L, EA, GA, EI, R, W, 0.3)
    with pytest.raises(ValueError, match=r"EI must be a positive finite number, got -1\.0"):
        table_reference(L, EA, GA, -1.0, R, W, D)

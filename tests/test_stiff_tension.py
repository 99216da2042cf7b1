"""Rods in strong tension (kL = L √(F/EI) from 10 to 1e4) against closed forms.

EI = 1 N m², L = 1 m, EA = GA = C = 1e12 N: with EA = GA the stretch and shear add exactly
n s / C to the inextensible elastica's positions (tests/_planar_elastica.py), so the closed
forms below are exact for softarm's model, not only in the inextensible limit. A zero
``DistributedForce`` keeps a tip force off the exact closed-form route, on the solver's.

* linear tension theory (tip force (F, 0, P), P = 1e-3 F): w = (P/F)(L − tanh(kL)/k) + PL/GA,
  whose dropped terms are −(P/F)³ L/2 = −5e-10 L;
* the separatrix of the pendulum equation for a hard oblique pull (ψ = 60°, 150°): the tip
  up to terms of order e^{−kL}/k, checked here against quadrature and solve_bvp.

Measured (``python`` with the helpers below): linear theory to ≤ 5e-10 L on both routes (the
O((P/F)³) term); the oblique pulls to ≤ 5.3e-10 L at tol 1e-9 for kL ≤ 1e3, and to 8.5e-9 L
(60°) and 6.4e-8 L (150°) at tol 1e-7 for kL = 1e4 (≈ 10 s and 15 s each: 32768 RK4 steps).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _planar_elastica import linear_tension_deflection, separatrix_tip, solve_planar
from scipy.integrate import quad

import softarm
from softarm.statics.solver import Solver

EI = 1.0  # N m²
LENGTH = 1.0  # m
C = 1e12  # N: EA = GAy = GAz
ARM = softarm.Arm.from_stiffness(LENGTH, EA=C, GAy=C, GAz=C, GJ=EI, EIy=EI, EIz=EI)
NO_LOAD = softarm.DistributedForce([0.0, 0.0, 0.0])  # the numerical route for a tip force
LATERAL = 1e-3  # P / F


def _solve(force, route, tol):
    """softarm's equilibrium under a dead tip force: ``route`` "auto" through softarm.solve,
    otherwise a Solver forced onto that shooting route (no stability verdict: see
    test_a_rod_in_tension_is_stable)."""
    loads = [softarm.TipLoad(force=force), NO_LOAD]
    if route == "auto":
        return softarm.solve(ARM, loads, tol=tol, stability=False)
    return Solver(ARM, tol=tol, shooting=route, stability=False).solve(loads)


def _pull(T, psi):
    """A tip force of magnitude T (N) at angle ψ (rad) from +x towards +z."""
    return [T * math.cos(psi), 0.0, T * math.sin(psi)]


# ---------------------------------------------------------------------------------------------
# (a) linear tension theory


@pytest.mark.parametrize("route", ["auto", "multiple"])
@pytest.mark.parametrize("load", [1e2, 1e3, 1e4, 1e6, 1e8])  # F L² / EI
def test_lateral_deflection_under_tension_matches_linear_theory(load, route):
    F = load * EI / LENGTH**2
    P = LATERAL * F
    eq = _solve([F, 0.0, P], route, tol=1e-10)
    w = linear_tension_deflection(F, P, EI, LENGTH, C)
    # dropped by the linear theory: (P/F)³ L / 2 = 5e-10 L; the solver's tolerance 1e-10 L
    assert abs(eq.tip_position[2] - w) < 1e-9 * LENGTH
    assert eq.tip_position[1] == 0.0
    # the shear term counts where the test can see it (F L²/EI = 1e8: P L/GA = 1e-7 L)
    if load == 1e8:
        assert abs(eq.tip_position[2] - (w - P * LENGTH / C)) > 5e-8 * LENGTH


# ---------------------------------------------------------------------------------------------
# (b) the separatrix under a hard oblique pull


def _separatrix_by_quadrature(k, psi, length):
    """∫₀^L (cos θ, sin θ) ds for the separatrix θ(s) = ψ − 4 atan(tan(ψ/4) e^{−ks}),
    by adaptive quadrature of the boundary layer's part (cos θ − cos ψ, sin θ − sin ψ),
    which decays like e^{−ks}, split at multiples of its width 1/k."""
    theta = lambda s: psi - 4.0 * math.atan(math.tan(psi / 4.0) * math.exp(-k * s))  # noqa: E731
    points = [p / k for p in (1.0, 4.0, 16.0) if p / k < length]
    layer = [quad(lambda s, f=f: f(theta(s)) - f(psi), 0.0, length, points=points,
                  epsabs=1e-15, epsrel=1e-13, limit=200)[0] for f in (math.cos, math.sin)]
    return length * np.array([math.cos(psi), math.sin(psi)]) + np.array(layer)


@pytest.mark.parametrize("psi_deg", [60.0, 150.0, -100.0])
@pytest.mark.parametrize("kL", [40.0, 100.0, 1e3])
def test_separatrix_closed_form_is_its_integral(kL, psi_deg):
    """The helper's closed form (inextensible: C = ∞) against quadrature of the separatrix;
    beyond kL = 40 the part past L is below e^{−40} L."""
    psi = math.radians(psi_deg)
    k = kL / LENGTH
    closed = separatrix_tip(k**2 * EI, psi, EI, LENGTH, math.inf)
    np.testing.assert_allclose(closed, _separatrix_by_quadrature(k, psi, LENGTH), rtol=0,
                               atol=1e-13 * LENGTH)


def test_separatrix_matches_collocation_at_kl_20():
    """At kL = 20 the free end's θ'(L) = 0 and the separatrix differ by e^{−20}; solve_bvp
    (extensible and shearable, C as in the tests) finds the closed form's tip to 1e-12 L."""
    psi, T = math.radians(150.0), 400.0
    force = _pull(T, psi)
    ref = solve_planar(LENGTH, EI, C, C, tip=(force[0], force[2]), tol=1e-9)
    np.testing.assert_allclose(ref.tip[[0, 2]], separatrix_tip(T, psi, EI, LENGTH, C), rtol=0,
                               atol=1e-12 * LENGTH)


# kL = 1e4 takes 10-15 s a solve (32768 RK4 steps): on the auto route only, which is
# multiple shooting there anyway
PULLS = [(kL, 1e-9, route) for kL in (20.0, 100.0, 1e3) for route in ("auto", "multiple")]
PULLS.append((1e4, 1e-7, "auto"))


@pytest.mark.parametrize("psi_deg", [60.0, 150.0])
@pytest.mark.parametrize(("kL", "tol", "route"), PULLS)
def test_hard_oblique_pull_matches_the_separatrix(kL, tol, route, psi_deg):
    psi = math.radians(psi_deg)
    T = kL**2 * EI / LENGTH**2
    eq = _solve(_pull(T, psi), route, tol=tol)
    ref = separatrix_tip(T, psi, EI, LENGTH, C)
    # tol bounds the tip's error estimate; the true error is within 2.2x of it (measured)
    assert np.max(np.abs(eq.tip_position[[0, 2]] - ref)) < max(2.0 * tol, 1e-9) * LENGTH
    # far from the clamp the arm lines up with the force
    tangent = eq.rotations[-1][:, 0]
    np.testing.assert_allclose(tangent, [math.cos(psi), 0.0, math.sin(psi)], rtol=0,
                               atol=10 * math.exp(-kL / 2) + 1e-9)


# ---------------------------------------------------------------------------------------------
# (c) a batch mixing easy and stiff cases equals each case alone


def test_mixed_batch_equals_each_case_alone():
    forces = np.array([_pull(1.0, math.radians(60.0)),  # kL = 1: single shooting
                       [1e4, 0.0, LATERAL * 1e4],  # kL = 100
                       [1e6, 0.0, LATERAL * 1e6],  # kL = 1000
                       _pull(1e4, math.radians(150.0))])
    batch = softarm.solve(ARM, [softarm.TipLoad(force=forces), NO_LOAD], tol=1e-8,
                          stability=False)
    for i, force in enumerate(forces):
        alone = softarm.solve(ARM, [softarm.TipLoad(force=force), NO_LOAD], tol=1e-8,
                              stability=False)
        for name in ("poses", "strains", "stresses", "base_wrench", "error_estimate",
                     "residual"):
            assert np.array_equal(getattr(batch, name)[i], getattr(alone, name)), (i, name)
    # the cases are really different routes and shapes
    assert batch.tip_position[0, 2] < 0.5 and batch.tip_position[3, 0] < 0.0


# ---------------------------------------------------------------------------------------------
# (d) the tolerance ladder


@pytest.mark.parametrize("psi_deg", [60.0, 150.0])
def test_tol_ladder_oblique_pull(psi_deg):
    """F L²/EI = 1e4 (kL = 100) at 60° and 150°: the tip error against the separatrix
    (exact to e^{−100}) shrinks at least tenfold per hundredfold tolerance and stays below
    tol·L. Measured: 6.2e-8, 3.1e-9, 2.8e-11 L (60°); 8.7e-7, 5.9e-9, 6.4e-11 L (150°)."""
    psi = math.radians(psi_deg)
    ref = separatrix_tip(1e4, psi, EI, LENGTH, C)
    errors = []
    for tol in (1e-6, 1e-8, 1e-10):
        eq = _solve(_pull(1e4, psi), "auto", tol=tol)
        errors.append(float(np.linalg.norm(eq.tip_position[[0, 2]] - ref)))
        assert errors[-1] < tol * LENGTH, (tol, errors)
    assert errors[1] < errors[0] / 10 and errors[2] < errors[1] / 10, errors


def test_tol_ladder_lateral_force():
    """F L²/EI = 1e4 with P = 1e-3 F: against the separatrix at ψ = atan(P/F) (linear theory
    with its nonlinear correction, exact to e^{−100}) the error is already 1.9e-13 L at
    tol 1e-6 (the solver's smallest step count resolves this mild layer), so the ladder can
    only stay flat: it never grows and stays below every tol·L."""
    F, P = 1e4, LATERAL * 1e4
    ref = separatrix_tip(math.hypot(F, P), math.atan2(P, F), EI, LENGTH, C)
    errors = []
    for tol in (1e-6, 1e-8, 1e-10):
        eq = _solve([F, 0.0, P], "auto", tol=tol)
        errors.append(float(np.linalg.norm(eq.tip_position[[0, 2]] - ref)))
        assert errors[-1] < tol * LENGTH, (tol, errors)
    assert errors[2] <= errors[1] <= errors[0], errors
    # the linear theory alone is off by its dropped (P/F)³ L / 2 here
    w = linear_tension_deflection(F, P, EI, LENGTH, C)
    assert abs(w - ref[1]) == pytest.approx(0.5 * LATERAL**3 * LENGTH, rel=0.05)


# ---------------------------------------------------------------------------------------------
# the stability verdict in strong tension (before its sweep took the solution's states:
# F L²/EI = 1e4 reported Morse index 15, 1e6 raised numpy's LinAlgError (NaN), 1e8 index 6200)


@pytest.mark.parametrize("load", [1e4, 1e6, 1e8])
def test_a_rod_in_tension_is_stable(load):
    """A straight rod pulled along its axis with a small lateral force is stable (the tension
    stiffens every mode): the default softarm.solve must say so without a warning."""
    F = load * EI / LENGTH**2
    eq = softarm.solve(ARM, [softarm.TipLoad(force=[F, 0.0, LATERAL * F]), NO_LOAD],
                       tol=1e-8)
    assert eq.stability.stable and eq.stability.index == 0

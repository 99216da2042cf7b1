"""A long heavy arm hanging under its own weight, against an independent solve_bvp reference.

The arm is clamped at the origin with its axis along +x, gravity along −z; its weight per
length q gives the nondimensional load q L³/EI from 1e2 (kL = 10: single shooting on the
auto route) to 1e5 (kL = 316: multiple shooting). The reference (tests/_planar_elastica.py)
is the planar Cosserat rod with the same constitutive law (stretch n₁/EA and shear n₃/GA
included, EA ≠ GA so that both count), solved by scipy's collocation with load continuation;
its own error is estimated by solving it again at a ten times tighter tolerance.

Measured (L = 2 m, EI = 0.3 N m², softarm tol 1e-9): the reference's two resolutions agree
to ≤ 1.1e-12 L (1900 to 4800 nodes), and softarm agrees with the reference at all 101
stations to ≤ 3.7e-10 L on both routes, its tip angle to ≤ 2e-11 rad; the bound asserted is
2·tol·L = 2e-9 L.
"""

from __future__ import annotations

import numpy as np
import pytest
from _planar_elastica import solve_planar

import softarm
from softarm.statics.solver import Solver

LENGTH = 2.0  # m
EI = 0.3  # N m²
EA = 1e8 * EI / LENGTH**2  # N: axial strain up to q L / EA = 1e-3 at the clamp (q L³/EI = 1e5)
GA = 5e7 * EI / LENGTH**2  # N
G = 9.81  # m/s²
LOADS = (1e2, 1e3, 1e4, 1e5)  # q L³ / EI
TOL = 1e-9  # softarm's tolerance, relative to L


def _arm(load):
    mu = load * EI / LENGTH**3 / G  # kg/m
    return softarm.Arm.from_stiffness(LENGTH, EA=EA, GAy=GA, GAz=GA, GJ=EI, EIy=EI, EIz=EI,
                                      mass_per_length=mu)


@pytest.fixture(scope="module")
def references():
    """Per load: (reference, its error estimate in m at the tip, the stations and tip angle)."""
    out = {}
    for load in LOADS:
        q = load * EI / LENGTH**3  # N/m
        coarse = solve_planar(LENGTH, EI, EA, GA, distributed=(0.0, -q), tol=1e-8)
        fine = solve_planar(LENGTH, EI, EA, GA, distributed=(0.0, -q), tol=1e-9,
                            previous=coarse)
        s = np.linspace(0.0, LENGTH, 101)
        estimate = max(np.max(np.abs(fine.positions(s) - coarse.positions(s))),
                       LENGTH * abs(fine.tip_angle - coarse.tip_angle))
        out[load] = fine, estimate
    return out


def _tip_angle(eq) -> float:
    """The tangent's angle at the tip from +x towards +z (rad)."""
    R = eq.rotations[-1]
    return float(np.arctan2(R[2, 0], R[0, 0]))


@pytest.mark.parametrize("route", ["auto", "multiple"])
@pytest.mark.parametrize("load", LOADS)
def test_hanging_arm_matches_the_collocation_reference(references, load, route):
    ref, estimate = references[load]
    arm = _arm(load)
    loads = [softarm.Gravity([0.0, 0.0, -G])]
    if route == "auto":
        eq = softarm.solve(arm, loads, tol=TOL)
    else:
        eq = Solver(arm, tol=TOL, shooting="multiple", stability=False).solve(loads)
    bound = max(2.0 * estimate, 2.0 * TOL * LENGTH)  # tol bounds the tip; 2 for the stations
    assert estimate < 1e-10 * LENGTH  # the reference is far finer than the bound
    assert np.max(np.abs(eq.positions - ref.positions(eq.s))) < bound
    assert np.max(np.abs(eq.tip_position - ref.tip)) < bound
    assert abs(_tip_angle(eq) - ref.tip_angle) < bound / LENGTH
    # the arm stays in its plane: e2 is +y all along
    np.testing.assert_allclose(eq.rotations[:, :, 1], np.tile([0.0, 1.0, 0.0], (101, 1)),
                               atol=1e-12)


def test_the_reference_sees_stretch_and_shear(references):
    """The comparison above would fail if softarm dropped the stretch or the shear: with EA
    and GA a hundred times stiffer the reference's tip moves by far more than the bound."""
    load = LOADS[-1]
    ref, _ = references[load]
    q = load * EI / LENGTH**3
    stiff = solve_planar(LENGTH, EI, 100 * EA, 100 * GA, distributed=(0.0, -q), tol=1e-8)
    assert np.max(np.abs(stiff.tip - ref.tip)) > 1e-4 * LENGTH


@pytest.mark.parametrize("load", LOADS)
def test_hanging_arm_balances_its_weight(references, load):
    """Global equilibrium: the base carries the whole weight, and the moment of the weight
    about the clamp, ∫ x(s) q ds = −m(0) of the reference (the planar moment m turns e1
    from +x towards +z, i.e. about −y)."""
    ref, _ = references[load]
    arm = _arm(load)
    eq = softarm.solve(arm, [softarm.Gravity([0.0, 0.0, -G])], tol=TOL)
    weight = arm.linear_density * G * LENGTH  # N
    np.testing.assert_allclose(eq.base_wrench[:3], [0.0, 0.0, -weight], rtol=0,
                               atol=1e-12 * weight)
    moment = -ref.state(np.array([0.0]))[5, 0]  # N m, about +y
    np.testing.assert_allclose(eq.base_wrench[3:], [0.0, moment, 0.0], rtol=0,
                               atol=1e-8 * weight * LENGTH)
    # the rod's own share is the whole of it (no actuators)
    np.testing.assert_allclose(eq.forces_spatial[0], eq.base_wrench[:3], rtol=0,
                               atol=1e-12 * weight)
    np.testing.assert_allclose(eq.moments_spatial[0], eq.base_wrench[3:], rtol=0,
                               atol=1e-12 * weight * LENGTH)

"""The hard contact zones' law in the kernel (issue 39, groundwork; docs/contact.md, "Hard
contact"): on a zone the pressure c = a/b holds the gap's second derivative at zero, and
its variation (the tangent columns every Jacobian and Newton step use) is exact.

References: the law's own defining property (the gap is affine in s along a zone, and not
off it; the gap measured by distance formulas written here, not softarm's), and central
differences of solves for the tip compliance through a zone on a tilted plane, a ball and a
capsule. ``Contact.zones`` is set by hand here: nothing in
``softarm.solve`` places zones yet.
"""

from __future__ import annotations

import numpy as np
import pytest

import softarm as sa

L, RADIUS = 0.5, 0.01
ZONE = (0.25, 0.4)
TIP = (0.01, 0.02, -0.03)
OBSTACLES = {
    "tilted plane": sa.Plane((0.0, 0.0, -0.03), (0.0, 0.3, 1.0)),
    "ball": sa.Sphere((0.3, 0.05, -0.3), 0.25),
    "capsule": sa.Capsule((0.2, -1.0, -0.2), (0.25, 1.0, -0.25), 0.1),
}


def _distance(name, p):
    """The signed distance of points p (..., 3) from each obstacle's surface, by hand."""
    if name == "tilted plane":
        normal = np.array([0.0, 0.3, 1.0]) / np.hypot(0.3, 1.0)
        return (p - [0.0, 0.0, -0.03]) @ normal
    if name == "ball":
        return np.linalg.norm(p - [0.3, 0.05, -0.3], axis=-1) - 0.25
    a, b = np.array([0.2, -1.0, -0.2]), np.array([0.25, 1.0, -0.25])
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * (b - a)), axis=-1) - 0.1


@pytest.fixture(scope="module")
def arm():
    return sa.Arm(L, sa.Circle(RADIUS), sa.Material(youngs_modulus=1e6, poisson_ratio=0.5,
                                                     density=1000.0))


def _solve(arm, obstacle, s, tip=TIP, **options):
    contact = sa.Contact(obstacle, distance=1e-5 * L, zones=((0, *ZONE),))
    return sa.solve(arm, [sa.Gravity(), sa.TipLoad(force=tip), contact], s=s,
                    stability=False, **options)


@pytest.mark.parametrize("name", OBSTACLES)
def test_a_zone_holds_the_gaps_second_derivative_at_zero(arm, name):
    """On the zone the gap is affine in s (g'' = 0, whatever it enters with); on the free
    arc before it, under the same loads, it is not."""
    obstacle = OBSTACLES[name]
    s = np.linspace(0.0, L, 401)
    eq = _solve(arm, obstacle, s)
    gaps = _distance(name, eq.positions) - RADIUS
    zone = (s >= ZONE[0]) & (s <= ZONE[1])
    free = (s >= 0.05) & (s <= 0.2)

    def off_a_line(mask):
        fit = np.polyval(np.polyfit(s[mask], gaps[mask], 1), s[mask])
        return np.abs(gaps[mask] - fit).max()

    assert off_a_line(zone) < 1e-8 * L  # measured 9e-14 to 8e-12 L
    assert off_a_line(free) > 1e-4 * L  # (the arm droops there)


@pytest.mark.parametrize("name", OBSTACLES)
def test_the_zones_variation_gives_the_tip_compliance_of_finite_differences(arm, name):
    """The zone's pressure changes with the state, and the tangent columns carry that change
    (kernels/rod.py, ``_zone_variation``): the tip compliance through a zone against central
    differences of solves."""
    obstacle = OBSTACLES[name]
    s = np.array([0.0, L])
    eq = _solve(arm, obstacle, s, jacobians=True)
    h = 1e-6
    columns = []
    for i in range(3):
        step = np.zeros(3)
        step[i] = h
        plus = _solve(arm, obstacle, s, tip=np.add(TIP, step)).tip_position
        minus = _solve(arm, obstacle, s, tip=np.subtract(TIP, step)).tip_position
        columns.append((plus - minus) / (2 * h))
    difference = np.stack(columns, axis=-1)
    compliance = eq.tip_compliance[:3, :3]
    assert np.abs(compliance - difference).max() < 1e-6 * np.abs(difference).max()

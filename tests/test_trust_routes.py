"""Issue 42 ("Trust, round 4"): the solver's route counts every force, out-of-range inputs
are refused up front, and a limit reached is said.

- a field gradient pulling a magnetised arm (kL = 32 by its pull) goes to multiple shooting
  and is solved: its tip against a collocation solution (scipy's solve_bvp) of the planar
  extensible, shearable rod under the magnetic force density G (R m) and torque
  (R m) × B(p), continued in the load factor as the solver's path is;
- the route's force of a field on the arm's magnets against the hand bound Σ|G_ij| (|m| L +
  |dipole|), and actuators' counting nothing (measured in docs/solver.md).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_bvp

import softarm as sa
from softarm.loads import largest_force

EA = GA = 1e6
EI = 1.0


def _magnetic_reference(g: float, b: float) -> np.ndarray:
    """Tip (x, z) of the planar rod (L = 1, EI, EA, GA above) clamped at the origin along x,
    magnetised (1, 0, 0) A m²/m along its axis, in B(x) = (0, 0, b) + diag(g, -g/2, -g/2) x.

    Unknowns along s: x, z, the tangent's angle θ (towards +z), the internal force (N_x,
    N_z) and moment M_y, spatial. With t = (cos θ, 0, sin θ), d3 = (-sin θ, 0, cos θ):
    p' = (1 + n·t/EA) t + (n·d3/GA) d3, θ' = -M_y/EI (a rotation about y by -θ),
    n' = -G t (the force ∇(m·B) = Gᵀ t, G symmetric), M_y' = -(p' × n)_y - (t × B(p))_y.
    The free tip: n = 0, M_y = 0. Continued from the unloaded arm in λ (b and g scaled)."""

    def rhs(lam):
        def f(s, y):
            x, z, th, nx, nz, m = y
            c, sn = np.cos(th), np.sin(th)
            n1, n3 = nx * c + nz * sn, -nx * sn + nz * c
            v1, v3 = 1.0 + n1 / EA, n3 / GA
            px, pz = v1 * c - v3 * sn, v1 * sn + v3 * c
            G = lam * g
            torque = G * x * sn - (lam * b - 0.5 * G * z) * c  # (t × B)_y
            return np.vstack([px, pz, -m / EI, -G * c, 0.5 * G * sn,
                              -(pz * nx - px * nz) - torque])
        return f

    def bc(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[3], yb[4], yb[5]])

    s = np.linspace(0.0, 1.0, 201)
    y = np.zeros((6, s.size))
    y[0] = s
    for lam in (0.1, 0.3, 0.6, 1.0):
        sol = solve_bvp(rhs(lam), bc, s, y, tol=1e-9, max_nodes=200000)
        assert sol.success, sol.message
        s, y = sol.x, sol.y
    return y[:2, -1]


def test_a_field_gradient_pulling_a_magnetised_arm_is_solved():
    # g M L³/EI = 1000: the arm is pulled along its axis by the force g per length, the
    # tension g L at the clamp (kL = 32); B0 bends it. Single shooting failed here with a
    # false fold after 12-45 s: the route did not count the magnets' force.
    g, b = 1000.0, 2.0
    arm = sa.Arm.from_stiffness(1.0, EA=EA, GAy=GA, GAz=GA, GJ=1.0, EIy=EI, EIz=EI,
                                magnetization=(1.0, 0.0, 0.0))
    field = sa.MagneticField([0.0, 0.0, b], gradient=np.diag([g, -g / 2, -g / 2]))
    eq = sa.solve(arm, field, method="numeric", tol=1e-10, s=3)
    x, z = _magnetic_reference(g, b)
    assert eq.tip_position == pytest.approx([x, 0.0, z], abs=1e-8)
    assert z > 1e-3  # (B0 does bend it: the comparison is not of a straight rod)


def test_the_route_counts_a_fields_force_on_the_magnets_and_no_actuator():
    m, d, L = np.array([0.3, -0.4, 0.0]), np.array([0.0, 2.0, 0.0]), 0.5
    arm = sa.Arm.from_stiffness(L, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0,
                                magnetization=tuple(m), tip_magnet=tuple(d))
    G = np.array([[1.0, 2.0, 0.0], [2.0, -3.0, 0.5], [0.0, 0.5, 2.0]])
    bound = np.abs(G).sum() * (np.linalg.norm(m) * L + np.linalg.norm(d))
    assert largest_force(arm, [sa.MagneticField([0.0, 0.0, 1.0], gradient=G)]) == \
        pytest.approx(bound, rel=1e-15)
    # a uniform field only turns the magnets; the gradients of a batch, case by case
    assert largest_force(arm, [sa.MagneticField([0.0, 0.0, 1.0])]) == 0.0
    batch = sa.MagneticField([0.0, 0.0, 1.0], gradient=np.stack([G, 2 * G, 0 * G]))
    assert largest_force(arm, [batch]) == pytest.approx([bound, 2 * bound, 0.0], rel=1e-15)
    # forces add up; a tendon and a chamber are internal
    tendon = sa.Tendon(1e4, sa.routing.Straight(0.0, 0.01))
    chamber = sa.Chamber(1e6, 1e-4, sa.routing.Straight(0.01, 0.0))
    tip = sa.TipLoad(force=[3.0, -4.0, 0.0])
    push = sa.DistributedForce([0.0, 0.0, -2.0], span=(0.1, 0.3))
    assert largest_force(arm, [tip, tendon, chamber, push]) == pytest.approx(7.0 + 0.4)

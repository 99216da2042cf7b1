"""axial_force (exact) and shear_force (eqs. 56-59, the Timoshenko cantilever)."""

from __future__ import annotations

import numpy as np
import pytest

from softarm import Arm, InadmissibleStateError
from softarm.analytic import axial_force, elastica, shear_force

# Grazioso et al. 2018, §IV.B (Princeton beam as printed): EIy = 36.28 N m²,
# GAz = 0.9039e6 N, L = 0.508 m; the other stiffnesses from validation/data/princeton_beam.json
# (MBDyn princeton_gen.m values: EA 2841910 N, GAy 640131 N, GJ 3.10338 N m², EIz 2.42873).
PRINCETON = Arm.from_stiffness(0.508, EA=2841910.0, GAy=640131.0, GAz=0.9039e6, GJ=3.10338,
                               EIy=36.28, EIz=2.42873)
# Grazioso et al. 2018, §IV.B: P1..P4 in N.
PRINCETON_LOADS = [4.448, 8.896, 13.345, 17.792]


def _arm(curvature=(0.0, 0.0, 0.0)):
    return Arm.from_stiffness(2.0, EA=100.0, GAy=50.0, GAz=70.0, GJ=1.0, EIy=1.0, EIz=3.0,
                              curvature=curvature)


@pytest.mark.parametrize("F", [10.0, -30.0, 0.0])
def test_axial_force(F):
    # §IV.B: constant axial strain F/EA; the length becomes L (1 + F/EA).
    eq = axial_force(_arm(), [F, 0.0, 0.0], s=5)
    assert eq.exact
    np.testing.assert_allclose(eq.positions[:, 0], np.linspace(0, 2, 5) * (1 + F / 100.0),
                               atol=1e-15)
    np.testing.assert_allclose(eq.positions[:, 1:], 0.0, atol=0)
    np.testing.assert_allclose(eq.rotations, np.broadcast_to(np.eye(3), (5, 3, 3)), atol=0)
    np.testing.assert_allclose(eq.stresses, np.broadcast_to([F, 0, 0, 0, 0, 0], (5, 6)),
                               atol=1e-12)


def test_axial_force_on_twisted_arm():
    # A pure initial twist keeps the axis straight; the frame turns about e1.
    eq = axial_force(_arm(curvature=(0.9, 0.0, 0.0)), [10.0, 0.0, 0.0], s=3)
    np.testing.assert_allclose(eq.tip_position, [2.2, 0.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(eq.forces_spatial[-1], [10.0, 0.0, 0.0], atol=1e-14)


def test_axial_force_bad_inputs():
    with pytest.raises(ValueError, match="straight"):
        axial_force(_arm(curvature=(0.0, 1.0, 0.0)), [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="force must be axial"):
        axial_force(_arm(), [1.0, 0.1, 0.0])
    # EA = 100 N: a compression of EA leaves v₁ = 1 - 100/100 = 0, the arm inside out
    with pytest.raises(InadmissibleStateError, match=r"axial stretch v₁ = 0 <= 0 at s = 0 m"):
        axial_force(_arm(), [-100.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="force"):
        axial_force(_arm(), 1.0)


@pytest.mark.parametrize("P", PRINCETON_LOADS)
def test_shear_force_princeton_timoshenko(P):
    # Timoshenko cantilever tip deflection P L³/3EI + P L/GA (eq. 58 at s = L).
    eq = shear_force(PRINCETON, [0.0, 0.0, P])
    L = 0.508
    assert not eq.exact
    np.testing.assert_allclose(eq.tip_position[2], P * L**3 / (3 * 36.28) + P * L / 0.9039e6,
                               rtol=1e-14)
    # eq. 58 along the arm and eq. 59 (θ_y = -(P L²/EI)(s/L - s²/2L²)) at the tip
    s = eq.s
    w = s * P / 0.9039e6 + P * L**3 / (6 * 36.28) * (3 * s**2 / L**2 - s**3 / L**3)
    np.testing.assert_allclose(eq.positions[:, 2], w, rtol=1e-14, atol=1e-18)
    theta_tip = -P * L**2 / 36.28 * (1 - 0.5)
    tip_R = eq.tip[:3, :3]
    np.testing.assert_allclose(np.arctan2(-tip_R[2, 0], tip_R[0, 0]), theta_tip, rtol=1e-13)


def test_shear_force_signs():
    # Sign check of docs/closed-forms.md (eqs. 50 with C6, and 58): +z tip force -> +z
    # deflection, negative κ_y.
    eq = shear_force(_arm(), [0.0, 0.0, 0.01])
    assert np.all(eq.positions[1:, 2] > 0)
    assert np.all(eq.strains[:-1, 4] < 0)
    np.testing.assert_allclose(eq.stresses[0, 4], -0.01 * 2.0, rtol=1e-14)  # m_y(0) = -P L
    # +y tip force -> +y deflection, positive κ_z, bending with EIz and GAy
    eq = shear_force(_arm(), [0.0, 0.01, 0.0])
    assert np.all(eq.positions[1:, 1] > 0)
    assert np.all(eq.strains[:-1, 5] > 0)
    np.testing.assert_allclose(eq.tip_position[1], 0.01 * 8 / 9 + 0.01 * 2 / 50, rtol=1e-14)


def test_shear_force_superposition():
    arm = _arm()
    both = shear_force(arm, [2.0, 0.01, -0.02])
    y = shear_force(arm, [0.0, 0.01, 0.0])
    z = shear_force(arm, [0.0, 0.0, -0.02])
    x = axial_force(arm, [2.0, 0.0, 0.0])
    np.testing.assert_allclose(both.strains, x.strains + y.strains + z.strains, atol=1e-15)
    expected = x.positions + (y.positions - y.positions[:, :1] * [1, 0, 0]) + \
        (z.positions - z.positions[:, :1] * [1, 0, 0])
    np.testing.assert_allclose(both.positions, expected, atol=1e-15)
    # an axial force alone coincides with the exact axial solution
    ax = shear_force(arm, [2.0, 0.0, 0.0])
    assert ax.exact
    np.testing.assert_allclose(ax.poses, x.poses, atol=1e-15)


def test_shear_force_small_load_limit_of_elastica():
    # The small-deflection solution is the k -> 0 limit of the exact extensible elastica:
    # the tip gap (relative) falls like k², the whole-shape gap (relative to the tip
    # deflection, dominated by the neglected shortening) like k.
    ks = np.array([1e-1, 1e-2, 1e-3])
    tip_gap, shape_gap = [], []
    for k in ks:
        force = [0.0, 0.0, k * 36.28 / 0.508**2]
        small, exact = shear_force(PRINCETON, force), elastica(PRINCETON, force)
        w = exact.tip_position[2]
        tip_gap.append(abs(small.tip_position[2] - w) / w)
        shape_gap.append(np.max(np.linalg.norm(small.positions - exact.positions, axis=-1)) / w)
    tip_gap, shape_gap = np.array(tip_gap), np.array(shape_gap)
    np.testing.assert_allclose(tip_gap / ks**2, tip_gap[0] / ks[0] ** 2, rtol=1e-2)
    np.testing.assert_allclose(shape_gap / ks, shape_gap[0] / ks[0], rtol=1e-2)
    assert shape_gap[-1] < 3e-4


def test_shear_force_bad_inputs():
    with pytest.raises(ValueError, match="straight"):
        shear_force(_arm(curvature=(0.1, 0.0, 0.0)), [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="force"):
        shear_force(_arm(), [[0.0, 1.0]])
    with pytest.raises(InadmissibleStateError, match=r"axial stretch v₁ = -1 <= 0"):
        shear_force(_arm(), [-200.0, 0.0, 1.0])  # v₁ = 1 - 200/100
    with pytest.raises(ValueError, match="s must"):
        shear_force(_arm(), [0.0, 0.0, 1.0], s=[0.5, 0.2])


def test_shear_force_error_estimate():
    # error_estimate = L k²/15, the neglected shortening: it is the largest position gap to
    # the exact elastica for small k (and the elastica's own u/L -> k²/15, Mattiasson table:
    # k = 0.1 gives u/L = 0.0006654 against 0.1²/15 = 0.000667).
    for k in (1e-1, 1e-2, 1e-3):
        force = [0.0, 0.0, k * 36.28 / 0.508**2]
        small, exact = shear_force(PRINCETON, force), elastica(PRINCETON, force)
        gap = np.max(np.linalg.norm(small.positions - exact.positions, axis=-1))
        np.testing.assert_allclose(small.error_estimate, 0.508 * k**2 / 15, rtol=1e-12)
        np.testing.assert_allclose(gap, small.error_estimate, rtol=1e-2)

"""elastica: the exact large-deflection cantilever, against Mattiasson's table and statics."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import reference_table

from softarm import Arm
from softarm.analytic import elastica, shear_force


def _arm(EA=1e6, GAy=1e6, GAz=1e6, EIy=1.0, EIz=2.0, L=1.0, curvature=(0.0, 0.0, 0.0)):
    return Arm.from_stiffness(L, EA=EA, GAy=GAy, GAz=GAz, GJ=0.5, EIy=EIy, EIz=EIz,
                              curvature=curvature)


def _mattiasson():
    # softarm/validation/data/mattiasson_cantilever.json, "computed_here" table: elliptic-integral
    # values that match Mattiasson (1981) Table 1 to every quoted digit.
    rows = reference_table("mattiasson_cantilever.json")["computed_here"]["table"]
    return {key: np.array([row[key] for row in rows])
            for key in ("k", "w_over_L", "x_tip_over_L", "tip_rotation_rad")}


@pytest.mark.parametrize("L", [1.0, 0.37])
def test_mattiasson_table(L):
    table = _mattiasson()
    k = table["k"]
    EI = 2.5
    force = np.stack([0 * k, 0 * k, k * EI / L**2], axis=-1)  # P = k EI / L²
    arm = _arm(EIy=EI, L=L)
    for eq in (elastica(arm, force, extensible=False),
               # EA, GA ~1e15 x the loads: the compliant solution differs by ~1e-13 L
               elastica(_arm(EA=1e16, GAz=1e16, EIy=EI, L=L), force)):
        np.testing.assert_allclose(eq.tip_position[:, 2] / L, table["w_over_L"], atol=1e-7)
        np.testing.assert_allclose(eq.tip_position[:, 0] / L, table["x_tip_over_L"], atol=1e-7)
        np.testing.assert_allclose(eq.tip_position[:, 1], 0.0, atol=0)
        R = eq.tip[:, :3, :3]
        np.testing.assert_allclose(np.arctan2(R[:, 2, 0], R[:, 0, 0]),
                                   table["tip_rotation_rad"], atol=1e-7)


def test_fundamental_branch():
    # Stable branch: the section turns monotonically towards the force, no inflection
    # (κ_y keeps its sign), the tip angle stays below the force angle π/2.
    eq = elastica(_arm(), [0.0, 0.0, 20.0], extensible=False)
    theta = np.arctan2(eq.rotations[:, 2, 0], eq.rotations[:, 0, 0])
    assert np.all(np.diff(theta) > 0) and theta[-1] < np.pi / 2
    assert np.all(eq.strains[:-1, 4] < 0)


def test_signs():
    # Sign checks of docs/closed-forms.md: +z force -> +z deflection, κ_y < 0 (x-z plane, EIy);
    # +y force -> +y deflection, κ_z > 0 (x-y plane, EIz).
    eq = elastica(_arm(), [0.0, 0.0, 0.5])
    assert np.all(eq.positions[1:, 2] > 0) and np.all(eq.strains[:-1, 4] < 0)
    assert np.all(eq.strains[:, [3, 5]] == 0)
    eq = elastica(_arm(), [0.0, 0.5, 0.0])
    assert np.all(eq.positions[1:, 1] > 0) and np.all(eq.strains[:-1, 5] > 0)
    assert np.all(eq.strains[:, [3, 4]] == 0)


@pytest.mark.parametrize("extensible", [True, False])
@pytest.mark.parametrize("force", [[0.0, 0.0, 3.0], [-2.0, 0.0, -1.0], [1.0, 4.0, 0.0]])
def test_global_equilibrium(force, extensible):
    # Dead tip force: the spatial internal force is F everywhere and the spatial moment at s
    # is (p(L) - p(s)) × F (the part [s, L] in equilibrium).
    arm = _arm(EA=60.0, GAy=20.0, GAz=30.0)
    eq = elastica(arm, force, extensible=extensible)
    np.testing.assert_allclose(eq.forces_spatial, np.broadcast_to(force, (101, 3)), atol=1e-12)
    lever = np.cross(eq.tip_position - eq.positions, force)
    np.testing.assert_allclose(eq.moments_spatial, lever, atol=1e-12)
    if extensible:  # σ = K ε exactly
        np.testing.assert_allclose(eq.stresses, eq.strains * np.diagonal(arm.stiffness),
                                   atol=1e-12)


def test_skew_force_on_symmetric_section():
    # EIy = EIz, GAy = GAz: a force in any plane through the axis is a rotated planar case.
    arm = _arm(EIz=1.0, GAy=5e3, GAz=5e3, EA=1e4)
    angle = 0.7
    c, s = np.cos(angle), np.sin(angle)
    Q = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])  # rotation about e1
    planar = elastica(arm, [0.3, 0.0, 2.0])
    skew = elastica(arm, Q @ [0.3, 0.0, 2.0])
    np.testing.assert_allclose(skew.positions, planar.positions @ Q.T, atol=1e-13)
    np.testing.assert_allclose(skew.rotations, Q @ planar.rotations @ Q.T, atol=1e-13)


def test_compression_buckles_about_the_weaker_axis():
    # Beyond the Euler load π² EI/4L² the fundamental branch is the buckled one.
    weak_z = _arm(EIy=1.0, EIz=2.0)
    eq = elastica(weak_z, [-4.0, 0.0, 0.0], extensible=False)  # k = 4 > π²/4
    assert eq.tip_position[2] > 0.1 and eq.tip_position[1] == 0.0
    below = elastica(weak_z, [-2.0, 0.0, 0.0], extensible=False)  # k = 2 < π²/4
    np.testing.assert_allclose(below.tip_position, [1.0, 0.0, 0.0], atol=1e-12)


def test_small_load_matches_shear_force():
    arm = _arm(EA=1e3, GAz=2e3)
    a, b = elastica(arm, [0.0, 0.0, 1e-4]), shear_force(arm, [0.0, 0.0, 1e-4])
    np.testing.assert_allclose(a.positions, b.positions, atol=1e-8 * 1e-4 / 3)


def test_zero_force():
    eq = elastica(_arm(), [0.0, 0.0, 0.0], s=3)
    np.testing.assert_allclose(eq.positions, [[0, 0, 0], [0.5, 0, 0], [1, 0, 0]], atol=0)
    assert eq.exact


def test_bad_inputs():
    with pytest.raises(ValueError, match="principal plane"):
        elastica(_arm(), [0.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="GAy = GAz"):
        elastica(_arm(EIz=1.0, GAy=2e6), [0.0, 1.0, 1.0])
    assert not elastica(_arm(EIz=1.0, GAy=2e6), [0.0, 1.0, 1.0], extensible=False).exact
    with pytest.raises(ValueError, match="straight"):
        elastica(_arm(curvature=(0.0, 0.1, 0.0)), [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="force"):
        elastica(_arm(), [0.0, 0.0, 2e5])  # k > 1e5
    with pytest.raises(ValueError, match="force"):
        elastica(_arm(EA=10.0), [20.0, 0.0, 0.0])  # P >= EA
    with pytest.raises(ValueError, match="force"):
        elastica(_arm(), [0.0, 1.0])
    with pytest.raises(TypeError, match="extensible"):
        elastica(_arm(), [0.0, 0.0, 1.0], extensible="no")

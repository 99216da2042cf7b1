"""tip_moment: eqs. 30-38 (principal axes), the helix of C4 (closed-forms.md), the approximation."""

from __future__ import annotations

import numpy as np
import pytest

from softarm import ApproximationWarning, Arm, Circle, Material, SegmentedArm
from softarm.analytic import linear, tip_moment
from softarm.lie import se3, so3


def _arm(GJ=1.0, EIy=1.0, EIz=1.0, curvature=(0.0, 0.0, 0.0), L=1.0):
    return Arm.from_stiffness(L, EA=1e6, GAy=1e6, GAz=1e6, GJ=GJ, EIy=EIy, EIz=EIz,
                              curvature=curvature)


@pytest.mark.parametrize("EIz", [1.0, 2.0])  # helix route (EIy = EIz) and principal route
@pytest.mark.parametrize("tau", [1.0, 2.0, 3.0, 4.0, 5.0])
def test_fig2_circle(tau, EIz):
    # Grazioso et al. 2018, Fig. 2: EIy = 1 N m², L = 1 m, τ = 1..5 N m about +y; positions
    # eq. 37, rotations eq. 38 as corrected in C5 (docs/closed-forms.md), κ_y = τ/EIy (eq. 36).
    s = np.linspace(0.0, 1.0, 41)
    eq = tip_moment(_arm(EIz=EIz), [0.0, tau, 0.0], s=s)
    assert eq.exact
    a = s * tau
    p = np.stack([np.sin(a) / tau, 0 * a, -(1 - np.cos(a)) / tau], axis=-1)
    R = np.zeros((s.size, 3, 3))
    R[:, 0, 0], R[:, 0, 2], R[:, 1, 1] = np.cos(a), np.sin(a), 1.0
    R[:, 2, 0], R[:, 2, 2] = -np.sin(a), np.cos(a)
    np.testing.assert_allclose(eq.positions, p, rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq.rotations, R, rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq.strains, np.broadcast_to([0, 0, 0, 0, tau, 0], (41, 6)),
                               atol=1e-12)
    np.testing.assert_allclose(eq.stresses[:, 4], tau, atol=1e-12)


def test_sign_positive_moment_about_y_bends_towards_minus_z():
    # Sign check of docs/closed-forms.md (eq. 37): +τ about +y on a straight arm bends towards -z.
    eq = tip_moment(_arm(EIz=3.0), [0.0, 0.1, 0.0])
    assert np.all(eq.positions[1:, 2] < 0)
    assert eq.strains[0, 4] > 0


@pytest.mark.parametrize(("follower", "tip"), [
    (False, [0.8492, 0.1508, -0.4220]),  # C4 (docs/closed-forms.md), dead moment
    (True, [0.8492, 0.2688, -0.3586]),  # C4, follower moment
])
def test_helix_note4(follower, tip):
    # C4: L = 1, EIy = EIz = 1, GJ = 1/1.3, moment (1, 1, 0).
    eq = tip_moment(_arm(GJ=1 / 1.3), [1.0, 1.0, 0.0], follower=follower)
    assert eq.exact and eq.method == "analytic.tip_moment.helix"
    np.testing.assert_allclose(eq.tip_position, tip, atol=1e-4)
    # The constant-strain formula gives neither (C4: (0.8544, 0.1893, -0.3975)).
    assert np.max(np.abs(eq.tip_position - [0.8544, 0.1893, -0.3975])) > 0.02


def test_constant_strain_value_note4():
    # C4: the paper's constant-strain formula gives (0.8544, 0.1893, -0.3975).
    # The same arm with EIz nudged off EIy takes the constant-strain route.
    with pytest.warns(ApproximationWarning, match="principal axis"):
        eq = tip_moment(_arm(GJ=1 / 1.3, EIz=1.0 + 1e-9), [1.0, 1.0, 0.0])
    assert not eq.exact and eq.method == "analytic.tip_moment.constant_strain"
    assert np.isnan(eq.error_estimate)
    np.testing.assert_allclose(eq.tip_position, [0.8544, 0.1893, -0.3975], atol=1e-4)
    # linear() on the straight arm carries the same constant strain (n = 0, m constant).
    ref = linear(_arm(GJ=1 / 1.3), moment=[1.0, 1.0, 0.0])
    np.testing.assert_allclose(ref.tip_position, [0.8544, 0.1893, -0.3975], atol=1e-4)


@pytest.mark.parametrize("follower", [False, True])
def test_helix_equilibrium(follower, rng):
    # n = 0 and a constant spatial moment M (dead: the given one) along the whole arm; the
    # tip's material moment equals the follower moment.
    arm = _arm(GJ=0.6, EIy=1.7, EIz=1.7, L=0.8)
    moment = rng.normal(size=3)
    eq = tip_moment(arm, moment, follower=follower)
    M = eq.moments_spatial
    np.testing.assert_allclose(M, np.broadcast_to(M[0], M.shape), atol=1e-12)
    np.testing.assert_allclose(eq.stresses[:, :3], 0.0, atol=0)
    tip_material = eq.stresses[-1, 3:]
    np.testing.assert_allclose(tip_material if follower else M[-1], moment, atol=1e-12)
    # and a principal moment gives the same circle dead or follower
    a = tip_moment(arm, [0.0, 0.0, 0.5], follower=False)
    b = tip_moment(arm, [0.0, 0.0, 0.5], follower=True)
    np.testing.assert_allclose(a.poses, b.poses, atol=1e-14)


def test_circle_section_uses_helix():
    # A Circle has EIy = EIz: any moment direction is exact.
    arm = Arm(0.3, Circle(0.01), Material(1.0e6, poisson_ratio=0.5))
    eq = tip_moment(arm, [1e-3, 2e-3, -1e-3])
    assert eq.exact and eq.method == "analytic.tip_moment.helix"


def test_twist_moment_is_principal():
    eq = tip_moment(_arm(GJ=0.5, EIz=2.0), [0.3, 0.0, 0.0])
    assert eq.exact
    np.testing.assert_allclose(eq.strains[:, 3], 0.6, atol=1e-15)  # κ₁ = T/GJ
    np.testing.assert_allclose(eq.positions[:, 0], eq.s, atol=1e-15)  # axis stays straight


def test_curved_arm_warns_unless_parallel():
    # A moment about z on an arm curved about y is not a constant-strain case (C2).
    arm = _arm(EIy=1.0, EIz=2.0, curvature=(0.0, 1.0, 0.0))
    with pytest.warns(ApproximationWarning):
        assert not tip_moment(arm, [0.0, 0.0, 0.1]).exact
    assert tip_moment(arm, [0.0, 0.2, 0.0]).exact  # parallel to κ⁰: exact, no warning
    # equal bending stiffness but initial curvature: the helix is not claimed
    with pytest.warns(ApproximationWarning):
        assert not tip_moment(_arm(curvature=(0.0, 1.0, 0.0)), [0.0, 0.0, 0.1]).exact


def test_zero_moment_is_undeformed():
    eq = tip_moment(_arm(EIz=2.0), [0.0, 0.0, 0.0], s=5)
    np.testing.assert_allclose(eq.positions[:, 0], np.linspace(0, 1, 5), atol=0)
    assert eq.exact


def test_stations():
    s = [0.1, 0.5, 0.75]
    eq = tip_moment(_arm(EIz=2.0), [0.0, 1.0, 0.0], s=s)
    np.testing.assert_allclose(eq.positions[:, 0], np.sin(s), atol=1e-15)


def test_bad_inputs():
    arm = _arm()
    with pytest.raises(ValueError, match="moment"):
        tip_moment(arm, [1.0, 2.0])
    with pytest.raises(ValueError, match="moment"):
        tip_moment(arm, [np.nan, 0.0, 0.0])
    with pytest.raises(TypeError, match="moment"):
        tip_moment(arm, "abc")
    with pytest.raises(TypeError, match="follower"):
        tip_moment(arm, [0.0, 1.0, 0.0], follower="yes")
    with pytest.raises(ValueError, match="s must"):
        tip_moment(arm, [0.0, 1.0, 0.0], s=[0.0, 2.0])
    with pytest.raises(TypeError, match="arm"):
        tip_moment(SegmentedArm([arm, arm]), [0.0, 1.0, 0.0])
    with pytest.raises(TypeError, match="arm"):
        tip_moment("arm", [0.0, 1.0, 0.0])


def _slow_helix(arm, moment, follower, s):
    """C4 by the generic maps: exp_SE3(s (e1; M/B)) · exp_SE3(s (0; c e1))."""
    GJ, B = arm.rigidities.GJ, arm.rigidities.EIy
    c = arm.curvature[0] + moment[..., 0] * (1.0 / GJ - 1.0 / B)
    if follower:
        moment = np.einsum("...ij,...j->...i", so3.exp(arm.length * c[..., None] * [1, 0, 0]),
                           moment)
    zeta = np.concatenate(np.broadcast_arrays([1.0, 0.0, 0.0], moment / B), axis=-1)
    twist = np.zeros((*c.shape, s.size, 6))
    twist[..., 3] = c[..., None] * s
    return se3.exp(s[:, None] * zeta[..., None, :]) @ se3.exp(twist), moment


def _moments(rng, shape):
    """Random moments of all sizes, with zero, tiny and axis-aligned ones mixed in."""
    m = rng.normal(size=(*shape, 3)) * 10.0 ** rng.uniform(-3, 0.7, size=(*shape, 1))
    flat = m.reshape(-1, 3)
    flat[0] = 0.0
    flat[1] = [1e-300, 0.0, 0.0]
    flat[2] = [0.0, 1e-9, 0.0]
    flat[3] = [2e-12, -1e-12, 3e-12]
    flat[4] = [0.0, 0.0, 2.5]
    flat[5] = [1e-160, 1e-160, 0.0]
    return m


@pytest.mark.parametrize("follower", [False, True])
def test_helix_fast_path_matches_generic_maps(follower, rng):
    # The direct pose kernel against se3.exp / so3.exp evaluated the slow way (their series
    # coefficients of _series.py), for a batch with zero, tiny and large moments.
    arm = _arm(GJ=0.6, EIy=1.3, EIz=1.3, curvature=(0.4, 0.0, 0.0), L=0.9)
    s = np.linspace(0.0, 0.9, 23)
    moment = _moments(rng, (4, 10))
    eq = tip_moment(arm, moment, follower=follower, s=s)
    assert eq.method == "analytic.tip_moment.helix"
    ref, M = _slow_helix(arm, moment, follower, s)
    np.testing.assert_allclose(eq.poses, ref, rtol=0, atol=2e-15)
    # strains from the rotations: m = Rᵀ M, ε = (0; m / (GJ, B, B))
    m = np.einsum("...nji,...j->...ni", ref[..., :3, :3], M)
    np.testing.assert_allclose(eq.stresses[..., 3:], m, rtol=0, atol=4e-14)
    np.testing.assert_allclose(eq.strains[..., 3:], m / [0.6, 1.3, 1.3], rtol=0, atol=4e-14)
    assert np.all(eq.stresses[..., :3] == 0.0) and np.all(eq.strains[..., :3] == 0.0)


def test_principal_fast_path_matches_generic_maps(rng):
    # Eqs. 30-34, H(s) = exp_SE3(s (f⁰ + ε)), against se3.exp for moments about the principal
    # axes (and zero, tiny ones) on a twisted arm: exact for moments about e1 (parallel to κ⁰).
    arm = _arm(GJ=0.5, EIy=1.0, EIz=2.0, curvature=(0.7, 0.0, 0.0), L=1.2)
    s = np.linspace(0.0, 1.2, 17)
    moment = np.zeros((30, 3))
    moment[:, 0] = rng.normal(size=30) * 10.0 ** rng.uniform(-12, 0.5, size=30)
    moment[:3, 0] = [0.0, 1e-300, -4e-9]
    eq = tip_moment(arm, moment, s=s)
    assert eq.method == "analytic.tip_moment.principal"
    f = arm.reference_strain + np.concatenate([np.zeros_like(moment), moment / [0.5, 1, 2]], -1)
    np.testing.assert_allclose(eq.poses, se3.exp(s[:, None] * f[:, None, :]), rtol=0,
                               atol=2e-15)
    straight = _arm(EIy=1.0, EIz=2.0, L=1.2)
    for axis in (1, 2):
        moment = np.zeros((30, 3))
        moment[:, axis] = rng.normal(size=30) * 10.0 ** rng.uniform(-12, 0.7, size=30)
        moment[:2, axis] = [0.0, 3e-200]
        eq = tip_moment(straight, moment, s=s)
        assert eq.exact
        f = np.concatenate([np.broadcast_to([1.0, 0, 0], (30, 3)), moment / [1, 1, 2]], -1)
        ref = se3.exp(s[:, None] * f[:, None, :])
        np.testing.assert_allclose(eq.poses, ref, rtol=0, atol=2e-15)
        np.testing.assert_allclose(eq.rotations, so3.exp(s[:, None] * f[:, None, 3:]), rtol=0,
                                   atol=2e-15)
        # constant strain: a read-only broadcast view, no memory per station
        assert eq.strains.strides[-2] == 0 and not eq.strains.flags.writeable


def test_results_are_read_only_and_not_copied():
    eq = tip_moment(_arm(GJ=0.6), [[0.2, 0.5, -0.1], [0.0, 1.0, 0.3]])
    for name in ("poses", "strains", "stresses"):
        array = getattr(eq, name)
        with pytest.raises(ValueError, match="read-only"):
            array[..., 0] = 1.0
    assert eq.poses.base is eq.strains.base is eq.stresses.base  # one buffer, written once
    assert eq.poses.base.flags.owndata and not eq.poses.base.flags.writeable

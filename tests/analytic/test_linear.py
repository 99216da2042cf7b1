"""linear: eq. 27 with F(α) corrected (docs/closed-forms.md, C3), against the other closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from softarm import Arm
from softarm.analytic import axial_force, linear, shear_force, tip_moment


def _arm(curvature=(0.0, 0.0, 0.0), GJ=0.7, EIy=1.0, EIz=2.0):
    return Arm.from_stiffness(1.5, EA=300.0, GAy=80.0, GAz=120.0, GJ=GJ, EIy=EIy, EIz=EIz,
                              curvature=curvature)


def _hat4(h):
    u, w = h[:3], h[3:]
    return np.array([[0, -w[2], w[1], u[0]], [w[2], 0, -w[0], u[1]],
                     [-w[1], w[0], 0, u[2]], [0, 0, 0, 0]], dtype=float)


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def test_wrench_is_tip_wrench_transported_along_undeformed_curve(rng):
    # σ(s) = Ad(G(L)⁻¹ G(s))ᵀ σ(L) with G(s) = expm(s f⁰~) the undeformed pose, built here
    # from scipy.linalg.expm and Ad(H) = [[R, p~R], [0, R]] (docs/closed-forms.md, C3).
    arm = _arm(curvature=(0.3, -0.8, 0.5))
    f0 = np.array([1.0, 0, 0, 0.3, -0.8, 0.5])
    force, moment = rng.normal(size=3), rng.normal(size=3)
    s = np.linspace(0.0, 1.5, 13)
    eq = linear(arm, force=force, moment=moment, s=s, follower=True)
    for i, si in enumerate(s):
        H = expm((si - 1.5) * _hat4(f0))
        R, p = H[:3, :3], H[:3, 3]
        Ad = np.block([[R, _skew(p) @ R], [np.zeros((3, 3)), R]])
        np.testing.assert_allclose(eq.stresses[i], Ad.T @ np.concatenate([force, moment]),
                                   atol=1e-13)
    # straight arm, tip force P e3: m(s) = -(L - s) P e2 (docs/closed-forms.md, C3)
    eq = linear(_arm(), force=[0.0, 0.0, 2.0], s=s)
    np.testing.assert_allclose(eq.stresses[:, 4], -(1.5 - s) * 2.0, atol=1e-14)
    # dead loads on a curved arm are spatial: the undeformed tip frame turns them
    dead = linear(arm, force=force, moment=moment, s=s)
    R_tip = expm(1.5 * _skew([0.3, -0.8, 0.5]))
    np.testing.assert_allclose(dead.stresses[-1], np.concatenate([R_tip.T @ force,
                                                                  R_tip.T @ moment]), atol=1e-13)


def test_reproduces_shear_force():
    # Straight arm, small tip force: the same strains as eqs. 49-50 (superposed), positions
    # equal to first order in the load and O(h²) in the station spacing.
    arm = _arm()
    force = np.array([0.3, -1e-3, 2e-3])
    a = linear(arm, force=force, s=401)
    b = shear_force(arm, force, s=401)
    np.testing.assert_allclose(a.strains, b.strains, atol=1e-16)
    np.testing.assert_allclose(a.stresses, b.stresses, atol=1e-14)
    scale = np.max(np.abs(b.positions[:, 1:]))
    assert np.max(np.abs(a.positions - b.positions)) < 1e-3 * scale
    assert not a.exact


def test_reproduces_tip_moment():
    arm = _arm()
    # principal moment: both exact and identical (constant strain, eq. 32)
    a, b = linear(arm, moment=[0.0, 0.0, 0.8]), tip_moment(arm, [0.0, 0.0, 0.8])
    assert a.exact and b.exact
    np.testing.assert_allclose(a.poses, b.poses, atol=1e-13)
    # any small moment on an equal-stiffness arm: linear -> the exact helix as M -> 0
    arm = _arm(EIz=1.0)
    gaps = []
    for size in (1e-2, 1e-3):
        moment = size * np.array([1.0, 1.0, 0.0])
        a, b = linear(arm, moment=moment), tip_moment(arm, moment)
        assert not a.exact and b.exact
        gaps.append(np.max(np.abs(a.positions - b.positions)) / size)
    assert gaps[1] < 0.15 * gaps[0]  # the relative gap falls ∝ M


def test_axial_force_is_exact():
    arm = _arm(curvature=(0.4, 0.0, 0.0))
    a, b = linear(arm, force=[5.0, 0.0, 0.0]), axial_force(arm, [5.0, 0.0, 0.0])
    assert a.exact
    np.testing.assert_allclose(a.poses, b.poses, atol=1e-13)


def test_pose_converges_with_station_spacing():
    # Midpoint exponential steps: error O(h²) against a fine grid.
    arm = _arm(curvature=(0.2, 0.6, -0.4))
    load = dict(force=[0.4, -0.3, 0.5], moment=[0.1, 0.2, -0.1])
    fine = linear(arm, **load, s=4097).tip
    errors = [np.max(np.abs(linear(arm, **load, s=n).tip - fine)) for n in (9, 17, 33)]
    assert 3.5 < errors[0] / errors[1] < 4.5 and 3.5 < errors[1] / errors[2] < 4.5


def test_stations_not_starting_at_zero():
    arm = _arm()
    full = linear(arm, force=[0.0, 0.0, 0.01], s=np.linspace(0.0, 1.5, 301))
    part = linear(arm, force=[0.0, 0.0, 0.01], s=np.linspace(0.0, 1.5, 301)[150:])
    np.testing.assert_allclose(part.positions[-1], full.positions[-1], atol=1e-6)
    assert part.s[0] == 0.75


def test_bad_inputs():
    with pytest.raises(ValueError, match="force"):
        linear(_arm(), force=[1.0, 0.0])
    with pytest.raises(ValueError, match="moment"):
        linear(_arm(), moment=[np.inf, 0.0, 0.0])
    with pytest.raises(TypeError, match="follower"):
        linear(_arm(), follower=1)

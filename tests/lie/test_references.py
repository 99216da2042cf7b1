"""SO(3)/SE(3) maps against independent references: finite differences, scipy, mpmath.

EPS is the double-precision machine epsilon 2⁻⁵² ≈ 2.2e-16.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from softarm.lie import se3, so3

EPS = np.finfo(np.float64).eps


def sample_rotation_vectors(rng, n: int = 40) -> np.ndarray:
    """n rotation vectors in each regime: near 0, middle, near π (θ in [π - 1e-8, π))."""
    axes = rng.normal(size=(3 * n, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    theta = np.concatenate([
        10.0 ** rng.uniform(-9, -4, n),
        rng.uniform(1e-4, 3.0, n),
        np.pi - rng.uniform(0, 1e-8, n),
    ])
    return theta[:, None] * axes


def sample_twists(rng, n: int = 40) -> np.ndarray:
    w = sample_rotation_vectors(rng, n)
    return np.concatenate([rng.uniform(-2, 2, size=w.shape), w], axis=-1)


# ---------------------------------------------------------------------------------------------
# The defining property of the tangent operator (Grazioso et al. 2018, eqs. 72-73; STYLE.md):
#   exp(h)⁻¹ ∂/∂ε exp(h + εδ)|₀ = (T(h) δ)~,
# by central differences with step STEP. Truncation error ~ STEP² |∂³exp|/6 ≈ 1e-10 and rounding
# ~ EPS/STEP ≈ 2e-11 (times |exp| <= 1 + |p|); a wrong operator errs by O(|ω|) (jac_left in
# place of jac_right) or O(|u|) (a wrong T_uω+ block).

STEP = 1e-5
FD_TOL = 2e-9


def test_so3_jac_right_is_the_tangent_operator(rng):
    w = sample_rotation_vectors(rng)
    delta = rng.normal(size=w.shape)
    dR = (so3.exp(w + STEP * delta) - so3.exp(w - STEP * delta)) / (2 * STEP)
    lhs = np.swapaxes(so3.exp(w), -1, -2) @ dR
    rhs = so3.hat(np.einsum("...ij,...j->...i", so3.jac_right(w), delta))
    assert_allclose(lhs, rhs, rtol=0, atol=FD_TOL)
    # And the left Jacobian is the spatial (left-trivialised) derivative.
    lhs_left = dR @ np.swapaxes(so3.exp(w), -1, -2)
    rhs_left = so3.hat(np.einsum("...ij,...j->...i", so3.jac_left(w), delta))
    assert_allclose(lhs_left, rhs_left, rtol=0, atol=FD_TOL)


def test_se3_jac_right_is_the_tangent_operator(rng):
    h = sample_twists(rng)
    delta = rng.normal(size=h.shape)
    dH = (se3.exp(h + STEP * delta) - se3.exp(h - STEP * delta)) / (2 * STEP)
    lhs = se3.inverse(se3.exp(h)) @ dH
    rhs = se3.hat(np.einsum("...ij,...j->...i", se3.jac_right(h), delta))
    assert_allclose(lhs, rhs, rtol=0, atol=FD_TOL)


def test_finite_difference_check_detects_a_wrong_operator(rng):
    # The check above has teeth: jac_left in place of jac_right fails it in the middle regime.
    h = sample_twists(rng)[40:80]
    delta = rng.normal(size=h.shape)
    dH = (se3.exp(h + STEP * delta) - se3.exp(h - STEP * delta)) / (2 * STEP)
    lhs = se3.inverse(se3.exp(h)) @ dH
    wrong = np.swapaxes(se3.jac_right(h), -1, -2)
    rhs = se3.hat(np.einsum("...ij,...j->...i", wrong, delta))
    assert np.max(np.abs(lhs - rhs)) > 1e3 * FD_TOL


# ---------------------------------------------------------------------------------------------
# exp against scipy: the matrix exponential of the algebra element, and scipy's Rotation.


def test_so3_exp_against_expm(rng):
    for w in sample_rotation_vectors(rng, 10):
        # expm (Padé with scaling and squaring) is accurate to a few EPS in norm here.
        assert_allclose(so3.exp(w), expm(so3.hat(w)), rtol=0, atol=16 * EPS)


def test_se3_exp_against_expm(rng):
    for h in sample_twists(rng, 10):
        assert_allclose(se3.exp(h), expm(se3.hat(h)), rtol=0, atol=32 * EPS)


def test_se3_adjoint_of_exp_is_expm_of_ad(rng):
    # Ad(exp(h)) = expm(ad(h)): the adjoint representation commutes with exp.
    for h in sample_twists(rng, 10):
        # expm's error grows with |ad(h)| ~ |u|: measured <= 2.4e-14 with |u| <= 3.5.
        scale = (1 + np.linalg.norm(h[:3])) ** 2
        assert_allclose(se3.adjoint(se3.exp(h)), expm(se3.ad(h)), rtol=0, atol=32 * EPS * scale)


def test_so3_against_scipy_rotation(rng):
    w = sample_rotation_vectors(rng)
    R_scipy = Rotation.from_rotvec(w).as_matrix()
    assert_allclose(so3.exp(w), R_scipy, rtol=0, atol=8 * EPS)
    # Away from π (where ±ω are both right) scipy's log is a second opinion on ours.
    middle = w[:80]
    assert_allclose(so3.log(R_scipy[:80]), Rotation.from_matrix(R_scipy[:80]).as_rotvec(),
                    rtol=1e-14, atol=0)
    assert np.linalg.norm(middle) > 0


# ---------------------------------------------------------------------------------------------
# Jacobians at θ = 1e-7 against mpmath: the closed forms of the coefficients lose about half
# the digits here in double precision (sinc3 written directly keeps ~2 digits), so this pins the
# small-angle path of every block.

DIGITS = 120  # the closed forms lose <= 30 digits at θ = 1e-7; > 40 correct digits remain.


def mp_vector(v):
    return [mpmath.mpf(float(c)) for c in v]


def mp_hat(v):
    x, y, z = v
    return mpmath.matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])


def mp_so3_jac_right(w):
    """T_SO3 = I - ((1-cos θ)/θ²) ω~ + ((θ - sin θ)/θ³) ω~² (Grazioso et al. 2018, eq. 73)."""
    w = mp_vector(w)
    W = mp_hat(w)
    t2 = sum(c**2 for c in w)
    t = mpmath.sqrt(t2)
    return mpmath.eye(3) - (1 - mpmath.cos(t)) / t2 * W + (t - mpmath.sin(t)) / (t2 * t) * W * W


def mp_so3_jac_right_inv(w):
    """I + ½ ω~ + (1/θ² - (1 + cos θ)/(2 θ sin θ)) ω~² (e.g. Chirikjian, Stochastic Models,
    Information Theory, and Lie Groups, vol. 2, eq. 10.86; checked against mp.inverse below)."""
    w = mp_vector(w)
    W = mp_hat(w)
    t2 = sum(c**2 for c in w)
    t = mpmath.sqrt(t2)
    coefficient = 1 / t2 - (1 + mpmath.cos(t)) / (2 * t * mpmath.sin(t))
    return mpmath.eye(3) + W / 2 + coefficient * W * W


def mp_se3_jac_right(h):
    """T_SE3 = [[T_SO3, T_uω+], [0, T_SO3]] (eq. 72) with T_uω+ of eqs. 74-75 as corrected in
    C1 of docs/closed-forms.md (α = sin θ/θ, β = 2(1 - cos θ)/θ²)."""
    u, w = mp_vector(h[:3]), mp_vector(h[3:])
    U, W = mp_hat(u), mp_hat(w)
    t2 = sum(c**2 for c in w)
    t = mpmath.sqrt(t2)
    alpha = mpmath.sin(t) / t
    beta = 2 * (1 - mpmath.cos(t)) / t2
    wu = sum(a * b for a, b in zip(w, u, strict=True))
    t_uw = (-(beta / 2) * U + ((1 - alpha) / t2) * (U * W + W * U)
            + (wu / t2) * ((beta - alpha) * W + (beta / 2 - 3 * (1 - alpha) / t2) * W * W))
    T = mp_so3_jac_right(w)
    J = mpmath.zeros(6, 6)
    for i in range(3):
        for j in range(3):
            J[i, j] = J[i + 3, j + 3] = T[i, j]
            J[i, j + 3] = t_uw[i, j]
    return J


def assert_entrywise_relative(got, reference, rtol, floor=0.0):
    """|got - reference| <= rtol · max(|reference|, floor), entry by entry (exact zeros too)."""
    assert got.shape == (reference.rows, reference.cols)
    for i in range(reference.rows):
        for j in range(reference.cols):
            value = reference[i, j]
            error = abs(mpmath.mpf(got[i, j]) - value)
            assert error <= rtol * max(abs(value), floor), (i, j, got[i, j], value)


W_SMALL = [np.array([0.48, -0.6, 0.64]) * 1e-7, np.array([-0.36, 0.48, 0.8]) * 1e-7,
           np.array([1.0, 0.0, 0.0]) * 1e-7]
U = np.array([0.3, -1.2, 0.7])


@pytest.mark.parametrize("w", W_SMALL)
def test_so3_jacobians_at_small_angle_against_mpmath(w):
    with mpmath.workdps(DIGITS):
        T = mp_so3_jac_right(w)
        T_inv = mp_so3_jac_right_inv(w)
        # The inverse's closed form is the inverse: a check of the reference itself.
        assert mpmath.mnorm(T * T_inv - mpmath.eye(3), 1) < mpmath.mpf(10) ** -60
        assert_entrywise_relative(so3.jac_right(w), T, 1e-14)
        assert_entrywise_relative(so3.jac_right_inv(w), T_inv, 1e-14)
        assert_entrywise_relative(so3.jac_left(w), T.T, 1e-14)
        assert_entrywise_relative(so3.jac_left_inv(w), T_inv.T, 1e-14)


@pytest.mark.parametrize("w", W_SMALL)
def test_se3_jacobians_at_small_angle_against_mpmath(w):
    h = np.concatenate([U, w])
    # The upper-right blocks sum terms of size θ|u| (u~ω~, ...); an entry of J⁻¹'s block that
    # cancels to well below that (2.7e-10 against θ|u| = 1.5e-7 for the second ω) is held to
    # 1e-14 θ|u| absolute. Measured worst error: 2.1e-14 of that entry's value, 4e-17 θ|u|.
    floor = np.linalg.norm(w) * np.linalg.norm(U)
    with mpmath.workdps(DIGITS):
        J = mp_se3_jac_right(h)
        assert_entrywise_relative(se3.jac_right(h), J, 1e-14)
        assert_entrywise_relative(se3.jac_right_inv(h), mpmath.inverse(J), 1e-14, floor)


def test_se3_jacobian_mpmath_reference_matches_finite_differences():
    # The mpmath T_SE3 (C1) satisfies the defining property too, at a large angle
    # where every term of T_uω+ matters: an independent check of the reference formula.
    h = np.array([0.3, -1.2, 0.7, 0.9, -1.1, 1.6])
    with mpmath.workdps(30):
        J = mp_se3_jac_right(h)
        J = np.array([[float(J[i, j]) for j in range(6)] for i in range(6)])
    for k in range(6):
        delta = np.eye(6)[k]
        dH = (se3.exp(h + STEP * delta) - se3.exp(h - STEP * delta)) / (2 * STEP)
        assert_allclose(se3.vee(se3.inverse(se3.exp(h)) @ dH), J[:, k], rtol=0, atol=FD_TOL)


# ---------------------------------------------------------------------------------------------
# log near π (STYLE.md: test it at π - 1e-8).

AXES_NEAR_PI = [np.array([1.0, 0.0, 0.0]), np.array([0.0, -1.0, 0.0]),
                np.array([0.48, -0.6, 0.64]), np.array([-0.36, 0.48, -0.8]),
                np.array([0.6, 0.0, 0.8])]


@pytest.mark.parametrize("axis", AXES_NEAR_PI)
def test_so3_log_at_pi_minus_1e_8(axis):
    theta = np.pi - 1e-8
    R = so3.exp(theta * axis)
    w = so3.log(R)
    assert abs(np.linalg.norm(w) - theta) <= 4 * EPS
    assert_allclose(w, theta * axis, rtol=0, atol=8 * EPS)
    assert_allclose(so3.exp(w), R, rtol=0, atol=1e-15)


@pytest.mark.parametrize("axis", AXES_NEAR_PI)
def test_se3_log_at_pi_minus_1e_8(axis):
    h = np.concatenate([U, (np.pi - 1e-8) * axis])
    H = se3.exp(h)
    assert_allclose(se3.log(H), h, rtol=0, atol=32 * EPS)
    assert_allclose(se3.exp(se3.log(H)), H, rtol=0, atol=4e-15)


def test_so3_log_of_half_turns():
    # Exact half turns about the coordinate axes: |log| = π, the axis up to sign.
    for k in range(3):
        R = 2.0 * np.outer(np.eye(3)[k], np.eye(3)[k]) - np.eye(3)
        w = so3.log(R)
        assert abs(np.linalg.norm(w) - np.pi) <= 2 * EPS
        assert_allclose(np.abs(w), np.pi * np.eye(3)[k], rtol=0, atol=2 * EPS)
        assert_allclose(so3.exp(w), R, rtol=0, atol=2 * EPS)


def test_logs_at_identity_are_zero():
    assert np.array_equal(so3.log(np.eye(3)), np.zeros(3))
    assert np.array_equal(se3.log(np.eye(4)), np.zeros(6))
    assert np.array_equal(so3.exp(np.zeros(3)), np.eye(3))
    assert np.array_equal(se3.exp(np.zeros(6)), np.eye(4))

"""Group identities of SO(3) and SE(3), sampled near θ = 0, in the middle and near θ = π.

Tolerances are in units of the machine epsilon EPS = 2⁻⁵² ≈ 2.2e-16, scaled by the size of the
quantities involved; each is a few times the worst error measured over 20000 random samples
per regime (the figures are in the comments).
"""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from softarm.lie import se3, so3

EPS = np.finfo(np.float64).eps
SETTINGS = settings(max_examples=100, deadline=None, derandomize=True, database=None)

# Rotation angles θ = |ω| from three regimes: near 0 (1e-9 .. 1e-4 rad), the middle, and near
# π (π - 1e-8 .. π).
angles = st.one_of(
    st.floats(-9.0, -4.0).map(lambda e: 10.0**e),
    st.floats(1e-4, np.pi - 1e-8),
    st.floats(0.0, 1e-8).map(lambda d: np.pi - d),
)


def _unit(z: float, azimuth: float) -> np.ndarray:
    r = np.sqrt(1.0 - z * z)
    return np.array([r * np.cos(azimuth), r * np.sin(azimuth), z])


axes = st.builds(_unit, st.floats(-1.0, 1.0), st.floats(0.0, 2 * np.pi))
rotation_vectors = st.builds(lambda axis, theta: theta * axis, axes, angles)
translations = st.tuples(st.floats(-2.0, 2.0), st.floats(-2.0, 2.0), st.floats(-2.0, 2.0)).map(
    np.array
)
twists = st.builds(lambda u, w: np.concatenate([u, w]), translations, rotation_vectors)
W_NEAR_PI = np.array([0.48, -0.6, 0.64]) * (np.pi - 1e-8)  # unit axis (0.48, -0.6, 0.64)
W_NEAR_ZERO = np.array([0.48, -0.6, 0.64]) * 1e-9
H_NEAR_PI = np.concatenate([[0.3, -1.2, 0.7], W_NEAR_PI])


def norm(v) -> float:
    return float(np.linalg.norm(v))


# ---------------------------------------------------------------------------------------------
# SO(3)


@SETTINGS
@given(rotation_vectors)
@example(W_NEAR_PI)
@example(W_NEAR_ZERO)
def test_so3_log_exp(w):
    # |ω| < π: log(exp(ω)) = ω to a relative error of a few EPS (measured <= 2.3 EPS), in every
    # regime: near 0 this is the small-angle accuracy of both maps.
    R = so3.exp(w)
    w_back = so3.log(R)
    if np.pi - norm(w) < 1e-14:
        # sin θ < 1e-14 is below the rounding of exp's entries: ω and -ω (the same rotation at
        # θ = π) are equally valid answers.
        w_back = w_back if norm(w_back - w) < norm(w_back + w) else -w_back
    assert norm(w_back - w) <= 8 * EPS * norm(w)
    # exp(log R) = R: measured max error 6 EPS.
    assert_allclose(so3.exp(so3.log(R)), R, rtol=0, atol=16 * EPS)
    # R is a rotation about ω: measured max |R Rᵀ - I| = 10.5 EPS.
    assert_allclose(R @ R.T, np.eye(3), rtol=0, atol=16 * EPS)
    assert abs(np.linalg.det(R) - 1.0) <= 16 * EPS
    assert_allclose(R @ w, w, rtol=0, atol=16 * EPS * max(1.0, norm(w)))


@SETTINGS
@given(rotation_vectors)
def test_so3_vee_hat(w):
    W = so3.hat(w)
    assert_array_equal(so3.vee(W), w)
    assert_array_equal(W, -W.T)
    v = np.array([0.3, -0.4, 1.1])
    assert_allclose(W @ v, np.cross(w, v), rtol=0, atol=4 * EPS * norm(w))


@SETTINGS
@given(rotation_vectors)
@example(W_NEAR_PI)
def test_so3_jacobians(w):
    # J J⁻¹ = I, right and left: measured max error 3 EPS.
    assert_allclose(so3.jac_right(w) @ so3.jac_right_inv(w), np.eye(3), rtol=0, atol=16 * EPS)
    assert_allclose(so3.jac_left(w) @ so3.jac_left_inv(w), np.eye(3), rtol=0, atol=16 * EPS)
    # jac_left = jac_rightᵀ = jac_right(-ω), and the same for the inverses.
    assert_allclose(so3.jac_left(w), so3.jac_right(w).T, rtol=0, atol=2 * EPS)
    assert_allclose(so3.jac_left(w), so3.jac_right(-w), rtol=0, atol=2 * EPS)
    assert_allclose(so3.jac_left_inv(w), so3.jac_right_inv(w).T, rtol=0, atol=2 * EPS)
    # jac_left = R jac_right: the left and right trivialisations differ by Ad = R.
    assert_allclose(so3.jac_left(w), so3.exp(w) @ so3.jac_right(w), rtol=0, atol=16 * EPS)


# ---------------------------------------------------------------------------------------------
# SE(3)


@SETTINGS
@given(twists)
@example(H_NEAR_PI)
def test_se3_log_exp(h):
    # Measured max |log(exp h) - h| = 9.5 EPS and |exp(log H) - H| = 6 EPS with |u| ~ 1.
    H = se3.exp(h)
    h_back = se3.log(H)
    w = h[3:]
    if np.pi - norm(w) < 1e-14:
        # At θ = π (to rounding) ω and -ω give the same rotation; u then follows the sign choice.
        assert norm(h_back[3:] + w) < norm(h_back[3:] - w) or norm(h_back - h) <= 32 * EPS * (
            1 + norm(h)
        )
    else:
        assert norm(h_back[3:] - w) <= 8 * EPS * norm(w)
        assert norm(h_back[:3] - h[:3]) <= 32 * EPS * (1 + norm(h[:3]))
    assert_allclose(se3.exp(se3.log(H)), H, rtol=0, atol=16 * EPS * (1 + norm(h[:3])))


@SETTINGS
@given(twists)
def test_se3_vee_hat_and_exp_blocks(h):
    X = se3.hat(h)
    assert_array_equal(se3.vee(X), h)
    assert_array_equal(X[3], np.zeros(4))
    # exp on SE(3) is [[exp_SO3(ω), T_SO3(ω)ᵀ u], [0, 1]] (Grazioso et al. 2018, eq. 69).
    H = se3.exp(h)
    u, w = h[:3], h[3:]
    assert_allclose(H[:3, :3], so3.exp(w), rtol=0, atol=2 * EPS)
    assert_allclose(H[:3, 3], so3.jac_right(w).T @ u, rtol=0, atol=8 * EPS * (1 + norm(u)))
    assert_array_equal(H[3], [0.0, 0.0, 0.0, 1.0])


@SETTINGS
@given(twists, twists)
def test_se3_inverse_and_adjoint(g, h):
    G, H = se3.exp(g), se3.exp(h)
    sg, sh = 1 + norm(g[:3]), 1 + norm(h[:3])
    # inverse: G⁻¹ G = G G⁻¹ = I and exp(-g) = exp(g)⁻¹.
    assert_allclose(se3.inverse(G) @ G, np.eye(4), rtol=0, atol=16 * EPS * sg)
    assert_allclose(G @ se3.inverse(G), np.eye(4), rtol=0, atol=16 * EPS * sg)
    assert_allclose(se3.inverse(G), se3.exp(-g), rtol=0, atol=16 * EPS * sg)
    # Ad(G) h = vee(G h~ G⁻¹), with G⁻¹ from numpy's general inverse, not se3.inverse.
    expected = se3.vee(G @ se3.hat(h) @ np.linalg.inv(G))
    assert_allclose(se3.adjoint(G) @ h, expected, rtol=0, atol=32 * EPS * sg * (1 + norm(h)))
    # Ad(GH) = Ad(G) Ad(H), Ad(G⁻¹) = Ad(G)⁻¹.
    assert_allclose(se3.adjoint(G @ H), se3.adjoint(G) @ se3.adjoint(H), rtol=0,
                    atol=32 * EPS * sg * sh)
    assert_allclose(se3.adjoint(se3.inverse(G)), np.linalg.inv(se3.adjoint(G)), rtol=0,
                    atol=64 * EPS * sg**2)


@SETTINGS
@given(twists, twists)
def test_se3_ad_is_the_lie_bracket(a, b):
    scale = (1 + norm(a)) * (1 + norm(b))
    assert_allclose(se3.ad(a) @ b, -se3.ad(b) @ a, rtol=0, atol=4 * EPS * scale)
    A, B = se3.hat(a), se3.hat(b)
    assert_allclose(se3.ad(a) @ b, se3.vee(A @ B - B @ A), rtol=0, atol=8 * EPS * scale)


@SETTINGS
@given(twists)
@example(H_NEAR_PI)
def test_se3_jacobian(h):
    # J J⁻¹ = J⁻¹ J = I: measured max error 5 EPS with |u| ~ 1.
    scale = 1 + norm(h[:3])
    J, J_inv = se3.jac_right(h), se3.jac_right_inv(h)
    assert_allclose(J @ J_inv, np.eye(6), rtol=0, atol=32 * EPS * scale)
    assert_allclose(J_inv @ J, np.eye(6), rtol=0, atol=32 * EPS * scale)
    # Block structure [[T_SO3, T_uω+], [0, T_SO3]] (eq. 72).
    assert_array_equal(J[:3, :3], so3.jac_right(h[3:]))
    assert_array_equal(J[3:, 3:], so3.jac_right(h[3:]))
    assert_array_equal(J[3:, :3], np.zeros((3, 3)))

"""The rotation group SO(3): hat/vee, exponential and logarithm, and their Jacobians.

All functions take float64 arrays whose trailing axes are the object, (..., 3) for a rotation
vector ω (rad) and (..., 3, 3) for a rotation matrix; leading axes are batch axes that broadcast
like numpy. Notation follows Grazioso, Di Gironimo & Siciliano, "Analytic solutions for the
static equilibrium configurations of externally loaded cantilever soft robotic arms" (RoboSoft
2018), appendix, eqs. 63 and 70-73.

Jacobian convention: ``jac_right(ω)`` is the paper's tangent operator T_SO3 (eq. 73), the
*right* Jacobian: exp(ω)⁻¹ ∂/∂ε exp(ω + εδ) = (jac_right(ω) δ)~. ``jac_left(ω)`` = jac_right(ω)ᵀ
= jac_right(-ω) is the left Jacobian: ∂/∂ε exp(ω + εδ) exp(ω)⁻¹ = (jac_left(ω) δ)~.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_matrices, as_vectors
from ._series import cosc, jinv, sinc, sinc3

__all__ = [
    "exp",
    "from_quaternion",
    "hat",
    "jac_left",
    "jac_left_inv",
    "jac_right",
    "jac_right_inv",
    "log",
    "to_quaternion",
    "vee",
]


def _hat(w: np.ndarray) -> np.ndarray:
    zero = np.zeros_like(w[..., 0])
    x, y, z = w[..., 0], w[..., 1], w[..., 2]
    return np.stack(
        [
            np.stack([zero, -z, y], axis=-1),
            np.stack([z, zero, -x], axis=-1),
            np.stack([-y, x, zero], axis=-1),
        ],
        axis=-2,
    )


def hat(w):
    """Skew-symmetric matrix of a 3-vector: hat(w) @ v = w × v (the paper's tilde, eq. 63).

    Parameters
    ----------
    w : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> hat([1.0, 2.0, 3.0])
    array([[ 0., -3.,  2.],
           [ 3.,  0., -1.],
           [-2.,  1.,  0.]])
    """
    return _hat(as_vectors(w, "w", 3))


def vee(W):
    """Inverse of :func:`hat`: the 3-vector of the skew part of W, shape (..., 3, 3) -> (..., 3).

    The skew-symmetric part ½(W - Wᵀ) is used, so vee(hat(w)) = w exactly.
    """
    W = as_matrices(W, "W", 3)
    return 0.5 * np.stack(
        [W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]],
        axis=-1,
    )


def _with_hats(w: np.ndarray):
    W = _hat(w)
    theta2 = np.einsum("...i,...i->...", w, w)
    return W, W @ W, theta2[..., None, None]


def _exp(w: np.ndarray) -> np.ndarray:
    W, W2, t2 = _with_hats(w)
    return np.eye(3) + sinc(t2) * W + cosc(t2) * W2


def exp(w):
    """Rodrigues' formula, exp(w~) = I + (sin θ/θ) w~ + ((1 - cos θ)/θ²) w~² (eqs. 70-71).

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Rotation vector (rad), θ = |w|.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rotation matrix.

    Examples
    --------
    >>> import numpy as np
    >>> np.round(exp([0.0, 0.0, np.pi / 2]), 12)
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    return _exp(as_vectors(w, "w", 3))


def _log(R: np.ndarray) -> np.ndarray:
    # sin θ · axis from the skew part, cos θ from the trace: θ = atan2(|s|, c) is accurate
    # everywhere, including near 0 and π.
    s_axis = 0.5 * np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]],
        axis=-1,
    )
    c = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    s = np.linalg.norm(s_axis, axis=-1)
    theta = np.arctan2(s, c)
    # θ <= π/2: ω = θ/sin θ · (sin θ axis), exact at θ = 0.
    near_zero = s_axis / sinc(theta**2)[..., None]
    # θ > π/2: the symmetric part gives (1 - cos θ) axis axisᵀ = ½(R + Rᵀ) - cos θ I; take the
    # column with the largest diagonal and its sign from the skew part (cos θ < 0 here, so
    # 1 - c >= 1 and nothing divides by zero).
    S = 0.5 * (R + np.swapaxes(R, -1, -2)) - c[..., None, None] * np.eye(3)
    one_minus_c = np.where(c < 0, 1.0 - c, 1.0)
    diagonal = np.diagonal(S, axis1=-2, axis2=-1)
    k = np.argmax(diagonal, axis=-1)
    column = np.take_along_axis(S, k[..., None, None], axis=-1)[..., 0]
    pivot = np.take_along_axis(diagonal, k[..., None], axis=-1)
    pivot = np.where((c < 0)[..., None], pivot, 1.0)  # >= (1 - c)/3 >= 1/3 where it is used
    axis = column / np.sqrt(pivot * one_minus_c[..., None])
    sign = np.where(np.einsum("...i,...i->...", axis, s_axis) < 0, -1.0, 1.0)
    near_pi = (sign * theta)[..., None] * axis
    return np.where((c < 0)[..., None], near_pi, near_zero)


def log(R):
    """Logarithm of a rotation matrix: the rotation vector ω with exp(ω) = R and |ω| <= π.

    Stable near θ = 0 (no division by sin θ) and near θ = π (the axis is read from the
    symmetric part of R, not the vanishing skew part).

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrix (orthonormality is assumed, not checked).

    Returns
    -------
    ndarray, shape (..., 3)
    """
    return _log(as_matrices(R, "R", 3))


def _jac(w: np.ndarray, sign: float) -> np.ndarray:
    W, W2, t2 = _with_hats(w)
    return np.eye(3) + sign * cosc(t2) * W + sinc3(t2) * W2


def _jac_inv(w: np.ndarray, sign: float) -> np.ndarray:
    W, W2, t2 = _with_hats(w)
    return np.eye(3) - sign * 0.5 * W + jinv(t2) * W2


def jac_right(w):
    """Right Jacobian of exp on SO(3), the paper's tangent operator T_SO3 (eq. 73).

    T(ω) = I - ((1 - cos θ)/θ²) ω~ + ((θ - sin θ)/θ³) ω~², and
    exp(ω)⁻¹ ∂/∂ε exp(ω + εδ)|₀ = (T(ω) δ)~.

    Parameters
    ----------
    w : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    return _jac(as_vectors(w, "w", 3), -1.0)


def jac_right_inv(w):
    """Inverse of :func:`jac_right`: I + ½ ω~ + (1/θ² - (1 + cos θ)/(2θ sin θ)) ω~²."""
    return _jac_inv(as_vectors(w, "w", 3), -1.0)


def jac_left(w):
    """Left Jacobian of exp on SO(3): jac_right(ω)ᵀ = I + ((1-cos θ)/θ²) ω~ + ((θ-sin θ)/θ³) ω~².

    It is also the translation block ("V" matrix) of exp on SE(3): the paper's T_SO3ᵀ in eq. 69.
    """
    return _jac(as_vectors(w, "w", 3), 1.0)


def jac_left_inv(w):
    """Inverse of :func:`jac_left`: I - ½ ω~ + (1/θ² - (1 + cos θ)/(2θ sin θ)) ω~²."""
    return _jac_inv(as_vectors(w, "w", 3), 1.0)


def to_quaternion(R):
    """Unit quaternion (w, x, y, z) of a rotation matrix, with w >= 0.

    Scalar first, as in jaxlie and Sophus (scipy's ``Rotation.as_quat`` puts it last). Computed
    from the rotation vector ω = log(R): (cos(θ/2), sin(θ/2) ω/θ), with sin(θ/2)/θ = ½ sinc(θ/2)
    so that nothing divides by θ.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 4)

    Examples
    --------
    >>> import numpy as np
    >>> np.round(to_quaternion(exp([0.0, 0.0, np.pi / 2])), 12)
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    w = _log(as_matrices(R, "R", 3))
    theta2 = np.einsum("...i,...i->...", w, w)
    half_sinc = 0.5 * sinc(0.25 * theta2)  # sin(θ/2)/θ
    return np.concatenate([np.cos(0.5 * np.sqrt(theta2))[..., None], half_sinc[..., None] * w],
                          axis=-1)


def from_quaternion(q):
    """Rotation matrix of a quaternion (w, x, y, z) (normalised first).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Scalar first; any non-zero norm.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    q = as_vectors(q, "q", 4)
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise ValueError("q must be non-zero quaternions (w, x, y, z), got a zero quaternion")
    w, x, y, z = np.moveaxis(q / norm, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=-2)

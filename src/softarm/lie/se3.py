"""The rigid-motion group SE(3) with twists ordered linear part first, h = (u; ω).

Poses are (..., 4, 4) homogeneous matrices H = [[R, p], [0, 1]]; twists, strains and wrenches
are (..., 6) vectors with the linear part first, as in Grazioso, Di Gironimo & Siciliano
(RoboSoft 2018), eq. 64 (and jaxlie, Sophus, manif). Leading axes are batch axes and broadcast.

Jacobian convention: ``jac_right(h)`` is the paper's tangent operator T_SE3 (eqs. 72-75), the
right Jacobian: exp(h)⁻¹ ∂/∂ε exp(h + εδ)|₀ = (T(h) δ)~. The printed T_uω+ (eqs. 74-75) is
garbled by the text conversion; the form used here is the corrected one (docs/closed-forms.md, C1),
checked by finite differences in the tests.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_matrices, as_vectors
from . import so3
from ._series import cosc, sinc, sinc3, tuw3, tuw4

__all__ = [
    "ad",
    "adjoint",
    "exp",
    "from_rotation_translation",
    "hat",
    "inverse",
    "jac_right",
    "jac_right_inv",
    "log",
    "vee",
]


def _blocks(top_left, top_right, bottom_right):
    zero = np.zeros(np.broadcast_shapes(top_left.shape, top_right.shape, bottom_right.shape))
    top = np.concatenate(np.broadcast_arrays(top_left, top_right), axis=-1)
    bottom = np.concatenate(np.broadcast_arrays(zero, bottom_right), axis=-1)
    return np.concatenate([top, bottom], axis=-2)


def _pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    batch = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    H = np.zeros((*batch, 4, 4))
    H[..., :3, :3] = R
    H[..., :3, 3] = p
    H[..., 3, 3] = 1.0
    return H


def from_rotation_translation(R, p):
    """The pose [[R, p], [0, 1]] from rotations (..., 3, 3) and translations (..., 3), broadcast.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices (orthonormality is assumed, not checked).
    p : array_like, shape (..., 3)
        Translations in m.

    Returns
    -------
    ndarray, shape (..., 4, 4)
    """
    return _pose(as_matrices(R, "R", 3), as_vectors(p, "p", 3))


def hat(h):
    """4×4 matrix of a twist h = (u; ω): [[ω~, u], [0, 0]] (eq. 62).

    Parameters
    ----------
    h : array_like, shape (..., 6)

    Returns
    -------
    ndarray, shape (..., 4, 4)
    """
    h = as_vectors(h, "h", 6)
    top = np.concatenate([so3._hat(h[..., 3:]), h[..., :3, None]], axis=-1)
    return np.concatenate([top, np.zeros((*top.shape[:-2], 1, 4))], axis=-2)


def vee(X):
    """Inverse of :func:`hat`: (..., 4, 4) -> (..., 6), linear part first."""
    X = as_matrices(X, "X", 4)
    return np.concatenate([X[..., :3, 3], so3.vee(X[..., :3, :3])], axis=-1)


def _exp(h: np.ndarray) -> np.ndarray:
    u, w = h[..., :3], h[..., 3:]
    W, W2, t2 = so3._with_hats(w)
    R = np.eye(3) + sinc(t2) * W + cosc(t2) * W2
    V = np.eye(3) + cosc(t2) * W + sinc3(t2) * W2
    return _pose(R, np.einsum("...ij,...j->...i", V, u))


def exp(h):
    """Exponential map of SE(3) (eq. 69): [[exp(ω), T_SO3(ω)ᵀ u], [0, 1]].

    Parameters
    ----------
    h : array_like, shape (..., 6)
        Twist (u; ω): u in m (or m per unit parameter), ω in rad.

    Returns
    -------
    ndarray, shape (..., 4, 4)

    Examples
    --------
    A unit-length arc of curvature 1 about +y (the paper's eq. 37 with κ_y = 1):

    >>> import numpy as np
    >>> H = exp([1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    >>> np.allclose(H[:3, 3], [np.sin(1.0), 0.0, -(1 - np.cos(1.0))])
    True
    """
    return _exp(as_vectors(h, "h", 6))


def log(H):
    """Logarithm of a pose: the twist h = (u; ω) with exp(h) = H and |ω| <= π.

    Parameters
    ----------
    H : array_like, shape (..., 4, 4)

    Returns
    -------
    ndarray, shape (..., 6)
    """
    H = as_matrices(H, "H", 4)
    w = so3._log(H[..., :3, :3])
    u = np.einsum("...ij,...j->...i", so3._jac_inv(w, 1.0), H[..., :3, 3])
    return np.concatenate([u, w], axis=-1)


def inverse(H):
    """Inverse pose [[Rᵀ, -Rᵀ p], [0, 1]], shape (..., 4, 4)."""
    H = as_matrices(H, "H", 4)
    Rt = np.swapaxes(H[..., :3, :3], -1, -2)
    return _pose(Rt, -np.einsum("...ij,...j->...i", Rt, H[..., :3, 3]))


def adjoint(H):
    """Adjoint matrix of a pose, Ad(H) = [[R, p~ R], [0, R]], so Ad(H) h = vee(H h~ H⁻¹).

    Parameters
    ----------
    H : array_like, shape (..., 4, 4)

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    H = as_matrices(H, "H", 4)
    R = H[..., :3, :3]
    return _blocks(R, so3._hat(H[..., :3, 3]) @ R, R)


def _ad(h: np.ndarray) -> np.ndarray:
    W = so3._hat(h[..., 3:])
    return _blocks(W, so3._hat(h[..., :3]), W)


def ad(h):
    """Adjoint of the Lie algebra, ad(h) = [[ω~, u~], [0, ω~]]: the paper's hat (eq. 67).

    ad(a) b is the Lie bracket vee([a~, b~]).

    Parameters
    ----------
    h : array_like, shape (..., 6)

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    return _ad(as_vectors(h, "h", 6))


def _t_uw(h: np.ndarray) -> np.ndarray:
    """Upper-right block T_uω+ of the SE(3) right Jacobian (eqs. 74-75, C1 of closed-forms.md)."""
    u, w = h[..., :3], h[..., 3:]
    U = so3._hat(u)
    W, W2, t2 = so3._with_hats(w)
    wu = np.einsum("...i,...i->...", w, u)[..., None, None]
    return (
        -cosc(t2) * U
        + sinc3(t2) * (U @ W + W @ U)
        + wu * (tuw3(t2) * W + tuw4(t2) * W2)
    )


def jac_right(h):
    """Right Jacobian of exp on SE(3), the paper's tangent operator T_SE3 (eq. 72).

    T(h) = [[T_SO3(ω), T_uω+(u, ω)], [0, T_SO3(ω)]], and
    exp(h)⁻¹ ∂/∂ε exp(h + εδ)|₀ = (T(h) δ)~.

    Parameters
    ----------
    h : array_like, shape (..., 6)

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    h = as_vectors(h, "h", 6)
    T = so3._jac(h[..., 3:], -1.0)
    return _blocks(T, _t_uw(h), T)


def jac_right_inv(h):
    """Inverse of :func:`jac_right`: [[T⁻¹, -T⁻¹ T_uω+ T⁻¹], [0, T⁻¹]], shape (..., 6, 6)."""
    h = as_vectors(h, "h", 6)
    Tinv = so3._jac_inv(h[..., 3:], -1.0)
    return _blocks(Tinv, -Tinv @ _t_uw(h) @ Tinv, Tinv)

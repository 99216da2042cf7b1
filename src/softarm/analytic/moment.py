"""Pure end moment: the paper's constant-strain solution and the exact helix beyond it."""

from __future__ import annotations

import warnings

import numpy as np

from .._validate import stations
from ..errors import ApproximationWarning
from ..lie import se3, so3
from ..loads import TipLoad
from ._common import (
    E1,
    build,
    check_arm,
    check_follower,
    constant_strain_poses,
    moment_is_principal,
    negligible,
    rotational_stiffness,
    vectors,
)

__all__ = ["helix_applies", "tip_moment"]


def helix_applies(arm) -> bool:
    """Equal bending stiffnesses and an initially straight (possibly twisted) axis.

    Then the helix solution of NOTES.md note 4 is exact for every end moment, dead or follower.
    """
    _, EIy, EIz = rotational_stiffness(arm)
    _, ky, kz = arm.curvature
    return bool(negligible(EIy - EIz, max(EIy, EIz))) and ky == 0.0 and kz == 0.0


def _helix(arm, moment, follower, s):
    """Poses and strains of the exact pure-moment solution for EIy = EIz = B (note 4).

    With n = 0 the spatial moment M is constant. The material moment m = Rᵀ M gives the
    curvature κ⁰ + K⁻¹ m = m/B + c e1 with c = κ⁰₁ + M₁ (1/GJ - 1/B) constant (m₁' = 0), so
    R(s) = exp(s M/B) exp(s c e1) and p' = R e1 = exp(s M/B) e1:
    H(s) = exp_SE3(s (e1; M/B)) · exp_SE3(s (0; c e1)).
    """
    k = rotational_stiffness(arm)
    GJ, B = k[0], k[1]
    c = arm.curvature[0] + moment[..., 0] * (1.0 / GJ - 1.0 / B)
    if follower:  # the tip material components g = R(L)ᵀ M = exp(-L c e1) M are given
        moment = np.einsum("...ij,...j->...i", so3.exp(arm.length * c[..., None] * E1), moment)
    sc = s * c[..., None]                                                   # (B..., N)
    zeta = np.concatenate(np.broadcast_arrays(E1, moment / B), axis=-1)     # (B..., 6)
    twist = np.concatenate(np.broadcast_arrays(np.zeros(3), sc[..., None] * E1), axis=-1)
    poses = constant_strain_poses(zeta, s) @ se3.exp(twist)
    m = np.einsum("...ji,...j->...i", poses[..., :3, :3], moment[..., None, :])
    strains = np.concatenate(np.broadcast_arrays(np.zeros(3), m / k), axis=-1)
    return poses, strains


def _constant_strain(arm, moment, s):
    """Eqs. 30-34: ε = K⁻¹ (0; moment), constant, and H(s) = exp_SE3(s (f⁰ + ε))."""
    kappa = moment / rotational_stiffness(arm)
    strain = np.concatenate(np.broadcast_arrays(np.zeros(3), kappa), axis=-1)
    poses = constant_strain_poses(arm.reference_strain + strain, s)
    return poses, np.broadcast_to(strain[..., None, :], (*strain.shape[:-1], s.size, 6))


def tip_moment(arm, moment, follower=False, s=None):
    """Equilibrium of an arm under a pure end moment (Grazioso et al. 2018, eqs. 30-34).

    Model: a uniform Cosserat rod clamped at the base with f⁰ = (1, 0, 0, κ⁰), loaded at the
    tip by a moment only (no force, so the internal force n vanishes everywhere and the spatial
    moment is constant along the arm). Three cases, chosen automatically:

    * **Principal axis** (exact, any f⁰ whose curvature κ⁰ is zero or parallel to the moment):
      the moment is an eigenvector of K_ωω = diag(GJ, EIy, EIz). Then the strain is constant,
      ε = (0; K_ωω⁻¹ M) (eq. 31), H(s) = exp_SE3(s (f⁰ + ε)) (eqs. 32-34), and dead and
      follower moments coincide. A moment τ about +y on a straight arm gives the circle of
      eqs. 37-38 of radius EIy/τ, bent towards -z.
    * **Equal bending stiffnesses** EIy = EIz = B (circle, tube, square) and an initially
      straight, possibly twisted arm (κ⁰ = (κ⁰₁, 0, 0)): exact for *any* moment direction,
      dead or follower, by the helix of NOTES.md note 4 (not in the paper):
      H(s) = exp_SE3(s (e1; M/B)) · exp_SE3(s (0; c e1)), c = κ⁰₁ + M₁ (1/GJ - 1/B), with M
      the spatial moment: M = moment (dead) or M = exp(L c e1) · moment (follower).
    * **Elsewhere** the paper's constant-strain formula (eqs. 30-34 with the moment taken as
      the tip's material components) is returned with ``exact=False`` and an
      :class:`~softarm.ApproximationWarning`: eq. 22 drops the term -κ × K_ωω κ, which does
      not vanish there (NOTES.md note 2), so the result is not an equilibrium.

    Parameters
    ----------
    arm : Arm
        A uniform arm (a SegmentedArm raises TypeError).
    moment : array_like, shape (..., 3)
        Tip moment in N m: spatial components for a dead moment, tip material components for a
        follower moment. Leading axes are a batch of load cases.
    follower : bool
        False: dead moment (fixed in space); True: follower moment (fixed in the tip frame).
    s : array_like, shape (N,), or int, optional
        Stations in m, strictly increasing in [0, L]; an int N gives N uniform stations;
        default 101 uniform stations.

    Returns
    -------
    Equilibrium
        ``method`` is ``"analytic.tip_moment.principal"``, ``"analytic.tip_moment.helix"`` or
        ``"analytic.tip_moment.constant_strain"``; ``exact`` says whether the result solves
        the full model (eq. 20).

    Warns
    -----
    ApproximationWarning
        When the constant-strain approximation is returned.

    References
    ----------
    S. Grazioso, G. Di Gironimo, B. Siciliano, "Analytic solutions for the static equilibrium
    configurations of externally loaded cantilever soft robotic arms", RoboSoft 2018,
    eqs. 22, 30-38; corrections in docs/closed-forms.md.

    Examples
    --------
    The circle of Fig. 2 (eqs. 37-38): τ = 1 N m about +y, EIy = 1 N m², L = 1 m.

    >>> import numpy as np
    >>> from softarm import Arm
    >>> from softarm.analytic import tip_moment
    >>> arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=2.0)
    >>> eq = tip_moment(arm, [0.0, 1.0, 0.0])
    >>> eq.exact, bool(np.allclose(eq.tip_position, [np.sin(1.0), 0.0, np.cos(1.0) - 1.0]))
    (True, True)

    The helix of NOTES.md note 4 (equal bending stiffnesses, a moment off the principal axes):

    >>> arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1 / 1.3, EIy=1.0, EIz=1.0)
    >>> np.round(tip_moment(arm, [1.0, 1.0, 0.0]).tip_position, 4)
    array([ 0.8492,  0.1508, -0.422 ])
    >>> np.round(tip_moment(arm, [1.0, 1.0, 0.0], follower=True).tip_position, 4)
    array([ 0.8492,  0.2688, -0.3586])
    """
    function = "tip_moment"
    arm = check_arm(arm, function)
    moment = vectors(moment, "moment", function)
    follower = check_follower(follower, function)
    s = stations(s, arm.length)
    loads = (TipLoad(moment=moment, follower=follower),)
    if helix_applies(arm):
        poses, strains = _helix(arm, moment, follower, s)
        return build(arm, s, poses, strains, loads, "analytic.tip_moment.helix", True)
    poses, strains = _constant_strain(arm, moment, s)
    exact = bool(np.all(moment_is_principal(arm, moment)))
    if not exact:
        warnings.warn(
            "tip_moment: the moment is not about a principal axis of K_ωω = diag(GJ, EIy, EIz) "
            f"= {tuple(float(k) for k in rotational_stiffness(arm))} parallel to the initial "
            f"curvature {arm.curvature}, and the helix needs EIy = EIz on a straight axis, so "
            "the constant-strain formula (eqs. 30-34) is only an approximation, not an "
            "equilibrium; use softarm.solve for the exact one",
            ApproximationWarning,
            stacklevel=2,
        )
        method = "analytic.tip_moment.constant_strain"
    else:
        method = "analytic.tip_moment.principal"
    return build(arm, s, poses, strains, loads, method, exact)

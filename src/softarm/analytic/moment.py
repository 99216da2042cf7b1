"""Pure end moment: the paper's constant-strain solution and the exact helix beyond it."""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..errors import ApproximationWarning
from ..loads import TipLoad, check_magnitudes
from ._common import (
    E1,
    ROUNDOFF,
    build,
    check_arm,
    check_follower,
    checked_stations,
    moment_is_principal,
    rotational_stiffness,
    screw_poses,
    stiffness_diagonal,
    thread_setting,
    vectors,
)
from ._elastica_math import compiled

__all__ = ["helix_applies", "solve_tip_moment", "tip_moment"]


def helix_applies(arm) -> bool:
    """Equal bending stiffnesses and an initially straight (possibly twisted) axis.

    Then the helix solution (docs/closed-forms.md, C4) is exact for every end moment, dead or
    follower.
    """
    r = arm.rigidities
    _, ky, kz = arm.curvature
    return abs(r.EIy - r.EIz) <= ROUNDOFF * max(r.EIy, r.EIz) and ky == 0.0 and kz == 0.0


def _helix(arm, moment, follower, s):
    """Poses, strains and stresses of the exact pure-moment solution for EIy = EIz = B (C4).

    With n = 0 the spatial moment M is constant. The material moment m = Rᵀ M gives the
    curvature κ⁰ + K⁻¹ m = m/B + c e1 with c = κ⁰₁ + M₁ (1/GJ - 1/B) constant (m₁' = 0), so
    R(s) = exp(s M/B) exp(s c e1) and p' = R e1 = exp(s M/B) e1:
    H(s) = exp_SE3(s (e1; M/B)) · exp_SE3(s (0; c e1)). Since exp(s M/B) fixes M,
    m(s) = exp(-s c e1) M = M + (1 - cos cs) (0, -M₂, -M₃) + sin(cs) (0, M₃, -M₂).
    """
    if moment.ndim == 1:
        return _helix_one(arm, moment.tolist(), follower, s)
    k = stiffness_diagonal(arm)
    GJ, B = k[3], k[4]
    c = arm.curvature[0] + moment[..., 0] * (1.0 / GJ - 1.0 / B)
    if follower:  # the tip material components g = R(L)ᵀ M = exp(-L c e1) M are given
        cos, sin = np.cos(arm.length * c), np.sin(arm.length * c)
        g2, g3 = moment[..., 1], moment[..., 2]
        moment = np.stack([moment[..., 0], cos * g2 - sin * g3, sin * g2 + cos * g3], axis=-1)
    # σ = (0; m) = Σ_y b_y(cs) rows y, b = (1, 1 - cos, sin); ε = K⁻¹ σ, in one buffer
    fields = np.zeros((*moment.shape[:-1], 3, 12))
    stress = fields[..., 6:]
    stress[..., 0, 3:] = moment
    stress[..., 1, 4:] = -moment[..., 1:]
    stress[..., 2, 4] = moment[..., 2]
    stress[..., 2, 5] = -moment[..., 1]
    fields[..., :6] = stress / k
    poses, extra = screw_poses(E1, moment / B, s, twist=c, fields=fields)
    return poses, extra[..., :6], extra[..., 6:]


def _helix_one(arm, moment, follower, s):
    """:func:`_helix` for one moment (three floats), by the compiled screw: the same
    arithmetic on floats."""
    r = arm.rigidities
    GJ, B, Bz = r.GJ, r.EIy, r.EIz  # B = EIy = EIz to roundoff; σ/K divides by each
    m1, m2, m3 = moment
    c = arm.curvature[0] + m1 * (1.0 / GJ - 1.0 / B)
    if follower:
        cos, sin = math.cos(arm.length * c), math.sin(arm.length * c)
        m2, m3 = cos * m2 - sin * m3, sin * m2 + cos * m3
    # rows b = (1, 1 - cos, sin): strains K⁻¹ σ, then stresses σ = (0; m)
    fields = np.array([(0.0, 0.0, 0.0, m1 / GJ, m2 / B, m3 / Bz, 0.0, 0.0, 0.0, m1, m2, m3),
                       (0.0, 0.0, 0.0, 0.0, -m2 / B, -m3 / Bz, 0.0, 0.0, 0.0, 0.0, -m2, -m3),
                       (0.0, 0.0, 0.0, 0.0, m3 / B, -m2 / Bz, 0.0, 0.0, 0.0, 0.0, m3, -m2)])
    poses, extra = _screw_one(np.array([m1 / B, m2 / B, m3 / B]), c, s, fields)
    return poses, extra[:, :6], extra[:, 6:]


def _screw_one(omega, twist, s, extra):
    """:func:`screw_poses` (u = e1) for one arm, compiled: poses (N, 4, 4) and the fields
    (N, C), read-only views of one fresh (N, 16 + C) buffer."""
    thread_setting()  # a bad $SOFTARM_NUM_THREADS is reported for one load as for a batch
    out = np.empty((s.shape[0], 16 + extra.shape[1]))
    s = s if s.flags.writeable else s.copy()  # one argument type: numba compiles one version
    compiled().screw(E1, omega, twist, s, extra, out)
    out.setflags(write=False)
    return out[:, :16].reshape(-1, 4, 4), out[:, 16:]


def _constant_strain(arm, moment, s):
    """Eqs. 30-34: ε = K⁻¹ (0; moment), constant, and H(s) = exp_SE3(s (f⁰ + ε))."""
    k = stiffness_diagonal(arm)
    kappa = moment / k[3:]
    if moment.ndim == 1:  # one load: the compiled screw, the fields as its constant columns
        fields = np.zeros((3, 12))
        fields[0, 3:6] = kappa
        fields[0, 9:] = kappa * k[3:]
        poses, extra = _screw_one(np.asarray(arm.curvature) + kappa, 0.0, s, fields)
        return poses, extra[:, :6], extra[:, 6:]
    poses, _ = screw_poses(E1, np.asarray(arm.curvature) + kappa, s)
    strain = np.zeros((*moment.shape[:-1], 1, 6))
    strain[..., 0, 3:] = kappa
    stress = strain * k
    strain.setflags(write=False)  # frozen before the views, which the Equilibrium then keeps
    stress.setflags(write=False)
    shape = (*moment.shape[:-1], s.size, 6)
    return poses, np.broadcast_to(strain, shape), np.broadcast_to(stress, shape)


def tip_moment(arm, moment, s=None, *, follower=False):
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
      dead or follower, by the helix of correction C4 (not in the paper):
      H(s) = exp_SE3(s (e1; M/B)) · exp_SE3(s (0; c e1)), c = κ⁰₁ + M₁ (1/GJ - 1/B), with M
      the spatial moment: M = moment (dead) or M = exp(L c e1) · moment (follower).
    * **Elsewhere** the paper's constant-strain formula (eqs. 30-34 with the moment taken as
      the tip's material components) is returned with ``exact=False`` and an
      :class:`~softarm.ApproximationWarning`: eq. 22 drops the term -κ × K_ωω κ, which does
      not vanish there (C2 in docs/closed-forms.md), so the result is not an equilibrium.

    Parameters
    ----------
    arm : Arm
        A uniform arm (a SegmentedArm raises TypeError).
    moment : array_like, shape (..., 3)
        Tip moment in N m: spatial components for a dead moment, tip material components for a
        follower moment. Leading axes are a batch of load cases.
    s : array_like, shape (N,), or int, optional
        Stations in m, strictly increasing in [0, L]; an int N gives N uniform stations;
        default 101 uniform stations.
    follower : bool, keyword-only
        False: dead moment (fixed in space); True: follower moment (fixed in the tip frame).

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

    The helix of C4 (equal bending stiffnesses, a moment off the principal axes):

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
    loads = (TipLoad(moment=moment, follower=follower),)
    check_magnitudes(arm, loads, function)
    return solve_tip_moment(arm, moment, checked_stations(s, arm.length), follower, loads)


def solve_tip_moment(arm, moment, s, follower, loads):
    """:func:`tip_moment` for checked arguments; the result carries ``loads`` as given
    (exact_closed_form passes the caller's)."""
    if helix_applies(arm):
        poses, strains, stresses = _helix(arm, moment, follower, s)
        return build(arm, s, poses, strains, loads, "analytic.tip_moment.helix", True,
                     stresses=stresses)
    poses, strains, stresses = _constant_strain(arm, moment, s)
    exact = bool(np.all(moment_is_principal(arm, moment)))
    if not exact:
        warnings.warn(
            "tip_moment: the moment is not about a principal axis of K_ωω = diag(GJ, EIy, EIz) "
            f"= {tuple(float(k) for k in rotational_stiffness(arm))} parallel to the initial "
            f"curvature {arm.curvature}, and the helix needs EIy = EIz on a straight axis, so "
            "the constant-strain formula (eqs. 30-34) is only an approximation, not an "
            "equilibrium; use softarm.solve for the exact one",
            ApproximationWarning,
            stacklevel=3,  # the caller of tip_moment
        )
        method = "analytic.tip_moment.constant_strain"
    else:
        method = "analytic.tip_moment.principal"
    return build(arm, s, poses, strains, loads, method, exact, stresses=stresses)

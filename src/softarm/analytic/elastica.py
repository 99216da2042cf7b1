"""Large-deflection cantilever under a dead tip force in a principal plane (planar elastica)."""

from __future__ import annotations

import numpy as np

from .._validate import stations
from ..lie import se3, so3
from ..loads import TipLoad
from ._common import E1, build, check_arm, negligible, vectors
from ._elastica_math import K_MAX, planar_elastica

__all__ = ["elastica", "elastica_plane"]


def elastica_plane(arm, force: np.ndarray, function: str = "elastica"):
    """The bending plane of a dead tip force on a straight arm, elementwise.

    Returns the in-plane unit normal b (B..., 3) (the plane is spanned by e1 and b; the
    cross-section turns about e1 × b), the force angle φ ∈ [0, π] from e1 towards b, the load
    magnitude P (N) and the plane's stiffnesses EI (N m²) and GA (N). ValueError (naming
    ``force``) if the force is outside a principal plane and the section is not symmetric.
    """
    r = arm.rigidities
    transverse = force * np.array([0.0, 1.0, 1.0])
    size = np.linalg.norm(transverse, axis=-1)
    # No transverse part: the plane of the weaker bending stiffness (where compression buckles).
    weak = np.array([0.0, 0.0, 1.0]) if r.EIy <= r.EIz else np.array([0.0, 1.0, 0.0])
    b = np.where((size > 0)[..., None], transverse / np.where(size > 0, size, 1.0)[..., None],
                 weak)
    skew = ~negligible(b[..., 1], 1.0) & ~negligible(b[..., 2], 1.0)
    symmetric = bool(negligible(r.EIy - r.EIz, max(r.EIy, r.EIz)))
    if np.any(skew) and not symmetric:
        raise ValueError(
            f"{function}: force must lie in a principal plane of the section (x-z with "
            f"force[..., 1] = 0 or x-y with force[..., 2] = 0) when EIy != EIz "
            f"({r.EIy!r} != {r.EIz!r} N m²), got {force!r}"
        )
    EI = r.EIy * b[..., 2] ** 2 + r.EIz * b[..., 1] ** 2
    GA = r.GAz * b[..., 2] ** 2 + r.GAy * b[..., 1] ** 2
    phi = np.arctan2(size, force[..., 0])
    P = np.linalg.norm(force, axis=-1)
    return b, phi, P, EI, GA, skew


def elastica(arm, force, s=None, *, extensible=True):
    """Exact large deflection of a straight cantilever under a dead tip force (planar elastica).

    Model: an initially straight arm (κ⁰ = 0) clamped at the base, a dead (fixed in space)
    tip force in a principal plane of the section: force (Fx, 0, Fz) bends in the x-z plane
    about y with EIy and GAz; (Fx, Fy, 0) bends in the x-y plane about z with EIz and GAy; any
    other direction (Fx, Fy, Fz) only for EIy = EIz (and GAy = GAz if ``extensible``), in the
    plane of e1 and the force. The motion is planar, torsion-free, and the geometrically exact
    equations reduce to θ'' = -(P/EI) sin(φ - θ) [1 + P (1/EA - 1/GA) cos(φ - θ)], solved in
    closed form by elliptic integrals on the fundamental (stable, inflection-free) branch
    (Bisshopp & Drucker 1945; Frisch-Fay 1962; extensible and shearable: Batista 2016).

    * ``extensible=True`` (default): the planar Reissner rod with the arm's EA and GA, which
      is the full Cosserat model (eq. 20) for this load: ``exact=True`` (positions along the
      force line by a Clenshaw-Curtis quadrature to ~1e-15 L). Needs P/EA < 1 and
      |P/EA - P/GA| < 1.
    * ``extensible=False``: the Euler elastica (inextensible, unshearable), ``exact=False``;
      strains have γ = 0 and the stresses are the true internal forces n = Rᵀ F (the
      constraint forces), so σ ≠ K ε in their linear part.

    Not in the paper, which has only the small-deflection version (eqs. 56-59, see
    :func:`shear_force`); this is the closed form beyond it that docs/closed-forms.md points to.
    Mattiasson (1981, Table 1) is reproduced to 1e-7 L for k = P L²/EI from 0.1 to 20.

    Parameters
    ----------
    arm : Arm
        A uniform arm with curvature (0, 0, 0).
    force : array_like, shape (..., 3)
        Dead tip force in N, spatial frame; k = |F| L²/EI ≤ 1e5. Leading axes are a batch.
    s : array_like, shape (N,), or int, optional
        Stations in m (default 101 uniform stations on [0, L]).
    extensible : bool, keyword-only
        Include the arm's axial and shear compliance (exact) or not (Euler elastica).

    Returns
    -------
    Equilibrium
        ``method="analytic.elastica"``. With θ the turn of the section from +x towards the
        force side b of the plane, R(s) = exp_SO3(θ(s) e1 × b) and κ = θ' e1 × b: in the x-z
        plane a +z force gives κ_y = -θ' < 0 (docs/closed-forms.md sign checks).

    References
    ----------
    K. E. Bisshopp, D. C. Drucker, Q. Appl. Math. 3 (1945) 272-275; K. Mattiasson, IJNME 17
    (1981) 145-153, Table 1; M. Batista, IJSS 87 (2016) 153-166; Grazioso et al. (2018)
    eqs. 56-59 for the small-deflection limit.

    Examples
    --------
    Mattiasson's k = 1 (P L²/EI = 1): tip deflection 0.30172 L, shortening 0.05643 L.

    >>> import numpy as np
    >>> from softarm import Arm
    >>> from softarm.analytic import elastica
    >>> arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=2.0)
    >>> eq = elastica(arm, [0.0, 0.0, 1.0], extensible=False)
    >>> np.round(eq.tip_position, 5)
    array([0.94357, 0.     , 0.30172])
    >>> eq = elastica(arm, [0.0, 0.0, 1.0])
    >>> eq.exact, np.round(eq.tip_position, 5)
    (True, array([0.94357, 0.     , 0.30172]))
    """
    function = "elastica"
    arm = check_arm(arm, function)
    force = vectors(force, "force", function)
    if not isinstance(extensible, (bool, np.bool_)):
        raise TypeError(f"{function}: extensible must be True or False, got {extensible!r}")
    if any(c != 0.0 for c in arm.curvature):
        raise ValueError(
            f"{function}: arm must be initially straight, curvature (0, 0, 0), got "
            f"{arm.curvature}; use softarm.solve for a curved arm"
        )
    b, phi, P, EI, GA, skew = elastica_plane(arm, force, function)
    r, L = arm.rigidities, arm.length
    if extensible and np.any(skew) and not negligible(r.GAy - r.GAz, max(r.GAy, r.GAz)):
        raise ValueError(
            f"{function}: a force outside the principal planes needs GAy = GAz for a planar "
            f"shearable solution, got GAy={r.GAy!r}, GAz={r.GAz!r} N and force {force!r}; "
            "pass extensible=False for the Euler elastica"
        )
    k = P * L**2 / EI
    if np.any(k > K_MAX):
        raise ValueError(
            f"{function}: force must have |F| L²/EI <= {K_MAX:g}, got max "
            f"{float(np.max(k))!r} (|F| up to {float(np.max(P))!r} N)"
        )
    axial_ratio = EI / (r.EA * L**2) if extensible else 0.0
    shear_ratio = EI / (GA * L**2) if extensible else 0.0
    if extensible and (np.any(P >= r.EA) or np.any(np.abs(P / r.EA - P / GA) >= 1.0)):
        raise ValueError(
            f"{function}: force must satisfy |F| < EA and ||F|/EA - |F|/GA| < 1 for the "
            f"extensible elastica, got |F| up to {float(np.max(P))!r} N with EA={r.EA!r} N; "
            "pass extensible=False or use softarm.solve"
        )
    s = stations(s, L)
    sol = planar_elastica(k, phi, s / L, axial_ratio=axial_ratio, shear_ratio=shear_ratio)
    axis = np.cross(E1, b)[..., None, :]                                   # (B..., 1, 3)
    R = so3.exp(sol.theta[..., None] * axis)
    p = L * (sol.x[..., None] * E1 + sol.z[..., None] * b[..., None, :])
    kappa = (sol.curvature / L)[..., None] * axis
    if extensible:
        gamma = sol.axial_strain[..., None] * E1 + sol.shear_strain[..., None] * b[..., None, :]
        stresses = None
    else:
        gamma = np.zeros_like(kappa)
        n = np.einsum("...ji,...j->...i", R, force[..., None, :])
        stresses = np.concatenate([n, kappa * np.diagonal(arm.stiffness)[3:]], axis=-1)
    strains = np.concatenate([gamma, kappa], axis=-1)
    poses = se3.from_rotation_translation(R, p)
    return build(arm, s, poses, strains, (TipLoad(force=force),), "analytic.elastica",
                 bool(extensible), stresses=stresses)

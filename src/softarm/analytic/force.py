"""Tip forces on a straight arm: the exact axial solution and the paper's shear solution."""

from __future__ import annotations

import numpy as np

from .._validate import stations
from ..lie import se3, so3
from ..loads import TipLoad, check_magnitudes
from ._common import build, check_arm, constant_strain_poses, negligible, vectors

__all__ = ["axial_force", "shear_force"]


def axial_force(arm, force, s=None):
    """Equilibrium of a straight arm under an axial tip force (Grazioso et al. 2018, §IV.B).

    Model and solution: a force F e1 along the arm axis at the tip of an initially straight
    arm (κ⁰ = 0, or a pure initial twist κ⁰ = (κ⁰₁, 0, 0), whose axis is still straight) gives
    the constant strain ε = (F/EA, 0, 0, 0, 0, 0), σ = (F, 0, 0, 0, 0, 0) and
    H(s) = exp_SE3(s (f⁰ + ε)) (eq. 32): the arm stays straight and its length becomes
    L (1 + F/EA). This is exact for the full model (eq. 20), and dead and follower forces
    coincide because the tip does not turn away from e1. A compressive force above the
    Euler load π² EI/(4 L²) leaves this equilibrium exact but unstable.

    On a precurved arm an axial tip force is not axial along the arm; this function raises
    ValueError there (use :func:`linear` or ``softarm.solve``).

    Parameters
    ----------
    arm : Arm
        A uniform arm with κ⁰₂ = κ⁰₃ = 0.
    force : array_like, shape (..., 3)
        Tip force in N, (F, 0, 0): tension positive; the y and z components must be zero
        (use :func:`shear_force`, :func:`linear` or :func:`elastica` otherwise). F > -EA:
        a compression of EA or more turns the arm inside out (v₁ = 1 + F/EA <= 0), an
        :class:`~softarm.InadmissibleStateError`.
    s : array_like, shape (N,), or int, optional
        Stations in m (default 101 uniform stations on [0, L]).

    Returns
    -------
    Equilibrium
        ``exact=True``, ``method="analytic.axial_force"``.

    References
    ----------
    Grazioso, Di Gironimo & Siciliano, RoboSoft 2018, §IV.B (first paragraph) and eq. 32.

    Examples
    --------
    >>> from softarm import Arm
    >>> from softarm.analytic import axial_force
    >>> arm = Arm.from_stiffness(2.0, EA=100.0, GAy=50.0, GAz=50.0, GJ=1.0, EIy=1.0, EIz=1.0)
    >>> eq = axial_force(arm, [10.0, 0.0, 0.0])
    >>> eq.tip_position.round(12), eq.exact
    (array([2.2, 0. , 0. ]), True)
    """
    function = "axial_force"
    arm = check_arm(arm, function)
    force = vectors(force, "force", function)
    if arm.curvature[1] != 0.0 or arm.curvature[2] != 0.0:
        raise ValueError(
            f"{function}: arm must be initially straight (curvature (κ⁰₁, 0, 0)) for an axial "
            f"force to stay axial, got curvature {arm.curvature}; use linear() for the "
            "small-load solution or softarm.solve"
        )
    transverse = ~negligible(force[..., 1:], np.abs(force[..., :1]))
    if np.any(transverse):
        raise ValueError(
            f"{function}: force must be axial, (F, 0, 0) in N, got a transverse component in "
            f"{force!r}; use shear_force, linear or elastica for transverse forces"
        )
    loads = (TipLoad(force=force),)
    check_magnitudes(arm, loads, function)
    s = stations(s, arm.length)
    strain = np.zeros((*force.shape[:-1], 6))
    strain[..., 0] = force[..., 0] / arm.rigidities.EA
    poses = constant_strain_poses(arm.reference_strain + strain, s)
    strain.setflags(write=False)  # fresh: its broadcast view goes to the result uncopied
    strains = np.broadcast_to(strain[..., None, :], (*strain.shape[:-1], s.size, 6))
    return build(arm, s, poses, strains, loads, "analytic.axial_force", True)


def shear_force(arm, force, s=None):
    """Small-deflection (Timoshenko) solution for a tip force on a straight arm (eqs. 56-59).

    Model: an initially straight arm (κ⁰ = 0) under a tip force (Fx, Fy, Fz), with small
    rotations (eq. 53), so dead and follower forces coincide. Each transverse component bends
    the arm in its principal plane and the axial component stretches it (superposition):

    * z: γ_z = Fz/GAz, κ_y(s) = -Fz (L - s)/EIy (eq. 50, sign corrected as in eqs. 44 and 48),
      θ_y(s) = -(Fz/EIy)(L s - s²/2) (eq. 59), p_z(s) = Fz s/GAz + Fz (3 L s² - s³)/(6 EIy)
      (eq. 58);
    * y: the same with EIz, GAy and θ_z = +(Fy/EIz)(L s - s²/2), κ_z = +Fy (L - s)/EIz;
    * x: γ_x = Fx/EA, p_x(s) = s (1 + Fx/EA) (exact, see :func:`axial_force`).

    The rotations are R(s) = exp_SO3((0, θ_y, θ_z)), equal to the paper's I + θ~ to first order
    and orthonormal. The tip deflection P L³/(3 EI) + P L/GA is the Timoshenko cantilever.
    The error against the geometrically exact answer grows with k = P L²/EI: at k = 1 this
    gives a tip deflection L/3 against the exact 0.3017 L (Mattiasson 1981; :func:`elastica`).
    ``exact`` is True only if the force is axial (then this equals :func:`axial_force`).

    Parameters
    ----------
    arm : Arm
        A uniform, initially straight arm (curvature (0, 0, 0)).
    force : array_like, shape (..., 3)
        Tip force in N (spatial = tip material components to first order). Fx > -EA
        (else :class:`~softarm.InadmissibleStateError`, as for :func:`axial_force`).
    s : array_like, shape (N,), or int, optional
        Stations in m (default 101 uniform stations on [0, L]).

    Returns
    -------
    Equilibrium
        ``method="analytic.shear_force"``, ``exact=False`` unless the force is axial.
        ``error_estimate`` (m, shape (B...)) is the leading neglected term, the tip shortening
        ½ ∫ |θ|² ds = (L⁵/15) ((Fz/EIy)² + (Fy/EIz)²) = L k²/15 in one plane (k = P L²/EI);
        it is the largest position error against the exact elastica to within 1 % for
        k ≤ 0.1 (tests/analytic/test_force.py).

    References
    ----------
    Grazioso, Di Gironimo & Siciliano, RoboSoft 2018, eqs. 39-59 (eq. 50 sign corrected).

    Examples
    --------
    The paper's Princeton beam (EIy = 36.28 N m², GAz = 0.9039e6 N, L = 0.508 m), P = 4.448 N:

    >>> from softarm import Arm
    >>> from softarm.analytic import shear_force
    >>> arm = Arm.from_stiffness(0.508, EA=2.84e6, GAy=6.4e5, GAz=0.9039e6, GJ=3.1,
    ...                          EIy=36.28, EIz=2.43)
    >>> eq = shear_force(arm, [0.0, 0.0, 4.448])
    >>> round(float(eq.tip_position[2]), 9)  # P L³/3EI + P L/GA
    0.005360064
    """
    function = "shear_force"
    arm = check_arm(arm, function)
    force = vectors(force, "force", function)
    if any(c != 0.0 for c in arm.curvature):
        raise ValueError(
            f"{function}: arm must be initially straight, curvature (0, 0, 0), got "
            f"{arm.curvature}; use linear() for a curved arm"
        )
    loads = (TipLoad(force=force),)
    check_magnitudes(arm, loads, function)
    s = stations(s, arm.length)
    L, r = arm.length, arm.rigidities
    Fx, Fy, Fz = (force[..., i, None] for i in range(3))                 # (B..., 1)
    bend = (L * s - s**2 / 2)                                              # ∫ (L - s)
    sag = (3 * L * s**2 - s**3) / 6                                        # ∫∫ (L - s)
    theta = np.stack(np.broadcast_arrays(0 * Fx * s, -Fz * bend / r.EIy, Fy * bend / r.EIz),
                     axis=-1)
    p = np.stack(np.broadcast_arrays(s * (1 + Fx / r.EA), Fy * s / r.GAy + Fy * sag / r.EIz,
                                     Fz * s / r.GAz + Fz * sag / r.EIy), axis=-1)
    strains = np.stack(np.broadcast_arrays(
        Fx / r.EA + 0 * s, Fy / r.GAy + 0 * s, Fz / r.GAz + 0 * s, 0 * s,
        -Fz * (L - s) / r.EIy, Fy * (L - s) / r.EIz), axis=-1)
    exact = bool(np.all(force[..., 1:] == 0.0))
    # Leading neglected effect: the shortening ½ ∫ |θ|² ds = (L⁵/15)((Fz/EIy)² + (Fy/EIz)²).
    shortening = L**5 / 15 * ((force[..., 2] / r.EIy) ** 2 + (force[..., 1] / r.EIz) ** 2)
    poses = se3.from_rotation_translation(so3.exp(theta), p)
    return build(arm, s, poses, strains, loads, "analytic.shear_force", exact,
                 error_estimate=shortening)



"""Small-deflection solution for any tip wrench on a constant-curvature arm (eq. 27, corrected)."""

from __future__ import annotations

import numpy as np

from .._validate import stations
from ..lie import se3, so3
from ..loads import TipLoad, check_magnitudes
from ._common import (
    build,
    check_arm,
    check_follower,
    moment_is_principal,
    stiffness_diagonal,
    vectors,
)

__all__ = ["linear", "transported_wrench"]


def transported_wrench(arm, wrench_tip: np.ndarray, s: np.ndarray) -> np.ndarray:
    """σ(s) = Ad(exp((s - L) f⁰))ᵀ σ(L): the tip wrench carried along the undeformed curve.

    This solves σ' = hat(f⁰)ᵀ σ (eq. 22 with the transpose restored) with σ(L) given; it is
    eq. 27's F(s) F(L)⁻¹ g with the corrected lower-left block of F (docs/closed-forms.md, C3).
    ``wrench_tip`` (B..., 6) in the undeformed tip's material frame, s (N,) → (B..., N, 6).
    """
    f0 = arm.reference_strain
    Ad = se3.adjoint(se3.exp((s - arm.length)[:, None] * f0))
    return np.einsum("nji,...j->...ni", Ad, wrench_tip)


def _integrate(f: callable, s: np.ndarray, length: float) -> np.ndarray:
    """H' = H f~ with f piecewise constant (its midpoint value) between stations, H(0) = I.

    One exact SE(3) exponential per interval (a second-order Magnus step). If the stations do
    not start at 0, [0, s₀] is split into steps no longer than the largest station spacing
    (L/100 for a single station). Returns poses (B..., N, 4, 4) at the stations.
    """
    widest = np.max(np.diff(s)) if s.size > 1 else length / 100
    lead = np.linspace(0.0, s[0], int(np.ceil(s[0] / widest)) + 1)[:-1]
    grid = np.concatenate([lead, s])
    steps = se3.exp(np.diff(grid)[:, None] * f(0.5 * (grid[1:] + grid[:-1])))
    H = np.broadcast_to(np.eye(4), (*steps.shape[:-3], 4, 4))
    poses = [H]
    for i in range(steps.shape[-3]):
        H = H @ steps[..., i, :, :]
        poses.append(H)
    return np.stack(poses[lead.size:], axis=-3)


def linear(arm, force=(0.0, 0.0, 0.0), moment=(0.0, 0.0, 0.0), s=None, *, follower=False):
    """Small-deflection equilibrium for any tip wrench on a constant-curvature arm (eq. 27).

    Model: the statics σ' - hat(f)ᵀ σ = 0 (eq. 20) linearised about the undeformed arm,
    σ' = hat(f⁰)ᵀ σ (eq. 22 with the transpose the printed equation lacks), whose solution
    carries the tip wrench along the *undeformed* reference curve,
    σ(s) = Ad(exp((s - L) f⁰))ᵀ σ(L) (eq. 27 with F(α) corrected: the lower-left block of
    eq. 24 is -(T_SO3(α f⁰_ω) α f⁰_u)~ Lᵀ, C3). The strain is ε(s) = K⁻¹ σ(s);
    the pose integrates H' = H (f⁰ + ε)~ exactly for the strain held at its midpoint value
    between consecutive stations (one SE(3) exponential per interval), an error O(h²) in the
    station spacing h on top of the model error O(load²).

    Exactness: the result solves the full model (``exact=True``) where it coincides with an
    exact closed form: a pure moment about a principal axis of K_ωω parallel to κ⁰ (or κ⁰ = 0),
    as in :func:`tip_moment`; an axial force alone on a straight (possibly twisted) arm, as in
    :func:`axial_force`; no load. Elsewhere it is the first-order solution (``exact=False``):
    on a straight arm with a transverse force it is :func:`shear_force` (eqs. 56-59) with the
    rotations integrated instead of linearised.

    Parameters
    ----------
    arm : Arm
        A uniform arm with any constant initial curvature κ⁰.
    force, moment : array_like, shape (..., 3)
        Tip force (N) and moment (N m): spatial components if dead (they are turned into the
        undeformed tip's material frame by exp(L κ⁰)ᵀ), tip material components if
        ``follower``; the two agree to first order. Leading axes are a batch.
    s : array_like, shape (N,), or int, optional
        Stations in m (default 101 uniform stations on [0, L]).
    follower : bool, keyword-only
        Whether force and moment are given in the tip's material frame.

    Returns
    -------
    Equilibrium
        ``method="analytic.linear"``; ``error_estimate`` 0 if exact, else NaN (unknown).

    References
    ----------
    Grazioso, Di Gironimo & Siciliano, RoboSoft 2018, eqs. 22-27 (eqs. 22 and 24 corrected).

    Examples
    --------
    A small tip force on a straight arm: the Euler-Bernoulli / Timoshenko deflection.

    >>> from softarm import Arm
    >>> from softarm.analytic import linear
    >>> arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    >>> eq = linear(arm, force=[0.0, 0.0, 3e-4], s=1001)
    >>> round(float(eq.tip_position[2] / 1e-4), 5)  # P L³/3EI = 1e-4 m
    1.0
    >>> eq.stresses[0, 4]  # bending moment at the clamp: -P L
    np.float64(-0.0003)
    """
    function = "linear"
    arm = check_arm(arm, function)
    force = vectors(force, "force", function)
    moment = vectors(moment, "moment", function)
    follower = check_follower(follower, function)
    s = stations(s, arm.length)
    loads = (TipLoad(force=force, moment=moment, follower=follower),)
    check_magnitudes(arm, loads, function)
    force, moment = np.broadcast_arrays(force, moment)
    if not follower:
        Rt = so3.exp(arm.length * np.asarray(arm.curvature)).T
        force, moment = force @ Rt.T, moment @ Rt.T
    wrench = np.concatenate([force, moment], axis=-1)
    k = stiffness_diagonal(arm)
    strains = transported_wrench(arm, wrench, s) / k
    poses = _integrate(lambda t: arm.reference_strain + transported_wrench(arm, wrench, t) / k, s,
                       arm.length)
    no_force = np.all(force == 0.0, axis=-1)
    axial = no_force | (np.all(force[..., 1:] == 0.0, axis=-1)
                        & (arm.curvature[1] == 0.0) & (arm.curvature[2] == 0.0))
    no_moment = np.all(moment == 0.0, axis=-1)
    exact = (no_force & moment_is_principal(arm, moment)) | (no_moment & axial)
    return build(arm, s, poses, strains, loads, "analytic.linear", bool(np.all(exact)))

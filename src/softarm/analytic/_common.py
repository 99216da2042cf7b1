"""Shared plumbing of the closed forms: argument checks and the assembly of an Equilibrium.

Every closed form computes rotations R (B..., N, 3, 3), positions p (B..., N, 3) and strains
ε (B..., N, 6) on the stations s (N,); :func:`build` broadcasts them to one batch shape, forms
the poses and the stresses σ = K ε, and returns the :class:`~softarm.Equilibrium`.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_vectors
from ..equilibrium import Equilibrium
from ..lie import se3
from ..model import Arm, SegmentedArm

__all__ = [
    "E1",
    "build",
    "check_arm",
    "check_follower",
    "constant_strain_poses",
    "moment_is_principal",
    "negligible",
    "pose",
    "rotational_stiffness",
    "vectors",
]

E1 = np.array([1.0, 0.0, 0.0])

#: Relative size under which a component is treated as zero (a few units of roundoff): a
#: closed form that is exact for the zero value is then exact to double precision.
_ROUNDOFF = 4.0 * np.finfo(np.float64).eps


def negligible(x, scale) -> np.ndarray:
    """|x| is at roundoff level relative to ``scale`` (both broadcast), elementwise."""
    return np.abs(x) <= _ROUNDOFF * np.abs(scale)


def check_arm(arm, function: str) -> Arm:
    """``arm`` as a uniform Arm, or TypeError naming the parameter."""
    if isinstance(arm, SegmentedArm):
        raise TypeError(
            f"{function}: arm must be a uniform softarm.Arm (the closed forms need constant "
            f"section and curvature; solve a SegmentedArm with softarm.solve), got {arm!r}"
        )
    if not isinstance(arm, Arm):
        raise TypeError(f"{function}: arm must be a softarm.Arm, got {arm!r}")
    return arm


def check_follower(follower, function: str) -> bool:
    if not isinstance(follower, (bool, np.bool_)):
        raise TypeError(f"{function}: follower must be True or False, got {follower!r}")
    return bool(follower)


def vectors(value, name: str, function: str) -> np.ndarray:
    """A finite float64 array of shape (..., 3); errors name the function and parameter."""
    return as_vectors(value, f"{function}: {name}", 3)


def rotational_stiffness(arm: Arm) -> np.ndarray:
    """diag K_ωω = (GJ, EIy, EIz), shape (3,)."""
    return np.diagonal(arm.stiffness)[3:]


def moment_is_principal(arm: Arm, moment: np.ndarray) -> np.ndarray:
    """Whether a pure end moment keeps a constant strain on ``arm``, shape (B...).

    True when the moment is an eigenvector of K_ωω (its non-zero components share one
    stiffness) and the initial curvature κ⁰ is parallel to it (or zero): then m' = -κ × m
    vanishes, σ is constant and H = exp(s (f⁰ + ε)) is exact (NOTES.md note 2), for a dead or
    a follower moment alike (the tip turns about the moment axis).
    """
    k = rotational_stiffness(arm)
    size = np.linalg.norm(moment, axis=-1)[..., None]
    present = ~negligible(moment, size)
    same = negligible(k[:, None] - k[None, :], np.maximum(k[:, None], k[None, :]))
    eigen = np.all(~(present[..., :, None] & present[..., None, :]) | same, axis=(-2, -1))
    kappa0 = np.asarray(arm.curvature)
    cross = np.cross(kappa0, moment)
    parallel = np.all(negligible(cross, np.linalg.norm(kappa0) * size), axis=-1)
    return eigen & parallel


def constant_strain_poses(f: np.ndarray, s: np.ndarray) -> np.ndarray:
    """H(s) = exp_SE3(s f) for a constant strain f (B..., 6): poses (B..., N, 4, 4), eq. 32."""
    return se3.exp(s[:, None] * f[..., None, :])


def build(arm: Arm, s: np.ndarray, poses, strains, loads, method: str, exact: bool,
          stresses=None, error_estimate=None) -> Equilibrium:
    """Broadcast the fields to one batch shape and assemble the Equilibrium.

    ``stresses`` defaults to σ = K ε. ``error_estimate`` defaults to 0 for exact results and
    NaN (unknown) for approximations, as :class:`~softarm.Equilibrium` documents.
    """
    n = s.shape[0]
    poses = np.asarray(poses, dtype=np.float64)
    strains = np.asarray(strains, dtype=np.float64)
    if stresses is None:
        stresses = strains * np.diagonal(arm.stiffness)
    batch = np.broadcast_shapes(poses.shape[:-3], strains.shape[:-2],
                                np.shape(stresses)[:-2])
    poses = np.broadcast_to(poses, (*batch, n, 4, 4))
    strains = np.broadcast_to(strains, (*batch, n, 6))
    stresses = np.broadcast_to(stresses, (*batch, n, 6))
    if error_estimate is None:
        error_estimate = 0.0 if exact else float("nan")
    return Equilibrium(s=s, poses=poses, strains=strains, stresses=stresses, arm=arm,
                       loads=tuple(loads), method=method, exact=bool(exact), residual=0.0,
                       error_estimate=error_estimate)


def pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    """[[R, p], [0, 1]] from R (..., 3, 3) and p (..., 3), broadcast."""
    batch = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    H = np.zeros((*batch, 4, 4))
    H[..., :3, :3] = R
    H[..., :3, 3] = p
    H[..., 3, 3] = 1.0
    return H

"""Shared plumbing of the closed forms: argument checks, the pose kernel, the Equilibrium.

Every closed form computes poses H (B..., N, 4, 4) and strains ε (B..., N, 6) on the stations
s (N,); :func:`build` broadcasts them to one batch shape, forms the stresses σ = K ε unless
given, and returns the :class:`~softarm.Equilibrium` without copying the arrays.

:func:`screw_poses` is the fast kernel of the constant-strain and helix closed forms,
H(s) = exp_SE3(s (u; ω)) · exp_SE3(s (0; τ e1)) (docs/closed-forms.md, C4; eq. 32 for τ = 0).
"""

from __future__ import annotations

import math

import numpy as np

from .._admissible import all_finite, check_finite, check_stretch
from .._threads import THREADS_VARIABLE, in_threads, thread_setting, threads_for
from .._validate import as_vectors, stations
from ..equilibrium import Equilibrium
from ..model import Arm, SegmentedArm

__all__ = [
    "E1",
    "ROUNDOFF",
    "THREADS_VARIABLE",
    "build",
    "check_arm",
    "check_follower",
    "checked_stations",
    "constant_strain_poses",
    "moment_is_principal",
    "negligible",
    "rotational_stiffness",
    "screw_poses",
    "stiffness_diagonal",
    "thread_count",
    "thread_setting",
    "vectors",
]

E1 = np.array([1.0, 0.0, 0.0])

#: Relative size under which a component is treated as zero (a few units of roundoff): a
#: closed form that is exact for the zero value is then exact to double precision.
ROUNDOFF = 4.0 * np.finfo(np.float64).eps


def checked_stations(s, length: float) -> np.ndarray:
    """``_validate.stations(s, length)``: a fresh array of stations in m.

    An increasing float64 array inside [0, L] (the common case: the solver's own stations) is
    accepted by a few comparisons and copied; anything else goes through ``stations``, which
    builds the default grid, clips roundoff at the ends or raises.
    """
    if (type(s) is np.ndarray and s.dtype == np.float64 and s.ndim == 1 and s.size >= 1
            and s[0] >= 0.0 and s[-1] <= length and (s[1:] > s[:-1]).all()):
        return s.copy()  # NaN and ±inf fail one of the comparisons
    return stations(s, length)


def negligible(x, scale) -> np.ndarray:
    """|x| is at roundoff level relative to ``scale`` (both broadcast), elementwise."""
    return np.abs(x) <= ROUNDOFF * np.abs(scale)


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


def stiffness_diagonal(arm: Arm) -> np.ndarray:
    """diag K = (EA, GAy, GAz, GJ, EIy, EIz), shape (6,) (without forming the 6×6 matrix)."""
    r = arm.rigidities
    return np.array([r.EA, r.GAy, r.GAz, r.GJ, r.EIy, r.EIz])


def rotational_stiffness(arm: Arm) -> np.ndarray:
    """diag K_ωω = (GJ, EIy, EIz), shape (3,)."""
    r = arm.rigidities
    return np.array([r.GJ, r.EIy, r.EIz])


def moment_is_principal(arm: Arm, moment: np.ndarray) -> np.ndarray:
    """Whether a pure end moment keeps a constant strain on ``arm``, shape (B...).

    True when the moment is an eigenvector of K_ωω (its non-zero components share one
    stiffness) and the initial curvature κ⁰ is parallel to it (or zero): then m' = -κ × m
    vanishes, σ is constant and H = exp(s (f⁰ + ε)) is exact (C2 of docs/closed-forms.md),
    for a dead or a follower moment alike (the tip turns about the moment axis).
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
    """H(s) = exp_SE3(s f) for a constant strain f (B..., 6): poses (B..., N, 4, 4), eq. 32.

    Fresh and read-only; see :func:`screw_poses`.
    """
    return screw_poses(f[..., :3], f[..., 3:], s)[0]


#: Arm × station elements per block of :func:`screw_poses`: the basis buffer (at most 10 rows
#: of this many floats, 640 KiB) and the block of output it expands to stay in the L2 cache.
_BLOCK = 8192

#: Arm × station elements each thread of :func:`screw_poses` gets at least: 1-3 ms of work,
#: against about 0.1 ms to start a thread (a batch of 1000 helices × 101 stations already runs
#: 1.3-1.7× faster on two threads).
_PER_THREAD = 4 * _BLOCK

_EYE3 = np.eye(3)
#: Component orders of the cross product: (a × u)_i = a_{i+1} u_{i+2} - a_{i+2} u_{i+1}.
_NEXT, _LAST = np.array([1, 2, 0]), np.array([2, 0, 1])


def thread_count(elements: int) -> int:
    """Threads for a kernel writing ``elements`` (arm, station) pairs: 1 for small work.

    At most :func:`softarm._threads.available_threads` (``$SOFTARM_NUM_THREADS`` or the CPUs
    available to the process); at least ``_PER_THREAD`` elements per thread.
    """
    return threads_for(elements, _PER_THREAD)


def _broadcast(array: np.ndarray, shape: tuple) -> np.ndarray:
    """``np.broadcast_to``, skipped when the shape already matches (the common case)."""
    return array if np.shape(array) == shape else np.broadcast_to(array, shape)


def _half_angle(rates_half: np.ndarray, s: np.ndarray, t: np.ndarray, q: np.ndarray,
                versine: np.ndarray, sine: np.ndarray) -> None:
    """1 - cos(2 r s) and sin(2 r s) for rates r (m, R) and stations s (N,), into (m, R, N).

    From t = tan(r s): sin φ = 2t/(1 + t²) and 1 - cos φ = 2t²/(1 + t²) hold for every φ (t
    stays finite: no float is an odd multiple of π/2) and have no cancellation, so 1 - cos φ
    keeps its full relative accuracy as φ → 0. One tan, vectorised by numpy, costs a fraction
    of a sin and a cos. ``t`` and ``q`` are (m, R, N) scratch.
    """
    np.multiply(rates_half[:, :, None], s, out=t)
    np.tan(t, out=t)
    np.multiply(t, t, out=q)
    np.add(q, 1.0, out=q)
    np.divide(2.0, q, out=q)
    np.multiply(t, q, out=sine)
    np.multiply(t, sine, out=versine)


def screw_poses(u, omega, s, twist=None, fields=None):
    """Poses of H(s) = exp_SE3(s (u; ω)) · exp_SE3(s (0; τ e1)), and fields linear in ψ = τ s.

    The closed form, per arm (θ = |ω|, a = ω/θ, a = e1 if ω = 0) and station (φ = θ s):

    * rotation exp(φ a~) · exp(ψ e1~), with exp(φ a~) = I + (1 - cos φ)(a aᵀ - I) + sin φ a~
      and the same for ψ about e1;
    * position ∫₀ˢ exp(t ω~) u dt = s (a·u) a + (sin φ/θ) u⊥ + ((1 - cos φ)/θ) a × u, with
      u⊥ = u - (a·u) a: the part of u along the axis advances, the rest turns on a circle. This
      is jac_left(s ω) s u (eq. 69) without the coefficient (θ - sin θ)/θ³ (no cancellation;
      sin φ and 1 - cos φ are divided only by the arm's θ > 0; θ = 0 takes a = e1, where these
      terms vanish).

    Every output entry is linear in the basis b(s) = (1, s, 1 - cos φ, sin φ) and, with twist,
    (1 - cos ψ, sin ψ) and the four products of the φ pair with the ψ pair (k = 4 or 10
    terms): H = Σ_k b_k(s) K_k with per-arm matrices K_k. The kernel fills b for a block of
    arms (one tan per angle, :func:`_half_angle`) and writes every output entry of an arm with
    one small matrix product, (N, k) @ (k, 16 + C), straight into the output buffer: the
    output is written once, contiguously, with no (..., N, 3, 3) temporaries. Blocks of about
    ``_BLOCK`` (arm, station) elements keep b and K in cache (a loop over blocks, not arms).
    Large batches are split into contiguous ranges of arms filled by concurrent threads
    (:func:`thread_count`, at most ``$SOFTARM_NUM_THREADS``); every arm is computed the same
    way in any split, so the result does not depend on the number of threads.

    Parameters
    ----------
    u, omega : ndarray, shape (B..., 3)
        Constant linear and angular strain (1, 1/m), material frame.
    s : ndarray, shape (N,)
        Stations (m).
    twist : ndarray, shape (B...), optional
        τ (1/m), the rate of the trailing rotation about e1.
    fields : ndarray, shape (B..., 3, C), optional
        With ``twist``: C more columns per station, Σ_y b_y(ψ) fields[..., y, :] with
        b = (1, 1 - cos ψ, sin ψ) (the helix's strains and stresses), written by the same
        matrix product into the same buffer.

    Returns
    -------
    poses : ndarray, shape (B..., N, 4, 4)
    extra : ndarray, shape (B..., N, C), or None without ``fields``
        Read-only views of one fresh (B..., N, 16 + C) buffer (so ``poses`` is contiguous
        only without ``fields``).
    """
    shapes = (u.shape[:-1], omega.shape[:-1], () if twist is None else np.shape(twist),
              () if fields is None else fields.shape[:-2])
    batch = shapes[0] if shapes.count(shapes[0]) == 4 else np.broadcast_shapes(*shapes)
    size, n = math.prod(batch), s.shape[0]
    u = _broadcast(u, (*batch, 3)).reshape(size, 3)
    omega = _broadcast(omega, (*batch, 3)).reshape(size, 3)
    theta = np.sqrt(np.einsum("bi,bi->b", omega, omega))
    still = theta == 0.0
    theta_safe = np.where(still, 1.0, theta)
    a = omega / theta_safe[:, None]
    a[still] = E1
    # Per-arm position terms of s, 1 - cos φ and sin φ (θ = 0: a = e1, u⊥ and a × u are
    # multiplied by 0 there).
    along_a = np.einsum("bi,bi->b", a, u)[:, None] * a
    position = np.empty((size, 3, 3))
    position[:, 0] = along_a
    position[still, 0] = u[still]
    position[:, 1] = a[:, _NEXT] * u[:, _LAST] - a[:, _LAST] * u[:, _NEXT]  # a × u
    np.subtract(u, along_a, out=position[:, 2])
    position[:, 1:] /= theta_safe[:, None, None]
    rates = np.empty((size, 1 if twist is None else 2))
    np.multiply(0.5, theta, out=rates[:, 0])
    if twist is not None:
        np.multiply(0.5, _broadcast(twist, batch).reshape(size), out=rates[:, 1])
    twisted = twist is not None
    k, r = (10, 2) if twisted else (4, 1)
    columns = 16 + (0 if fields is None else fields.shape[-1])
    buffer = np.empty((*batch, n, columns))
    flat = buffer.reshape(size, n, columns)
    if fields is not None:
        fields = _broadcast(fields, (*batch, 3, columns - 16)).reshape(size, 3, columns - 16)

    def fill(first: int, last: int) -> None:
        """Write arms first..last-1, block by block, with scratch of its own."""
        # Scratch reused by every block, constant rows written once. Basis rows: 1, s, then
        # (1 - cos, sin) of φ [and ψ] at rows 2 (4) and 3 (5), then the products 1 - cos φ and
        # sin φ times 1 - cos ψ and sin ψ at rows 6-9.
        block = max(1, min(last - first, _BLOCK // max(n, 1)))
        basis = np.empty((block, k, n))
        basis[:, 0] = 1.0
        basis[:, 1] = s
        t, q = np.empty((2, block, r, n))
        K = np.zeros((block, k, columns))
        pose = K[..., :16].reshape(block, k, 4, 4)
        pose[:, 0, :3, :3] = _EYE3
        pose[:, 0, 3, 3] = 1.0
        rotation = pose[..., :3, :3]
        if twisted:  # exp(ψ e1~) = I + (1 - cos ψ) (e1 e1ᵀ - I) + sin ψ e1~
            rotation[:, 4, 1, 1] = rotation[:, 4, 2, 2] = -1.0
            rotation[:, 5, 2, 1], rotation[:, 5, 1, 2] = 1.0, -1.0
        for start in range(first, last, block):
            stop = min(start + block, last)
            m = stop - start
            b, R, ab = basis[:m], rotation[:m], a[start:stop]
            np.multiply(ab[:, :, None], ab[:, None, :], out=R[:, 2])      # a aᵀ - I
            R[:, 2] -= _EYE3
            # a~ = [[0, -a₃, a₂], [a₃, 0, -a₁], [-a₂, a₁, 0]], by flat index 4 i + j of the pose
            K[:m, 3, [9, 2, 4]] = ab
            K[:m, 3, [6, 8, 1]] = -ab
            if twisted:  # P Q, Q = e1 e1ᵀ - I: (0, -P₂, -P₃); Q = e1~: (0, P₃, -P₂) by column
                products = R[:, 6:10].reshape(m, 2, 2, 3, 3)
                np.negative(R[:, 2:4, :, 1:], out=products[:, :, 0, :, 1:])
                products[:, :, 1, :, 1] = R[:, 2:4, :, 2]
                np.negative(R[:, 2:4, :, 1], out=products[:, :, 1, :, 2])
            pose[:m, 1:4, :3, 3] = position[start:stop]
            if fields is not None:
                K[:m, (0, 4, 5), 16:] = fields[start:stop]
            _half_angle(rates[start:stop], s, t[:m], q[:m],
                        b[:, 2:2 + 2 * r:2], b[:, 3:3 + 2 * r:2])
            if twisted:
                np.multiply(b[:, 2:4, None], b[:, None, 4:6], out=b[:, 6:10].reshape(m, 2, 2, n))
            np.matmul(b.transpose(0, 2, 1), K[:m], out=flat[start:stop])

    in_threads(fill, size, thread_count(size * n))
    buffer.setflags(write=False)
    poses = buffer[..., :16].reshape(*batch, n, 4, 4)
    return poses, (None if fields is None else buffer[..., 16:])


def _owned(array) -> np.ndarray:
    """``array`` as float64, made read-only in place if it is a fresh array (owns its data)."""
    array = np.asarray(array, dtype=np.float64)
    if array.base is None:
        array.setflags(write=False)
    return array


def build(arm: Arm, s: np.ndarray, poses, strains, loads, method: str, exact: bool,
          stresses=None, error_estimate=None) -> Equilibrium:
    """Broadcast the fields to one batch shape and assemble the Equilibrium.

    ``poses``, ``strains`` and ``stresses`` must be fresh arrays (or read-only views of them)
    that nothing else writes to: arrays that own their data are made read-only in place and
    handed to the Equilibrium without a copy. ``stresses`` defaults to σ = K ε.

    Every closed form's answer passes here, so the model's limits are checked here once:
    ConvergenceError for NaN or inf anywhere (a formula beyond its range in double
    precision), :class:`~softarm.InadmissibleStateError` for an axial stretch v₁ <= 0 at a
    station (``softarm._admissible``).
    ``error_estimate`` defaults to 0 for exact results and NaN (unknown) for approximations, as
    :class:`~softarm.Equilibrium` documents.
    """
    n = s.shape[0]
    s = _owned(s)
    poses = _owned(poses)
    strains = _owned(strains)
    if stresses is None:
        stresses = strains * stiffness_diagonal(arm)  # K ε
    stresses = _owned(stresses)
    # the model's limits (_admissible): an answer, finite, and an arm that is not inside out.
    # Fields that are views of one contiguous array (a batch route's (B..., N, 28) fields):
    # one pass over it (a pass over each strided view cost as much as the closed form)
    base = poses.base
    if not (isinstance(base, np.ndarray) and base.flags.c_contiguous
            and strains.base is base and stresses.base is base and all_finite(base)):
        check_finite(method, poses, 3)
        check_finite(method, strains, 2)
        check_finite(method, stresses, 2)
    check_stretch(strains, s, stresses=stresses, what=f"the equilibrium ({method})")
    shapes = (poses.shape[:-3], strains.shape[:-2], stresses.shape[:-2])
    batch = shapes[0] if shapes[0] == shapes[1] == shapes[2] else np.broadcast_shapes(*shapes)
    poses = _broadcast(poses, (*batch, n, 4, 4))
    strains = _broadcast(strains, (*batch, n, 6))
    stresses = _broadcast(stresses, (*batch, n, 6))
    if error_estimate is None:
        error_estimate = 0.0 if exact else float("nan")
    return Equilibrium(s=s, poses=poses, strains=strains, stresses=stresses, arm=arm,
                       loads=tuple(loads), method=method, exact=bool(exact), residual=0.0,
                       error_estimate=error_estimate)

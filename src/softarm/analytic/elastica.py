"""Large-deflection cantilever under a dead tip force in a principal plane (planar elastica)."""

from __future__ import annotations

import math

import numpy as np

from .._validate import PART_BYTES, WORK_PER_CASE, check_allocation
from ..loads import TipLoad, check_magnitudes
from ._common import (
    ROUNDOFF,
    build,
    check_arm,
    checked_stations,
    negligible,
    stiffness_diagonal,
    vectors,
)
from ._elastica_math import K_MAX, compiled, lone_rows, planar_elastica

__all__ = ["elastica", "elastica_plane", "solve_elastica"]


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
    :func:`shear_force`); this is the closed form beyond it (docs/closed-forms.md, C8).
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
        plane a +z force gives κ_y = -θ' < 0 (the signs of docs/closed-forms.md, eqs. 50 and 58).

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
    loads = (TipLoad(force=force),)
    check_magnitudes(arm, loads, function)
    return solve_elastica(arm, force, checked_stations(s, arm.length), bool(extensible),
                          loads, function)


def _any(condition) -> bool:
    """``condition.any()`` for an array, the bool itself for a scalar comparison."""
    return bool(condition.any()) if isinstance(condition, np.ndarray) else bool(condition)


def _plane_1(arm, force: np.ndarray, function: str):
    """:func:`elastica_plane` for one force of shape (3,), in floats (b as a tuple)."""
    r = arm.rigidities
    fx, fy, fz = force.tolist()
    size = math.sqrt(fy * fy + fz * fz)
    if size > 0.0:
        by, bz = fy / size, fz / size
    else:
        by, bz = (0.0, 1.0) if r.EIy <= r.EIz else (1.0, 0.0)
    skew = abs(by) > ROUNDOFF and abs(bz) > ROUNDOFF
    if skew and abs(r.EIy - r.EIz) > ROUNDOFF * max(r.EIy, r.EIz):
        elastica_plane(arm, force, function)  # raises its ValueError
    EI = r.EIy * (bz * bz) + r.EIz * (by * by)
    GA = r.GAz * (bz * bz) + r.GAy * (by * by)
    return (0.0, by, bz), math.atan2(size, fx), math.sqrt(fx * fx + fy * fy + fz * fz), EI, GA, \
        skew


def solve_elastica(arm, force: np.ndarray, s: np.ndarray, extensible: bool, loads,
                   function: str = "elastica"):
    """:func:`elastica` for checked arguments: ``force`` (B..., 3) finite, stations ``s`` (N,)
    from ``_validate.stations``; the result carries ``loads`` as given (exact_closed_form
    passes the caller's). A lone force (shape (3,)) takes the compiled route of
    ``_elastica_math`` (``lone_rows`` and ``_compiled.fields``, a fraction of the time
    of the batch route for one case).
    """
    if any(c != 0.0 for c in arm.curvature):
        raise ValueError(
            f"{function}: arm must be initially straight, curvature (0, 0, 0), got "
            f"{arm.curvature}; use softarm.solve for a curved arm"
        )
    lone = force.ndim == 1
    b, phi, P, EI, GA, skew = (_plane_1 if lone else elastica_plane)(arm, force, function)
    r, L = arm.rigidities, arm.length
    if extensible and _any(skew) and not negligible(r.GAy - r.GAz, max(r.GAy, r.GAz)):
        raise ValueError(
            f"{function}: a force outside the principal planes needs GAy = GAz for a planar "
            f"shearable solution, got GAy={r.GAy!r}, GAz={r.GAz!r} N and force {force!r}; "
            "pass extensible=False for the Euler elastica"
        )
    k = P * (L * L) / EI
    if _any(k > K_MAX):
        raise ValueError(
            f"{function}: force must have |F| L²/EI <= {K_MAX:g}, got max "
            f"{float(np.max(k))!r} (|F| up to {float(np.max(P))!r} N)"
        )
    axial_ratio = EI / (r.EA * (L * L)) if extensible else 0.0
    shear_ratio = EI / (GA * (L * L)) if extensible else 0.0
    if extensible and (_any(P >= r.EA) or _any(abs(P / r.EA - P / GA) >= 1.0)):
        raise ValueError(
            f"{function}: force must satisfy |F| < EA and ||F|/EA - |F|/GA| < 1 for the "
            f"extensible elastica, got |F| up to {float(np.max(P))!r} N with EA={r.EA!r} N; "
            "pass extensible=False or use softarm.solve"
        )
    one = None
    if lone and k * (1.0 + abs(k * (axial_ratio - shear_ratio))) <= K_MAX:
        one = lone_rows(k, phi, s / L, axial_ratio, shear_ratio)
    if one is not None:  # one load, compiled: (N, 28) fields written by the kernel
        fields = np.empty((s.shape[0], 28))
        compiled().fields(b[1], b[2], L, stiffness_diagonal(arm), one[0], fields)
    elif lone:  # a load the compiled route refuses: planar_elastica says why
        sol = planar_elastica(k, phi, s / L, axial_ratio=axial_ratio, shear_ratio=shear_ratio)
        fields = _fields(sol, b[1], b[2], L, r)
    else:
        fields = _batch_fields(k, phi, s / L, axial_ratio, shear_ratio, b, L, r)
    fields.setflags(write=False)  # fresh: poses, strains and stresses are views of it
    poses = fields[..., :16].reshape(*fields.shape[:-1], 4, 4)
    strains, stresses = fields[..., 16:22], fields[..., 22:]
    if not extensible:  # γ = 0, and n = Rᵀ F, the constraint force
        strains = np.concatenate([np.zeros_like(strains[..., :3]), strains[..., 3:]], axis=-1)
        n = np.einsum("...ji,...j->...i", poses[..., :3, :3], force[..., None, :])
        stresses = np.concatenate([n, strains[..., 3:] * np.diagonal(arm.stiffness)[3:]],
                                  axis=-1)
    return build(arm, s, poses, strains, loads, "analytic.elastica", extensible,
                 stresses=stresses)


#: Bytes of work per station of the batch route beside its WORK_PER_CASE a load case
#: (planar_elastica's quadrature and its arrays, measured about 10 kB a case and 0.2 kB a
#: station): a batch is evaluated in parts of at most PART_BYTES of work, so that it needs
#: its result's memory and little more
_STATION_BYTES = 400


def _batch_fields(k, phi, s_over_L, axial_ratio, shear_ratio, b, L, r) -> np.ndarray:
    """:func:`_fields` of :func:`planar_elastica` for a batch (B...,) of loads, written part
    by part (along the flattened batch) into one (B..., N, 28) array: the same numbers as
    one call on the whole batch (every load is solved on its own), in bounded memory."""
    shape = np.shape(k)
    count = int(np.prod(shape))
    check_allocation(count, s_over_L.size, "force")  # (softarm.solve checked it already)
    flat = [np.broadcast_to(x, shape).reshape(-1) for x in
            (k, phi, axial_ratio, shear_ratio, b[..., 1], b[..., 2])]
    fields = np.empty((*shape, s_over_L.size, 28))  # (the caller freezes this very array)
    rows = fields.reshape(count, s_over_L.size, 28)  # a view of it
    part = max(1, PART_BYTES // (WORK_PER_CASE + _STATION_BYTES * s_over_L.size))
    for first in range(0, count, part):
        k_, phi_, a_, g_, by, bz = (x[first:first + part] for x in flat)
        sol = planar_elastica(k_, phi_, s_over_L, axial_ratio=a_, shear_ratio=g_)
        rows[first:first + part] = _fields(sol, by, bz, L, r)
    return fields


#: Row and column of every entry of C (see :func:`_fields`) that depends on the plane, L or
#: the stiffnesses.
_ENTRIES = ((1, 1), (1, 2), (1, 4), (1, 8), (2, 5), (2, 10), (2, 6), (2, 9), (3, 3), (4, 7),
            (4, 11), (6, 17), (6, 18), (7, 20), (7, 21), (5, 22), (6, 23), (6, 24), (7, 26),
            (7, 27))
_ROWS, _COLUMNS = (np.array(index) for index in zip(*_ENTRIES, strict=True))
#: C without those entries: I and the pose's 1 (row 0), -1 of a aᵀ - I (row 2), e1 (row 5).
_CONSTANT = np.zeros((8, 28))
_CONSTANT[0, [0, 5, 10, 15]] = 1.0
_CONSTANT[2, 0] = -1.0
_CONSTANT[5, 16] = 1.0


def _fields(sol, by, bz, L, r):
    """Poses (flattened, 16 columns), strains (6) and stresses (6) of the planar solution.

    The section turns by θ about the unit axis a = e1 × b = (0, -b_z, b_y) (b = (0, b_y, b_z)
    the in-plane normal on the force side), so R = I + sin θ a~ + 2 sin²(θ/2) (a aᵀ - I)
    (Rodrigues, eqs. 70-71), p = L (x e1 + z b), γ = N/EA e1 + Q/GA b, κ = (θ'/L) a and
    σ = K ε (``r`` the arm's rigidities). Every entry is linear in c = (1, sin θ,
    2 sin²(θ/2), x, z, N/EA, Q/GA, θ'): one matrix product c @ C per arm, C of shape
    (B..., 8, 28), as in ``_common.screw_poses``; the result has shape (B..., N, 28).
    ``by``, ``bz`` are floats for one load, arrays (B...) for a batch.
    """
    half = np.sin(0.5 * sol.theta)
    columns = [np.ones(half.shape), np.sin(sol.theta), 2.0 * half * half, sol.x, sol.z,
               sol.axial_strain, sol.shear_strain, sol.curvature]
    # a~ = [[0, -b_y, -b_z], [b_y, 0, 0], [b_z, 0, 0]] and a aᵀ - I = [[-1, 0, 0],
    # [0, -b_y², -b_y b_z], [0, -b_y b_z, -b_z²]] (|b| = 1), at flat indices 4 i + j
    entries = (-by, -bz, by, bz, -(by * by), -(bz * bz), -(by * bz), -(by * bz), L, L * by,
               L * bz, by, bz, -bz / L, by / L, r.EA, r.GAy * by, r.GAz * bz,
               -bz / L * r.EIy, by / L * r.EIz)
    if isinstance(by, float):  # one load: a (N, 8) by (8, 28) product
        C = _CONSTANT.copy()
        C[_ROWS, _COLUMNS] = entries
        return np.array(columns).T @ C
    C = np.zeros((*np.shape(by), 8, 28))
    C[...] = _CONSTANT
    for (row, column), value in zip(_ENTRIES, entries, strict=True):
        C[..., row, column] = value
    return np.stack(columns, axis=-1) @ C
